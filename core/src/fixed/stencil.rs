//! Integer phase stencils: the fixed path's counterpart of [`crate::stencil`]. A view's integer
//! footprint ([`FixedTable`]) is sampled once per sub-pixel phase, so splatting a voxel is a run
//! of integer multiply-adds with no table walk per pixel and no second pass to renormalise.
//! No floating point here, at build or splat time (denied below, like [`super::splat`]).
//!
//! A voxel at Q24 screen position c = (i + φx, j + φy) (i, j whole pixels) covers pixel centres
//! in a box of B × B pixels around (i, j), B = 2·reach + 1. For each phase on a (P + 1) × (P + 1)
//! grid, φ = (a/P, b/P), the stencil holds the table walk's own integer weight
//! ([`FixedTable`]'s lookup, bit for bit) at each pixel of the box. For a footprint the walk
//! renormalises, each stencil is scaled once, here, to sum to exactly C = round(cell area · 2^f)
//! (the walk scales each voxel's value by C / S instead; rounding is spread so the sum is exact).
//! A voxel's weights are the bilinear blend of the four stencils around its phase, with Q8
//! fractions: (Σ c_k s_k + 2¹⁵) >> 16, c_k summing to 2¹⁶.
//!
//! **Nearest phase** ([`FixedStencils::with_phase_lookup`], [`PhaseLookup::Nearest`]): a narrow
//! or blended footprint may instead read the one corner stencil nearest the phase, (a + [f_x ≥
//! ½], b + [f_y ≥ ½]) with the Q8 fractions f (f ≥ 128 exactly when the phase's fraction is at
//! least ½, as the float stencils decide it). Its weights are that stencil's entries as they
//! are, the same integers the blend gives at that corner's phase (there c = 2¹⁶, and
//! (2¹⁶·s + 2¹⁵) >> 16 = s), so every voxel still deposits exactly what its stencil sums to; the
//! footprint is placed up to 1/(2P) px off per axis, the float path's nearest error
//! ([`crate::stencil::PhaseLookup`]). One entry read per pixel and no multiply of the blend. An
//! edged footprint is always blended.
//!
//! **Narrow and wide.** A *narrow* footprint (box side ≤ [`crate::stencil::NARROW_SIDE`]) is
//! blended over every pixel where a corner stencil is non-zero, as the float path does. A *wide*
//! one (up to [`MAX_STENCIL_SIDE`] px, and [`MAX_STENCIL_FLOATS`] entries, with the fewer phases
//! the caller picks for it, see [`crate::stencil::edged_phases_for`]) is blended only where all four
//! corner stencils are non-zero; at the support's edge, where one of them is zero (the truncated
//! kernel drops there from a few per cent of its peak to nothing), the pixel takes the walk's
//! own weight, so no blend crosses the edge. Rows and runs are widened by a pixel so that an edge
//! pixel none of the four corners reaches is still visited. Footprints beyond those limits, and
//! renormalised ones whose scaled weights would not fit an `i32`, are splatted by the walk.
//!
//! **Accuracy.** The blend adds the error of linear interpolation over a phase step of 1/P px,
//! as for the float stencils (see [`crate::stencil`]), and Q8 fractions add at most 1/512 of a
//! phase step; the harness's `verify` measures it, and `tests/stencils.rs` compares these
//! stencils with the walk.
//!
//! **Memory.** (P + 1)² · B² + P² · B `i32`s ([`len_for`]), built per view in caller storage:
//! the same count as the float stencils.
#![deny(clippy::float_arithmetic, clippy::disallowed_types)]

use super::{is_grey, FixedTable, POS_FRAC};
use crate::splat::{BufferError, ImageMut, SplatStats};
use crate::stencil::walk::{self, corner_rows, SpanWalk};
use crate::stencil::{
    corner_offsets, nonzero_run, PhaseLookup, MAX_STENCIL_FLOATS, MAX_STENCIL_SIDE, NARROW_SIDE,
};

const HALF_POS: i64 = 1 << (POS_FRAC - 1);

/// Why integer stencils were not built (the table walk serves the view instead).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum StencilError {
    /// The footprint's box is wider than [`MAX_STENCIL_SIDE`] pixels, or the stencils would
    /// exceed [`MAX_STENCIL_FLOATS`] entries.
    Wide,
    /// `phases` is 0.
    NoPhases,
    /// A renormalised weight does not fit an `i32`.
    Range,
    /// The caller's buffer is shorter than [`len_for`].
    Buffer(BufferError),
}

