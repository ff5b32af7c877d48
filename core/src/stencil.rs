//! Phase stencils: a view's footprint sampled once per sub-pixel phase, so that splatting a small
//! or middling footprint is a run of multiply-adds with no table walk per pixel.
//!
//! A voxel projected to screen position c = (i + φx, j + φy) (i, j whole pixels, φ ∈ [0, 1)²)
//! covers pixel centres whose offsets from its pixel (i, j) lie in a fixed box of B × B pixels,
//! B = 2·⌈e + ½⌉ + 1 for half-extent e. For each phase on a (P + 1) × (P + 1) grid
//! (φ = (a/P, b/P), a, b = 0 … P) the stencil holds the footprint weight (px⁻²) at each pixel of the
//! box, read from a [`Sampler`] (the view table), zero outside the footprint's support, and, for a
//! footprint small enough to be renormalised ([`Footprint::renormalise`]), divided by its sum so a
//! voxel deposits exactly one unit. A voxel's weights are the bilinear blend of the four stencils
//! around its phase; since every stencil sums to one, so does the blend.
//!
//! **Accuracy.** Blending between phases adds the error of linear interpolation over a phase step
//! of 1/P px: at most (1/P)²/8 · |∂²w/∂φ²| ≤ (1/P)²/4 · max|∇²w|, for P = 16 well under a tenth of a
//! percent of the peak for the smallest footprint the geometry allows (semi-axis 1.5 px); the
//! harness's `verify` measures it with the rest. The support's edge is blended too, so a pixel at
//! the edge may keep a weight that the exact support test would zero; the footprint is near zero
//! there.
//!
//! **Memory.** (P + 1)² · B² floats, built once per view in caller storage: [`Stencils::len_for`].
//! For P = 16: 29 KiB at e ≤ 1.5 px (B = 5), 140 KiB at e = 4.2 px (B = 11), 296 KiB at the largest
//! side used, B = [`MAX_STENCIL_SIDE`].

use crate::geometry::Footprint;
use crate::math;
use crate::splat::{floor_i64, BufferError, ImageMut, Pixel, Sampler, SplatStats, Splatter};

/// Phases per pixel the harness uses.
pub const DEFAULT_PHASES: usize = 32;

/// Largest box side (pixels) worth stencils; larger footprints amortise a table walk per row.
pub const MAX_STENCIL_SIDE: usize = 16;

/// One view's phase stencils (see the module docs), in caller storage.
#[derive(Clone, Copy, Debug)]
pub struct Stencils<'a> {
    data: &'a [f32],
    side: usize,
    reach: i64,
    phases: usize,
}

impl<'a> Stencils<'a> {
    /// Box side B for `footprint`, if stencils are worth it (B ≤ [`MAX_STENCIL_SIDE`]).
    pub fn side_for(footprint: &Footprint) -> Option<usize> {
        let e = footprint.half_extent[0].max(footprint.half_extent[1]);
        if !(e.is_finite() && e >= 0.0) {
            return None;
        }
        let reach = -math::floor(-(e + 0.5)); // ⌈e + ½⌉
        let side = 2.0 * reach + 1.0;
        (side <= MAX_STENCIL_SIDE as f32).then_some(side as usize)
    }

    /// Floats needed for `footprint`'s stencils at `phases` phases per pixel, if stencils apply.
    pub fn len_for(footprint: &Footprint, phases: usize) -> Option<usize> {
        let side = Self::side_for(footprint)?;
        Some((phases + 1) * (phases + 1) * side * side)
    }

