//! The compact path's per-view set-up, in float (once per view; see [`super`]): box sizes,
//! the phase stencils and the voxel placement.
// Float is this file's purpose (the integer-only lints are the parent module's).
#![allow(clippy::float_arithmetic, clippy::disallowed_types)]

use super::{
    pack_origin, pack_run, stencil_len, CompactError, CompactPlacement, CompactStencils,
    MAX_PHASES, MAX_SCREEN_PX, MAX_SIDE, MAX_WEIGHT_FRAC, ONE, POS_FRAC,
};
use crate::fixed::FixedError;
use crate::frame::FrameSetup;
use crate::math;
use crate::splat::BufferError;

/// Box width and height (pixels) of `frame`'s footprint: ⌊2e⌋ + 1 pixel centres fit in an
/// interval of length 2e, per axis.
pub fn box_for(frame: &FrameSetup) -> Result<[usize; 2], CompactError> {
    let e = frame.footprint.half_extent;
    let mut out = [0; 2];
    for (o, &e) in out.iter_mut().zip(&e) {
        if !(e >= 0.0 && e < MAX_SIDE as f32) {
            return Err(CompactError::Wide {
                side: if e.is_finite() {
                    e as usize * 2 + 1
                } else {
                    usize::MAX
                },
            });
        }
        let side = math::floor(2.0 * e) as usize + 1;
        if side > MAX_SIDE {
            return Err(CompactError::Wide { side });
        }
        *o = side;
    }
    Ok(out)
}

/// `i16`s the stencils of `frame` need at `phases` per axis: P² · (1 + By · (Bx + 1)).
pub fn len_for(frame: &FrameSetup, phases: usize) -> Result<usize, CompactError> {
    if phases == 0 || phases > MAX_PHASES {
        return Err(CompactError::Phases { phases });
    }
    let [bx, by] = box_for(frame)?;
    Ok(phases * phases * stencil_len(bx, by))
}

impl<'a> CompactStencils<'a> {
    /// Samples `frame`'s footprint through `sampler` (its weight in px⁻² at a screen offset,
    /// e.g. a [`crate::splat::Direct`] over a generic table in flash: no view table in RAM) at
    /// the centre of each of `phases`² phase cells, into `buffer` (at least [`len_for`] long).
    pub fn build<S: crate::splat::Sampler + ?Sized>(
        frame: &FrameSetup,
        sampler: &S,
        phases: usize,
        buffer: &'a mut [i16],
    ) -> Result<Self, CompactError> {
        if frame.camera().is_some() {
            return Err(FixedError::Perspective.into());
        }
        let len = len_for(frame, phases)?;
        if buffer.len() < len {
            return Err(CompactError::Buffer(BufferError::TooSmall {
                needed: len,
                got: buffer.len(),
            }));
        }
        let [bx, by] = box_for(frame)?;
        let covering = covering_bound(frame)?;
        // The largest |weight| that keeps every sum in `i32` (see `covering_bound`).
        let cap = (65_535 / covering).min(32_767) as f32;
        // One sampling pass at the finest W; a stencil whose weights do not fit it restarts the
        // pass at the W its largest weight allows (W only falls, so this ends, and it ends at
        // the W of the view's largest weight).
        let mut frac = MAX_WEIGHT_FRAC;
        let frac = loop {
            match fill(
                frame,
                sampler,
                phases,
                [bx, by],
                (frac, cap),
                &mut buffer[..len],
            ) {
                Ok(()) => break frac,
                Err(Fill::Over(largest)) => {
                    let lower = weight_frac(largest, cap)?;
                    if lower >= frac {
                        return Err(FixedError::Range {
                            what: "stencil weight",
                        }
                        .into());
                    }
                    frac = lower;
                }
                Err(Fill::Error(e)) => return Err(e),
            }
        };
        Ok(CompactStencils {
            data: &buffer[..len],
            phases: phases as u32,
            bx,
            by,
            stride: stencil_len(bx, by),
            frac,
            covering,
        })
    }
}

/// Why a fill pass stopped: a weight too large for W (the stencil's largest |weight|), or an
/// error.
enum Fill {
    Over(f32),
    Error(CompactError),
}

impl From<CompactError> for Fill {
    fn from(e: CompactError) -> Self {
        Fill::Error(e)
    }
}