impl core::fmt::Display for StencilError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Wide => write!(f, "the footprint is too wide for integer stencils"),
            Self::NoPhases => write!(f, "integer stencils need at least one phase"),
            Self::Range => write!(f, "a stencil weight does not fit 32 bits"),
            Self::Buffer(e) => write!(f, "{e}"),
        }
    }
}

impl core::error::Error for StencilError {}

/// Box side B of `table`'s footprint, if stencils apply: 2·⌈e + ½⌉ + 1 px ≤
/// [`MAX_STENCIL_SIDE`], e the larger half-extent (as [`crate::stencil::side_for`], in
/// integers).
pub fn side_for<const M: usize>(table: &FixedTable<M>) -> Option<usize> {
    let e = table.half_extent[0].max(table.half_extent[1]);
    if e < 0 {
        return None;
    }
    let reach = (e + HALF_POS + (1 << POS_FRAC) - 1) >> POS_FRAC; // ⌈e + ½⌉
    let side = 2 * reach + 1;
    (side <= MAX_STENCIL_SIDE as i64).then_some(side as usize)
}

/// `i32`s needed for `table`'s stencils at `phases` phases per pixel, if stencils apply:
/// (P + 1)² · B² + P² · B ≤ [`MAX_STENCIL_FLOATS`]. A wide footprint should be given the fewer
/// phases [`crate::stencil::edged_phases_for`] picks for it.
pub fn len_for<const M: usize>(table: &FixedTable<M>, phases: usize) -> Option<usize> {
    let side = side_for(table)?;
    let len = crate::stencil::stencil_len(phases, side)?;
    (len <= MAX_STENCIL_FLOATS).then_some(len)
}

/// One view's integer phase stencils, in caller storage, with the table they were sampled from.
#[derive(Debug)]
pub struct FixedStencils<'a, const M: usize> {
    /// (P + 1)² stencils of B² weights (Q f), then P² cells of B row runs (first | last << 16).
    data: &'a [i32],
    ranges: usize,
    side: usize,
    phases: usize,
    /// Box side above [`NARROW_SIDE`]: blended only inside all four corners' support.
    wide: bool,
    /// How a voxel's phase is read ([`FixedStencils::with_phase_lookup`]; built blended).
    lookup: PhaseLookup,
    /// The table the stencils were sampled from (a wide footprint's edge pixels read it).
    table: &'a FixedTable<M>,
    /// The largest |weight| a splat can give a pixel (the largest stencil entry, and for an edged
    /// footprint the largest table entry, plus one for rounding).
    max_weight: i64,
}

impl<const M: usize> Clone for FixedStencils<'_, M> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<const M: usize> Copy for FixedStencils<'_, M> {}

impl<'a, const M: usize> FixedStencils<'a, M> {
    /// Samples `table`'s footprint at every phase (`phases` ≥ 1 per pixel) into `buffer` (at
    /// least [`len_for`] long). A footprint wider than [`NARROW_SIDE`] is edged: blended only
    /// where all four corners are non-zero, its edge pixels weighted by the walk.
    pub fn build(
        table: &'a FixedTable<M>,
        phases: usize,
        buffer: &'a mut [i32],
    ) -> Result<Self, StencilError> {
        Self::build_as(table, phases, buffer, true)
    }

    /// [`FixedStencils::build`], but a footprint wider than [`NARROW_SIDE`] is blended up to its
    /// edge as a narrow one is (the float stencils' *blended* plan,
    /// [`crate::stencil::plan_for`]: give it that plan's phases, P·r ≥
    /// [`crate::stencil::BLEND_REACH`]).
    pub fn build_blended(
        table: &'a FixedTable<M>,
        phases: usize,
        buffer: &'a mut [i32],
    ) -> Result<Self, StencilError> {
        Self::build_as(table, phases, buffer, false)
    }

