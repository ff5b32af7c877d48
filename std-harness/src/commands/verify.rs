//! `footprint verify`: render with the core and with the f64 reference (no tables), and measure
//! how far apart they are.
//!
//! Colour space: the renderers' output, linear premultiplied RGBA in [0, 1], composited over the
//! background (transparent black if none); the measures are [`crate::metrics`]'.

use crate::args::{Lod, MethodArg, ReconstructionArg, ReferenceArg, RenderArgs};
use crate::io::image::{check_style, encode_rgb_for, RGB_EXTENSIONS};
use crate::io::json::Json;
use crate::io::outputs::{self, Planned};
use crate::metrics::compare;
use crate::pipeline::ends::continuous::{continuous_models, models_json, others, PIXEL_FILTER};
use crate::pipeline::quality::{choose::apply_quality, field::prepare_field, model::quality_json};
use crate::pipeline::{describe, prepare, render_core, render_ref};
use crate::plan::{plan, End, Inputs, Precision};
use crate::reference::continuous::Reconstruction;
use crate::CliError;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub struct VerifyArgs {
    #[command(flatten)]
    pub render: RenderArgs,
    /// Exit with code 1 if the PSNR is below this, dB: against the continuous integral with
    /// `--reference continuous` (of the finer sampling with `--reference field`); against full resolution (the f64 reference of level 0) when a
    /// coarser level was rendered; else the overall figure against the same sheets.
    #[arg(long)]
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
    /// chosen.
    #[arg(long, value_enum, default_value_t = ReferenceArg::Sheets)]
    pub reference: ReferenceArg,
    /// With `--reference continuous` or `field`: reconstruct the field with the kernel (Gaussian) or
    /// trilinearly (as VTK's ray casters do).
    #[arg(long, value_enum, default_value_t = ReconstructionArg::Kernel)]
    pub reconstruction: ReconstructionArg,
}