/// Samples and quantises every phase stencil at weight fraction `frac` into `out`.
fn fill<S: crate::splat::Sampler + ?Sized>(
    frame: &FrameSetup,
    sampler: &S,
    phases: usize,
    [bx, by]: [usize; 2],
    (frac, cap): (u32, f32),
    out: &mut [i16],
) -> Result<(), Fill> {
    let fp = &frame.footprint;
    let (area, renormalise) = (frame.cell_area, fp.renormalise);
    let scale = (1u32 << frac) as f32;
    let stride = stencil_len(bx, by);
    let mut weights = [0.0f32; MAX_SIDE * MAX_SIDE];
    for (k, out) in out.chunks_exact_mut(stride).enumerate() {
        let phi = [k % phases, k / phases].map(|i| (i as f32 + 0.5) / phases as f32);
        // First pixel (relative to the voxel's pixel) whose centre is within e.
        let first = [0, 1].map(|a| -math::floor(fp.half_extent[a] + 0.5 - phi[a]) as i32);
        let mut sum = 0.0f32;
        for y in 0..by {
            for x in 0..bx {
                let q = [
                    (first[0] + x as i32) as f32 + 0.5 - phi[0],
                    (first[1] + y as i32) as f32 + 0.5 - phi[1],
                ];
                let w = sampler.weight(q) * area;
                let w = if w.is_finite() { w } else { 0.0 };
                weights[y * bx + x] = w;
                sum += w;
            }
        }
        let weights = &mut weights[..bx * by];
        if renormalise && !(sum > 0.0) {
            // No pixel centre in the support: the whole cell on the voxel's own pixel.
            if area * scale > cap {
                return Err(Fill::Over(area));
            }
            out.fill(0);
            out[0] = pack_origin(0, 0);
            out[1] = pack_run(0, 1);
            out[2] = quantise(area * scale)?;
            continue;
        }
        if renormalise {
            let s = area / sum;
            weights.iter_mut().for_each(|w| *w *= s);
        }
        let largest = weights.iter().fold(0.0f32, |m, w| m.max(math::abs(*w)));
        if largest * scale > cap {
            return Err(Fill::Over(largest));
        }
        out[0] = pack_origin(first[0], first[1]);
        let mut q = [0i16; MAX_SIDE * MAX_SIDE];
        for (d, &w) in q.iter_mut().zip(weights.iter()) {
            *d = quantise(w * scale)?;
        }
        if renormalise {
            spread_remainder(&mut q[..bx * by], quantise_i32(area * scale)?)?;
        }
        // Rounding (and the remainder) may push one weight past the cap: a lower W then.
        let most = q[..bx * by]
            .iter()
            .map(|w| w.unsigned_abs())
            .max()
            .unwrap_or(0);
        if f32::from(most) > cap {
            return Err(Fill::Over(f32::from(most) / scale));
        }
        for y in 0..by {
            let row = &q[y * bx..(y + 1) * bx];
            let lo = row.iter().position(|&w| w != 0).unwrap_or(0);
            let hi = row.iter().rposition(|&w| w != 0).map_or(0, |i| i + 1);
            let at = 1 + y * (bx + 1);
            out[at] = pack_run(lo, hi);
            out[at + 1..at + 1 + bx].copy_from_slice(row);
        }
    }
    Ok(())
}

/// The largest W ≤ [`MAX_WEIGHT_FRAC`] with `largest` · 2^W ≤ `cap`.
fn weight_frac(largest: f32, cap: f32) -> Result<u32, CompactError> {
    let range = || {
        CompactError::Fixed(FixedError::Range {
            what: "stencil weight",
        })
    };
    if !largest.is_finite() {
        return Err(range());
    }
    let mut frac = MAX_WEIGHT_FRAC;
    while largest * (1u32 << frac) as f32 > cap {
        frac = frac.checked_sub(1).ok_or_else(range)?;
    }
    Ok(frac)
}