    fn build_as(
        table: &'a FixedTable<M>,
        phases: usize,
        buffer: &'a mut [i32],
        edged: bool,
    ) -> Result<Self, StencilError> {
        if phases == 0 {
            return Err(StencilError::NoPhases);
        }
        let side = side_for(table).ok_or(StencilError::Wide)?;
        let len = len_for(table, phases).ok_or(StencilError::Wide)?;
        let wide = side > NARROW_SIDE && edged;
        if side > NARROW_SIDE && table.renorm != 0 {
            // Renormalised footprints are a few pixels wide; a wide one is not expected.
            return Err(StencilError::Wide);
        }
        if buffer.len() < len {
            return Err(StencilError::Buffer(BufferError::TooSmall {
                needed: len,
                got: buffer.len(),
            }));
        }
        let reach = (side / 2) as i64;
        let cells = side * side;
        let ranges = (phases + 1) * (phases + 1) * cells;
        let (weights, spans) = buffer[..len].split_at_mut(ranges);
        let mut raw = [0i64; NARROW_SIDE * NARROW_SIDE];
        for (k, stencil) in weights.chunks_exact_mut(cells).enumerate() {
            let (pa, pb) = ((k % (phases + 1)) as i64, (k / (phases + 1)) as i64);
            // The phase's offset inside pixel (0, 0), Q24 (a/P of a pixel, rounded down).
            let phase = [
                (pa << POS_FRAC) / phases as i64,
                (pb << POS_FRAC) / phases as i64,
            ];
            let weight_at = |n: usize| {
                let (mx, my) = ((n % side) as i64, (n / side) as i64);
                let q = [
                    ((mx - reach) << POS_FRAC) + HALF_POS - phase[0],
                    ((my - reach) << POS_FRAC) + HALF_POS - phase[1],
                ];
                table.weight(&table.cursor(q))
            };
            if table.renorm == 0 {
                // The walk's entries as they are (an entry is an i32).
                for (n, o) in stencil.iter_mut().enumerate() {
                    *o = i32::try_from(weight_at(n)).map_err(|_| StencilError::Range)?;
                }
                continue;
            }
            let raw = &mut raw[..cells];
            let mut sum = 0i64;
            for (n, w) in raw.iter_mut().enumerate() {
                *w = weight_at(n);
                sum += *w;
            }
            if sum > 0 {
                // Scaled to sum to C exactly: each weight is the step of round(C · prefix / S).
                let (c, s) = (i128::from(table.renorm), i128::from(sum));
                let (mut prefix, mut before) = (0i128, 0i128);
                for w in raw.iter_mut() {
                    prefix += i128::from(*w);
                    let upto = (c * prefix * 2 + s).div_euclid(2 * s);
                    *w = i64::try_from(upto - before).map_err(|_| StencilError::Range)?;
                    before = upto;
                }
            } else {
                // No pixel centre saw the footprint: the whole voxel goes to the pixel holding
                // its centre, as the walk does.
                raw.fill(0);
                let (cx, cy) = (phase[0] >> POS_FRAC, phase[1] >> POS_FRAC);
                let at = (reach + cy) as usize * side + (reach + cx) as usize;
                raw[at] = table.renorm;
            }
            for (o, &w) in stencil.iter_mut().zip(raw.iter()) {
                *o = i32::try_from(w).map_err(|_| StencilError::Range)?;
            }
        }
        // Per phase cell and box row: the first and last pixel where one of the cell's four
        // corner stencils is non-zero (wide: on this row or the next or previous one, widened by
        // a pixel each side, so edge pixels no corner reaches are visited too); first > last when
        // there is none.
        let weights = &*weights;
        let nonzero = |stencil: usize, my: usize| {
            nonzero_run(&weights[stencil * cells + my * side..][..side])
        };
        let run = |corners: [usize; 4], my: usize| {
            let rows = if wide {
                my.saturating_sub(1)..(my + 2).min(side)
            } else {
                my..my + 1
            };
            let (first, last) = rows
                .flat_map(|r| corners.iter().filter_map(move |&s| nonzero(s, r)))
                .fold((side, 0), |(f, l), (a, b)| (f.min(a), l.max(b)));
            if wide && first <= last {
                (first.saturating_sub(1), (last + 1).min(side - 1))
            } else {
                (first, last)
            }
        };
        walk::pack_runs(spans, side, phases, run, |bits| bits as i32);
        let entries = |e: &[i32]| e.iter().map(|w| i64::from(*w).abs()).max().unwrap_or(0);
        let mut max_weight = entries(weights) + 1;
        if wide {
            max_weight = max_weight.max(entries(table.as_slice()) + 1);
        }
        Ok(FixedStencils {
            data: &buffer[..len],
            ranges,
            side,
            phases,
            wide,
            lookup: PhaseLookup::Blend,
            table,
            max_weight,
        })
    }

