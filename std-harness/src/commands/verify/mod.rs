//! `footprint verify`: render with the core and with the f64 reference (no tables), and measure
//! how far apart they are.
//!
//! Colour space: the renderers' output, linear premultiplied RGBA in [0, 1], composited over the
//! background (transparent black if none); the measures are [`crate::metrics`]'.

mod report;

use crate::args::keywords::{self, Keywords, Value};
use crate::args::{plan, BlendArg, ClassificationArg, Lod, MethodArg, ReconstructionArg};
use crate::args::{ReferenceArg, RenderArgs};
use crate::io::image::{check_style, RGB_EXTENSIONS};
use crate::io::outputs::{self, Planned};
use crate::metrics::{compare, ErrorStats};
use crate::pipeline::ends::continuous::{continuous_models, ModelFigures};
use crate::pipeline::quality::{field::prepare_field, model::Choice};
use crate::pipeline::{render, render_ref, Prepared, Renderer};
use crate::plan::{End, Plan, Precision};
use crate::reference::continuous::{Continuous, Model};
use crate::scene::Scene;
use crate::CliError;
use clap::Args;
use footprint::render::RenderStats;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub struct VerifyArgs {
    #[command(flatten)]
    pub render: RenderArgs,
    /// Exit with code 1 if the PSNR is below this, dB: against the continuous integral with
    /// `--reference continuous` (of the finer sampling with `--reference field`); against full resolution (the f64 reference of level 0) when a
    /// coarser level was rendered; else the overall figure against the same sheets.
    #[arg(long, value_parser = crate::args::parse_finite_f64, allow_hyphen_values = true)]
    pub min_psnr: Option<f64>,
    /// Also write the reference render here (`.png` or `.pfm`, as `--out`): the reference
    /// `--reference` chose.
    #[arg(long)]
    pub reference_out: Option<PathBuf>,
    /// What the core is measured against: `sheets` (the f64 renderer of the same sheets,
    /// shading and compositing with exact footprints: table and precision error only) or
    /// `continuous` (the emission–absorption integral of the field the voxels, kernel and
    /// transfer function define, ray-marched in f64 until converged; both figures are printed
    /// and written, the continuous one under the JSON key `continuous`), or `field` (the
    /// built-in scene only: the same integral of its analytic field sampled --field-size N³ over
    /// the same box, the finer field the grid stands for, under `continuous` with `field_size`;
    /// the one reference `--refine` may be measured against). `--min-psnr` applies to the one
    /// chosen. The plan is `render`'s, defaults included: where `--slicing auto` (the default)
    /// chooses slabs, the figure against `sheets` is the difference between the two slicings
    /// (said so); give `--slicing object` to measure the sheets' table and precision error.
    #[arg(long, value_enum, default_value_t = ReferenceArg::Sheets)]
    pub reference: ReferenceArg,
}

/// `verify`'s own keywords (`min_psnr`, `reference_out`, `reference`), then `render`'s (among
/// them `reconstruction`, which also chooses the continuous model's).
impl Keywords for VerifyArgs {
    fn set(&mut self, key: &str, v: &Value) -> Result<(), CliError> {
        match key {
            "min_psnr" => self.min_psnr = Some(keywords::finite(key, v)?),
            "reference_out" => self.reference_out = Some(keywords::text(key, v)?.into()),
            "reference" => self.reference = keywords::choice(key, v)?,
            _ => self.render.set(key, v)?,
        }
        Ok(())
    }
}

pub fn run(args: &VerifyArgs) -> Result<(), CliError> {
    check(args)?;
    let r = &args.render;
    // The continuous reference integrates full resolution: `--lod auto` then renders level 0
    // (an explicit level is compared with it as asked, and refused by it).
    let full;
    let r = if args.reference != ReferenceArg::Sheets && r.lod == Lod::Auto {
        full = RenderArgs {
            lod: Lod::Level(0),
            ..r.clone()
        };
        &full
    } else {
        r
    };
    let m = measure(args, r)?;
    m.print(args, r);
    // --min-psnr judges the image against the volume as given: the continuous integral when
    // asked, full resolution when a level was rendered, else the same sheets.
    let judged = match (&m.continuous, &m.full_resolution) {
        (Some(c), _) => c.error.psnr_db,
        (None, Some(e)) => e.psnr_db,
        (None, None) => m.overall.psnr_db,
    };
    let pass = args.min_psnr.is_none_or(|m| judged >= m);
    outputs::write_all(&m.files(args, r, pass)?)?;
    if pass {
        Ok(())
    } else {
        Err(CliError::check(format!(
            "PSNR {:.2} dB is below --min-psnr {}",
            judged,
            args.min_psnr.unwrap_or(f64::NAN)
        )))
    }
}

/// `r`'s plan. `--reconstruction` also names the continuous model measured against: a
/// pre-classified frame (which reconstructs shaded voxels with the kernel, whatever the model)
/// is planned as if it were `kernel`, which is all `render` accepts there.
fn planned(r: &RenderArgs) -> Result<Plan, CliError> {
    if r.classification == ClassificationArg::Pre && r.blend == BlendArg::Composite {
        return plan(&RenderArgs {
            reconstruction: ReconstructionArg::Kernel,
            ..r.clone()
        });
    }
    plan(r)
}

