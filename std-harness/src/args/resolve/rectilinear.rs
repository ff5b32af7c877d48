//! What a rectilinear grid (`.vtr`, `crate::io::grid`) renders with: the paper's sheets, each
//! sample splatted with its own footprint, scaled to its spacings (`footprint::refine`,
//! "Rectilinear grids"; the refined renderer draws them, so `--refine` refines the grid
//! further). Everything that places kernels on one uniform grid (image-aligned slabs and so
//! `--clip`, post-classification and projections, the fixed-point path, perspective footprints,
//! the f64 sheet reference and the other table methods, levels of detail, `--quality`'s choices,
//! culling and nearest-phase stencils) or reads the file in parts (`--stream`, `--crop`) is
//! refused with the reason. The format is known from the file's name before it is read (or from
//! a volume in memory, Python's `coordinates=`).

use crate::args::{
    AccumArg, BlendArg, ClassificationArg, Lod, MethodArg, PhaseLookupArg, RenderArgs, SlicingArg,
};
use crate::io::formats::is_rectilinear;
use crate::CliError;

/// Whether `args` render a rectilinear grid, after checking the flags it refuses.
pub(super) fn rectilinear_rules(args: &RenderArgs) -> Result<bool, CliError> {
    let path = args.volume.as_deref().or(args.stream.as_deref());
    let in_memory = args
        .memory
        .as_ref()
        .is_some_and(|m| m.volume.grid.is_some());
    if !(path.is_some_and(is_rectilinear) || in_memory) {
        return Ok(false);
    }
    let uniform = "kernels on one uniform grid, where a rectilinear grid's samples each have \
                   their own spacing";
    let lod = match args.lod {
        Lod::Level(n @ 1..) => Some(format!("--lod {n}")),
        _ => None,
    };
    let why: Option<(&str, String)> = if args.stream.is_some() {
        Some(("--stream", "a .vtr is read whole: drop --stream".into()))
    } else if args.slicing == Some(SlicingArg::Image) {
        Some((
            "--slicing image",
            format!("image-aligned slabs place {uniform}"),
        ))
    } else if !args.clip.is_empty() {
        Some((
            "--clip",
            format!("the planes cut kernels between image-aligned slabs, which place {uniform}"),
        ))
    } else if args.classification == ClassificationArg::Post || args.blend != BlendArg::Composite {
        Some((
            "--classification post / --blend",
            format!("post-classification's slabs place {uniform}"),
        ))
    } else if args.accum == AccumArg::Fixed {
        Some((
            "--accum fixed",
            format!("the fixed-point path places {uniform}"),
        ))
    } else if args.perspective.is_some() {
        Some((
            "--perspective",
            "the per-sample footprints are orthographic".into(),
        ))
    } else if args.footprint.method != MethodArg::Robust {
        Some(("--method", format!("the per-sample footprints read view tables the robust method builds; the f64 sheet reference places {uniform}")))
    } else if let Some(c) = args.crop {
        Some((
            "--crop",
            format!(
                "{c}: a crop is cut from a uniform grid's bricks; crop the file's extent instead"
            ),
        ))
    } else if let Some(flag) = &lod {
        Some((
            flag.as_str(),
            "a coarser level averages neighbours a uniform step apart (give --lod 0 or auto)"
                .into(),
        ))
    } else if args.quality.is_some() {
        Some((
            "--quality",
            "--quality chooses among uniform grids' configurations".into(),
        ))
    } else if args.cull.0.is_some() {
        Some((
            "--cull",
            format!("culling's occlusion map places {uniform}"),
        ))
    } else if args.phase_lookup == PhaseLookupArg::Nearest {
        Some((
            "--phase-lookup nearest",
            "each sample's footprint is read at its own scale, not from phase stencils".into(),
        ))
    } else {
        None
    };
    match why {
        Some((flag, why)) => Err(CliError::input(format!(
            "a rectilinear grid with {flag}: {why}"
        ))),
        None => Ok(true),
    }
}
