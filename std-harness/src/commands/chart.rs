//! `footprint chart`: speed against accuracy on one scene, and stability where methods fail.
//!
//! **Trade-off** (`DIR/tradeoff.csv`, `.svg`, `.png`): every configuration of table size
//! N ∈ {5, 11, 21, 33, 65, 101, 129}, lookup (nearest, bilinear), method (`view`: the two-stage
//! view table; `direct`) and accumulation (float, fixed) renders the scene `--runs` times. Time is
//! the whole frame as `render` does it (table build, every sheet), median and min–max; error is
//! against the f64 reference of the same scene (PSNR over RGB, max abs), as in `verify`. The
//! math backend is a build-time choice and is recorded in every row. A configuration is on the
//! Pareto frontier when no other is at least as fast and at least as accurate, and strictly
//! better in one of the two.
//!
//! **Stability** (`DIR/stability.svg`, `.png`): one voxel of the paper Gaussian against the exact
//! footprint (max |core − reference| / reference peak), table 65, bilinear:
//! (a) against rotation about the view axis, 0–90° with 0.01° steps from 44.5° to 45.5° and
//! points 10⁻⁴° and 8·10⁻⁵° from 45°, for the robust map and the paper's θ map (with its 0.01°
//! cheat, and without: `--paper-cheat 0`), on a 2:1 grid;
//! (b) against anisotropy 1–1000 (grid spacing r:1:1, seen obliquely); (c) against footprint size
//! 0.1–1000 px across, nearest and bilinear. A configuration that fails (a typed error, a non-finite
//! result) is drawn as a cross on the top edge.

use super::render::{prepare, render_core_with, render_ref, RenderArgs};
use super::splat::{splat_image, SplatArgs};
use super::verify::compare;
use crate::cli::{AccumArg, FootprintArgs, LookupArg, MethodArg};
use crate::io;
use crate::CliError;
use clap::Args;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

#[derive(Args, Debug, Clone)]
pub struct ChartArgs {
    /// The scene and every render flag; `--out` is the output directory (required).
    #[command(flatten)]
    pub render: RenderArgs,
    /// Timed renders per configuration (the median is charted, min–max is the spread).
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Skip the stability sweeps (trade-off only).
    #[arg(long)]
    pub no_stability: bool,
    /// Only print the `--quality` model's footprint error of every configuration at this view
    /// (CSV on standard output; no rendering).
    #[arg(long)]
    pub model_only: bool,
}

/// Table sizes swept.
pub const SIZES: [usize; 7] = [5, 11, 21, 33, 65, 101, 129];

/// One configuration of the sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    pub table: usize,
    pub lookup: LookupArg,
    pub method: MethodArg,
    pub accum: AccumArg,
}

impl Config {
    /// Every configuration the chart sweeps.
    pub fn all() -> Vec<Config> {
        let mut v = Vec::new();
        for table in SIZES {
            for lookup in [LookupArg::Nearest, LookupArg::Bilinear] {
                for method in [MethodArg::Robust, MethodArg::Direct] {
                    for accum in [AccumArg::Float, AccumArg::Fixed] {
                        v.push(Config {
                            table,
                            lookup,
                            method,
                            accum,
                        });
                    }
                }
            }
        }
        v
    }

    /// `n=65/bilinear/view/float/libm`, the bench naming.
    pub fn label(&self) -> String {
        format!(
            "n={}/{}/{}/{}/{}",
            self.table,
            lookup_name(self.lookup),
            method_name(self.method),
            accum_name(self.accum),
            footprint::math::BACKEND
        )
    }

    /// `args` with this configuration's table, lookup, method and accumulation.
    pub fn apply(&self, args: &RenderArgs) -> RenderArgs {
        let mut a = args.clone();
        a.footprint.table = self.table;
        a.footprint.table_file = None;
        a.footprint.lookup = self.lookup;
        a.footprint.method = self.method;
        a.accum = self.accum;
        a
    }
}

