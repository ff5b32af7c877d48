//! Compact fixed point: a 32-bit integer path for small cores (Cortex-M0/M3/M4 class), where the
//! Q24 path's `i64` accumulators, per-pixel table walk and per-voxel renormalising division are
//! library calls and long sequences. Every per-voxel and per-pixel operation here is a 32-bit
//! add, shift or multiply (which every Cortex-M has in one instruction), and a voxel's weights
//! are read from a precomputed phase stencil, not computed. No floating point at splat or
//! composite time (denied below and audited on the boards); the per-view set-up
//! ([`CompactStencils::build`], [`CompactPlacement::new`]) is float.
//!
//! # Formats
//! | quantity | type | format | range |
//! |---|---|---|---|
//! | voxel value (premultiplied RGBA channel) | `u16` | Q15: v / 2¹⁵ | 0 … [`ONE`] (clamped) |
//! | stencil weight = footprint weight × cell area | `i16` | Q*W*, W ≤ [`MAX_WEIGHT_FRAC`] chosen per view | \|w\| ≤ 65 535 / N |
//! | sheet accumulator channel | `i32` | Q(15 + W) | never overflows (below) |
//! | working-image channel | `u16` | Q15, [`ONE`] = opacity 1 | saturates at 2¹⁶ − 1 |
//! | screen positions | `i32` | Q16 pixels | ±2¹⁴ px (checked at set-up) |
//!
//! # Why the sums cannot overflow
//! A sheet's sum at one pixel has one term per voxel whose stencil covers that pixel, each a
//! value (clamped to [`ONE`] = 2¹⁵) times a weight. Per view the set-up bounds N, the most voxels
//! of a sheet whose stencils can cover one pixel, from the sheet's lattice on screen (a count of
//! lattice cells in a rectangle: `setup::covering_bound`), and picks W so that every |weight| ≤
//! 65 535 / N. Then |sum| ≤ N · 2¹⁵ · 65 535 / N < 2³¹: the adds are plain 32-bit adds, no
//! saturation test (on a Cortex-M0 that test was 1.1 M instructions of a 21.5 M frame). The
//! price is weight precision: for the demo scene at 1.3 px a voxel, N = 31 and W = 12 (was 14
//! with saturating adds), its peak weight about 1 400 (10.5 bits); against float the image moved
//! from 52.78 to 52.77 dB. Its unit tests check N against a brute-force count of covering voxels
//! over six views. Compositing
//! multiplies a Q15 channel (≤ 2¹⁶) by a Q15 transparency (≤ 2¹⁵) in `u32`.
//!
//! # Phases
//! A voxel at Q16 position c = (i + φx, j + φy) (i, j whole pixels, φ in [0, 1)) takes the
//! stencil of phase (⌊φx·P⌋, ⌊φy·P⌋), sampled at the phase cell's centre ((k + ½)/P): the voxel
//! moves by at most 1/(2P) px. Each stencil holds the weights of the pixels whose centres lie
//! within the footprint's box around that centre, and per row the run of pixels it touches.
//! A renormalised footprint (see [`crate::geometry::RENORMALISE_BELOW_PX`]) has each stencil
//! scaled to sum to exactly round(cell area · 2^W), the rounding remainder put on its largest
//! weight, so no voxel needs a division; a stencil no pixel centre falls in puts the whole cell
//! on the pixel containing the voxel, as the float path does.
//!
//! # Memory
//! P² stencils of 1 + By·(Bx + 1) `i16`s ([`len_for`]), Bx, By the box's width and height in
//! pixels (⌊2e⌋ + 1 for half-extent e). The demo scene's (e = 2.1 px, P = 8): 64 × 31 × 2 B =
//! 3 968 B.
//!
//! # Rounding
//! As in [`super`]: every shift rounds to nearest (half an LSB added first); opacity 1 is 2¹⁵,
//! a power of two, so a transparent sheet leaves the image bit-identical.
#![deny(clippy::float_arithmetic, clippy::disallowed_types)]

mod setup;

pub use setup::{box_for, len_for, quantise_value, to_f32};

use super::FixedError;
use crate::frame::Order;
use crate::splat::{BufferError, ImageMut, SplatStats};

