//! `--phase-lookup`'s rules: the nearest phase only where the plan reads phase stencils
//! (`crate::plan::Plan::reads_phase_stencils`).

use super::refused_if;
use crate::args::{MethodArg, PhaseLookupArg, RenderArgs};
use crate::plan::End;
use crate::CliError;

/// The rules `--phase-lookup nearest` adds: sheets, float or fixed, through a view table's
/// stencils (slabs, refined grids, perspective frames and `--method direct` have no phase to
/// read nearest).
pub(super) fn phase_lookup_rules(end: &End, args: &RenderArgs) -> Result<(), CliError> {
    if args.phase_lookup != PhaseLookupArg::Nearest {
        return Ok(());
    }
    let why = if !matches!(end, End::Sheets(_)) {
        Some("object slicing only (drop --slicing image, --refine or --method reference)")
    } else if args.perspective.is_some() {
        Some("orthographic views only (a perspective view samples each voxel's own footprint)")
    } else if args.footprint.method == MethodArg::Direct {
        Some("view-table methods only (--method direct samples the generic table per pixel)")
    } else if args.phases == 0 {
        Some("--phases 0 walks the table: give a phase count")
    } else {
        None
    };
    refused_if("--phase-lookup nearest", why)
}