pub fn lookup_name(l: LookupArg) -> &'static str {
    match l {
        LookupArg::Nearest => "nearest",
        LookupArg::Bilinear => "bilinear",
    }
}

/// `view` for the two-stage (view-table) methods, as in the bench names.
pub fn method_name(m: MethodArg) -> &'static str {
    match m {
        MethodArg::Robust => "view",
        MethodArg::Paper => "paper",
        MethodArg::Direct => "direct",
        MethodArg::Reference => "reference",
    }
}

pub fn accum_name(a: AccumArg) -> &'static str {
    match a {
        AccumArg::Float => "float",
        AccumArg::Fixed => "fixed",
    }
}

/// One measured configuration.
#[derive(Clone, Debug)]
pub struct Measured {
    pub config: Config,
    /// Frame seconds: median, min, max over the runs.
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    /// Overall RGB PSNR against the f64 reference, dB (infinite if identical).
    pub psnr_db: f64,
    /// Max abs RGB error against the reference.
    pub max_abs: f64,
    /// The `--quality` model's footprint error for this configuration at this view.
    pub footprint_error: f64,
    pub pareto: bool,
}

impl Measured {
    /// PSNR + 20·log₁₀(footprint error): what the `--quality` model calls K, for this row.
    pub fn k_db(&self) -> f64 {
        self.psnr_db + 20.0 * self.footprint_error.log10()
    }
}

/// Renders the scene of `base` with every configuration in `configs`, `runs` times each, and
/// measures it against the f64 reference. Prints one line per configuration.
pub fn sweep(
    base: &RenderArgs,
    configs: &[Config],
    runs: usize,
) -> Result<Vec<Measured>, CliError> {
    let p = prepare(base)?;
    let (reference, ref_s) = render_ref(&p)?;
    crate::say!(
        "{}: {}x{}, reference {:.2} s; {} configurations x {runs} runs",
        p.name,
        base.size.0,
        base.size.1,
        ref_s,
        configs.len()
    );
    // One untimed render first, so the first configuration is not timed with cold caches.
    if let Some(c) = configs.first() {
        render_core_with(&p, &c.apply(base), c.accum)?;
    }
    let mut out = Vec::new();
    for c in configs {
        let args = c.apply(base);
        let mut times = Vec::with_capacity(runs);
        let mut image = Vec::new();
        for _ in 0..runs.max(1) {
            let (img, _, secs) = render_core_with(&p, &args, c.accum)?;
            times.push(secs);
            image = img;
        }
        times.sort_by(f64::total_cmp);
        let (_, overall) = compare(&image, &reference);
        let footprint_error = crate::quality::footprint_error(&p, c)?;
        let m = Measured {
            footprint_error,
            config: *c,
            median_s: times[times.len() / 2],
            min_s: times[0],
            max_s: times[times.len() - 1],
            psnr_db: overall.psnr_db,
            max_abs: overall.max_abs,
            pareto: false,
        };
        crate::say!(
            "{:<36} {:>8.3} s ({:.3}–{:.3})  {:>7.2} dB  max {:.2e}",
            c.label(),
            m.median_s,
            m.min_s,
            m.max_s,
            m.psnr_db,
            m.max_abs
        );
        out.push(m);
    }
    mark_pareto(&mut out);
    Ok(out)
}

/// Marks the configurations no other beats in both time (median) and PSNR.
pub fn mark_pareto(rows: &mut [Measured]) {
    let snapshot: Vec<(f64, f64)> = rows.iter().map(|r| (r.median_s, r.psnr_db)).collect();
    for (i, r) in rows.iter_mut().enumerate() {
        let (t, q) = snapshot[i];
        r.pareto = !snapshot
            .iter()
            .enumerate()
            .any(|(j, &(tj, qj))| j != i && tj <= t && qj >= q && (tj < t || qj > q));
    }
}

