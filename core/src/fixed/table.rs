//! Per-view set-up of the fixed-point path (float allowed here, once per view): the integer
//! footprint table with its maps, and the voxel placement in Q24 pixels.

use super::{MAX_ENTRY_FRAC, POS_FRAC};
use crate::frame::FrameSetup;
use crate::kernel::Shape;
use crate::math;
use crate::table::{for_each_view_node, GenericTable, Lookup, ViewLayout};
use core::fmt;

/// Largest screen coordinate, footprint half-extent or table coordinate the fixed path accepts,
/// in pixels (or nodes): 2³⁰, so Q24 values and their sums stay far inside `i64`.
pub const MAX_POS: f32 = (1u64 << 30) as f32;

/// Why a fixed-point set-up was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum FixedError {
    /// A quantity does not fit its fixed-point format (or is not finite).
    Range {
        /// What overflowed.
        what: &'static str,
    },
    /// A perspective frame: the fixed path is orthographic only (one integer affine placement
    /// and one integer table per view); render perspective in float
    /// ([`crate::render::PerVoxel`]).
    Perspective,
}

impl fmt::Display for FixedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Range { what } => write!(f, "{what} is outside the fixed-point range"),
            Self::Perspective => f.write_str(
                "the fixed-point path is orthographic only; render perspective in float",
            ),
        }
    }
}

impl core::error::Error for FixedError {}

/// Q24 of `x`, rounded to nearest, if |x| < [`MAX_POS`].
pub(crate) fn q24(x: f32, what: &'static str) -> Result<i64, FixedError> {
    if !(math::abs(x) < MAX_POS) {
        return Err(FixedError::Range { what });
    }
    Ok(math::floor(x * (1u32 << POS_FRAC) as f32 + 0.5) as i64)
}

/// An M×M integer footprint table for one view, and the integer maps from a pixel's screen offset
/// to its table coordinates and to the unit disc.
///
/// Entry e at a node stands for the weight × cell-area share w' = e / 2^f of a voxel's value that
/// a pixel there receives (see [`crate::fixed`]). A pixel at offset q (Q24 px) from the voxel's
/// projected centre reads the table at t = T q + t₀ (Q24 nodes, 0 … M−1) and lies in the
/// footprint's support when u = A q is inside the unit disc (radial kernels) or square
/// (separable kernels), A = [`crate::Footprint::to_unit`].
#[derive(Clone, Debug, PartialEq)]
pub struct FixedTable<const M: usize> {
    pub(crate) data: [[i32; M]; M],
    /// f: fraction bits of the entries.
    pub(crate) frac: u32,
    /// T, Q24 nodes per pixel, row-major.
    pub(crate) t_map: [[i64; 2]; 2],
    /// t₀, Q24 nodes.
    pub(crate) t0: [i64; 2],
    /// A, Q24 unit-disc units per pixel, row-major.
    pub(crate) u_map: [[i64; 2]; 2],
    /// Half-width and half-height of the footprint's box, Q24 px.
    pub(crate) half_extent: [i64; 2],
    /// round(cell area · 2^f) for small footprints whose weights are renormalised per splat; 0
    /// when they are not.
    pub(crate) renorm: i64,
    pub(crate) separable: bool,
    pub(crate) lookup: Lookup,
}

impl<const M: usize> FixedTable<M> {
    const VALID: () = assert!(M >= 2, "a table needs at least 2×2 nodes");

