//! The refinement sweep (`footprint chart --refine-only`, `refine.csv` and `refine.svg`/`.png`):
//! the built-in scene's analytic field sampled at `--scene-size` (16 for issue 15's test) and
//! rendered unrefined and with `--refine` at each of [`THRESHOLDS`], each point's frame time
//! (median over the runs, the configurations timed in turn within each run so that drift hits
//! them alike) and its PSNR (RGB) against the same field sampled at a finer grid
//! (`--refine-reference`, 128 by default) rendered with the same flags. The paper calls the
//! threshold "a time versus quality tradeoff control"; this is that trade-off, measured.

use super::plot::{
    draw_timed_points, median_min_max, plot_err, time_chart, time_spread, write_svg_png, TimedPoint,
};
use crate::args::RenderArgs;
use crate::io::outputs::Batch;
use crate::metrics::compare;
use crate::pipeline::Renderer;
use crate::CliError;
use plotters::coord::Shift;
use plotters::prelude::*;

/// The thresholds swept (premultiplied RGBA differences).
pub const THRESHOLDS: [f32; 7] = [0.5, 0.3, 0.2, 0.1, 0.05, 0.02, 0.0];

/// One configuration's row.
#[derive(Clone, Debug)]
pub struct RefineRow {
    /// `None`: unrefined.
    pub threshold: Option<f32>,
    /// Whether the sheet axis was refined too.
    pub sheets: bool,
    /// Samples splatted (refined grid; the coarse grid unrefined).
    pub samples: usize,
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    /// PSNR (RGB) against the finer sampling, dB.
    pub psnr_db: f64,
}

/// The sweep over `base` (the built-in scene only), against the field sampled at `reference`³.
pub fn sweep(base: &RenderArgs, reference: usize, runs: usize) -> Result<Vec<RefineRow>, CliError> {
    if base.volume.is_some() || base.stream.is_some() {
        return Err(CliError::input(
            "the refinement chart measures against a finer sampling of the built-in scene's \
             analytic field: give no volume (set the grid with --scene-size)",
        ));
    }
    let mut fine = base.clone();
    fine.scene_size = reference;
    fine.refine = None;
    fine.refine_sheets = false;
    let truth: Vec<[f64; 4]> = super::open(&fine)?
        .frame()?
        .0
        .image
        .iter()
        .map(|c| c.map(f64::from))
        .collect();
    let mut configs: Vec<(RenderArgs, Option<f32>, bool)> = Vec::new();
    let mut with = |t: Option<f32>, sheets: bool| {
        let mut a = base.clone();
        a.refine = t;
        a.refine_sheets = sheets;
        a.quality = None;
        configs.push((a, t, sheets));
    };
    with(None, false);
    for t in THRESHOLDS {
        with(Some(t), false);
    }
    with(Some(0.0), true);
    let opened: Vec<Renderer> = configs
        .iter()
        .map(|(a, _, _)| super::open(a))
        .collect::<Result<_, _>>()?;
    let mut rows = Vec::new();
    let mut times = vec![Vec::new(); configs.len()];
    for run in 0..=runs.max(1) {
        for (((_, t, sheets), r), times) in configs.iter().zip(&opened).zip(&mut times) {
            let (p, f) = (r.prepared(), r.fresh_frame_of(r.plan())?);
            if run == 0 {
                // The first pass gives the image (and warms caches); the rest are timed.
                rows.push(RefineRow {
                    threshold: *t,
                    sheets: *sheets,
                    samples: f
                        .refine
                        .as_ref()
                        .map_or(p.frame.dims.iter().product(), |r| r.samples),
                    median_s: 0.0,
                    min_s: 0.0,
                    max_s: 0.0,
                    psnr_db: compare(&f.image, &truth).1.psnr_db,
                });
            } else {
                times.push(f.seconds);
            }
        }
    }
    for (r, t) in rows.iter_mut().zip(&mut times) {
        (r.median_s, r.min_s, r.max_s) = median_min_max(t);
    }
    Ok(rows)
}

/// A row's label: `unrefined`, `t=0.1`, or `t=0 +sheets`.
pub fn label(r: &RefineRow) -> String {
    match r.threshold {
        None => "unrefined".into(),
        Some(t) => format!("t={t}{}", if r.sheets { " +sheets" } else { "" }),
    }
}

/// `threshold,sheets,samples,median_s,min_s,max_s,psnr_db,time_ratio,gain_db` (ratio and gain
/// against the unrefined row; threshold empty for it).
pub fn csv(rows: &[RefineRow]) -> String {
    let mut s =
        String::from("threshold,sheets,samples,median_s,min_s,max_s,psnr_db,time_ratio,gain_db\n");
    let base = rows.first();
    for r in rows {
        s.push_str(&format!(
            "{},{},{},{:.6},{:.6},{:.6},{:.3},{:.3},{:.3}\n",
            r.threshold.map_or(String::new(), |t| t.to_string()),
            r.sheets,
            r.samples,
            r.median_s,
            r.min_s,
            r.max_s,
            r.psnr_db,
            base.map_or(f64::NAN, |b| r.median_s / b.median_s),
            base.map_or(f64::NAN, |b| r.psnr_db - b.psnr_db),
        ));
    }
    s
}

/// `DIR/refine.svg` and `.png`: PSNR against the finer sampling over frame time, one point per
/// threshold; dashed guides at twice the unrefined time and 3 dB above its PSNR (issue 15's bar).
pub fn write_chart(out: &mut Batch, rows: &[RefineRow], title: &str) -> Result<(), CliError> {
    write_svg_png(
        out,
        "refine",
        (900, 560),
        |r| draw(r, rows, title),
        |r| draw(r, rows, title),
    )
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[RefineRow],
    title: &str,
) -> Result<(), CliError> {
    root.fill(&WHITE).map_err(plot_err)?;
    let Some(base) = rows.first() else {
        return Ok(());
    };
    let ymax = rows.iter().map(|r| r.psnr_db).fold(f64::MIN, f64::max) + 3.0;
    let ymin = rows.iter().map(|r| r.psnr_db).fold(f64::MAX, f64::min) - 3.0;
    let (tmin, tmax) = time_spread(rows, |r| r.min_s, |r| r.max_s);
    let mut chart = time_chart(
        root,
        title,
        (tmin, tmax),
        (0.8, 2.0),
        ymin..ymax,
        "PSNR against the finer sampling, dB",
    )?;
    let guide = BLACK.mix(0.4).stroke_width(1);
    let (t2, g3) = (2.0 * base.median_s, base.psnr_db + 3.0);
    chart
        .draw_series(DashedLineSeries::new(
            vec![(t2, ymin), (t2, ymax)],
            6,
            4,
            guide,
        ))
        .map_err(plot_err)?;
    chart
        .draw_series(DashedLineSeries::new(
            vec![(tmin * 0.8, g3), (tmax * 2.0, g3)],
            6,
            4,
            guide,
        ))
        .map_err(plot_err)?;
    let points: Vec<TimedPoint> = rows
        .iter()
        .map(|r| TimedPoint {
            min_s: r.min_s,
            max_s: r.max_s,
            median_s: r.median_s,
            y: r.psnr_db,
            colour: match (r.threshold, r.sheets) {
                (None, _) => RED,
                (_, true) => MAGENTA,
                _ => BLUE,
            },
            label: format!("{} ({} samples)", label(r), r.samples),
        })
        .collect();
    draw_timed_points(&mut chart, &points)?;
    root.present().map_err(plot_err)?;
    Ok(())
}