/// The trade-off CSV: one row per configuration.
pub fn csv(rows: &[Measured]) -> String {
    let mut s = String::from(
        "config,table,lookup,method,accum,backend,median_s,min_s,max_s,psnr_db,max_abs,footprint_error,k_db,pareto\n",
    );
    for r in rows {
        let c = &r.config;
        s.push_str(&format!(
            "{},{},{},{},{},{},{:.6},{:.6},{:.6},{:.3},{:.4e},{:.4e},{:.3},{}\n",
            c.label(),
            c.table,
            lookup_name(c.lookup),
            method_name(c.method),
            accum_name(c.accum),
            footprint::math::BACKEND,
            r.median_s,
            r.min_s,
            r.max_s,
            r.psnr_db,
            r.max_abs,
            r.footprint_error,
            r.k_db(),
            r.pareto
        ));
    }
    s
}

static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

fn register_font() -> Result<(), CliError> {
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

fn plot_err<E: std::fmt::Display>(e: E) -> CliError {
    CliError::input(format!("chart: {e}"))
}

const COLOURS: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
];

fn series_colour(c: &Config) -> RGBColor {
    let i = match (c.method, c.accum) {
        (MethodArg::Direct, AccumArg::Float) => 1,
        (MethodArg::Direct, AccumArg::Fixed) => 3,
        (_, AccumArg::Float) => 0,
        (_, AccumArg::Fixed) => 2,
    };
    COLOURS[i]
}

