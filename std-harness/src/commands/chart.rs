//! `footprint chart`: speed against accuracy on one scene, and stability where methods fail (see
//! [`crate::charts`] for what is swept and how it is measured).

use crate::args::{ClassificationArg, Lod, RenderArgs};
use crate::charts::{lod, plot, popping, post, refine, stability, sweep};
use crate::io::outputs::Batch;
use crate::pipeline::quality::config::Config;
use crate::pipeline::quality::model as quality;
use crate::CliError;
use clap::Args;

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
    /// Skip the popping sweep (the stability chart's panel d: 101 frames through azimuth
    /// 40°–50°, each with object slicing, image slicing and the continuous reference).
    #[arg(long)]
    pub no_popping: bool,
    /// Image size of the popping sweep, WxH pixels.
    #[arg(long, default_value = "128x128", value_parser = crate::args::parse_size)]
    pub popping_size: (usize, usize),
    /// Skip the levels-of-detail sweep (lod.csv, lod.svg, lod.png).
    #[arg(long)]
    pub no_lod: bool,
    /// Only the levels-of-detail sweep (no trade-off or stability charts).
    #[arg(long, conflicts_with = "no_lod")]
    pub lod_only: bool,
    /// Only the refinement sweep (refine.csv, refine.svg, refine.png): the built-in scene at
    /// --scene-size, unrefined and at each --refine threshold, against --refine-reference.
    #[arg(long, conflicts_with = "lod_only")]
    pub refine_only: bool,
    /// The finer sampling the refinement sweep measures against, N×N×N.
    #[arg(long, value_name = "N", default_value_t = 128, value_parser = crate::args::parse_scene_size)]
    pub refine_reference: usize,
    /// Only print the `--quality` model's footprint error of every configuration at this view
    /// (CSV on standard output; no rendering).
    #[arg(long)]
    pub model_only: bool,
}

