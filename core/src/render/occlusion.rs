//! Occlusion culling (Mueller, Shareef, Huang and Crawfis 1999, "High-quality splatting on
//! rectilinear grids with efficient culling of occluded voxels"): front to back, the working image
//! is cut into tiles of [`OCCLUSION_TILE`]² pixels, and a tile whose every pixel has reached the
//! opacity 1 − ε is *closed*: nothing more is composited into it, and a voxel whose footprint
//! lies on closed tiles only is skipped before it is shaded.
//!
//! **Error.** Front to back a pixel of opacity α receives at most (1 − α) of what lies behind it,
//! per premultiplied channel at most 1 − α ≤ ε. So a closed tile's pixels are each within ε of the
//! image without culling per channel (in the units of the premultiplied image, peak 1), and in an 8-bit
//! image within ε·255 steps.
//!
//! **Determinism.** Whether a tile is closed depends on that tile's own pixels only, and a pixel
//! only grows more opaque front to back, so the image is a function of each tile's history: a band
//! of rows ([`super::SheetRenderer::with_band`]) that starts on a tile row
//! (a multiple of [`OCCLUSION_TILE`]) renders exactly the pixels a whole-image render does, and
//! the image is byte-identical for any number of such bands. The voxel test only skips voxels
//! whose every addition would land on closed tiles, where composition discards it anyway.

use super::precision::Precision;
use crate::frame::FrameSetup;

/// Side of an occlusion tile, pixels. Bands must start on multiples of it.
pub const OCCLUSION_TILE: usize = 8;

/// A tile's count once every pixel in it is opaque.
const CLOSED: u8 = u8::MAX;

/// Length of the occlusion buffer ([`super::SheetRenderer::with_occlusion`]) for a band of
/// `rows` rows of `width` pixels: one byte per tile.
pub const fn occlusion_len(width: usize, rows: usize) -> usize {
    width.div_ceil(OCCLUSION_TILE) * rows.div_ceil(OCCLUSION_TILE)
}

/// Why occlusion culling was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum OcclusionError {
    /// Culling needs front-to-back compositing (what is in front must be known first).
    BackToFront,
    /// A perspective frame: footprints differ per voxel (not supported).
    Perspective,
    /// A band that does not start on a tile row.
    BandStart {
        /// The band's first row.
        start: usize,
    },
    /// The threshold ε is not in (0, 1).
    Threshold,
}

impl core::fmt::Display for OcclusionError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            OcclusionError::BackToFront => {
                f.write_str("occlusion culling needs front-to-back compositing")
            }
            OcclusionError::Perspective => {
                f.write_str("occlusion culling works on orthographic frames only")
            }
            OcclusionError::BandStart { start } => write!(
                f,
                "a band culling occluded voxels must start on a multiple of {OCCLUSION_TILE} rows, not row {start}"
            ),
            OcclusionError::Threshold => {
                f.write_str("the occlusion threshold ε must lie strictly between 0 and 1")
            }
        }
    }
}

/// The occlusion map of one band: per tile, how many of its pixels are opaque (or [`CLOSED`]).
pub(super) struct Occlusion<'a, X> {
    counts: &'a mut [u8],
    tiles_x: usize,
    width: usize,
    rows: usize,
    /// A pixel of opacity 1 − ε in the image's format, and the test against it.
    opaque: X,
    reaches: fn(&X, &X) -> bool,
    /// Half extents of a footprint's box plus a pixel (against rounding of the placement).
    reach: [f32; 2],
}

impl<'a, X: Copy> Occlusion<'a, X> {
    /// A map over `counts` (at least [`occlusion_len`]) for a band of `rows` rows of `width`
    /// pixels, all open; footprints within `half` pixels of their centres; pixels of `P`'s
    /// format, opaque from 1 − `eps`.
    pub(super) fn new<P: Precision<Pixel = X>>(
        counts: &'a mut [u8],
        [width, rows]: [usize; 2],
        half: [f32; 2],
        eps: f32,
    ) -> Self {
        Self::with_test(
            counts,
            [width, rows],
            half,
            P::opacity_pixel(1.0 - eps),
            P::reaches,
        )
    }

