//! `--phase-lookup`'s rules: which plans read phase stencils, so that the nearest phase can mean
//! something there (`footprint::stencil::PhaseLookup`).

use super::{refused_if, End, Footprints, Plan, Precision};
use crate::args::{MethodArg, PhaseLookupArg, RenderArgs};
use crate::CliError;

impl Plan {
    /// Whether the frame reads phase stencils, whose phase lookup it sets: float sheets through
    /// the view table, `--phases` > 0. (A perspective frame samples each voxel's own footprint:
    /// the flags refuse `--phase-lookup nearest` there and the pilot does not try it.)
    pub fn reads_phase_stencils(&self) -> bool {
        self.end == End::Sheets(Precision::Float)
            && self.table.footprints == Footprints::ViewTable
            && self.phases > 0
    }
}

/// The rules `--phase-lookup nearest` adds: float sheets through a view table's stencils (the
/// fixed path's integer stencils, slabs, refined grids, perspective frames and `--method direct`
/// have no phase to read nearest).
pub(super) fn phase_lookup_rules(end: &End, args: &RenderArgs) -> Result<(), CliError> {
    if args.phase_lookup != PhaseLookupArg::Nearest {
        return Ok(());
    }
    let why = if *end != End::Sheets(Precision::Float) {
        Some("float object slicing only (drop --accum fixed, --slicing image, --refine or --method reference)")
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
