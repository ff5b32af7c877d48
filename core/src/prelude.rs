//! The names a first render needs, in one import: `use footprint::prelude::*;`.
//!
//! [`render_volume`] with [`Settings`] and [`Buffers`] renders a volume in memory (see
//! [`crate::quick`]); [`Preset`] gives the CLI's transfer functions; [`linear8`], [`srgb8`],
//! [`straight8`] and [`straight_srgb8`] turn the result into 8-bit pixels.

pub use crate::composite::RowSpan;
pub use crate::frame::Order;
pub use crate::output::{linear8, rgb565, srgb8, straight8, straight_srgb8};
pub use crate::quick::{render_volume, Buffers, Lengths, Settings};
pub use crate::render::RenderStats;
pub use crate::shade::{Phong, Preset, Shading, LUT_SIZE};
pub use crate::{Error, FootprintOptions, GenericTable, Kernel, Lookup};