/// Draws the trade-off chart on `root`.
fn draw_tradeoff<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[Measured],
    title: &str,
) -> Result<(), CliError>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_err)?;
    let (plot, side) = root.split_horizontally(root.dim_in_pixel().0 * 72 / 100);
    let finite: Vec<&Measured> = rows.iter().filter(|r| r.psnr_db.is_finite()).collect();
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
        .y_desc("PSNR vs f64 reference, dB")
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
        let label = format!("{}", r.config.table);
        let style = if r.config.lookup == LookupArg::Bilinear {
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
    // The side panel: the key and the frontier's members.
    let mut lines = vec![
        "Labels: table size N.".to_string(),
        "Filled: bilinear lookup;".to_string(),
        "ring: nearest.".to_string(),
        String::new(),
        "Pareto frontier (fastest first):".to_string(),
    ];
    for r in &front {
        lines.push(format!(
            "{} {} {} n={}",
            method_name(r.config.method),
            lookup_name(r.config.lookup),
            accum_name(r.config.accum),
            r.config.table
        ));
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
    root.present().map_err(plot_err)?;
    Ok(())
}

/// One stability curve: (x, error) points, `None` where the method failed.
pub struct Curve {
    pub name: &'static str,
    pub points: Vec<(f64, Option<f64>)>,
}

fn splat_error(args: &SplatArgs) -> Option<f64> {
    let core = splat_image(args).ok()?.0;
    let mut r = args.clone();
    r.footprint.method = MethodArg::Reference;
    let reference = splat_image(&r).ok()?.0;
    let e = super::compare::max_rel_diff(&core, &reference).ok()?;
    e.is_finite().then_some(e)
}

fn base_splat(method: MethodArg, lookup: LookupArg) -> SplatArgs {
    SplatArgs {
        footprint: FootprintArgs {
            kernel: "gaussian:spread=1.6,sigmas=2.5".into(),
            table: 65,
            table_file: None,
            lookup,
            method,
            min_radius: footprint::geometry::DEFAULT_MIN_RADIUS_PX,
            paper_cheat: 0.01,
        },
        spacing: [2.0, 1.0, 1.0],
        grid_matrix: None,
        view_matrix: None,
        rotate_x: 0.0,
        rotate_y: 0.0,
        rotate_z: 0.0,
        size: (128, 128),
        center: None,
        out: PathBuf::from("unused.pfm"),
    }
}

/// The three stability sweeps.
pub fn stability() -> [Vec<Curve>; 3] {
    // (a) rotation about the view axis, a 2:1 grid about 40 px across.
    let mut angles: Vec<f64> = (0..=90).map(f64::from).collect();
    angles.extend((0..=100).map(|i| 44.5 + 0.01 * f64::from(i)));
    angles.extend([45.0 - 1e-4, 45.0 + 8e-5, 45.0 + 1e-4]);
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    let rotation = [
        (MethodArg::Robust, 0.01, "robust (Cholesky)"),
        (MethodArg::Paper, 0.01, "paper (θ, 0.01° cheat)"),
        (MethodArg::Paper, 0.0, "paper (θ, no cheat)"),
    ]
    .map(|(m, cheat, name)| Curve {
        name,
        points: angles
            .iter()
            .map(|&a| {
                let mut s = base_splat(m, LookupArg::Bilinear);
                s.footprint.paper_cheat = cheat;
                s.spacing = [12.0, 6.0, 6.0];
                s.rotate_z = a as f32;
                (a, splat_error(&s))
            })
            .collect(),
    })
    .into();
    // (b) anisotropy r:1:1, seen at 30° about y and 20° about x, long axis ~100 px.
    let ratios: Vec<f64> = (0..=30).map(|i| 10f64.powf(f64::from(i) / 10.0)).collect();
    let aniso = [
        (MethodArg::Robust, "robust (Cholesky)"),
        (MethodArg::Paper, "paper (θ, 0.01° cheat)"),
    ]
    .map(|(m, name)| Curve {
        name,
        points: ratios
            .iter()
            .map(|&r| {
                let mut s = base_splat(m, LookupArg::Bilinear);
                let unit = 100.0 / (3.2 * r as f32);
                s.spacing = [unit * r as f32, unit, unit];
                s.rotate_y = 30.0;
                s.rotate_x = 20.0;
                s.rotate_z = 10.0;
                (r, splat_error(&s))
            })
            .collect(),
    })
    .into();
    // (c) footprint size, isotropic, 0.1 to 1000 px across on a 128x128 image.
    let sizes: Vec<f64> = (-10..=30)
        .map(|i| 10f64.powf(f64::from(i) / 10.0))
        .collect();
    let size = [
        (LookupArg::Bilinear, "bilinear"),
        (LookupArg::Nearest, "nearest"),
    ]
    .map(|(l, name)| Curve {
        name,
        points: sizes
            .iter()
            .map(|&d| {
                let mut s = base_splat(MethodArg::Robust, l);
                let spacing = d as f32 / 3.2;
                s.spacing = [spacing; 3];
                s.rotate_z = 10.0;
                s.center = Some([64.3, 64.2]);
                (d, splat_error(&s))
            })
            .collect(),
    })
    .into();
    [rotation, aniso, size]
}

fn draw_stability<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    curves: &[Vec<Curve>; 3],
) -> Result<(), CliError>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_err)?;
    let panels = root.split_evenly((1, 3));
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

/// The stability curves as CSV: panel, curve, x, error (empty where it failed).
fn stability_csv(curves: &[Vec<Curve>; 3]) -> String {
    let mut s = String::from("panel,curve,x,max_rel_error\n");
    for (panel, set) in ["rotation_deg", "anisotropy", "footprint_px"]
        .iter()
        .zip(curves)
    {
        for c in set {
            for &(x, e) in &c.points {
                let e = e.map_or(String::new(), |e| format!("{e:.4e}"));
                s.push_str(&format!("{panel},\"{}\",{x},{e}\n", c.name));
            }
        }
    }
    s
}

fn write_svg_png(
    dir: &Path,
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
    io::write_atomic(&dir.join(format!("{stem}.svg")), svg.as_bytes())?;
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
    io::write_atomic(&dir.join(format!("{stem}.png")), &png)?;
    Ok(())
}