pub fn run(args: &VerifyArgs) -> Result<(), CliError> {
    let r = &args.render;
    // Every rule the flags decide, before anything is loaded.
    plan(r)?;
    if r.footprint.method == MethodArg::Reference {
        return Err(CliError::input(
            "verify compares a table method with the reference: choose robust, paper or direct",
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
    let inputs = Inputs::from(r);
    let (p, plan, choice) = apply_quality(prepare(r)?, &inputs, &plan(r)?)?;
    let (core, stats, core_s) = render_core(&p, &plan)?;
    let (reference, ref_s) = render_ref(&p)?;
    let (per, overall) = compare(&core, &reference);
    let continuous = match args.reference {
        ReferenceArg::Sheets => None,
        reference => {
            // `field`: the same integral, over the finer sampling of the built-in scene.
            let fine = match reference {
                ReferenceArg::Field => Some(prepare_field(&inputs)?),
                _ => None,
            };
            let over = fine.as_ref().unwrap_or(&p);
            let (recon, absorption) = (args.reconstruction.into(), p.absorption);
            let (c, secs, models) = continuous_models(over, recon, absorption, &core)?;
            let (_, e) = compare(&core, &c.image);
            Some((c, secs, e, models))
        }
    };
    // A coarser level is also measured against full resolution: its own error counts there.
    let full_resolution = match (args.reference, p.level) {
        (ReferenceArg::Sheets, 1..) => {
            let at_full = Inputs {
                lod: Lod::Level(0),
                quality: false,
                ..inputs.clone()
            };
            let level0 = prepare(&(at_full, plan.clone()))?;
            let (full, _) = render_ref(&level0)?;
            Some(compare(&core, &full).1)
        }
        _ => None,
    };
    crate::say!(
        "{}: {}x{}, core {:.3} s, reference {:.3} s",
        p.name,
        r.size.0,
        r.size.1,
        core_s,
        ref_s
    );
    crate::say!("channel   PSNR dB      RMSE   max abs");
    for (name, e) in ["R", "G", "B", "A"].iter().zip(&per) {
        crate::say!(
            "{name:<7} {:>9.2} {:>9.2e} {:>9.2e}",
            e.psnr_db,
            e.rmse,
            e.max_abs
        );
    }
    crate::say!(
        "overall {:>9.2} {:>9.2e} {:>9.2e}   (RGB, linear premultiplied)",
        overall.psnr_db,
        overall.rmse,
        overall.max_abs
    );
    if let Some(e) = &full_resolution {
        crate::say!(
            "full res {:>8.2} {:>9.2e} {:>9.2e}   (RGB, against the f64 reference of level 0: \
             level {}'s own error included)",
            e.psnr_db,
            e.rmse,
            e.max_abs,
            p.level
        );
    }
    if matches!(plan.end, End::Refined { .. }) {
        crate::say!(
            "(--refine: the sheet reference renders the grid as given, so `overall` above is what \
             refinement changed; the field line below measures it against the finer sampling)"
        );
    }
    if matches!(plan.end, End::Slabs { .. }) {
        crate::say!(
            "(--slicing image: the sheet reference renders the paper's object-aligned sheets, so \
             `overall` above is the difference between the two slicings; --reference continuous \
             measures image slicing against the truth)"
        );
    }
    if let Some((c, secs, e, models)) = &continuous {
        crate::say!(
            "{} {:>9.2} {:>9.2e} {:>9.2e}   (RGB, against the continuous integral{}, {} \
             reconstruction, {} model{}; step {:.4} world units after {} passes, last change \
             {:.1} dB{}; {:.1} s)",
            args.reference.name(),
            e.psnr_db,
            e.rmse,
            e.max_abs,
            match args.reference {
                ReferenceArg::Field => format!(" of the field sampled {}^3", r.field_size),
                _ => String::new(),
            },
            Reconstruction::from(args.reconstruction).name(),
            models[0].0.name(),
            others(models),
            c.step,
            c.passes,
            c.change_db,
            if c.converged { "" } else { ", NOT converged" },
            secs
        );
    }
    // The fixed path is also measured against the float path of the same table and method.
    let fixed_vs_float = if plan.precision() == Precision::Fixed {
        let (float, _, _) = render_core(&p, &plan.with_precision(Precision::Float))?;
        let float: Vec<[f64; 4]> = float.iter().map(|c| c.map(f64::from)).collect();
        let (_, e) = compare(&core, &float);
        crate::say!(
            "fixed vs float {:>9.2} {:>9.2e} {:>9.2e}   (RGB, same table and method)",
            e.psnr_db,
            e.rmse,
            e.max_abs
        );
        Some(e)
    } else {
        None
    };
    let mut files: Vec<(&std::path::Path, Vec<u8>)> = Vec::new();
    if let Some(out) = &r.out {
        files.push((
            out,
            encode_rgb_for(out, &core, r.size.0, r.size.1, r.png_style())?,
        ));
    }
    if let Some(out) = &args.reference_out {
        let chosen = continuous.as_ref().map_or(&reference, |c| &c.0.image);
        let img: Vec<[f32; 4]> = chosen.iter().map(|c| c.map(|x| x as f32)).collect();
        files.push((
            out,
            encode_rgb_for(out, &img, r.size.0, r.size.1, r.png_style())?,
        ));
    }
    // --min-psnr judges the image against the volume as given: the continuous integral when
    // asked, full resolution when a level was rendered, else the same sheets.
    let judged = match (&continuous, &full_resolution) {
        (Some(c), _) => c.2.psnr_db,
        (None, Some(e)) => e.psnr_db,
        (None, None) => overall.psnr_db,
    };
    let pass = args.min_psnr.is_none_or(|m| judged >= m);
    if let Some(j) = &r.json {
        let channels = Json::object()
            .obj("r", per[0].json())
            .obj("g", per[1].json())
            .obj("b", per[2].json())
            .obj("a", per[3].json());
        let mut summary = describe(&p, &inputs, &plan).str("command", "verify");
        if let Some(e) = fixed_vs_float {
            summary = summary.obj("fixed_vs_float", e.json());
        }
        if let Some(c) = &choice {
            summary = summary.obj("quality", quality_json(c));
        }
        if let Some(e) = &full_resolution {
            summary = summary.obj("full_resolution", e.json());
        }
        summary = summary.str("reference", args.reference.name());
        if let Some((c, secs, e, models)) = &continuous {
            let e = match args.reference {
                ReferenceArg::Field => e.json().num("field_size", r.field_size as f64),
                _ => e.json(),
            };
            summary = summary.obj(
                "continuous",
                e.str(
                    "reconstruction",
                    Reconstruction::from(args.reconstruction).name(),
                )
                .str("absorption", models[0].0.name())
                .obj("models", models_json(models))
                .str("pixel_filter", PIXEL_FILTER)
                .num("step_world", c.step)
                .num("passes", c.passes as f64)
                .num("change_db", c.change_db)
                .bool("converged", c.converged)
                .num("seconds", *secs),
            );
        }
        let summary = summary
            .num("core_seconds", core_s)
            .num("reference_seconds", ref_s)
            .num("voxels_splatted", stats.voxels_splatted as f64)
            .obj("overall", overall.json())
            .obj("channels", channels)
            .num("min_psnr_db", args.min_psnr.unwrap_or(f64::NAN))
            .bool("pass", pass);
        files.push((j, summary.finish().into_bytes()));
    }
    outputs::write_all(&files)?;
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