/// Fraction bits of values and of the working image.
pub const FRAC: u32 = 15;
/// Opacity 1 (and colour 1): 2¹⁵.
pub const ONE: u16 = 1 << FRAC;
/// Fraction bits of screen positions.
pub const POS_FRAC: u32 = 16;
/// The largest weight fraction W: keeps a flat field of opacity 1 at 2²⁹ (see the module docs).
pub const MAX_WEIGHT_FRAC: u32 = 14;
/// The widest box a stencil holds, pixels per side (footprints of half-extent below 4.5 px; the
/// set-up keeps one box of weights on the stack, so this bounds its stack too).
pub const MAX_SIDE: usize = 9;
/// The most phases per pixel axis.
pub const MAX_PHASES: usize = 64;
/// The largest screen coordinate a voxel may land on, pixels (so Q16 sums stay in `i32`).
pub const MAX_SCREEN_PX: i32 = 1 << 14;

/// Why a compact path cannot serve a view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum CompactError {
    /// A position, step or weight outside its format, or a perspective frame.
    Fixed(FixedError),
    /// The footprint's box is wider than [`MAX_SIDE`] pixels (render it with the Q24 path).
    Wide {
        /// The box side it would need, pixels.
        side: usize,
    },
    /// `phases` is 0 or above [`MAX_PHASES`].
    Phases {
        /// The phases asked for.
        phases: usize,
    },
    /// The caller's stencil buffer is shorter than [`len_for`].
    Buffer(BufferError),
}

impl core::fmt::Display for CompactError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Fixed(e) => e.fmt(f),
            Self::Wide { side } => write!(
                f,
                "the footprint needs a {side}-pixel box; compact stencils hold at most {MAX_SIDE}"
            ),
            Self::Phases { phases } => {
                write!(
                    f,
                    "compact stencils need 1 to {MAX_PHASES} phases, got {phases}"
                )
            }
            Self::Buffer(e) => e.fmt(f),
        }
    }
}

impl core::error::Error for CompactError {}

impl From<FixedError> for CompactError {
    fn from(e: FixedError) -> Self {
        Self::Fixed(e)
    }
}

pub(crate) fn stencil_len(bx: usize, by: usize) -> usize {
    1 + by * (bx + 1)
}

/// One view's phase stencils in caller storage (see the module docs for the layout).
#[derive(Clone, Copy, Debug)]
pub struct CompactStencils<'a> {
    data: &'a [i16],
    phases: u32,
    bx: usize,
    by: usize,
    stride: usize,
    frac: u32,
    /// The most voxels of a sheet whose stencils can cover one pixel (the overflow proof's N).
    covering: u32,
}

impl<'a> CompactStencils<'a> {
    // `build`: see setup.rs (float, per view).

    /// Weight fraction bits W (per view).
    pub fn frac_bits(&self) -> u32 {
        self.frac
    }

    /// The most voxels of one sheet whose stencils can cover one pixel, N (see "Why the sums
    /// cannot overflow"): every |weight| is at most 65 535 / N.
    pub fn covering_bound(&self) -> u32 {
        self.covering
    }

    /// The largest |weight| of any stencil (Q W).
    pub fn max_weight(&self) -> u32 {
        let w = self.bx + 1;
        self.data
            .chunks(self.stride)
            .flat_map(|st| st[1..].chunks(w).flat_map(|row| &row[1..]))
            .map(|x| u32::from(x.unsigned_abs()))
            .max()
            .unwrap_or(0)
    }

    /// Phases per pixel axis.
    pub fn phases(&self) -> usize {
        self.phases as usize
    }

    /// Box width and height, pixels.
    pub fn box_size(&self) -> [usize; 2] {
        [self.bx, self.by]
    }

    /// The stencil of phase cell (kx, ky): origin (box's first pixel relative to the voxel's)
    /// and By rows of (first, end) run and Bx weights.
    #[inline]
    fn stencil(&self, kx: u32, ky: u32) -> &[i16] {
        let k = (ky * self.phases + kx) as usize;
        &self.data[k * self.stride..(k + 1) * self.stride]
    }

