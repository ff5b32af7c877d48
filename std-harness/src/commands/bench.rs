//! `footprint bench`: frame times of one volume, loaded once. Frame 1 renders from the freshly
//! loaded volume (tables and classification included, loading excluded); each later frame turns
//! `--orbit` degrees of azimuth further (a user turning the volume around) and may reuse what the
//! earlier frames cached (the visible-voxel lists of each sheet axis).
//!
//! Prints and writes (`--json`): `first_ms` (what a fresh volume costs: frame 1 and `plan_ms`,
//! choosing the plan, the default's pilot or `--quality`'s; the default's pilot renders frame 1
//! itself, so there `first_ms` is `plan_ms`), `plan_ms`, `median_ms`,
//! `min_ms`, `max_ms` (over frames 2…N, which keep frame 1's plan; null when N = 1), `threads`, `phases_ms` (frame 1: `classify`, `tables`, `splat`,
//! `composite`, and `resample` for `--subsample`), `rerender_phases_ms` (the same, medians over
//! frames 2…N), `frames_ms` (every frame), `frames`, `orbit_deg`, `culled_voxels` (frame 1's
//! voxels skipped by occlusion culling, `--cull`; per band, as `render` counts them) and
//! `culled_voxels_per_frame`, and the render summary's fields (`plan`: what drew the frames).

use crate::args::keywords::{self, Keywords, Value};
use crate::args::{plan, RenderArgs};
use crate::io::{self, json::Json};
use crate::pipeline::quality::model::quality_json;
use crate::pipeline::stages::bands::Phases;
use crate::pipeline::{describe, Renderer};
use crate::CliError;
use clap::Args;

#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// The scene and every render flag (`--out` writes frame 1's image, if given).
    #[command(flatten)]
    pub render: RenderArgs,
    /// Frames to render (1 to 100 000).
    #[arg(long, default_value_t = 10)]
    pub frames: usize,
    /// Azimuth added per frame, degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = crate::args::parse_finite_f32)]
    pub orbit: f32,
}

/// `bench`'s own keywords (`frames`, `orbit`), then `render`'s.
impl Keywords for BenchArgs {
    fn set(&mut self, key: &str, v: &Value) -> Result<(), CliError> {
        match key {
            "frames" => self.frames = keywords::whole(key, v)? as usize,
            "orbit" => {
                self.orbit = crate::args::finite_f32(keywords::finite(key, v)?)
                    .map_err(|e| keywords::refused(key, v, e))?
            }
            _ => self.render.set(key, v)?,
        }
        Ok(())
    }
}

/// Most frames one bench renders: its per-frame times (about 50 bytes a frame) stay small, and
/// even 1 ms frames take under two minutes.
const MAX_FRAMES: usize = 100_000;

fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[s.len() / 2]
}

fn phases_json(p: &Phases) -> Json {
    Json::object()
        .num("classify", p.classify * 1e3)
        .num("tables", p.tables * 1e3)
        .num("splat", p.splat * 1e3)
        .num("composite", p.composite * 1e3)
        .num("resample", p.resample * 1e3)
}

/// Each phase's median over `later` frames.
fn medians(later: &[Phases]) -> Phases {
    let over = |phase: fn(&Phases) -> f64| median(&later.iter().map(phase).collect::<Vec<_>>());
    Phases {
        classify: over(|p| p.classify),
        tables: over(|p| p.tables),
        splat: over(|p| p.splat),
        composite: over(|p| p.composite),
        resample: over(|p| p.resample),
    }
}

/// Every rule the flags decide, before anything is loaded.
fn check(args: &BenchArgs) -> Result<(), CliError> {
    plan(&args.render)?;
    if args.frames == 0 {
        return Err(CliError::input("--frames must be at least 1"));
    }
    if args.frames > MAX_FRAMES {
        return Err(CliError::input(format!(
            "--frames {}: at most {MAX_FRAMES} frames (each frame's times are kept for the medians)",
            args.frames
        )));
    }
    if !args.orbit.is_finite() {
        return Err(CliError::input(
            "--orbit must be a finite number of degrees",
        ));
    }
    args.render.note_inputs();
    io::outputs::check_image_and_json(args.render.out.as_deref(), args.render.json.as_deref())?;
    if let Some(out) = &args.render.out {
        io::image::check_style(out, args.render.png_style())?;
    }
    Ok(())
}

