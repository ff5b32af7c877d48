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