    /// Spreads `value` (Q15 premultiplied RGBA, each channel clamped to [`ONE`]) of a voxel at
    /// `center` (Q16 px; y relative to `acc`'s first row) into `acc` (Q(15 + W), adds that cannot
    /// overflow within a sheet: see the module docs), calling `touched(y, x0, x1)`
    /// for each row it updated. Not inlined, so the object-code audit (embedded/elf_check.py)
    /// finds it by name.
    #[inline(never)]
    pub fn splat(
        &self,
        center: [i32; 2],
        value: &[u16; 4],
        acc: &mut ImageMut<'_, [i32; 4]>,
        mut touched: impl FnMut(usize, usize, usize),
    ) -> SplatStats {
        #[cfg(footprint_audit_plant)]
        let value = &[
            (value[0] as f32 * 1.0001) as u16,
            value[1],
            value[2],
            value[3],
        ];
        let pos = |c: i32| {
            (
                c >> POS_FRAC,
                ((c & 0xffff) as u32 * self.phases) >> POS_FRAC,
            )
        };
        let ((ix, kx), (iy, ky)) = (pos(center[0]), pos(center[1]));
        let st = self.stencil(kx, ky);
        let origin = st[0] as u16;
        let x0 = ix + i32::from(origin as u8 as i8);
        let y0 = iy + i32::from((origin >> 8) as u8 as i8);
        let (w, h, stride) = (acc.width() as i32, acc.height() as i32, acc.stride());
        // The box's rows inside `acc`, found once (a band holds a few of them).
        let (r0, r1) = ((-y0).max(0), (h - y0).min(self.by as i32));
        let mut stats = SplatStats::default();
        if r0 >= r1 {
            return stats;
        }
        // Values above one are clamped to it: the overflow proof assumes |value| ≤ 2¹⁵.
        let value = value.map(|c| i32::from(c.min(ONE)));
        let data = acc.data_mut();
        let width = self.bx + 1;
        // The box's rows inside `acc`, without `chunks` (their length is a division, a library
        // call on a Cortex-M0).
        let rows = (r0 as usize..r1 as usize).map(|r| &st[1 + r * width..1 + (r + 1) * width]);
        let first = (y0 + r0) as usize;
        let mut n = 0u32;
        if x0 >= 0 && x0 + self.bx as i32 <= w {
            // The whole box lies inside the rows (most voxels): no clipping per row.
            let mut at = first * stride + x0 as usize;
            for (y, row) in (first..).zip(rows) {
                let run = row[0] as u16;
                let (lo, hi) = (usize::from(run & 0xff), usize::from(run >> 8));
                if lo < hi {
                    add_row(&mut data[at + lo..at + hi], &row[1 + lo..1 + hi], &value);
                    n += (hi - lo) as u32;
                    touched(y, x0 as usize + lo, x0 as usize + hi - 1);
                }
                at += stride;
            }
        } else {
            for (y, row) in (first..).zip(rows) {
                let run = row[0] as u16;
                let (lo, hi) = (i32::from(run & 0xff), i32::from(run >> 8));
                let (xa, xb) = ((x0 + lo).max(0), (x0 + hi).min(w));
                if xa >= xb {
                    continue;
                }
                let at = y * stride;
                let line = &mut data[at + xa as usize..at + xb as usize];
                let k = (xa - x0) as usize;
                add_row(line, &row[1 + k..1 + k + line.len()], &value);
                n += (xb - xa) as u32;
                touched(y, xa as usize, xb as usize - 1);
            }
        }
        stats.pixels_visited = n;
        stats.pixels_updated = n;
        stats
    }
}

/// Adds `weights[i] · value` to `line[i]`, the two the same length. Cannot wrap ("Why the sums
/// cannot overflow"); wrapping_add, not `+`, so that a broken proof would show as a wrong image
/// rather than a panic.
#[inline(always)]
fn add_row(line: &mut [[i32; 4]], weights: &[i16], value: &[i32; 4]) {
    for (px, &wt) in line.iter_mut().zip(weights) {
        let wt = i32::from(wt);
        px[0] = px[0].wrapping_add(value[0] * wt);
        px[1] = px[1].wrapping_add(value[1] * wt);
        px[2] = px[2].wrapping_add(value[2] * wt);
        px[3] = px[3].wrapping_add(value[3] * wt);
    }
}

