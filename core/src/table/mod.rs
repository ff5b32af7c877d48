//! Footprint tables: the generic table (once per kernel) and the view-transformed table (once per
//! view), both square grids of samples over a symmetric box.
//!
//! # Layout
//! An n×n table holds samples at the *nodes* t = 0 … n−1 along each axis, node t sitting at
//! `−half + 2·half·t/(n−1)` (so the first and last nodes lie on the box edges, where every
//! footprint is zero). Storage is row-major: `data[row][col]`, row along screen/unit y, col along x.
//!
//! # Normalisation: what sums to one
//! The generic table stores F(u)/∫∫F, the kernel's footprint divided by its exact integral over
//! the unit domain ([`crate::kernel::Kernel::integral`]). A view's footprint weight is
//! `|det A| · T(A q)`, so **each voxel's footprint integrates to exactly one over the screen
//! plane** (units px⁻²). A sheet whose voxels project to a lattice with cell area `a` px² then
//! accumulates Σ weights ≈ 1/a at every pixel (Poisson summation: the footprint's integral is the
//! lattice sum's mean; its ripple is the footprint's spectrum at the lattice frequencies, measured
//! per kernel in `tests/flat_field.rs`). Multiplying by `a` makes a flat sheet flat at one.

mod format;
mod generic;
mod section;
mod view;

pub use format::{crc32, Crc32, TableError, FORMAT_VERSION, MAGIC};
pub use generic::GenericTable;
pub use section::{SectionError, SectionRay, SectionTable};
pub(crate) use view::for_each_view_node;
pub use view::{box_fill, ViewLayout, ViewTable, MIN_BOX_FILL};

/// How a table is read between its nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Lookup {
    /// The value of the nearest node.
    Nearest,
    /// Bilinear interpolation of the four surrounding nodes.
    Bilinear,
}

/// Samples an n×n row-major node grid at fractional node coordinates `t` (0 ≤ t ≤ n−1 inside;
/// anything outside reads as zero, the footprint's value beyond its support).
#[inline]
pub(crate) fn sample_nodes(data: &[f32], n: usize, t: [f32; 2], lookup: Lookup) -> f32 {
    let last = (n - 1) as f32;
    // The negated comparisons also send NaN to zero.
    if !(t[0] >= 0.0 && t[1] >= 0.0 && t[0] <= last && t[1] <= last) {
        return 0.0;
    }
    match lookup {
        Lookup::Nearest => {
            // t ≥ 0, so truncation after +0.5 rounds half up; ≤ n−1 by the test above.
            let c = (t[0] + 0.5) as usize;
            let r = (t[1] + 0.5) as usize;
            data[r.min(n - 1) * n + c.min(n - 1)]
        }
        Lookup::Bilinear => {
            let c0 = (t[0] as usize).min(n - 2);
            let r0 = (t[1] as usize).min(n - 2);
            let fx = t[0] - c0 as f32;
            let fy = t[1] - r0 as f32;
            let i = r0 * n + c0;
            let top = data[i] + fx * (data[i + 1] - data[i]);
            let bottom = data[i + n] + fx * (data[i + n + 1] - data[i + n]);
            top + fy * (bottom - top)
        }
    }
}