    /// These stencils read at each voxel's phase by `lookup` (the module docs, "Nearest
    /// phase"); an edged footprint ignores it and is blended.
    pub fn with_phase_lookup(self, lookup: PhaseLookup) -> Self {
        Self { lookup, ..self }
    }

    /// How a voxel's phase is read: [`PhaseLookup::Blend`] for an edged footprint.
    pub fn phase_lookup(&self) -> PhaseLookup {
        self.lookup.unless_edged(self.wide)
    }

    /// Box side B, pixels.
    pub fn side(&self) -> usize {
        self.side
    }

    /// The largest channel value (Q24) up to which a sheet's additions into any pixel cannot
    /// overflow the `i64` accumulator, for voxels placed by `place` (one sheet's centres lie on
    /// the lattice u·a + v·b, Q24 px): at most N voxels' boxes hold a pixel, each adding at most
    /// value × [`FixedStencils`]'s largest weight, and N · weight · value ≤ 2⁶². N counts the
    /// lattice points in a square of side B + 1 px (where a centre must lie for its box to hold
    /// the pixel): at most ⌊L / m⌋ + 1 per lattice row (m = max(|aₓ|, |a_y|), consecutive points'
    /// larger coordinate step) times ⌊L · (|aₓ| + |a_y|) / |a × b|⌋ + 1 rows (the square's width
    /// across the rows over their spacing), the smaller of the bounds with a and b swapped.
    /// `None` when the lattice is degenerate. Below it, wrapping adds equal saturating ones (see
    /// [`crate::render::FixedPath::with_value_bound`]).
    pub fn exact_below(&self, along_a: [i64; 2], along_b: [i64; 2]) -> Option<u64> {
        let l = i128::from((self.side as i64 + 1) << POS_FRAC);
        let cell = (i128::from(along_a[0]) * i128::from(along_b[1])
            - i128::from(along_a[1]) * i128::from(along_b[0]))
        .abs();
        let count = |a: [i64; 2]| {
            let (x, y) = (i128::from(a[0]).abs(), i128::from(a[1]).abs());
            let m = x.max(y);
            if m == 0 || cell == 0 {
                return None;
            }
            let per_row = l / m + 1;
            let rows = (l * (x + y)) / cell + 1;
            per_row.checked_mul(rows)
        };
        let n = match (count(along_a), count(along_b)) {
            (Some(p), Some(q)) => p.min(q),
            (p, q) => p.or(q)?,
        };
        let per_value = n.checked_mul(i128::from(self.max_weight))?;
        u64::try_from((1i128 << 62) / per_value.max(1)).ok()
    }

    /// Phases per pixel P.
    pub fn phases(&self) -> usize {
        self.phases
    }

    /// Spreads `value` (premultiplied RGBA, Q24) of a voxel projected to `center` (Q24 px,
    /// absolute) into `acc` (Q(24 + f), saturating adds), calling `touched(y, x0, x1)` for each
    /// row it updated: the blend of the four stencils around the centre's sub-pixel phase, or
    /// the nearest one's entries ([`FixedStencils::with_phase_lookup`]).
    ///
    /// Not inlined (nor is [`FixedStencils::splat_unsaturated`]): inlined, its then eight instances
    /// raised the firmware's frame (which never splats through stencils) from 1976 to 2456 bytes
    /// of stack on Cortex-M3; the host called it out of line anyway.
    #[inline(never)]
    pub fn splat(
        &self,
        center: [i64; 2],
        value: &[u32; 4],
        acc: &mut ImageMut<'_, [i64; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> SplatStats {
        self.splat_with::<false>(center, value, acc, touched)
    }

    /// [`FixedStencils::splat`] with wrapping adds, for a caller that has shown no pixel's sum
    /// can leave the `i64` range ([`FixedStencils::exact_below`]): the same sums, and cheaper
    /// (an `i64` saturating add is a compare and select per channel).
    #[inline(never)]
    pub fn splat_unsaturated(
        &self,
        center: [i64; 2],
        value: &[u32; 4],
        acc: &mut ImageMut<'_, [i64; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> SplatStats {
        self.splat_with::<true>(center, value, acc, touched)
    }