/// The most voxels of one sheet whose stencils can cover one pixel, N: the bound behind the
/// plain adds (see [`super`], "Why the sums cannot overflow").
///
/// A stencil covers the pixels whose centres lie within the footprint's half-extents e of its
/// phase centre, which is within half a pixel of the voxel's Q16 position c (a whole-cell
/// stencil covers only the pixel holding c). So a pixel centre p is covered only by voxels with
/// |p − c| ≤ e + ½ per axis: lattice points c = o + u·a + v·b in a (2eₓ + 1) × (2e_y + 1)
/// rectangle. Each such point's cell {c + s·a + t·b : s, t ∈ [0, 1)} lies in the rectangle
/// widened by |aₓ| + |bₓ| and |a_y| + |b_y|, and the cells are disjoint with area |det(a, b)|,
/// so N ≤ (2eₓ + 1 + |aₓ| + |bₓ|)(2e_y + 1 + |a_y| + |b_y|) / |det|, rounded up with a margin
/// for the float set-up and the Q16 steps.
pub(super) fn covering_bound(frame: &FrameSetup) -> Result<u32, CompactError> {
    let m = frame.grid_to_screen;
    let (a, b) = (m.col(frame.in_sheet.0), m.col(frame.in_sheet.1));
    let e = frame.footprint.half_extent;
    let wx = 2.0 * e[0] + 1.0 + math::abs(a.x) + math::abs(b.x);
    let wy = 2.0 * e[1] + 1.0 + math::abs(a.y) + math::abs(b.y);
    let det = math::abs(a.x * b.y - a.y * b.x);
    let n = wx * wy / (det * 0.999) + 1.0;
    if !(1.0..65_536.0).contains(&n) {
        return Err(FixedError::Range {
            what: "voxels over one pixel",
        }
        .into());
    }
    Ok(n as u32)
}

fn quantise_i32(x: f32) -> Result<i32, CompactError> {
    if !(math::abs(x) < (1u32 << 30) as f32) {
        return Err(FixedError::Range {
            what: "stencil weight",
        }
        .into());
    }
    Ok(math::floor(x + 0.5) as i32)
}

fn quantise(x: f32) -> Result<i16, CompactError> {
    i16::try_from(quantise_i32(x)?).map_err(|_| {
        FixedError::Range {
            what: "stencil weight",
        }
        .into()
    })
}

/// Adds `target − Σ q` to the largest weight so the stencil sums to `target` exactly.
fn spread_remainder(q: &mut [i16], target: i32) -> Result<(), CompactError> {
    let sum: i32 = q.iter().map(|&w| i32::from(w)).sum();
    let Some(big) = (0..q.len()).max_by_key(|&i| q[i].unsigned_abs()) else {
        return Ok(());
    };
    q[big] = i16::try_from(i32::from(q[big]) + target - sum).map_err(|_| {
        CompactError::Fixed(FixedError::Range {
            what: "stencil weight",
        })
    })?;
    Ok(())
}

impl CompactPlacement {
    /// The placement of `frame`'s voxels. Refused for a perspective frame, and when a corner of
    /// the volume lands [`MAX_SCREEN_PX`] or more from the image origin (or the image is that
    /// large).
    pub fn new(frame: &FrameSetup) -> Result<Self, CompactError> {
        if frame.camera().is_some() {
            return Err(FixedError::Perspective.into());
        }
        let limit = MAX_SCREEN_PX as f32;
        if frame.size.iter().any(|&s| s >= MAX_SCREEN_PX as usize) {
            return Err(FixedError::Range { what: "image size" }.into());
        }
        let m = frame.grid_to_screen;
        for p in frame.voxel_corners() {
            if !(math::abs(p.x) < limit && math::abs(p.y) < limit) {
                return Err(FixedError::Range {
                    what: "volume corner on screen",
                }
                .into());
            }
        }
        let q16 = |x: f32| math::floor(x * (1u32 << POS_FRAC) as f32 + 0.5) as i32;
        let col = |c: usize| [q16(m.col(c).x), q16(m.col(c).y)];
        let (a, b) = frame.in_sheet;
        Ok(CompactPlacement {
            origin: [q16(frame.origin.x), q16(frame.origin.y)],
            sheet: col(frame.sheet_axis),
            along_a: col(a),
            along_b: col(b),
        })
    }
}

/// A float premultiplied RGBA value in Q15, each channel clamped to [0, 1] (NaN to 0).
pub fn quantise_value(rgba: [f32; 4]) -> [u16; 4] {
    rgba.map(|c| {
        let c = if c > 0.0 { c.min(1.0) } else { 0.0 };
        math::floor(c * f32::from(ONE) + 0.5) as u16
    })
}

/// A Q15 pixel as float.
pub fn to_f32(p: [u16; 4]) -> [f32; 4] {
    p.map(|c| f32::from(c) / f32::from(ONE))
}
