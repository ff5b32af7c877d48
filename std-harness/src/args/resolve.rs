//! The command line resolved once (issue 76): `render`'s flags ([`RenderArgs`]) into the
//! pipeline's two typed values, what is rendered ([`Scene`]) and what draws it ([`Plan`]), with
//! every compatibility rule that the flags alone decide, before anything is loaded: between end
//! points, precision and model ([`plan`]), with a streamed volume, `--cull`, `--subsample` and
//! `--phase-lookup`, and post-classification's (`post.rs`). Nothing below this layer names a
//! flag's clap type: the pipeline reads the typed values only (`tests/layering.rs`).

use super::{
    AccumArg, BlendArg, ClassificationArg, FootprintArgs, Lod, LookupArg, MethodArg, OrderArg,
    QualityReferenceArg, RenderArgs, SlicingArg, SplatArgs, Supersample,
};
use crate::pipeline::ends::single::{compose_view, Single};
use crate::plan::{
    check_levels, quality_level_of_stream, End, Footprints, Method, Plan, Precision, Quality,
    QualityReference, Request, Table, SUBSAMPLE_NOT_AT_A_LEVEL, SUBSAMPLE_NOT_PERSPECTIVE,
};
use crate::scene::{KernelModel, Scene, ShadingSpec};
use crate::CliError;
use footprint::frame::Order;
use footprint::geometry::FootprintOptions;
use footprint::render::Absorption;
use footprint::{Grid, Lookup, View};

mod auto;
mod labels;
mod phase;
mod post;
mod rectilinear;
use phase::phase_lookup_rules;
use post::{no_post_flags, post_plan};

/// `args`' plan, with every rule the flags alone decide (see the module docs).
pub fn plan(args: &RenderArgs) -> Result<Plan, CliError> {
    request_rules(args)?;
    labels::label_rules(args)?;
    let rectilinear = rectilinear::rectilinear_rules(args)?;
    let fa = &args.footprint;
    let precision = Precision::from(args.accum);
    clip_rules(args)?;
    if args.classification == ClassificationArg::Post || args.blend != BlendArg::Composite {
        return post_plan(args, precision);
    }
    no_post_flags(args)?;
    // Clipping planes cut kernels between image-aligned slabs: a clipped frame is slabs
    // (`--slab` thick) unless object slicing is asked for, which `clip_rules` refused.
    let slicing = match args.slicing {
        Some(SlicingArg::Image) => SlicingArg::Image,
        None | Some(SlicingArg::Auto) if !args.clip.is_empty() => SlicingArg::Image,
        _ => SlicingArg::Object,
    };
    let end = match (fa.method, args.refine, slicing) {
        (MethodArg::Reference, _, _) => End::Reference,
        (_, Some(threshold), _) => End::Refined {
            threshold,
            sheets: args.refine_sheets,
        },
        (_, None, SlicingArg::Image) => End::Slabs {
            thickness: args.slab,
        },
        (_, None, _) => End::Sheets(precision),
    };
    let refuse = |flag: &str, why: &str| Err(CliError::input(format!("{flag}: {why}")));
    match end {
        End::Refined { .. } if precision == Precision::Fixed => {
            return refuse("--refine", "float accumulation only (drop --accum fixed)")
        }
        End::Refined { .. } if slicing == SlicingArg::Image => {
            return refuse("--refine", "the paper's sheets only (drop --slicing image)")
        }
        End::Refined { .. } if args.perspective.is_some() => {
            return refuse("--refine", "orthographic views only (drop --perspective)")
        }
        End::Refined { .. } if fa.method != MethodArg::Robust => {
            return refuse(
                "--refine",
                "the rate tables are view tables built by the robust method (drop --method)",
            )
        }
        End::Slabs { .. } if precision == Precision::Fixed => {
            return refuse(
                "--slicing image",
                "there is no fixed-point slab path (each slab is composited with an exponential \
                 per pixel): use --accum float or --slicing object",
            )
        }
        _ => {}
    }
    flag_rules(&end, args)?;
    let extinction = Absorption::from(args.absorption) == Absorption::Extinction;
    if extinction && matches!(end, End::Sheets(_) | End::Refined { .. }) {
        // (Perspective sheets place each voxel's optical depth along its own ray: `PerVoxel`.)
        if precision == Precision::Fixed {
            return refuse(
                "--absorption extinction",
                "--accum fixed composites the opacity model only: use --accum float (or \
                 --absorption opacity)",
            );
        }
    }
    subsample_rules(args)?;
    // A rectilinear grid renders sheets (`rectilinear`): the pilot has no slabs to offer it.
    let auto_slicing = auto::slicing_target(&end, args).filter(|_| !rectilinear);
    let plan = Plan {
        end,
        table: Table {
            size: fa.table,
            lookup: Lookup::from(fa.lookup),
            footprints: match fa.method {
                MethodArg::Direct => Footprints::Direct,
                _ => Footprints::ViewTable,
            },
            file: fa.table_file.clone(),
        },
        phases: args.phases,
        depth_phases: args.depth_phases,
        phase_lookup: args.phase_lookup.fixed(),
        threads: args.thread_count(),
        subsample: args.subsample.unwrap_or(Supersample::Fixed(1)),
        cull: args.cull.0,
        quality: args.quality.map(|target_db| Quality {
            target_db,
            reference: args.quality_reference.into(),
        }),
        auto_slicing,
        auto_subsample: args.subsample.is_none() && auto_slicing.is_some(),
        // A label volume renders level 0 (an average of labels names none), and so does a
        // rectilinear grid (one of uneven spacing): `auto` means it.
        lod: match args.lod {
            Lod::Auto if args.labels.is_some() || rectilinear => Lod::Level(0),
            lod => lod,
        },
        supersample: args.supersample,
        // Culling needs what is in front first.
        order: match args.order {
            None if args.cull.0.is_some() => Some(Order::FrontToBack),
            order => order.map(Order::from),
        },
        // A command flag of `render` (`RenderCommandArgs::bricks`), set there.
        bricks: None,
    };
    check_levels(&scene(args)?, &plan.resolution())?;
    Ok(plan)
}

