//! The small-box splat: [`Stencils::splat`] of a footprint up to 15 px across whose box lies
//! wholly inside the image, with rows of a fixed width. Measured against the general loop
//! (`footprint bench --frames 8 --orbit 2 --threads 1`, 512×512, builds alternated): 18 % off a
//! blobs frame (box side 7), 19 % off the walnut (11), about 20 % at sides 13 and 15 (the walnut at
//! 640² and 760²); at side 19 (headsq, an anisotropic footprint) padding the rows cost 21 %, so
//! wider boxes take the general loop.

use super::Stencils;
use crate::splat::{Pixel, SplatStats};

/// Where a small box goes: the four corner stencils' offsets, their blend weights, the phase
/// cell's row runs and the box's corner pixel.
type SmallBox<'s> = ([usize; 4], [f32; 4], &'s [f32], (usize, usize));

impl<S: ?Sized> Stencils<'_, S> {
    /// [`Stencils::splat_box`] for this view's box side if it is odd and at most 15 px (one
    /// instance per side, each with a fixed trip count), else `None`.
    #[inline(always)]
    pub(super) fn splat_small<P: Pixel>(
        &self,
        (corners, blend, spans, at): SmallBox<'_>,
        value: &P,
        data: &mut [P],
        stride: usize,
        touched: &mut impl FnMut(usize, usize, usize),
    ) -> Option<SplatStats> {
        macro_rules! by_side {
            ($($side:literal)*) => {
                match self.side {
                    $($side => self.splat_box::<$side, P>(
                        corners, blend, spans, at, value, data, stride, touched,
                    ),)*
                    _ => None,
                }
            };
        }
        by_side!(3 5 7 9 11 13 15)
    }

    /// [`Stencils::splat`] of a narrow footprint whose box (side `B`) lies wholly inside the
    /// image with its corner at pixel `at`: each row's weights are blended over the whole box
    /// width (a fixed-length loop the compiler vectorises) and added across it. Outside a row's
    /// stored run all four corner stencils are zero, so the weight there is +0 and the pixel is
    /// unchanged: the same sums, statistics and touched runs as the general loop. `None` (nothing
    /// added) if the stencils are not `B` wide.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn splat_box<const B: usize, P: Pixel>(
        &self,
        corners: [usize; 4],
        [w00, w10, w01, w11]: [f32; 4],
        spans: &[f32],
        (x0, y0): (usize, usize),
        value: &P,
        data: &mut [P],
        stride: usize,
        touched: &mut impl FnMut(usize, usize, usize),
    ) -> Option<SplatStats> {
        if self.side != B || spans.len() != B {
            return None;
        }
        let grid = |s: usize| Some(self.data.get(s..s + B * B)?.as_chunks::<B>().0);
        let (g00, g10, g01, g11) = (
            grid(corners[0])?,
            grid(corners[1])?,
            grid(corners[2])?,
            grid(corners[3])?,
        );
        let mut stats = SplatStats::default();
        let rows = spans
            .iter()
            .zip(g00.iter().zip(g10))
            .zip(g01.iter().zip(g11));
        for (my, ((span, (a, b)), (c, d))) in rows.enumerate() {
            let bits = span.to_bits();
            let (first, last) = ((bits & 0xffff) as usize, (bits >> 16) as usize);
            if first > last {
                continue;
            }
            let mut wt = [0.0f32; B];
            for (k, o) in wt.iter_mut().enumerate() {
                *o = w00 * a[k] + w10 * b[k] + w01 * c[k] + w11 * d[k];
            }
            let y = y0 + my;
            let start = y * stride + x0;
            // The box is inside the image, so the row is inside the buffer ImageMut checked.
            let px = &mut data[start..start + B];
            let mut updated = 0u32;
            for (d, &w) in px.iter_mut().zip(&wt) {
                d.add_weighted(value, w);
                updated += u32::from(w != 0.0);
            }
            stats.pixels_visited += (last - first + 1) as u32;
            stats.pixels_updated += updated;
            touched(y, x0 + first, x0 + last);
        }
        Some(stats)
    }
}
