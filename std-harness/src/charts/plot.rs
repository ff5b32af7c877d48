//! Drawing the charts with plotters: the trade-off scatter with its Pareto frontier and the three
//! stability panels, each written as SVG and PNG. Text uses a bundled DejaVu Sans, so the PNGs need
//! no system fonts.

use super::popping::Popping;
use super::stability::Curve;
use super::sweep::Measured;
use crate::io;
use crate::io::outputs::Batch;
use crate::pipeline::quality::config::{accum_name, lookup_name, method_name, Config};
use crate::plan::{Method, Precision};
use crate::CliError;
use footprint::Lookup;
use plotters::coord::Shift;
use plotters::prelude::*;

static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

pub fn register_font() -> Result<(), CliError> {
    static ONCE: std::sync::Once = std::sync::Once::new();
    let mut ok = true;
    ONCE.call_once(|| {
        ok = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok();
    });
    if ok {
        Ok(())
    } else {
        Err(CliError::input(
            "the bundled chart font could not be loaded",
        ))
    }
}

pub(crate) fn plot_err<E: std::fmt::Display>(e: E) -> CliError {
    CliError::input(format!("chart: {e}"))
}

const COLOURS: [RGBColor; 5] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
];

fn series_colour(c: &Config) -> RGBColor {
    if c.slab().is_some() {
        return COLOURS[4];
    }
    let i = match (c.method, c.accum) {
        (Method::Direct, Precision::Float) => 1,
        (Method::Direct, Precision::Fixed) => 3,
        (_, Precision::Float) => 0,
        (_, Precision::Fixed) => 2,
    };
    COLOURS[i]
}