/// What `--clip` cannot be drawn with: each kernel is cut between image-aligned slabs
/// (`footprint::render::clip`), so object slicing, post-classification's slabs, refinement,
/// the f64 sheet reference and perspective views are refused with the reason.
fn clip_rules(args: &RenderArgs) -> Result<(), CliError> {
    if args.clip.is_empty() {
        return Ok(());
    }
    if args.clip.len() > footprint::render::clip::MAX_CLIP_PLANES {
        return Err(CliError::input(format!(
            "--clip: {} planes; at most {} clip one frame",
            args.clip.len(),
            footprint::render::clip::MAX_CLIP_PLANES
        )));
    }
    let why = if args.slicing == Some(SlicingArg::Object) {
        Some("--slicing object (a sheet composites each kernel whole; the planes cut kernels between image-aligned slabs: drop it)")
    } else if args.classification == ClassificationArg::Post {
        Some("--classification post (its slabs do not cut kernels yet)")
    } else if args.blend != BlendArg::Composite {
        Some("--blend (a projection renders post-classified slabs, which do not cut kernels yet; crop with --crop instead)")
    } else if args.refine.is_some() {
        Some("--refine (refinement renders the paper's sheets)")
    } else if args.footprint.method == MethodArg::Reference {
        Some("--method reference (the f64 sheet reference does not cut kernels)")
    } else if args.perspective.is_some() {
        Some("--perspective (image-aligned slabs are orthographic)")
    } else if args.accum == AccumArg::Fixed {
        Some("--accum fixed (there is no fixed-point slab path)")
    } else {
        None
    };
    match why {
        Some(w) => Err(CliError::input(format!("--clip does not render with {w}"))),
        None => Ok(()),
    }
}

/// The rules between fields that hold for any request, whether flags or keywords built it: a flag
/// that needs another (`--eye-distance` a perspective view, `--refine-sheets` `--refine`,
/// `--quality-reference` a `--quality` target), and what `--quality` chooses itself (the table,
/// lookup, method, accumulation and slab), which a request may not also set. On the command
/// line clap refuses the last two when the flags are given at all (even at their defaults);
/// here they are checked on the values, so a request built from keywords meets them too.
fn request_rules(args: &RenderArgs) -> Result<(), CliError> {
    let refuse = |why: &str| Err(CliError::input(why.to_string()));
    if args.eye_distance.is_some() && args.perspective.is_none() {
        return refuse("--eye-distance: needs --perspective (an orthographic eye is at infinity)");
    }
    if args.refine_sheets && args.refine.is_none() {
        return refuse("--refine-sheets: needs --refine THRESHOLD");
    }
    if args.quality.is_none() {
        return match args.quality_reference {
            QualityReferenceArg::Sheets => Ok(()),
            _ => refuse("--quality-reference: needs --quality DB"),
        };
    }
    if args.refine.is_some() {
        return refuse("--refine cannot be used with --quality (which chooses the method itself)");
    }
    let d: RenderArgs = super::keywords::defaults();
    let (fa, da) = (&args.footprint, &d.footprint);
    let set = [
        ("--table", fa.table != da.table),
        ("--lookup", fa.lookup != da.lookup),
        ("--method", fa.method != da.method),
        ("--accum", args.accum != d.accum),
        ("--table-file", fa.table_file.is_some()),
        ("--slab", args.slab != d.slab),
    ];
    match set.iter().find(|(_, set)| *set) {
        Some((flag, _)) => refuse(&format!(
            "{flag} cannot be used with --quality (which chooses it): drop one"
        )),
        None => Ok(()),
    }
}