    /// [`Occlusion::new`] for pixels opaque where `reaches(pixel, &opaque)`.
    pub(super) fn with_test(
        counts: &'a mut [u8],
        [width, rows]: [usize; 2],
        half: [f32; 2],
        opaque: X,
        reaches: fn(&X, &X) -> bool,
    ) -> Self {
        let n = occlusion_len(width, rows);
        counts[..n].fill(0);
        Occlusion {
            counts: &mut counts[..n],
            tiles_x: width.div_ceil(OCCLUSION_TILE),
            width,
            rows,
            opaque,
            reaches,
            reach: [half[0] + 1.0, half[1] + 1.0],
        }
    }

    /// The refusals every renderer shares: `eps` outside (0, 1), back to front, a band starting
    /// off a tile row, a `buffer` shorter than [`occlusion_len`]`(size)`.
    pub(super) fn check(
        eps: f32,
        order: crate::frame::Order,
        band_start: usize,
        size: [usize; 2],
        buffer: usize,
    ) -> Result<(), super::RenderError> {
        let refuse = |e| Err(super::RenderError::Occlusion(e));
        if !(eps > 0.0 && eps < 1.0) {
            return refuse(OcclusionError::Threshold);
        }
        if order != crate::frame::Order::FrontToBack {
            return refuse(OcclusionError::BackToFront);
        }
        if !band_start.is_multiple_of(OCCLUSION_TILE) {
            return refuse(OcclusionError::BandStart { start: band_start });
        }
        let needed = occlusion_len(size[0], size[1]);
        if buffer < needed {
            return Err(crate::splat::BufferError::TooSmall {
                needed,
                got: buffer,
            }
            .into());
        }
        Ok(())
    }

    /// Whether the footprint of the voxel of sheet `sheet` at (u, v) of `f` lies on closed tiles
    /// only within the band whose first image row is `row0`.
    #[inline]
    pub(super) fn hides(
        &self,
        f: &FrameSetup,
        sheet: usize,
        u: usize,
        v: usize,
        row0: usize,
    ) -> bool {
        let [x, y] = super::precision::float_position(f, sheet, u, v);
        self.hides_at(x, y - row0 as f32)
    }

    /// Whether a footprint centred at screen x `x` and band row `y` (pixels) lies on closed tiles
    /// only (a footprint that misses the band is left to the band test: not hidden).
    #[inline]
    pub(super) fn hides_at(&self, x: f32, y: f32) -> bool {
        let (x0, x1) = (x - self.reach[0], x + self.reach[0]);
        let (y0, y1) = (y - self.reach[1], y + self.reach[1]);
        // `!` keeps NaN out: such a voxel is never hidden.
        if !(x1 >= 0.0 && y1 >= 0.0 && x0 < self.width as f32 && y0 < self.rows as f32) {
            return false;
        }
        let tile = |z: f32, n: usize| (z.max(0.0) as usize).min(n - 1) / OCCLUSION_TILE;
        let (tx0, tx1) = (tile(x0, self.width), tile(x1, self.width));
        let (ty0, ty1) = (tile(y0, self.rows), tile(y1, self.rows));
        (ty0..=ty1).all(|ty| {
            self.counts[ty * self.tiles_x + tx0..=ty * self.tiles_x + tx1]
                .iter()
                .all(|&c| c == CLOSED)
        })
    }