    /// Samples `sampler`'s footprint at every phase into `buffer` (at least
    /// [`Stencils::len_for`] floats). `phases` ≥ 1.
    pub fn build<S: Sampler + ?Sized>(
        sampler: &S,
        phases: usize,
        buffer: &'a mut [f32],
    ) -> Result<Self, BufferError> {
        let fp = sampler.footprint();
        let phases = phases.max(1);
        let (Some(side), Some(len)) = (Self::side_for(fp), Self::len_for(fp, phases)) else {
            let e = fp.half_extent[0].max(fp.half_extent[1]);
            let side = (2.0 * e + 2.0).min(1e9) as usize;
            return Err(BufferError::TooLarge {
                width: side,
                height: side,
            });
        };
        if buffer.len() < len {
            return Err(BufferError::TooSmall {
                needed: len,
                got: buffer.len(),
            });
        }
        let reach = (side / 2) as i64;
        let cells = side * side;
        for (k, stencil) in buffer[..len].chunks_exact_mut(cells).enumerate() {
            let (pa, pb) = (k % (phases + 1), k / (phases + 1));
            let phase = [pa as f32 / phases as f32, pb as f32 / phases as f32];
            let mut sum = 0.0f32;
            for (my, row) in stencil.chunks_exact_mut(side).enumerate() {
                let qy = (my as i64 - reach) as f32 + 0.5 - phase[1];
                for (mx, w) in row.iter_mut().enumerate() {
                    let q = [(mx as i64 - reach) as f32 + 0.5 - phase[0], qy];
                    *w = if fp.contains(q) {
                        sampler.weight(q)
                    } else {
                        0.0
                    };
                    sum += *w;
                }
            }
            if fp.renormalise {
                if sum > 0.0 {
                    let inv = 1.0 / sum;
                    stencil.iter_mut().for_each(|w| *w *= inv);
                } else {
                    // No pixel centre saw the footprint: the whole voxel goes to its own pixel.
                    stencil.fill(0.0);
                    stencil[reach as usize * side + reach as usize] = 1.0;
                }
            }
        }
        Ok(Stencils {
            data: &buffer[..len],
            side,
            reach,
            phases,
        })
    }

    /// Box side B, pixels.
    pub fn side(&self) -> usize {
        self.side
    }

    /// Spreads `value` of a voxel projected to `center` (pixels, absolute) into `image`, calling
    /// `touched(y, x0, x1)` for each row it visited: the blend of the four stencils around the
    /// centre's sub-pixel phase.
    pub fn splat<P: Pixel>(
        &self,
        center: [f32; 2],
        value: &P,
        image: &mut ImageMut<'_, P>,
        mut touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError> {
        if !(center[0].is_finite() && center[1].is_finite()) {
            return Err(BufferError::NonFiniteCenter);
        }
        let (w, h) = (image.width() as i64, image.height() as i64);
        let (ix, iy) = (floor_i64(center[0]), floor_i64(center[1]));
        let (x0, y0) = (ix - self.reach, iy - self.reach);
        let b = self.side as i64;
        let mut stats = SplatStats::default();
        if x0 + b <= 0 || y0 + b <= 0 || x0 >= w || y0 >= h {
            return Ok(stats);
        }
        let p = self.phases;
        let phase = |c: f32, i: i64| {
            let t = (c - i as f32) * p as f32;
            let k = (t.max(0.0) as usize).min(p - 1);
            (k, (t - k as f32).clamp(0.0, 1.0))
        };
        let ((ka, fx), (kb, fy)) = (phase(center[0], ix), phase(center[1], iy));
        let cells = self.side * self.side;
        let at = |a: usize, b: usize| (b * (p + 1) + a) * cells;
        let (s00, s10, s01, s11) = (
            at(ka, kb),
            at(ka + 1, kb),
            at(ka, kb + 1),
            at(ka + 1, kb + 1),
        );
        let (w00, w10, w01, w11) = (
            (1.0 - fx) * (1.0 - fy),
            fx * (1.0 - fy),
            (1.0 - fx) * fy,
            fx * fy,
        );
        let (lo, hi) = (x0.max(0), (x0 + b - 1).min(w - 1));
        let (m0, n) = ((lo - x0) as usize, (hi - lo + 1) as usize);
        let stride = image.stride();
        let data = image.data_mut();
        for my in 0..self.side {
            let y = y0 + my as i64;
            if y < 0 || y >= h {
                continue;
            }
            let r = my * self.side + m0;
            let (r00, r10, r01, r11) = (
                &self.data[s00 + r..s00 + r + n],
                &self.data[s10 + r..s10 + r + n],
                &self.data[s01 + r..s01 + r + n],
                &self.data[s11 + r..s11 + r + n],
            );
            let start = y as usize * stride + lo as usize;
            // Clipped to the image, so the range is inside the buffer ImageMut checked.
            let px = &mut data[start..start + n];
            for (k, d) in px.iter_mut().enumerate() {
                let wt = w00 * r00[k] + w10 * r10[k] + w01 * r01[k] + w11 * r11[k];
                d.add_weighted(value, wt);
                stats.pixels_updated += u32::from(wt != 0.0);
            }
            stats.pixels_visited += n as u32;
            touched(y as usize, lo as usize, hi as usize);
        }
        Ok(stats)
    }
}

impl Splatter for Stencils<'_> {
    #[inline]
    fn splat_voxel<P: Pixel>(
        &self,
        center: [f32; 2],
        value: &P,
        image: &mut ImageMut<'_, P>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError> {
        self.splat(center, value, image, touched)
    }
}