pub fn run(args: &ChartArgs) -> Result<(), CliError> {
    if args.render.blend != crate::args::BlendArg::Composite {
        return Err(CliError::input(
            "chart --blend: the charts sweep composited configurations against composited \
             models; measure a projection with verify --blend ... --reference continuous",
        ));
    }
    if args.model_only {
        let r = crate::charts::open(&args.render)?;
        let p = r.prepared();
        crate::say!("config,footprint_error");
        for c in Config::for_frame(&p.frame) {
            crate::say!("{},{:.4e}", c.label(), quality::footprint_error(p, &c)?);
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
    // Every file is written at the end, all or nothing (a folder that does not exist yet is
    // created only then): a failure or a signal leaves no half-charted folder.
    let mut out = Batch::new("--out", &dir)?;
    plot::register_font()?;
    let mut base = args.render.clone();
    base.out = None;
    base.json = None;
    // The trade-off, stability, popping and refinement charts measure the method against the
    // continuous reference, which integrates full resolution: `--lod auto` means level 0 there
    // (the levels-of-detail sweep sets its own levels).
    if base.lod == Lod::Auto {
        base.lod = Lod::Level(0);
    }
    let name = base
        .volume
        .as_ref()
        .or(base.stream.as_ref())
        .and_then(|p| p.file_name())
        .map_or("built-in scene".to_string(), |n| {
            n.to_string_lossy().into_owned()
        });
    if base.classification == ClassificationArg::Post {
        // Post-classification has its own trade-off (slab and value subsampling against the
        // post-classified integral); the pre-classified sweeps do not apply to it.
        let rows = post::sweep(&base, args.runs)?;
        out.add("post.csv", post::csv(&rows));
        let title = format!(
            "{name}, {}x{}: post-classified ({}) frame time against error",
            base.size.0,
            base.size.1,
            crate::reference::continuous::Reconstruction::from(base.reconstruction).name()
        );
        post::write_chart(&mut out, &rows, &title)?;
    } else if args.refine_only {
        refine_chart(&mut out, &base, args)?;
    } else {
        if !args.no_lod {
            lod_chart(&mut out, &base, &name, args.runs)?;
        }
        if !args.lod_only {
            tradeoff_chart(&mut out, &base, &name, args.runs)?;
            if !args.no_stability {
                stability_chart(&mut out, &base, args)?;
            }
        }
    }
    out.commit()?;
    crate::say!("wrote {}", dir.display());
    Ok(())
}

/// The refinement sweep: refine.csv and its chart.
fn refine_chart(out: &mut Batch, base: &RenderArgs, args: &ChartArgs) -> Result<(), CliError> {
    let rows = refine::sweep(base, args.refine_reference, args.runs)?;
    out.add("refine.csv", refine::csv(&rows));
    let title = format!(
        "built-in scene {n}^3 at {}x{}, against {r}^3: --refine, {} thread(s)",
        base.size.0,
        base.size.1,
        base.thread_count(),
        n = base.scene_size,
        r = args.refine_reference,
    );
    refine::write_chart(out, &rows, &title)?;
    for r in &rows {
        crate::say!(
            "refine {}: {} samples, {:.4} s ({:.2}x unrefined), {:.2} dB ({:+.2} dB)",
            refine::label(r),
            r.samples,
            r.median_s,
            r.median_s / rows[0].median_s,
            r.psnr_db,
            r.psnr_db - rows[0].psnr_db
        );
    }
    Ok(())
}

/// The levels-of-detail sweep: lod.csv and its chart.
fn lod_chart(out: &mut Batch, base: &RenderArgs, name: &str, runs: usize) -> Result<(), CliError> {
    let (rows, auto) = lod::sweep(base, runs)?;
    out.add("lod.csv", lod::csv(&rows, auto));
    let title = format!(
        "{name}, {}x{}: levels of detail, {} thread(s)",
        base.size.0,
        base.size.1,
        base.thread_count()
    );
    lod::write_chart(out, &rows, auto, &title)?;
    for r in &rows {
        crate::say!(
            "lod {}: {:?}, {:.4} s ({:.1}x level 0), {:.2} dB against level 0{}",
            r.level,
            r.dims,
            r.median_s,
            rows[0].median_s / r.median_s,
            r.psnr_db,
            if r.level == auto { " (auto)" } else { "" }
        );
    }
    Ok(())
}

/// The trade-off sweep over every configuration: tradeoff.csv, its chart and both frontiers.
fn tradeoff_chart(
    out: &mut Batch,
    base: &RenderArgs,
    name: &str,
    runs: usize,
) -> Result<(), CliError> {
    let opened = crate::charts::open(base)?;
    let prepared = opened.prepared();
    let mut configs = Config::for_frame(&prepared.frame);
    configs.extend(Config::slabs(&prepared.frame, &prepared.kernel));
    drop(opened);
    let rows = sweep::sweep(base, &configs, runs)?;
    out.add("tradeoff.csv", sweep::csv(&rows));
    let title = format!(
        "{name}, {}x{}: frame time against error ({} backend)",
        base.size.0,
        base.size.1,
        footprint::math::BACKEND
    );
    plot::write_tradeoff(out, &rows, &title)?;
    print_frontier("Pareto frontier:", &rows, |r| r.pareto, |r| r.psnr_db);
    print_frontier(
        "Pareto frontier against the continuous integral:",
        &rows,
        |r| r.pareto_continuous,
        |r| r.continuous_db,
    );
    Ok(())
}

/// The stability sweeps (rotation, anisotropy, footprint size) and, unless `--no-popping`, the
/// popping sweep: stability.csv, popping.csv and their chart.
fn stability_chart(out: &mut Batch, base: &RenderArgs, args: &ChartArgs) -> Result<(), CliError> {
    let curves = stability::stability();
    out.add("stability.csv", stability::stability_csv(&curves));
    let pop = if args.no_popping {
        None
    } else {
        let mut a = base.clone();
        a.size = args.popping_size;
        // A scene the sweep cannot render (a footprint-model kernel has no continuous
        // reference or slabs; a perspective view no slabs) charts without panel (d).
        match popping::popping(&a, crate::io::progress::sheets("popping")) {
            Ok(pop) => {
                out.add("popping.csv", pop.csv());
                for (k, name) in popping::NAMES.iter().enumerate() {
                    let (db, az) = pop.worst(k);
                    crate::say!("popping: {name:<21} largest change {db:.2} dB (PSNR) at {az:.1}°");
                }
                Some(pop)
            }
            Err(e) => {
                crate::warn!("the popping panel (d) is left out: {e}");
                None
            }
        }
    };
    plot::write_stability(out, &curves, pop.as_ref())?;
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
    Ok(())
}

/// Prints one frontier, fastest first: the rows `on` marks, with the PSNR `db` gives.
fn print_frontier(
    title: &str,
    rows: &[sweep::Measured],
    on: impl Fn(&sweep::Measured) -> bool,
    db: impl Fn(&sweep::Measured) -> f64,
) {
    crate::say!("{title}");
    let mut front: Vec<&sweep::Measured> = rows.iter().filter(|r| on(r)).collect();
    front.sort_by(|a, b| a.median_s.total_cmp(&b.median_s));
    for r in front {
        crate::say!(
            "  {:<36} {:.3} s  {:.2} dB",
            r.config.label(),
            r.median_s,
            db(r)
        );
    }
}
