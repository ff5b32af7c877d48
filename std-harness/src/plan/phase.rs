//! `--phase-lookup`'s rules: which plans read phase stencils, so that the nearest phase can mean
//! something there (`footprint::stencil::PhaseLookup`).

use super::{refused_if, End, Footprints, Plan};
use crate::args::{MethodArg, PhaseLookupArg, RenderArgs};
use crate::CliError;

impl Plan {
    /// Whether the frame reads phase stencils, whose phase lookup it sets: sheets (float, or the
    /// fixed path's integer stencils) through the view table, `--phases` > 0. (A perspective
    /// frame samples each voxel's own footprint: the flags refuse `--phase-lookup nearest`
    /// there and the pilot does not try it.)
    pub fn reads_phase_stencils(&self) -> bool {
        matches!(self.end, End::Sheets(_))
            && self.table.footprints == Footprints::ViewTable
            && self.phases > 0
    }
}

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