    /// An all-zero table (every weight zero), for `static` storage before the first build.
    pub const fn zeroed() -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::VALID;
        FixedTable {
            data: [[0; M]; M],
            frac: 0,
            t_map: [[0; 2]; 2],
            t0: [0; 2],
            u_map: [[0; 2]; 2],
            half_extent: [0; 2],
            renorm: 0,
            separable: false,
            lookup: Lookup::Nearest,
        }
    }

    /// The two-stage method: the view table of [`crate::ViewTable::build`] (M×M nodes in the
    /// footprint's [`ViewLayout`], read from `generic` with `build` lookup), scaled by `frame`'s
    /// cell area and quantised; pixels read it with `sample` lookup.
    pub fn build_view<const N: usize>(
        &mut self,
        frame: &FrameSetup,
        generic: &GenericTable<N>,
        build: Lookup,
        sample: Lookup,
    ) -> Result<(), FixedError> {
        let fp = &frame.footprint;
        let [ex, ey] = fp.half_extent;
        let steps = (M - 1) as f32;
        // A view-table value interpolates generic values, so this bounds every entry.
        let bound = fp.scale * frame.cell_area * max_abs(generic.as_slice());
        let scale = self.set_maps(frame, bound)?;
        let layout = ViewLayout::for_footprint(fp);
        for_each_view_node(fp, generic, build, layout, &mut self.data, |e, t| {
            *e = quantise(t * scale)
        });
        let half = 0.5 * steps;
        self.t_map = match layout {
            ViewLayout::ScreenBox => {
                let npp = [steps / (2.0 * ex), steps / (2.0 * ey)];
                [
                    [q24(npp[0], "view table resolution")?, 0],
                    [0, q24(npp[1], "view table resolution")?],
                ]
            }
            ViewLayout::Unit => q24_mat(&fp.to_unit, half)?,
        };
        self.t0 = [q24(half, "table size")?; 2];
        self.lookup = sample;
        Ok(())
    }

    /// The direct method: `generic` itself (M = N), scaled by the view's |det A| and cell area and
    /// quantised; a pixel at q reads it at the unit coordinates A q with `lookup`.
    pub fn build_direct(
        &mut self,
        frame: &FrameSetup,
        generic: &GenericTable<M>,
        lookup: Lookup,
    ) -> Result<(), FixedError> {
        let fp = &frame.footprint;
        let bound = fp.scale * frame.cell_area * max_abs(generic.as_slice());
        let scale = self.set_maps(frame, bound)?;
        for (dst, src) in self.data.iter_mut().zip(&generic.data) {
            for (e, &v) in dst.iter_mut().zip(src) {
                *e = quantise(v * scale);
            }
        }
        let half = 0.5 * (M - 1) as f32;
        self.t_map = q24_mat(&fp.to_unit, half)?;
        self.t0 = [q24(half, "table size")?; 2];
        self.lookup = lookup;
        Ok(())
    }

    /// Sets everything but the entries and the table map; returns 2^f · |det A| · cell area, the
    /// factor from generic-table values to entries.
    fn set_maps(&mut self, frame: &FrameSetup, bound: f32) -> Result<f32, FixedError> {
        let fp = &frame.footprint;
        if !bound.is_finite() {
            return Err(FixedError::Range {
                what: "footprint weight",
            });
        }
        let limit = (1u32 << MAX_ENTRY_FRAC) as f32;
        let mut frac = MAX_ENTRY_FRAC;
        while frac > 0 && bound * (1u64 << frac) as f32 > limit {
            frac -= 1;
        }
        if bound > limit {
            return Err(FixedError::Range {
                what: "footprint weight",
            });
        }
        let pow = (1u64 << frac) as f32;
        self.frac = frac;
        self.u_map = q24_mat(&fp.to_unit, 1.0)?;
        self.half_extent = [
            q24(fp.half_extent[0], "footprint extent")?,
            q24(fp.half_extent[1], "footprint extent")?,
        ];
        self.renorm = if fp.renormalise {
            let c = frame.cell_area * pow;
            if !(c < (1u64 << 38) as f32) {
                return Err(FixedError::Range { what: "cell area" });
            }
            (math::floor(c + 0.5) as i64).max(1)
        } else {
            0
        };
        self.separable = fp.shape == Shape::Separable;
        Ok(fp.scale * frame.cell_area * pow)
    }

    /// f, the entries' fraction bits.
    pub fn frac_bits(&self) -> u32 {
        self.frac
    }

    /// The entries, row-major.
    pub fn as_slice(&self) -> &[i32] {
        self.data.as_flattened()
    }
}

/// Q24 of k·m, entry by entry.
fn q24_mat(m: &[[f32; 2]; 2], k: f32) -> Result<[[i64; 2]; 2], FixedError> {
    let e = |x: f32| q24(x * k, "unit map");
    Ok([[e(m[0][0])?, e(m[0][1])?], [e(m[1][0])?, e(m[1][1])?]])
}

fn max_abs(v: &[f32]) -> f32 {
    v.iter().fold(0.0f32, |m, &x| m.max(math::abs(x)))
}

/// Rounds to the nearest `i32` (the caller's bound keeps |x| ≤ 2²⁸).
fn quantise(x: f32) -> i32 {
    math::floor(x + 0.5) as i32
}

/// Where every voxel of a frame lands on screen, in Q24 pixels: voxel (u, v) of sheet s sits at
/// `origin + s·c_k + u·c_a + v·c_b`, the columns of [`FrameSetup::grid_to_screen`] quantised.
/// Integer sums, so positions are exact and the same on every target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// Screen x, y of voxel (0, 0, 0), Q24 px.
    pub(crate) origin: [i64; 2],
    /// Screen x, y step per sheet (sheet axis), Q24 px.
    pub(crate) sheet: [i64; 2],
    /// Screen x, y step per u (in-sheet axis a), Q24 px.
    pub(crate) along_a: [i64; 2],
    /// Screen x, y step per v (in-sheet axis b), Q24 px.
    pub(crate) along_b: [i64; 2],
}

impl Placement {
    /// The placement of `frame`'s voxels. Refused when a corner of the volume lands more than
    /// 2³⁰ px from the image origin.
    pub fn new(frame: &FrameSetup) -> Result<Self, FixedError> {
        let m = frame.grid_to_screen;
        for p in frame.voxel_corners() {
            q24(p.x, "volume corner on screen")?;
            q24(p.y, "volume corner on screen")?;
        }
        let col = |c: usize| -> Result<[i64; 2], FixedError> {
            Ok([
                q24(m.col(c).x, "voxel step on screen")?,
                q24(m.col(c).y, "voxel step on screen")?,
            ])
        };
        let (a, b) = frame.in_sheet;
        Ok(Placement {
            origin: [
                q24(frame.origin.x, "volume origin on screen")?,
                q24(frame.origin.y, "volume origin on screen")?,
            ],
            sheet: col(frame.sheet_axis)?,
            along_a: col(a)?,
            along_b: col(b)?,
        })
    }
}