pub fn run(args: &ChartArgs) -> Result<(), CliError> {
    if args.model_only {
        let p = prepare(&args.render)?;
        crate::say!("config,footprint_error");
        for c in Config::all() {
            crate::say!(
                "{},{:.4e}",
                c.label(),
                crate::quality::footprint_error(&p, &c)?
            );
        }
        return Ok(());
    }
    let dir =
        args.render.out.clone().ok_or_else(|| {
            CliError::input("chart needs --out DIR (the directory for the charts)")
        })?;
    if args.runs == 0 {
        return Err(CliError::input("--runs must be at least 1"));
    }
    std::fs::create_dir_all(&dir)
        .map_err(|e| CliError::input(format!("{}: cannot create: {e}", dir.display())))?;
    register_font()?;
    let mut base = args.render.clone();
    base.out = None;
    base.json = None;
    let rows = sweep(&base, &Config::all(), args.runs)?;
    io::write_atomic(&dir.join("tradeoff.csv"), csv(&rows).as_bytes())?;
    let name = base
        .volume
        .as_ref()
        .and_then(|p| p.file_name())
        .map_or("built-in scene".to_string(), |n| {
            n.to_string_lossy().into_owned()
        });
    let title = format!(
        "{name}, {}x{}: frame time against error ({} backend)",
        base.size.0,
        base.size.1,
        footprint::math::BACKEND
    );
    write_svg_png(
        &dir,
        "tradeoff",
        (1100, 650),
        |r| draw_tradeoff(r, &rows, &title),
        |r| draw_tradeoff(r, &rows, &title),
    )?;
    crate::say!("Pareto frontier:");
    let mut front: Vec<&Measured> = rows.iter().filter(|r| r.pareto).collect();
    front.sort_by(|a, b| a.median_s.total_cmp(&b.median_s));
    for r in front {
        crate::say!(
            "  {:<36} {:.3} s  {:.2} dB",
            r.config.label(),
            r.median_s,
            r.psnr_db
        );
    }
    if !args.no_stability {
        let curves = stability();
        io::write_atomic(
            &dir.join("stability.csv"),
            stability_csv(&curves).as_bytes(),
        )?;
        write_svg_png(
            &dir,
            "stability",
            (1500, 520),
            |r| draw_stability(r, &curves),
            |r| draw_stability(r, &curves),
        )?;
        for (panel, set) in ["rotation", "anisotropy", "footprint size"]
            .iter()
            .zip(&curves)
        {
            for c in set {
                let worst = c.points.iter().filter_map(|p| p.1).fold(0.0f64, f64::max);
                let fails = c.points.iter().filter(|p| p.1.is_none()).count();
                crate::say!(
                    "stability {panel}: {:<24} worst {:.2e}, {} failed",
                    c.name,
                    worst,
                    fails
                );
            }
        }
    }
    crate::say!("wrote {}", dir.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(t: f64, q: f64) -> Measured {
        Measured {
            config: Config::all()[0],
            median_s: t,
            min_s: t,
            max_s: t,
            psnr_db: q,
            max_abs: 0.0,
            footprint_error: 0.1,
            pareto: false,
        }
    }

    #[test]
    fn pareto_keeps_exactly_the_undominated() {
        // (time, PSNR): b dominates c (faster and better); a and d trade off; e ties a.
        let mut rows = vec![
            row(1.0, 40.0),
            row(2.0, 60.0),
            row(2.5, 55.0),
            row(3.0, 70.0),
            row(1.0, 40.0),
        ];
        mark_pareto(&mut rows);
        let front: Vec<bool> = rows.iter().map(|r| r.pareto).collect();
        assert_eq!(front, [true, true, false, true, true]);
    }

    #[test]
    fn every_configuration_once_with_bench_names() {
        let all = Config::all();
        assert_eq!(all.len(), 56);
        let mut labels: Vec<String> = all.iter().map(Config::label).collect();
        labels.sort();
        labels.dedup();
        assert_eq!(labels.len(), 56);
        assert!(labels.contains(&format!(
            "n=33/bilinear/direct/fixed/{}",
            footprint::math::BACKEND
        )));
    }
}
