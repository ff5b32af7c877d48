//! `--phase-lookup`: how the phase stencils are read at a voxel's sub-pixel phase.

use footprint::stencil::PhaseLookup;

/// `--phase-lookup`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PhaseLookupArg {
    /// The default plan's pilot measures the nearest phase first and keeps it where it reaches
    /// the target; blended everywhere else (the fixed path, which has no pilot, included).
    #[default]
    Auto,
    /// The bilinear blend of the four stencils around the phase.
    Blend,
    /// The stencil of the nearest phase.
    Nearest,
}

impl PhaseLookupArg {
    /// The lookup the flag fixes; `None` for `auto`.
    pub fn fixed(self) -> Option<PhaseLookup> {
        match self {
            PhaseLookupArg::Auto => None,
            PhaseLookupArg::Blend => Some(PhaseLookup::Blend),
            PhaseLookupArg::Nearest => Some(PhaseLookup::Nearest),
        }
    }
}

pub use crate::plan::phase_lookup_name;