pub fn run(args: &BenchArgs) -> Result<(), CliError> {
    check(args)?;
    let base = &args.render;
    let inputs = crate::args::scene(base)?;
    let asked = plan(base)?;
    // The default plan's pilot (or --quality's) is part of a fresh volume's cost.
    let mut r = Renderer::open(&inputs, &asked)?;
    let plan_ms = r.choosing_seconds() * 1e3;
    // Frame 1 as the default plan's pilot rendered it, if it did (its time is in plan_ms).
    let mut pilot_frame = false;
    let mut times = Vec::with_capacity(args.frames);
    let mut phases = Vec::with_capacity(args.frames);
    let mut first_image = None;
    let mut threads = 1;
    let mut culled = Vec::with_capacity(args.frames);
    for k in 0..args.frames {
        // The same plan every frame; only the view turns.
        if k > 0 {
            r.reframe(&inputs.turned(args.orbit * k as f32))?;
        }
        let (f, piloted) = r.frame()?;
        pilot_frame |= piloted;
        crate::say!(
            "frame {:>3}: {:8.2} ms (classify {:.2}, tables {:.2}, splat {:.2}, composite {:.2}, resample {:.2}); sheets along {}",
            k + 1,
            f.seconds * 1e3,
            f.phases.classify * 1e3,
            f.phases.tables * 1e3,
            f.phases.splat * 1e3,
            f.phases.composite * 1e3,
            f.phases.resample * 1e3,
            ["i", "j", "k"][r.prepared().frame.sheet_axis]
        );
        times.push(f.seconds * 1e3);
        phases.push(f.phases);
        threads = f.threads;
        culled.push(f.stats.culled_voxels as f64);
        if k == 0 {
            first_image = Some(f.image);
        } else {
            r.recycle(f.image);
        }
    }
    let (p, plan, choice) = r.into_parts();
    let later = &times[1..];
    let first = if pilot_frame {
        plan_ms
    } else {
        times[0] + plan_ms
    };
    let med = median(later);
    let (min, max) = later
        .iter()
        .fold((f64::NAN, f64::NAN), |(lo, hi), &t| (lo.min(t), hi.max(t)));
    let rerender = medians(&phases[1..]);
    let later_text = if later.is_empty() {
        "no later frames (--frames 1)".to_string()
    } else {
        format!("frames 2..: median {med:.2} ms (min {min:.2}, max {max:.2})")
    };
    crate::say!(
        "{}: {} frames on {threads} thread(s): first {first:.2} ms{}; {later_text}",
        p.name,
        args.frames,
        match (&choice, pilot_frame) {
            (Some(_), true) => format!(
                " (the plan's pilot, which rendered frame 1 in {:.2} ms)",
                times[0]
            ),
            (Some(_), false) => format!(
                " (choosing the plan {plan_ms:.2} ms, frame 1 {:.2} ms)",
                times[0]
            ),
            (None, _) => String::new(),
        }
    );
    let mut files: Vec<(&std::path::Path, Vec<u8>)> = Vec::new();
    if let Some(out) = &base.out {
        let img = first_image.expect("frame 1 was rendered");
        files.push((
            out.as_path(),
            io::image::encode_rgb_for(out, &img, base.size.0, base.size.1, base.png_style())?,
        ));
    }
    if let Some(j) = &base.json {
        let mut summary = describe(&p, &inputs, &plan)
            .str("command", "bench")
            .num("frames", args.frames as f64)
            .num("orbit_deg", f64::from(args.orbit))
            .num("threads", threads as f64)
            .num("first_ms", first)
            .num("plan_ms", plan_ms)
            .num("median_ms", med)
            .num("min_ms", min)
            .num("max_ms", max)
            .obj("phases_ms", phases_json(&phases[0]))
            .obj("rerender_phases_ms", phases_json(&rerender))
            .arr_f64("frames_ms", &times)
            .num("culled_voxels", culled[0])
            .arr_f64("culled_voxels_per_frame", &culled);
        if let Some(c) = &choice {
            summary = summary.obj("quality", quality_json(c));
        }
        files.push((j.as_path(), summary.finish().into_bytes()));
    }
    io::outputs::write_all(&files)?;
    Ok(())
}