/// Draws the trade-off chart on `root`.
fn draw_tradeoff<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[Measured],
    title: &str,
    truth: bool,
) -> Result<(), CliError>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_err)?;
    let (plot, side) = root.split_horizontally(root.dim_in_pixel().0 * 72 / 100);
    let finite = charted(rows, truth);
    let finite: Vec<&Measured> = finite.iter().collect();
    let (t0, t1) = finite.iter().fold((f64::MAX, 0.0f64), |(a, b), r| {
        (a.min(r.min_s), b.max(r.max_s))
    });
    let (q0, q1) = finite.iter().fold((f64::MAX, f64::MIN), |(a, b), r| {
        (a.min(r.psnr_db), b.max(r.psnr_db))
    });
    let ms = |s: f64| s * 1e3;
    let mut chart = ChartBuilder::on(&plot)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(
            (ms(t0) * 0.9)..(ms(t1) * 1.08),
            (q0 - 3.0).floor()..(q1 + 3.0).ceil(),
        )
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("frame time, ms (median; bar: min-max)")
        .y_desc(if truth {
            "PSNR vs the continuous integral, dB"
        } else {
            "PSNR vs f64 sheet reference, dB"
        })
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(plot_err)?;
    // The frontier, fastest first.
    let mut front: Vec<&Measured> = finite.iter().copied().filter(|r| r.pareto).collect();
    front.sort_by(|a, b| a.median_s.total_cmp(&b.median_s));
    chart
        .draw_series(LineSeries::new(
            front.iter().map(|r| (ms(r.median_s), r.psnr_db)),
            BLACK.stroke_width(2),
        ))
        .map_err(plot_err)?
        .label("Pareto frontier")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(2)));
    for r in &finite {
        let col = series_colour(&r.config);
        let (x, y) = (ms(r.median_s), r.psnr_db);
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(ms(r.min_s), y), (ms(r.max_s), y)],
                col.mix(0.6),
            )))
            .map_err(plot_err)?;
        let label = match r.config.slab() {
            Some(t) => format!("slab {t}"),
            None => format!("{}", r.config.table),
        };
        let style = if r.config.lookup == Lookup::Bilinear {
            col.filled()
        } else {
            col.stroke_width(2)
        };
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((x, y))
                    + Circle::new((0, 0), 4, style)
                    + Text::new(label, (5, -12), ("sans-serif", 11).into_font()),
            ))
            .map_err(plot_err)?;
    }
    for (i, name) in [
        "view, float",
        "direct, float",
        "view, fixed",
        "direct, fixed",
        "image slabs, float",
    ]
    .iter()
    .enumerate()
    {
        let col = COLOURS[i];
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(plot_err)?
            .label(*name)
            .legend(move |(x, y)| Circle::new((x + 9, y), 4, col.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(plot_err)?;
    draw_key(&side, &front)?;
    root.present().map_err(plot_err)?;
    Ok(())
}

/// The rows a trade-off chart plots, with `psnr_db` and `pareto` set to the chart's figure:
/// against the sheet reference (`truth` false) the paper's sheets only (image slabs are another
/// method, not an approximation of that reference); against the continuous integral every row.
/// Rows without a finite figure are left out.
fn charted(rows: &[Measured], truth: bool) -> Vec<Measured> {
    let db = |r: &Measured| if truth { r.continuous_db } else { r.psnr_db };
    let on_front = |r: &Measured| if truth { r.pareto_continuous } else { r.pareto };
    rows.iter()
        .filter(|r| db(r).is_finite() && (truth || r.config.slab().is_none()))
        .map(|r| Measured {
            psnr_db: db(r),
            pareto: on_front(r),
            ..r.clone()
        })
        .collect()
}

/// The trade-off chart's side panel: the key and the frontier's members, fastest first.
fn draw_key<DB: DrawingBackend>(
    side: &DrawingArea<DB, Shift>,
    front: &[&Measured],
) -> Result<(), CliError>
where
    DB::ErrorType: 'static,
{
    let ms = |s: f64| s * 1e3;
    let mut lines = vec![
        "Labels: table size N.".to_string(),
        "Filled: bilinear lookup;".to_string(),
        "ring: nearest.".to_string(),
        String::new(),
        "Pareto frontier (fastest first):".to_string(),
    ];
    for r in front {
        lines.push(match r.config.slab() {
            Some(t) => format!("image slabs {t}"),
            None => format!(
                "{} {} {} n={}",
                method_name(r.config.method),
                lookup_name(r.config.lookup),
                accum_name(r.config.accum),
                r.config.table
            ),
        });
        lines.push(format!("   {:.0} ms, {:.1} dB", ms(r.median_s), r.psnr_db));
    }
    for (i, l) in lines.iter().enumerate() {
        side.draw(&Text::new(
            l.as_str(),
            (8, 40 + 17 * i as i32),
            ("sans-serif", 13).into_font(),
        ))
        .map_err(plot_err)?;
    }
    Ok(())
}

fn draw_stability<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    curves: &[Vec<Curve>; 3],
    popping: Option<&Popping>,
) -> Result<(), CliError>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_err)?;
    let panels = root.split_evenly((1, 3 + usize::from(popping.is_some())));
    if let Some(pop) = popping {
        draw_popping(&panels[3], pop)?;
    }
    let specs = [
        ("(a) rotation about the view axis", "degrees", false),
        ("(b) anisotropy (grid r:1:1)", "ratio r", true),
        ("(c) footprint size", "pixels across", true),
    ];
    for ((panel, set), (title, xdesc, logx)) in panels.iter().zip(curves).zip(specs) {
        let xs: Vec<f64> = set[0].points.iter().map(|p| p.0).collect();
        let (x0, x1) = (xs[0], xs[xs.len() - 1]);
        let ylo = 1e-5f64;
        let yhi = 1.0f64;
        let mut builder = ChartBuilder::on(panel);
        builder
            .caption(title, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(38)
            .y_label_area_size(60);
        let fail_y = yhi * 0.8;
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(xdesc)
                    .y_desc("max error / reference peak")
                    .y_label_formatter(&|v: &f64| format!("{v:.0e}"))
                    .label_style(("sans-serif", 12))
                    .draw()
                    .map_err(plot_err)?;
                for (i, c) in set.iter().enumerate() {
                    let col = COLOURS[i];
                    // Draw each unbroken run of successes as a line.
                    let mut run: Vec<(f64, f64)> = Vec::new();
                    let mut runs = Vec::new();
                    for &(x, e) in &c.points {
                        match e {
                            Some(e) => run.push((x, e.max(ylo))),
                            None => {
                                if !run.is_empty() {
                                    runs.push(std::mem::take(&mut run));
                                }
                            }
                        }
                    }
                    if !run.is_empty() {
                        runs.push(run);
                    }
                    for (k, r) in runs.into_iter().enumerate() {
                        let s = chart
                            .draw_series(LineSeries::new(r, col.stroke_width(2)))
                            .map_err(plot_err)?;
                        if k == 0 {
                            s.label(c.name).legend(move |(x, y)| {
                                PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(2))
                            });
                        }
                    }
                    let fails: Vec<f64> = c
                        .points
                        .iter()
                        .filter(|p| p.1.is_none())
                        .map(|p| p.0)
                        .collect();
                    if !fails.is_empty() {
                        chart
                            .draw_series(
                                fails
                                    .iter()
                                    .map(|&x| Cross::new((x, fail_y), 6, col.stroke_width(2))),
                            )
                            .map_err(plot_err)?
                            .label(format!("{}: failed ({} points)", c.name, fails.len()))
                            .legend(move |(x, y)| Cross::new((x + 9, y), 5, col.stroke_width(2)));
                    }
                }
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 12))
                    .draw()
                    .map_err(plot_err)?;
            }};
        }
        if logx {
            body!(builder
                .build_cartesian_2d((x0..x1).log_scale(), (ylo..yhi).log_scale())
                .map_err(plot_err)?);
        } else {
            body!(builder
                .build_cartesian_2d(x0..x1, (ylo..yhi).log_scale())
                .map_err(plot_err)?);
        }
    }
    root.present().map_err(plot_err)?;
    Ok(())
}