pub(crate) fn pack_origin(x: i32, y: i32) -> i16 {
    // |first| ≤ MAX_SIDE: fits an i8 each.
    ((x as i8 as u8 as u16) | ((y as i8 as u8 as u16) << 8)) as i16
}

pub(crate) fn pack_run(lo: usize, hi: usize) -> i16 {
    (lo as u16 | ((hi as u16) << 8)) as i16
}

/// Where every voxel of a frame lands, Q16 px: voxel (u, v) of sheet s at `origin + s·sheet +
/// u·along_a + v·along_b`, 32-bit integer sums (exact, the same on every target).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CompactPlacement {
    origin: [i32; 2],
    sheet: [i32; 2],
    along_a: [i32; 2],
    along_b: [i32; 2],
}

impl CompactPlacement {
    // `new`: see setup.rs (float, per view).

    /// Screen position of voxel (u, v) of sheet `sheet`, Q16 px.
    #[inline]
    pub fn at(&self, sheet: usize, u: usize, v: usize) -> [i32; 2] {
        let (s, u, v) = (sheet as i32, u as i32, v as i32);
        [0, 1]
            .map(|i| self.origin[i] + s * self.sheet[i] + u * self.along_a[i] + v * self.along_b[i])
    }
}

/// A Q15 pixel as Q24 ([`super::FRAC`]): exact.
pub fn to_q24(p: [u16; 4]) -> [u32; 4] {
    p.map(|c| u32::from(c) << (super::FRAC - FRAC))
}

/// An accumulated sheet pixel (Q(15 + W)) rounded to Q15 and clamped to [0, [`ONE`]].
#[inline]
pub fn resolve(acc: [i32; 4], frac: u32) -> [u16; 4] {
    let half = (1i32 << frac) >> 1;
    acc.map(|a| (a.saturating_add(half) >> frac).clamp(0, i32::from(ONE)) as u16)
}

/// `front over back` in Q15, rounded, saturating at 2¹⁶ − 1.
#[inline]
pub fn over(front: [u16; 4], back: [u16; 4]) -> [u16; 4] {
    let t = u32::from(ONE.saturating_sub(front[3]));
    let mut out = [0u16; 4];
    for ((o, &f), &b) in out.iter_mut().zip(&front).zip(&back) {
        let behind = (u32::from(b) * t + (1 << (FRAC - 1))) >> FRAC;
        *o = (u32::from(f) + behind).min(u32::from(u16::MAX)) as u16;
    }
    out
}

/// Composites one accumulated sheet row into the image row (over back to front, under front to
/// back) and clears the accumulator row. (Not inlined: audited by name, like the splat.)
#[inline(never)]
pub fn composite_row(acc: &mut [[i32; 4]], image: &mut [[u16; 4]], frac: u32, order: Order) {
    let half = (1i32 << frac) >> 1;
    for (a, px) in acc.iter_mut().zip(image.iter_mut()) {
        let [a0, a1, a2, a3] = *a;
        // An empty layer composites to the pixel itself, exactly (over and under by nothing).
        if (a0 | a1 | a2 | a3) == 0 {
            continue;
        }
        *a = [0; 4];
        // [`resolve`] without its saturation: a sheet's sum is below 2¹⁵ · 65 535 in magnitude
        // ("Why the sums cannot overflow"), so adding half of 2^W ≤ 2¹³ cannot wrap.
        let r = |x: i32| (x.wrapping_add(half) >> frac).clamp(0, i32::from(ONE)) as u16;
        let layer = [r(a0), r(a1), r(a2), r(a3)];
        *px = match order {
            Order::BackToFront => over(layer, *px),
            Order::FrontToBack => over(*px, layer),
        };
    }
}

/// `front = front over back`, pixel by pixel.
pub fn over_row(front: &mut [[u16; 4]], back: &[[u16; 4]]) {
    for (f, &b) in front.iter_mut().zip(back) {
        *f = over(*f, b);
    }
}

/// CRC-32 of a Q15 image, each channel as two little-endian bytes, pixels in order.
pub fn checksum(image: &[[u16; 4]]) -> u32 {
    super::channel_crc(image, |c, crc| crc.update(&c.to_le_bytes()))
}

#[cfg(test)]
mod tests;