/// The rules `--subsample` adds: not with `--quality` (which chooses at the output size), an
/// explicit factor not with `--refine`, a perspective view, supersampling or a coarser level.
fn subsample_rules(args: &RenderArgs) -> Result<(), CliError> {
    let refuse = |flag: &str, why: &str| Err(CliError::input(format!("{flag}: {why}")));
    let factor = match args.subsample {
        None | Some(Supersample::Fixed(1)) => None,
        Some(Supersample::Fixed(s)) => Some(s.to_string()),
        Some(Supersample::Auto) => Some("auto".to_string()),
    };
    let Some(s) = factor else {
        return Ok(());
    };
    if args.quality.is_some() {
        return refuse(
            &format!("--subsample {s}"),
            "--quality chooses the method from measured errors at the output size; drop one",
        );
    }
    if args.refine.is_some() && s != "auto" {
        return refuse(
            &format!("--subsample {s}"),
            "--refine adds samples for magnified volumes; subsampling removes pixels: drop one",
        );
    }
    // An explicit factor where the flags already rule subsampling out (`auto` then means
    // 1; the frame decides the rest: `pipeline::stages::subsample::factor`).
    let blocked = if s == "auto" {
        None
    } else if args.perspective.is_some() {
        Some(SUBSAMPLE_NOT_PERSPECTIVE)
    } else if matches!(args.supersample, Supersample::Fixed(2..)) {
        Some("the frame is supersampled (--supersample): give one of them")
    } else if matches!(args.lod, Lod::Level(1..)) {
        Some(SUBSAMPLE_NOT_AT_A_LEVEL)
    } else {
        None
    };
    if let Some(why) = blocked {
        return refuse(&format!("--subsample {s}"), why);
    }
    Ok(())
}

impl From<Lookup> for LookupArg {
    fn from(l: Lookup) -> Self {
        match l {
            Lookup::Nearest => LookupArg::Nearest,
            Lookup::Bilinear => LookupArg::Bilinear,
        }
    }
}

/// The rules a streamed volume and `--cull` add to `end`.
fn flag_rules(end: &End, args: &RenderArgs) -> Result<(), CliError> {
    phase_lookup_rules(end, args)?;
    if args.stream.is_some() {
        streamed_rules(end, args)?;
    }
    match args.cull.0 {
        Some(eps) => cull_rules(eps, end, args),
        None => Ok(()),
    }
}

/// `flag` refused for reason `why`, if there is one.
fn refused_if(flag: &str, why: Option<&str>) -> Result<(), CliError> {
    match why {
        Some(why) => Err(CliError::input(format!("{flag}: {why}"))),
        None => Ok(()),
    }
}

/// The rules `--cull EPS` adds: sheets or pre-classified slabs, front to back, orthographic, and
/// not with `--quality` (which chooses the method itself).
fn cull_rules(eps: f32, end: &End, args: &RenderArgs) -> Result<(), CliError> {
    let why = if !matches!(end, End::Sheets(_) | End::Slabs { .. }) {
        Some("the paper's sheets and pre-classified slabs only: drop --classification post, --refine or --method reference")
    } else if args.perspective.is_some() {
        Some("orthographic views only (a perspective view's footprints vary per voxel)")
    } else if args.order == Some(OrderArg::BackToFront) {
        Some("culling needs front-to-back compositing: drop --order back-to-front")
    } else if args.quality.is_some() {
        Some("--quality chooses the method from measured errors: drop one")
    } else {
        None
    };
    refused_if(&format!("--cull {eps}"), why)
}