    /// [`FixedStencils::splat_as`] for this voxel's colour and this view's [`mode`](Self::mode),
    /// with wrapping adds if `WRAP`: the one dispatch both splats share.
    #[inline(always)]
    fn splat_with<const WRAP: bool>(
        &self,
        center: [i64; 2],
        value: &[u32; 4],
        acc: &mut ImageMut<'_, [i64; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> SplatStats {
        match (is_grey(value), self.mode()) {
            (true, EDGED) => self.splat_as::<WRAP, true, EDGED>(center, value, acc, touched),
            (true, NEAREST) => self.splat_as::<WRAP, true, NEAREST>(center, value, acc, touched),
            (true, _) => self.splat_as::<WRAP, true, BLENDED>(center, value, acc, touched),
            (false, EDGED) => self.splat_as::<WRAP, false, EDGED>(center, value, acc, touched),
            (false, NEAREST) => self.splat_as::<WRAP, false, NEAREST>(center, value, acc, touched),
            (false, _) => self.splat_as::<WRAP, false, BLENDED>(center, value, acc, touched),
        }
    }

    /// How [`FixedStencils::splat_as`] reads this view's stencils: [`EDGED`], [`NEAREST`] or
    /// [`BLENDED`].
    fn mode(&self) -> u8 {
        match (self.wide, self.phase_lookup()) {
            (true, _) => EDGED,
            (false, PhaseLookup::Nearest) => NEAREST,
            (false, PhaseLookup::Blend) => BLENDED,
        }
    }

    /// The splat, with wrapping adds if `WRAP`; `GREY` for a grey voxel ([`super::is_grey`]), whose colour
    /// products it computes once per pixel: 7–9 % off the fixed splat of the walnut and the CT
    /// head (`footprint bench --accum fixed`, 512², builds alternated); `MODE` [`EDGED`] for
    /// stencils blended only inside all four corners' support (`self.wide`, passed as a constant
    /// so the narrow loop carries no edge test per pixel: fixed splat blobs 68.4–69.3 → 66.8–67.1
    /// ms, walnut 59.1–59.2 → 57.3–58.3 ms, CT head 71.4–72.2 → 64.4–65.1 ms, three rounds),
    /// [`NEAREST`] for the nearest corner's entries as they are, [`BLENDED`] otherwise.
    fn splat_as<const WRAP: bool, const GREY: bool, const MODE: u8>(
        &self,
        center: [i64; 2],
        value: &[u32; 4],
        acc: &mut ImageMut<'_, [i64; 4]>,
        mut touched: impl FnMut(usize, usize, usize),
    ) -> SplatStats {
        let (ix, iy) = (center[0] >> POS_FRAC, center[1] >> POS_FRAC);
        let mut stats = SplatStats::default();
        let Some(walk) = SpanWalk::new([ix, iy], self.side, acc.width(), acc.height()) else {
            return stats;
        };
        let p = self.phases;
        // Phase cell k and the Q8 fraction within it.
        let phase = |c: i64, i: i64| {
            let t = (c - (i << POS_FRAC)) * p as i64; // [0, P) in Q24
            let k = ((t >> POS_FRAC) as usize).min(p - 1);
            let f = ((t - ((k as i64) << POS_FRAC)) >> (POS_FRAC - 8)).clamp(0, 256);
            (k, f)
        };
        let ((ka, fx), (kb, fy)) = (phase(center[0], ix), phase(center[1], iy));
        let side = self.side;
        let corners = corner_offsets(ka, kb, p, side * side);
        // Nearest: the corner (a + [fx ≥ ½], b + [fy ≥ ½]) read alone (its entries as they are).
        let corners = if MODE == NEAREST {
            [corners[usize::from(fx >= 128) + 2 * usize::from(fy >= 128)]; 4]
        } else {
            corners
        };
        let (c00, c10, c01, c11) = (
            (256 - fx) * (256 - fy),
            fx * (256 - fy),
            (256 - fx) * fy,
            fx * fy,
        );
        let v = value.map(i64::from);
        let spans = &self.data[self.ranges + (kb * p + ka) * side..][..side];
        let stride = acc.stride();
        let data = acc.data_mut();
        for row in walk.rows(spans, |s| s as u32) {
            let Some(clip) = walk.clip(row.my, row.first, row.last) else {
                continue;
            };
            let (r00, r10, r01, r11) = corner_rows(self.data, corners, clip.entry, clip.n);
            let start = row.y * stride + clip.lo;
            // Clipped to the image, so the range is inside the buffer ImageMut checked.
            let px = &mut data[start..start + clip.n];
            let mut updated = 0u32;
            // A wide footprint's edge pixel, weighted as the walk weights it.
            let exact = |k: usize| {
                let q = [
                    (((clip.lo + k) as i64) << POS_FRAC) + HALF_POS - center[0],
                    ((row.y as i64) << POS_FRAC) + HALF_POS - center[1],
                ];
                self.table.weight(&self.table.cursor(q))
            };
            for (k, d) in px.iter_mut().enumerate() {
                let (a, b, c, e) = (r00[k], r10[k], r01[k], r11[k]);
                let wt = if MODE == NEAREST {
                    i64::from(a)
                } else if MODE == EDGED && (a == 0 || b == 0 || c == 0 || e == 0) {
                    exact(k)
                } else {
                    (c00 * i64::from(a)
                        + c10 * i64::from(b)
                        + c01 * i64::from(c)
                        + c11 * i64::from(e)
                        + (1 << 15))
                        >> 16
                };
                let add = |a: &mut i64, p: i64| {
                    *a = if WRAP {
                        a.wrapping_add(p)
                    } else {
                        a.saturating_add(p)
                    }
                };
                // |v| < 2³² and |wt| < 2³¹: the product fits.
                if GREY {
                    // R = G = B: the same products, the colour's computed once.
                    let (c, o) = (v[0] * wt, v[3] * wt);
                    let [r, g, b, al] = d;
                    add(r, c);
                    add(g, c);
                    add(b, c);
                    add(al, o);
                } else {
                    for (a, c) in d.iter_mut().zip(&v) {
                        add(a, c * wt);
                    }
                }
                updated += u32::from(wt != 0);
            }
            stats.pixels_visited += clip.n as u32;
            stats.pixels_updated += updated;
            touched(row.y, clip.lo, clip.hi);
        }
        stats
    }
}

