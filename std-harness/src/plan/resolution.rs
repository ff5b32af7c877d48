//! The resolution chain's settings, before the frame decides them: the level of detail
//! ([`Lod`]) and supersampling or subsampling ([`Supersample`]). Plain values: the command line
//! parses them (`crate::args`), programs build them.

/// Supersampling (`--supersample`) or subsampling (`--subsample`): `auto`, or a fixed factor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Supersample {
    /// k from the footprint's natural size (1 when no widening is needed).
    Auto,
    /// This factor (1 = off).
    Fixed(usize),
}

/// The level of detail (`--lod`): `auto`, or a fixed level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lod {
    /// The level from the projected voxel size (`pipeline::stages::lod::auto_level`).
    Auto,
    /// This level (0 = full resolution).
    Level(u32),
}

/// The resolution chain as a frame's set-up reads it: the level asked for, supersampling, and
/// whether the frame must stay at full resolution because the end refines it or `--quality`
/// measures the levels itself (`crate::plan::Plan::resolution`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolution {
    /// The level of detail asked for.
    pub lod: Lod,
    /// Supersampling asked for.
    pub supersample: Supersample,
    /// The end refines the grid (`--refine`): level 0 always.
    pub refine: bool,
    /// `--quality` chooses the level: the volume is prepared at level 0.
    pub quality: bool,
}

impl Resolution {
    /// The same chain at level `n`.
    pub fn at_level(self, n: u32) -> Resolution {
        Resolution {
            lod: Lod::Level(n),
            ..self
        }
    }
}