/// The rules a streamed volume (`--stream`: read once, a few sheets at a time) adds to `end`.
fn streamed_rules(end: &End, args: &RenderArgs) -> Result<(), CliError> {
    let refuse = |flag: &str, why: &str| Err(CliError::input(format!("{flag}: {why}")));
    match end {
        End::Refined { .. } => refuse("--refine", "the volume must be in memory (drop --stream)"),
        End::Slabs { .. } => refuse(
            "--slicing image",
            "a slab of an oblique view crosses every sheet, so it cannot be fed from a few \
             streamed sheets: drop --stream (the volume is loaded) or use --slicing object",
        ),
        _ => match (args.quality, args.lod) {
            (Some(_), Lod::Level(n @ 1..)) => Err(quality_level_of_stream(n)),
            _ => Ok(()),
        },
    }
}

/// `a`'s scene: what the render loads and how it sees it, the kernel parsed and the mapping's
/// rules checked (`--kernel`, `--paper-cheat`).
pub fn scene(a: &RenderArgs) -> Result<Scene, CliError> {
    Ok(Scene {
        memory: a.memory.clone(),
        stdin: a.stdin.clone(),
        volume: a.volume.clone(),
        stream: a.stream.clone(),
        dims: a.dims,
        sample_type: a.sample_type,
        big_endian: a.endian == super::EndianArg::Big,
        spacing: a.spacing,
        array: a.array.clone(),
        scene_size: a.scene_size,
        field_size: a.field_size,
        size: a.size,
        view: a.view,
        zoom: a.zoom,
        view_matrix: a.view_matrix,
        perspective: a.perspective,
        eye_distance: a.eye_distance,
        tfs: a.tf.clone(),
        window: a.window,
        shading: ShadingSpec::parse(&a.shading)?,
        labels: a
            .labels
            .as_deref()
            .map(crate::tf::labels::LabelTable::load)
            .transpose()?,
        background: a.background.clone(),
        gamma: a.gamma.curve(),
        depth: a.depth,
        kernel: kernel_model(&a.footprint)?,
        absorption: a.absorption.into(),
        crop: a.crop,
        clip: a.clip.clone(),
    })
}

/// The kernel model `--kernel`, `--method paper`'s `--paper-cheat`, `--min-radius` and
/// `--table-file` ask for.
pub fn kernel_model(fa: &FootprintArgs) -> Result<KernelModel, CliError> {
    Ok(KernelModel {
        kernel: fa.kernel()?,
        options: FootprintOptions {
            mapping: fa.mapping()?,
            min_radius_px: fa.min_radius,
        },
        table_from_file: fa.table_file.is_some(),
    })
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Robust => Method::Robust,
            MethodArg::Paper => Method::Paper,
            MethodArg::Direct => Method::Direct,
            MethodArg::Reference => Method::Reference,
        }
    }
}

impl From<QualityReferenceArg> for QualityReference {
    fn from(r: QualityReferenceArg) -> Self {
        match r {
            QualityReferenceArg::Sheets => QualityReference::Sheets,
            QualityReferenceArg::Continuous => QualityReference::Continuous,
            QualityReferenceArg::Field => QualityReference::Field,
        }
    }
}

impl From<AccumArg> for Precision {
    fn from(a: AccumArg) -> Self {
        match a {
            AccumArg::Float => Precision::Float,
            AccumArg::Fixed => Precision::Fixed,
        }
    }
}

/// `footprint splat`'s one voxel, resolved from its flags.
pub fn single(args: &SplatArgs) -> Result<Single, CliError> {
    let fa = &args.footprint;
    let kernel = kernel_model(fa)?;
    let grid = match args.grid_matrix {
        Some(m) => Grid::from_matrix(glam::Mat3::from_cols_array(&m).transpose()),
        None => Grid::from_spacing(args.spacing),
    }
    .map_err(|e| CliError::input(format!("grid: {e}")))?;
    let view = View::new(compose_view(
        args.view_matrix,
        args.rotate_x,
        args.rotate_y,
        args.rotate_z,
    ))
    .map_err(|e| CliError::input(format!("view: {e}")))?;
    Ok(Single {
        kernel,
        method: fa.method.into(),
        table: fa.table,
        lookup: fa.lookup.into(),
        table_file: fa.table_file.clone(),
        grid,
        view,
        size: args.size,
        center: args.center,
    })
}

impl Request for RenderArgs {
    fn scene(&self) -> Result<Scene, CliError> {
        scene(self)
    }
    fn plan(&self) -> Result<Plan, CliError> {
        plan(self)
    }
}