pub(crate) fn write_svg_png(
    out: &mut Batch,
    stem: &str,
    size: (u32, u32),
    draw: impl Fn(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), CliError>,
    draw_png: impl Fn(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), CliError>,
) -> Result<(), CliError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(&root)?;
    }
    out.add(&format!("{stem}.svg"), svg);
    let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        draw_png(&root)?;
    }
    let rgba: Vec<[f32; 4]> = rgb
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]].map(|v| f32::from(v) / 255.0))
        .map(|[r, g, b]| [r, g, b, 1.0])
        .collect();
    let png = io::image::encode_png_rgb(&rgba, size.0 as usize, size.1 as usize)?;
    out.add(&format!("{stem}.png"), png);
    Ok(())
}

/// `DIR/tradeoff.svg` and `.png` (against the sheet reference, object slicing) and
/// `DIR/tradeoff-continuous.svg` and `.png` (every configuration against the continuous
/// integral, with that frontier).
/// A chart over frame time (x, seconds, log scale, padded by `pad` = (below, above) factors
/// around the spread `times` = (fastest min, slowest max)) and PSNR (y, `ys`), with its mesh and
/// axis labels drawn: the levels-of-detail and refinement charts.
pub fn time_chart<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    times: (f64, f64),
    pad: (f64, f64),
    ys: std::ops::Range<f64>,
    y_desc: &str,
) -> Result<TimeChart<'a, DB>, CliError> {
    let tmin = times.0.max(1e-6);
    let tmax = times.1.max(tmin * 2.0);
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d((tmin * pad.0..tmax * pad.1).log_scale(), ys)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("frame time, s (median; bar: min-max)")
        .y_desc(y_desc)
        .draw()
        .map_err(plot_err)?;
    Ok(chart)
}

/// The median, least and greatest of `times` (sorted in place; at least one).
pub fn median_min_max(times: &mut [f64]) -> (f64, f64, f64) {
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], times[0], times[times.len() - 1])
}

