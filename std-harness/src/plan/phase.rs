//! Which plans read phase stencils, so that the nearest phase can mean something there
//! (`footprint::stencil::PhaseLookup`), and the lookups' names.

use super::{End, Footprints, Plan};
use footprint::stencil::PhaseLookup;

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

/// The name `--phase-lookup` and the JSON use.
pub fn phase_lookup_name(l: PhaseLookup) -> &'static str {
    match l {
        PhaseLookup::Blend => "blend",
        PhaseLookup::Nearest => "nearest",
    }
}
