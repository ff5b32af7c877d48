//! The plan's rules for `--classification post` (issue 47): what post-classified slabs need, and
//! post's own flags refused without it.

use super::plan;
use crate::args::{
    BlendArg, ClassificationArg, Lod, MethodArg, ReconstructionArg, RenderArgs, SlicingArg,
    Supersample,
};
use crate::plan::{End, Plan, Precision};
use crate::CliError;
use footprint::frame::Order;
use footprint::render::Absorption;

/// `--slab-post` and `--value-subsample` without `--classification post`: refused, not ignored.
pub(super) fn no_post_flags(args: &RenderArgs) -> Result<(), CliError> {
    if args.slab_post.is_some() || args.value_subsample != Supersample::Auto {
        return Err(CliError::input(
            "--slab-post and --value-subsample set up post-classified slabs: add \
             --classification post (or drop them)",
        ));
    }
    if args.reconstruction == ReconstructionArg::Trilinear {
        return Err(CliError::input(
            "--reconstruction trilinear reconstructs post-classified values: add \
             --classification post (pre-classified voxels are reconstructed with the kernel; \
             `verify --reference continuous --reconstruction trilinear` measures them against \
             the trilinear model)",
        ));
    }
    Ok(())
}

/// What a projection (`--blend` other than `composite`) cannot be combined with: shading (one
/// value per ray is classified, with no gradient). Clipping planes are refused with the other
/// clip rules (`clip_rules`).
fn blend_rules(args: &RenderArgs) -> Result<(), CliError> {
    let blend = footprint::render::Blend::from(args.blend);
    let refuse = |flag: &str, why: &str| {
        Err(CliError::input(format!(
            "--blend {} with {flag}: {why}",
            blend.name()
        )))
    };
    if !blend.projects() {
        return Ok(());
    }
    if args.shading != "emission" {
        return refuse(
            &format!("--shading {}", args.shading),
            "a projection classifies one value per ray, which has no surface to light: drop --shading",
        );
    }
    Ok(())
}

/// `--classification post`'s plan (and a projection's, `--blend`): post-classified slabs, after
/// the rules that the flags alone decide (what image slicing needs, and what
/// post-classification cannot be combined with).
pub(super) fn post_plan(args: &RenderArgs, precision: Precision) -> Result<Plan, CliError> {
    blend_rules(args)?;
    let refuse = |flag: &str, why: &str| {
        Err(CliError::input(format!(
            "--{} with {flag}: {why}",
            match footprint::render::Blend::from(args.blend) {
                footprint::render::Blend::Composite => "classification post".to_string(),
                b => format!("blend {}", b.name()),
            }
        )))
    };
    let fa = &args.footprint;
    if precision == Precision::Fixed {
        return refuse(
            "--accum fixed",
            "there is no fixed-point post-classification (each slab sample is divided by its \
             weight and shaded per pixel): use --accum float",
        );
    }
    if fa.method == MethodArg::Reference {
        return refuse(
            "--method reference",
            "the f64 sheet reference is pre-classified: compare against --reference continuous",
        );
    }
    if args.refine.is_some() {
        return refuse("--refine", "refinement refines the paper's sheets only");
    }
    if args.slicing == Some(SlicingArg::Object) {
        return refuse(
            "--slicing object",
            "post-classification renders image-aligned slabs (drop --slicing)",
        );
    }
    if args.perspective.is_some() {
        return refuse(
            "--perspective",
            "image-aligned slabs are orthographic only (drop --perspective)",
        );
    }
    if args.stream.is_some() {
        return refuse(
            "--stream",
            "a slab of an oblique view crosses every sheet, so it cannot be fed from a few \
             streamed sheets: drop --stream (the volume is loaded)",
        );
    }
    if Absorption::from(args.absorption) == Absorption::Extinction {
        return refuse(
            "--absorption extinction",
            "post-classification composites each sample's opacity over its step, as ray casters \
             do (drop --absorption)",
        );
    }
    if let Lod::Level(n @ 1..) = args.lod {
        return refuse(
            &format!("--lod {n}"),
            "a coarser level carries pre-classified colours; post-classification reconstructs \
             the values at full resolution (give --lod 0 or auto)",
        );
    }
    if args.quality.is_some() {
        return refuse(
            "--quality",
            "--quality chooses among pre-classified methods; give --slab-post instead",
        );
    }
    if let Some(eps) = args.cull.0 {
        return refuse(
            &format!("--cull {eps}"),
            "post-classified slabs skip opaque pixels already (front to back); drop --cull",
        );
    }
    let mut plan = plan(&RenderArgs {
        classification: ClassificationArg::Pre,
        blend: BlendArg::Composite,
        reconstruction: ReconstructionArg::Kernel,
        slicing: Some(SlicingArg::Image),
        slab_post: None,
        value_subsample: Supersample::Auto,
        ..args.clone()
    })?;
    plan.end = End::Post {
        thickness: args
            .slab_post
            .unwrap_or_else(|| crate::args::default_post_slab(&args.shading, args.reconstruction)),
        values: args.value_subsample,
        blend: args.blend.into(),
        reconstruction: args.reconstruction.into(),
    };
    // Post-classification composites front to back unless told: opaque pixels then take
    // nothing more (exact), where back to front must classify every slab.
    plan.order = Some(args.order.map_or(Order::FrontToBack, Order::from));
    // It reconstructs the values at full resolution (a coarser level carries pre-classified
    // colours): `auto` means level 0 there.
    if plan.lod == Lod::Auto {
        plan.lod = Lod::Level(0);
    }
    Ok(plan)
}