/// Every rule the flags decide, and the outputs' paths and styles, before anything is loaded.
fn check(args: &VerifyArgs) -> Result<(), CliError> {
    let r = &args.render;
    planned(r)?;
    if r.footprint.method == MethodArg::Reference {
        return Err(CliError::input(
            "verify compares a table method with the reference: choose robust, paper or direct",
        ));
    }
    if !r.clip.is_empty() && args.reference != ReferenceArg::Continuous {
        return Err(CliError::input(
            "--clip: the f64 sheet reference and the field reference do not cut kernels; \
             measure a clipped frame against its cut model with --reference continuous",
        ));
    }
    if r.blend != crate::args::BlendArg::Composite && args.reference != ReferenceArg::Continuous {
        return Err(CliError::input(
            "--blend: the f64 sheet reference and the field reference composite; measure a \
             projection against its own model with --reference continuous",
        ));
    }
    let rectilinear = r
        .volume
        .as_deref()
        .is_some_and(crate::io::formats::is_rectilinear);
    if rectilinear && args.reference != ReferenceArg::Continuous {
        return Err(CliError::input(
            "a rectilinear grid (.vtr): the f64 sheet reference and the field reference place \
             voxels on a uniform grid; measure it against its continuous model with \
             --reference continuous",
        ));
    }
    if r.refine.is_some() && args.reference != ReferenceArg::Field {
        return Err(CliError::input(
            "verify's sheet and continuous references render the grid as given, so they would \
             measure --refine against the unrefined grid: measure refinement against a finer \
             sampling of the built-in scene with --reference field (or chart it with \
             `footprint chart --refine-only`)",
        ));
    }
    let mut planned = Vec::new();
    for (flag, path, extensions) in [
        ("--out", &r.out, &RGB_EXTENSIONS[..]),
        ("--reference-out", &args.reference_out, &RGB_EXTENSIONS[..]),
        ("--json", &r.json, &[][..]),
    ] {
        if let Some(path) = path {
            planned.push(Planned {
                flag,
                path,
                extensions,
            });
        }
    }
    r.note_inputs();
    outputs::check(&planned)?;
    for path in [&r.out, &args.reference_out].into_iter().flatten() {
        check_style(path, r.png_style())?;
    }
    Ok(())
}

/// The figure against the continuous integral: the integral, its seconds, the core's error
/// against it, and the core against every model.
struct AgainstContinuous {
    integral: Continuous,
    seconds: f64,
    error: ErrorStats,
    models: ModelFigures,
}

/// What `verify` measured: the core's render and every figure it is compared by.
struct Measured {
    p: Prepared,
    inputs: Scene,
    plan: Plan,
    choice: Option<Choice>,
    core: Vec<[f32; 4]>,
    stats: RenderStats,
    core_s: f64,
    reference: Vec<[f64; 4]>,
    ref_s: f64,
    per: [ErrorStats; 4],
    overall: ErrorStats,
    continuous: Option<AgainstContinuous>,
    /// A coarser level against the f64 reference of level 0.
    full_resolution: Option<ErrorStats>,
    /// The fixed path against the float path of the same table and method.
    fixed_vs_float: Option<ErrorStats>,
}

/// Renders `r`'s plan with the core and measures it against the f64 sheet reference, the
/// continuous integral when asked, full resolution for a coarser level, and the float path for
/// the fixed one.
fn measure(args: &VerifyArgs, r: &RenderArgs) -> Result<Measured, CliError> {
    let inputs = crate::args::scene(r)?;
    let (frame, renderer) = render(&inputs, &planned(r)?)?;
    let (core, stats, core_s) = (frame.image, frame.stats, frame.seconds);
    // The fixed path against the float path of the same table and method.
    let fixed_vs_float = if renderer.plan().precision() == Precision::Fixed {
        let float_plan = renderer.plan().with_precision(Precision::Float);
        let float = renderer.fresh_frame_of(&float_plan)?.image;
        let float: Vec<[f64; 4]> = float.iter().map(|c| c.map(f64::from)).collect();
        Some(compare(&core, &float).1)
    } else {
        None
    };
    let (p, plan, choice) = renderer.into_parts();
    let (reference, ref_s) = render_ref(&p)?;
    let (per, overall) = compare(&core, &reference);
    let continuous = match args.reference {
        ReferenceArg::Sheets => None,
        reference => {
            // `field`: the same integral, over the finer sampling of the built-in scene.
            let fine = match reference {
                ReferenceArg::Field => Some(prepare_field(&inputs, &plan)?),
                _ => None,
            };
            let over = fine.as_ref().unwrap_or(&p);
            let model = match plan.end {
                End::Post { blend, .. } if blend.projects() => Model::Projection(blend),
                End::Post { .. } => Model::Post,
                _ => Model::Pre(p.absorption),
            };
            let recon = args.render.reconstruction.into();
            let (integral, seconds, models) = continuous_models(over, recon, model, &core)?;
            let (_, error) = compare(&core, &integral.image);
            Some(AgainstContinuous {
                integral,
                seconds,
                error,
                models,
            })
        }
    };
    // A coarser level is also measured against full resolution: its own error counts there.
    let full_resolution = match (args.reference, p.level) {
        (ReferenceArg::Sheets, 1..) => {
            let level0 = Renderer::prepare(&inputs, &plan.at_level_0())?;
            let (full, _) = render_ref(level0.prepared())?;
            Some(compare(&core, &full).1)
        }
        _ => None,
    };
    Ok(Measured {
        p,
        inputs,
        plan,
        choice,
        core,
        stats,
        core_s,
        reference,
        ref_s,
        per,
        overall,
        continuous,
        full_resolution,
        fixed_vs_float,
    })
}