/// A timed chart's chart area: log time against a linear axis.
pub type TimeChart<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<
        plotters::coord::combinators::LogCoord<f64>,
        plotters::coord::types::RangedCoordf64,
    >,
>;

/// One timed point: min–max time bar, median, its y, colour and label.
pub struct TimedPoint {
    pub min_s: f64,
    pub max_s: f64,
    pub median_s: f64,
    pub y: f64,
    pub colour: RGBColor,
    pub label: String,
}

/// Draws each point's min–max bar and a filled dot at its median, labelled to its right.
pub fn draw_timed_points<DB: DrawingBackend>(
    chart: &mut TimeChart<'_, DB>,
    points: &[TimedPoint],
) -> Result<(), CliError> {
    chart
        .draw_series(
            points.iter().map(|p| {
                PathElement::new(vec![(p.min_s, p.y), (p.max_s, p.y)], BLACK.stroke_width(1))
            }),
        )
        .map_err(plot_err)?;
    for p in points {
        chart
            .draw_series(std::iter::once(Circle::new(
                (p.median_s, p.y),
                5,
                p.colour.filled(),
            )))
            .map_err(plot_err)?;
        chart
            .draw_series(std::iter::once(Text::new(
                p.label.clone(),
                (p.median_s * 1.04, p.y + 0.4),
                ("sans-serif", 13),
            )))
            .map_err(plot_err)?;
    }
    Ok(())
}

/// The fastest minimum and slowest maximum of timed rows.
pub fn time_spread<T>(rows: &[T], min: impl Fn(&T) -> f64, max: impl Fn(&T) -> f64) -> (f64, f64) {
    (
        rows.iter().map(&min).fold(f64::INFINITY, f64::min),
        rows.iter().map(&max).fold(0.0, f64::max),
    )
}

pub fn write_tradeoff(out: &mut Batch, rows: &[Measured], title: &str) -> Result<(), CliError> {
    for (stem, truth) in [("tradeoff", false), ("tradeoff-continuous", true)] {
        write_svg_png(
            out,
            stem,
            (1100, 650),
            |r| draw_tradeoff(r, rows, title, truth),
            |r| draw_tradeoff(r, rows, title, truth),
        )?;
    }
    Ok(())
}

/// `DIR/stability.svg` and `.png`, with the popping panel when it was swept.
pub fn write_stability(
    out: &mut Batch,
    curves: &[Vec<Curve>; 3],
    popping: Option<&Popping>,
) -> Result<(), CliError> {
    let width = if popping.is_some() { 2000 } else { 1500 };
    write_svg_png(
        out,
        "stability",
        (width, 520),
        |r| draw_stability(r, curves, popping),
        |r| draw_stability(r, curves, popping),
    )
}

/// Panel (d): consecutive-frame change through 40°–50° azimuth, PSNR dB (lower = a larger jump).
fn draw_popping<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    pop: &Popping,
) -> Result<(), CliError>
where
    DB::ErrorType: 'static,
{
    let all = pop
        .change_db
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.is_finite());
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let (lo, hi) = if lo <= hi {
        (lo - 3.0, hi + 8.0)
    } else {
        (0.0, 100.0)
    };
    let (x0, x1) = (pop.azimuths[0], pop.azimuths[pop.azimuths.len() - 1]);
    let mut chart = ChartBuilder::on(panel)
        .caption(
            format!("(d) popping: change per 0.1° (slab {})", pop.slab),
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(38)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, lo..hi)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("azimuth, degrees")
        .y_desc("PSNR of frame vs previous frame, dB")
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(plot_err)?;
    for (k, name) in super::popping::NAMES.iter().enumerate() {
        let col = COLOURS[k];
        let pts: Vec<(f64, f64)> = pop.change_db[k]
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_finite())
            .map(|(i, &v)| (0.5 * (pop.azimuths[i] + pop.azimuths[i + 1]), v))
            .collect();
        chart
            .draw_series(LineSeries::new(pts, col.stroke_width(2)))
            .map_err(plot_err)?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(plot_err)?;
    Ok(())
}
