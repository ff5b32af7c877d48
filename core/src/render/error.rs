//! Why a render step was refused: [`RenderError`].

use crate::splat::BufferError;
use core::fmt;

/// Why a render step was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum RenderError {
    /// A caller buffer has the wrong size.
    Buffer(BufferError),
    /// A sheet holds the wrong number of samples.
    SheetLength {
        /// Samples expected (`dims[a] × dims[b]`).
        expected: usize,
        /// Samples given.
        got: usize,
    },
    /// A sheet index beyond the volume.
    SheetIndex {
        /// Index given.
        index: usize,
        /// Number of sheets.
        count: usize,
    },
    /// More sheets pushed into a [`SheetRing`](super::SheetRing) than the volume has.
    TooManySheets,
    /// [`SheetRing::finish`](super::SheetRing::finish) before every sheet of the frame was pushed.
    MissingSheets {
        /// Sheets pushed.
        delivered: usize,
        /// Sheets the frame has.
        expected: usize,
    },
    /// A band of rows that is not inside the image.
    Band {
        /// First row asked for.
        start: usize,
        /// One past the last row asked for.
        end: usize,
        /// Image height, rows.
        height: usize,
    },
    /// A transfer function that cannot classify.
    TransferFunction(crate::shade::TransferFunctionError),
    /// A perspective frame given to a precision that splats with one footprint per view
    /// ([`FloatPath`](super::FloatPath), [`FixedPath`](super::FixedPath)): use a float path placing each voxel ([`PerVoxel`](super::PerVoxel)).
    Projection,
    /// A voxel's own footprint (perspective) could not be built.
    Geometry(crate::geometry::GeometryError),
    /// A voxel given to a [`SlabRenderer`](super::SlabRenderer) overlaps a slab already composited (voxels must come
    /// in the order of the slab they reach first).
    SlabOrder {
        /// The voxel's first slab.
        first: usize,
        /// Its last slab.
        last: usize,
        /// Slabs composited so far.
        composited: usize,
    },
    /// A [`SheetRing`](super::SheetRing) made for another compositing order than the renderer's
    /// (make it with [`SheetRing::for_renderer`](super::SheetRing::for_renderer)).
    RingOrder {
        /// The ring's order.
        ring: crate::frame::Order,
        /// The renderer's.
        renderer: crate::frame::Order,
    },
    /// Occlusion culling refused ([`SheetRenderer::with_occlusion`](super::SheetRenderer::with_occlusion)).
    Occlusion(super::OcclusionError),
    /// A voxel above the channel bound a [`FixedPath`](super::FixedPath) was promised
    /// ([`FixedPath::with_value_bound`](super::FixedPath::with_value_bound)).
    ValueAboveBound {
        /// The channel value (Q24).
        value: u32,
        /// The bound.
        bound: u32,
    },
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Buffer(e) => e.fmt(f),
            Self::SheetLength { expected, got } => {
                write!(f, "sheet has {got} samples, expected {expected}")
            }
            Self::SheetIndex { index, count } => write!(f, "sheet {index} is outside 0..{count}"),
            Self::TooManySheets => f.write_str("more sheets than the volume has"),
            Self::MissingSheets {
                delivered,
                expected,
            } => write!(
                f,
                "the frame ended after {delivered} of its {expected} sheets were delivered"
            ),
            Self::Band { start, end, height } => {
                write!(
                    f,
                    "band of rows {start}..{end} is not inside an image {height} rows high"
                )
            }
            Self::TransferFunction(e) => e.fmt(f),
            Self::Projection => f.write_str(
                "a perspective frame needs per-voxel footprints (FloatPath over PerVoxel); this path has one footprint per view",
            ),
            Self::Geometry(e) => write!(f, "a voxel's footprint: {e}"),
            Self::SlabOrder {
                first,
                last,
                composited,
            } => write!(
                f,
                "a voxel overlapping slabs {first}..={last} came after {composited} slabs were \
                 composited: feed voxels in the order of the slab they reach first"
            ),
            Self::RingOrder { ring, renderer } => write!(
                f,
                "the sheet ring was made for {ring:?} but the renderer composites {renderer:?}: \
                 make the ring with SheetRing::for_renderer"
            ),
            Self::Occlusion(e) => e.fmt(f),
            Self::ValueAboveBound { value, bound } => write!(
                f,
                "a voxel channel of {value} (Q24) is above the bound {bound} the fixed path was given"
            ),
        }
    }
}

impl core::error::Error for RenderError {}

impl From<crate::shade::TransferFunctionError> for RenderError {
    fn from(e: crate::shade::TransferFunctionError) -> Self {
        RenderError::TransferFunction(e)
    }
}

impl From<BufferError> for RenderError {
    fn from(e: BufferError) -> Self {
        RenderError::Buffer(e)
    }
}