/// [`FixedStencils::splat_as`]'s modes: a narrow or blended footprint's four corners blended up
/// to the edge,
const BLENDED: u8 = 0;
/// an edged one's blended inside all four corners' support and walked at the edge,
const EDGED: u8 = 1;
/// or a narrow or blended one read at its nearest corner.
const NEAREST: u8 = 2;

#[cfg(test)]
mod tests {
    use super::{FixedStencils, PhaseLookup, POS_FRAC};
    use crate::fixed::FixedTable;

    /// `exact_below`'s count of voxels whose box can hold one pixel is at least the true count,
    /// found by brute force over lattices of every shape (thin, sheared, sub-pixel, magnified).
    #[test]
    fn the_overlap_bound_holds_against_brute_force() {
        let table = FixedTable::<2>::zeroed();
        let one = 1i64 << POS_FRAC;
        let mut seed = 12345u64;
        let mut next = |m: i64| {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            ((seed >> 33) as i64 % (2 * m + 1)) - m
        };
        let mut tight = false;
        for case in 0..300 {
            let side = [5usize, 9, 17][case % 3];
            let st = FixedStencils {
                data: &[],
                ranges: 0,
                side,
                phases: 1,
                wide: false,
                lookup: PhaseLookup::Blend,
                table: &table,
                max_weight: 1000,
            };
            // Steps up to ¼, 1 or 6 px per axis component.
            let scale = [one / 4, one, one * 6][(case / 3) % 3];
            let a = [next(scale), next(scale)];
            let b = [next(scale), next(scale)];
            let Some(bound) = st.exact_below(a, b) else {
                continue;
            };
            let n_bound = (1u128 << 62) / (u128::from(bound) * 1000);
            // Brute force: lattice points u·a + v·b + o in [0, B + 1)² for a few offsets o.
            let l = (side as i64 + 1) * one;
            let mut most = 0u128;
            for o in 0..4 {
                let off = [next(one), next(one)];
                let mut count = 0u128;
                for u in -200i64..200 {
                    for v in -200i64..200 {
                        let x = u * a[0] + v * b[0] + off[0] + o * one / 3;
                        let y = u * a[1] + v * b[1] + off[1];
                        count += u128::from((0..l).contains(&x) && (0..l).contains(&y));
                    }
                }
                most = most.max(count);
            }
            assert!(
                most <= n_bound + 1,
                "case {case}: {most} lattice points, bound {n_bound} (a {a:?}, b {b:?})"
            );
            tight |= most * 4 > n_bound;
        }
        // Not vacuous: somewhere the bound comes within a factor of 4 of the count.
        assert!(tight);
    }
}
