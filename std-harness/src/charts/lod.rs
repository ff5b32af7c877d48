//! The levels-of-detail sweep (`footprint chart`, `lod.csv` and `lod.svg`/`.png`): every level
//! of the scene from 0 (full resolution) down to `pipeline::stages::lod::deepest_level` (at most
//! [`MAX_CHARTED`]), each rendered with the
//! chart's flags, its frame time (median over the runs, the levels timed in turn within each run
//! so that drift hits them alike) and its PSNR (RGB) against level 0's image. `auto`'s pick is
//! marked.

use super::plot::{plot_err, time_chart, time_spread, write_svg_png};
use crate::args::{Lod, RenderArgs};
use crate::io::outputs::Batch;
use crate::metrics::compare;
use crate::pipeline::Renderer;
use crate::CliError;
use plotters::coord::Shift;
use plotters::prelude::*;

/// The deepest level charted.
pub const MAX_CHARTED: u32 = 6;

/// One level's row.
#[derive(Clone, Debug)]
pub struct LevelRow {
    pub level: u32,
    pub dims: [usize; 3],
    /// The supersampling the level renders with (`--supersample`).
    pub supersample: usize,
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    /// PSNR (RGB) against level 0's image, dB (infinite for level 0).
    pub psnr_db: f64,
}

/// The sweep, and the level `--lod auto` picks for `base`'s view.
pub fn sweep(base: &RenderArgs, runs: usize) -> Result<(Vec<LevelRow>, u32), CliError> {
    let with = |lod: Lod| {
        let mut a = base.clone();
        a.lod = lod;
        a.quality = None;
        a
    };
    // `--lod auto`'s pick, its render dropped before the levels are prepared.
    let (deepest, auto) = {
        let r = super::open(&with(Lod::Auto))?;
        let p = r.prepared();
        let deepest = crate::pipeline::stages::lod::deepest_level(p.fine_dims);
        (deepest.min(MAX_CHARTED), p.level)
    };
    let mut levels: Vec<Renderer> = Vec::new();
    for level in 0..=deepest {
        let r = match super::open(&with(Lod::Level(level))) {
            Ok(r) => r,
            // A frame levels are not placed for (perspective): the sweep ends where they stop.
            Err(e) if level > 0 => {
                crate::say!(
                    "levels of detail: the sweep stops at level {}: {e}",
                    level - 1
                );
                break;
            }
            Err(e) => return Err(e),
        };
        levels.push(r);
    }
    let mut images = Vec::new();
    for r in &mut levels {
        images.push(r.frame()?.0.image);
    }
    let mut times = vec![Vec::new(); levels.len()];
    for _ in 0..runs.max(1) {
        for (r, t) in levels.iter_mut().zip(&mut times) {
            t.push(r.frame()?.0.seconds);
        }
    }
    let full: Vec<[f64; 4]> = images[0].iter().map(|c| c.map(f64::from)).collect();
    let rows = levels
        .iter()
        .zip(&images)
        .zip(&mut times)
        .map(|((r, img), t)| {
            let p = r.prepared();
            t.sort_by(f64::total_cmp);
            LevelRow {
                level: p.level,
                dims: p.frame.dims,
                supersample: p.supersample,
                median_s: t[t.len() / 2],
                min_s: t[0],
                max_s: t[t.len() - 1],
                psnr_db: compare(img, &full).1.psnr_db,
            }
        })
        .collect();
    Ok((rows, auto))
}

/// `level,dims,supersample,median_s,min_s,max_s,psnr_db,speedup,auto`.
pub fn csv(rows: &[LevelRow], auto: u32) -> String {
    let mut s = String::from("level,dims,supersample,median_s,min_s,max_s,psnr_db,speedup,auto\n");
    let base = rows.first().map_or(f64::NAN, |r| r.median_s);
    for r in rows {
        s.push_str(&format!(
            "{},{}x{}x{},{},{:.6},{:.6},{:.6},{},{:.3},{}\n",
            r.level,
            r.dims[0],
            r.dims[1],
            r.dims[2],
            r.supersample,
            r.median_s,
            r.min_s,
            r.max_s,
            if r.psnr_db.is_finite() {
                format!("{:.3}", r.psnr_db)
            } else {
                "inf".into()
            },
            base / r.median_s,
            r.level == auto
        ));
    }
    s
}

/// `DIR/lod.svg` and `.png`: PSNR against level 0 over frame time, one point per level.
pub fn write_chart(
    out: &mut Batch,
    rows: &[LevelRow],
    auto: u32,
    title: &str,
) -> Result<(), CliError> {
    write_svg_png(
        out,
        "lod",
        (900, 560),
        |r| draw(r, rows, auto, title),
        |r| draw(r, rows, auto, title),
    )
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[LevelRow],
    auto: u32,
    title: &str,
) -> Result<(), CliError> {
    root.fill(&WHITE).map_err(plot_err)?;
    let finite: Vec<f64> = rows
        .iter()
        .map(|r| r.psnr_db)
        .filter(|d| d.is_finite())
        .collect();
    let ymax = finite.iter().copied().fold(20.0f64, f64::max) + 10.0;
    let ymin = finite.iter().copied().fold(ymax - 10.0, f64::min).min(30.0) - 5.0;
    let times = time_spread(rows, |r| r.min_s, |r| r.max_s);
    let mut chart = time_chart(
        root,
        title,
        times,
        (0.7, 4.0),
        ymin..ymax,
        "PSNR against level 0, dB (level 0 drawn at the top)",
    )?;
    let y = |r: &LevelRow| {
        if r.psnr_db.is_finite() {
            r.psnr_db
        } else {
            ymax - 2.0
        }
    };
    chart
        .draw_series(rows.iter().map(|r| {
            PathElement::new(
                vec![(r.min_s, y(r)), (r.max_s, y(r))],
                BLACK.stroke_width(1),
            )
        }))
        .map_err(plot_err)?;
    chart
        .draw_series(LineSeries::new(
            rows.iter().map(|r| (r.median_s, y(r))),
            BLUE,
        ))
        .map_err(plot_err)?;
    for r in rows {
        let colour = if r.level == auto { RED } else { BLUE };
        let label = format!(
            "level {} ({}x{}x{}){}",
            r.level,
            r.dims[0],
            r.dims[1],
            r.dims[2],
            if r.level == auto { ", auto" } else { "" }
        );
        chart
            .draw_series(std::iter::once(Circle::new(
                (r.median_s, y(r)),
                5,
                colour.filled(),
            )))
            .map_err(plot_err)?;
        chart
            .draw_series(std::iter::once(Text::new(
                label,
                (r.median_s * 1.05, y(r) + 0.8),
                ("sans-serif", 14),
            )))
            .map_err(plot_err)?;
    }
    root.present().map_err(plot_err)?;
    Ok(())
}