    /// Composites row `y` (band-relative) of `image` over columns `lo..=hi` tile by tile:
    /// `segment(pixels, closed, image)` composites the image pixels `pixels` (indices into the
    /// band's image), or, where `closed`, only clears their accumulators. Returns the pixels
    /// composited.
    pub(super) fn composite_row(
        &mut self,
        y: usize,
        (lo, hi): (usize, usize),
        image: &mut [X],
        mut segment: impl FnMut(core::ops::Range<usize>, bool, &mut [X]),
    ) -> u64 {
        let (w, t) = (self.width, OCCLUSION_TILE);
        let ty = y / t;
        let tile_rows = t.min(self.rows - ty * t);
        let (opaque, reaches) = (self.opaque, self.reaches);
        let count_opaque = |img: &[X]| img.iter().filter(|p| reaches(p, &opaque)).count();
        let mut done = 0;
        let mut x = lo;
        while x <= hi {
            let tx = x / t;
            let end = hi.min(tx * t + t - 1);
            let pixels = y * w + x..y * w + end + 1;
            let count = &mut self.counts[ty * self.tiles_x + tx];
            if *count == CLOSED {
                segment(pixels, true, image);
            } else {
                let before = count_opaque(&image[pixels.clone()]);
                segment(pixels.clone(), false, image);
                let after = count_opaque(&image[pixels]);
                // A pixel only grows more opaque front to back; saturate in case a path rounds
                // down.
                let n = usize::from(*count) + after.saturating_sub(before);
                let full = t.min(w - tx * t) * tile_rows;
                *count = if n >= full { CLOSED } else { n as u8 };
                done += (end + 1 - x) as u64;
            }
            x = end + 1;
        }
        done
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Order;

    fn reaches(p: &[f32; 4], at: &[f32; 4]) -> bool {
        p[3] >= at[3]
    }

    /// Composites row `y`, columns `lo..=hi`, setting each open pixel's opacity to `a`; returns
    /// the pixels composited and the segments seen (open, closed).
    fn paint(
        o: &mut Occlusion<'_, [f32; 4]>,
        image: &mut [[f32; 4]],
        (y, lo, hi): (usize, usize, usize),
        a: f32,
    ) -> (u64, [usize; 2]) {
        let mut calls = [0usize; 2];
        let done = o.composite_row(y, (lo, hi), image, |px, closed, img| {
            calls[usize::from(closed)] += 1;
            if !closed {
                for p in &mut img[px] {
                    p[3] = a;
                }
            }
        });
        (done, calls)
    }

    /// A tile closes once its last pixel is opaque, then takes nothing more; a footprint on
    /// closed tiles only is hidden, one reaching an open tile is not.
    #[test]
    fn tiles_close_when_every_pixel_is_opaque() {
        let (w, h) = (20, 12); // 3 × 2 tiles, the last column and row partial
        let mut counts = [0u8; 6];
        let opaque = [0.0, 0.0, 0.0, 0.99];
        let mut o = Occlusion::with_test(&mut counts, [w, h], [1.0, 1.0], opaque, reaches);
        let mut image = vec![[0.0f32; 4]; w * h];
        for y in 0..7 {
            paint(&mut o, &mut image, (y, 0, 7), 1.0);
        }
        // Row 7 translucent at first: the tile stays open.
        paint(&mut o, &mut image, (7, 0, 7), 0.5);
        assert!(!o.hides_at(3.0, 3.0), "row 7 is still translucent");
        paint(&mut o, &mut image, (7, 0, 7), 1.0);
        assert!(o.hides_at(3.0, 3.0), "tile (0, 0) closed");
        assert!(!o.hides_at(6.5, 3.0), "reaches tile (1, 0)");
        assert!(
            !o.hides_at(-10.0, 3.0),
            "off the band: left to the band test"
        );
        // A closed tile takes nothing more: its segment is only cleared, and not counted.
        let (done, calls) = paint(&mut o, &mut image, (2, 0, 9), 0.2);
        assert_eq!((done, calls), (2, [1, 1]), "columns 8 and 9 composited");
        assert!(image[2 * w..2 * w + 8].iter().all(|p| p[3] == 1.0));
        // The partial tile (2, 1), 4 × 4 pixels, closes with its 16 pixels.
        for y in 8..11 {
            paint(&mut o, &mut image, (y, 16, 19), 1.0);
        }
        assert!(!o.hides_at(18.0, 10.0));
        paint(&mut o, &mut image, (11, 16, 19), 1.0);
        assert!(o.hides_at(18.0, 10.0));
    }

    #[test]
    fn what_culling_needs_is_checked() {
        let ok = Occlusion::<[f32; 4]>::check(0.01, Order::FrontToBack, 16, [20, 12], 6);
        assert_eq!(ok, Ok(()));
        let err = |e| Err(crate::render::RenderError::Occlusion(e));
        for eps in [0.0, 1.0, f32::NAN, -0.5] {
            let r = Occlusion::<[f32; 4]>::check(eps, Order::FrontToBack, 0, [20, 12], 6);
            assert_eq!(r, err(OcclusionError::Threshold));
        }
        let r = Occlusion::<[f32; 4]>::check(0.01, Order::BackToFront, 0, [20, 12], 6);
        assert_eq!(r, err(OcclusionError::BackToFront));
        let r = Occlusion::<[f32; 4]>::check(0.01, Order::FrontToBack, 12, [20, 12], 6);
        assert_eq!(r, err(OcclusionError::BandStart { start: 12 }));
        let r = Occlusion::<[f32; 4]>::check(0.01, Order::FrontToBack, 0, [20, 12], 5);
        assert!(matches!(r, Err(crate::render::RenderError::Buffer(_))));
    }
}
