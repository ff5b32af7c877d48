//! The post-classification sweep (`footprint chart --classification post`: `post.csv` and
//! `post.svg`/`.png`): the scene rendered post-classified at each slab thickness of
//! [`SLABS`] and value subsampling of [`SCALES`], each point's frame time (median over the runs,
//! the configurations timed in turn within each run so that drift hits them alike) and its PSNR
//! (RGB) against the post-classified continuous integral of the same view, in the reconstruction
//! the sweep renders (`--reconstruction`: the kernel or trilinear): the speed a post-classified frame buys with accuracy. The pre-classified trade-off
//! charts do not apply to this mode (they measure against the pre-classified models).

use super::plot::{
    draw_timed_points, median_min_max, plot_err, time_chart, time_spread, write_svg_png, TimedPoint,
};
use crate::args::{ClassificationArg, RenderArgs, Supersample};
use crate::io::outputs::Batch;
use crate::metrics::compare;
use crate::pipeline::ends::continuous::render_continuous_as;
use crate::reference::continuous::{Model, Reconstruction, DEFAULT_CAP};
use crate::CliError;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Slab thicknesses swept, smallest grid spacings.
pub const SLABS: [f32; 7] = [2.0, 1.5, 1.0, 0.7, 0.5, 0.4, 0.3];
/// Value subsamplings swept.
pub const SCALES: [usize; 3] = [1, 2, 3];

/// One configuration's row.
#[derive(Clone, Debug)]
pub struct PostRow {
    pub slab: f32,
    pub scale: usize,
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    /// PSNR (RGB) against the post-classified integral, dB.
    pub psnr_db: f64,
}

/// The sweep over `base` (rendered post-classified whatever its `--classification`).
pub fn sweep(base: &RenderArgs, runs: usize) -> Result<Vec<PostRow>, CliError> {
    let mut base = base.clone();
    base.classification = ClassificationArg::Post;
    let mut r = super::open(&base)?;
    let (truth, _) = render_continuous_as(
        r.prepared(),
        Reconstruction::from(base.reconstruction),
        Model::Post,
        DEFAULT_CAP,
    )?;
    let configs: Vec<(RenderArgs, f32, usize)> = SLABS
        .iter()
        .flat_map(|&slab| SCALES.iter().map(move |&s| (slab, s)))
        .map(|(slab, s)| {
            let mut a = base.clone();
            a.slab_post = Some(slab);
            a.value_subsample = Supersample::Fixed(s);
            (a, slab, s)
        })
        .collect();
    let plans = configs
        .iter()
        .map(|(a, _, _)| crate::args::plan(a))
        .collect::<Result<Vec<_>, _>>()?;
    let mut rows = Vec::new();
    let mut times = vec![Vec::new(); configs.len()];
    // One renderer, one cache: every configuration splats the same voxels, found once.
    for run in 0..=runs.max(1) {
        for (((_, slab, scale), plan), times) in configs.iter().zip(&plans).zip(&mut times) {
            let f = r.frame_of(plan)?;
            if run == 0 {
                rows.push(PostRow {
                    slab: *slab,
                    scale: *scale,
                    median_s: 0.0,
                    min_s: 0.0,
                    max_s: 0.0,
                    psnr_db: compare(&f.image, &truth.image).1.psnr_db,
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

/// `slab,value_subsample,median_s,min_s,max_s,psnr_db`.
pub fn csv(rows: &[PostRow]) -> String {
    let mut s = String::from("slab,value_subsample,median_s,min_s,max_s,psnr_db\n");
    for r in rows {
        s.push_str(&format!(
            "{},{},{:.6},{:.6},{:.6},{:.3}\n",
            r.slab, r.scale, r.median_s, r.min_s, r.max_s, r.psnr_db
        ));
    }
    s
}

/// `DIR/post.svg` and `.png`: PSNR against the post-classified integral over frame time, one
/// point per configuration, a colour per value subsampling; a dashed guide at the 44 dB target.
pub fn write_chart(out: &mut Batch, rows: &[PostRow], title: &str) -> Result<(), CliError> {
    write_svg_png(
        out,
        "post",
        (900, 560),
        |r| draw(r, rows, title),
        |r| draw(r, rows, title),
    )
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[PostRow],
    title: &str,
) -> Result<(), CliError> {
    root.fill(&WHITE).map_err(plot_err)?;
    if rows.is_empty() {
        return Ok(());
    }
    let finite = rows.iter().map(|r| r.psnr_db).filter(|v| v.is_finite());
    let ymax = finite.clone().fold(44.0, f64::max) + 3.0;
    let ymin = finite.fold(44.0, f64::min) - 3.0;
    let (tmin, tmax) = time_spread(rows, |r| r.min_s, |r| r.max_s);
    let mut chart = time_chart(
        root,
        title,
        (tmin, tmax),
        (0.8, 2.0),
        ymin..ymax,
        "PSNR against the post-classified integral, dB",
    )?;
    chart
        .draw_series(DashedLineSeries::new(
            vec![(tmin * 0.8, 44.0), (tmax * 2.0, 44.0)],
            6,
            4,
            BLACK.mix(0.4).stroke_width(1),
        ))
        .map_err(plot_err)?;
    let points: Vec<TimedPoint> = rows
        .iter()
        .map(|r| TimedPoint {
            min_s: r.min_s,
            max_s: r.max_s,
            median_s: r.median_s,
            y: r.psnr_db,
            colour: [BLUE, RED, MAGENTA][(r.scale - 1).min(2)],
            label: format!("slab {}, 1/{}", r.slab, r.scale),
        })
        .collect();
    draw_timed_points(&mut chart, &points)?;
    root.present().map_err(plot_err)?;
    Ok(())
}
