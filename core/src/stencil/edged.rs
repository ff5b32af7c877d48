//! The edged footprints' splat ([`super::Stencils::splat`] for [`super::Plan::edged`]): pixel
//! centres inside the support, blended from the stencils where all four corners are non-zero and
//! read from the sampler at the edge, where the footprint is not smooth.

use super::walk::{corner_rows, SpanWalk};
use super::{Stencils, MAX_STENCIL_SIDE};
use crate::splat::{row_pixels, Pixel, Sampler, SplatStats};

impl<S: Sampler + ?Sized> Stencils<'_, S> {
    /// [`Stencils::splat`] of an edged footprint ([`Plan::edged`]): the pixel centres inside the
    /// support, blended where all four corners (`corners`, weighed `blend`) are non-zero and read
    /// from the sampler at the edge. `spans` are the phase cell's runs, `data` the image's
    /// pixels (`stride` apart, `w` wide).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn splat_edged<P: Pixel>(
        &self,
        walk: SpanWalk,
        (corners, blend, spans, center): ([usize; 4], [f32; 4], &[f32], [f32; 2]),
        value: &P,
        data: &mut [P],
        stride: usize,
        w: i64,
        touched: &mut impl FnMut(usize, usize, usize),
    ) -> SplatStats {
        let mut stats = SplatStats::default();
        let [w00, w10, w01, w11] = blend;
        let mut weights = [0.0f32; MAX_STENCIL_SIDE];
        for row in walk.rows(spans, f32::to_bits) {
            let qy = row.y as f32 + 0.5 - center[1];
            // Edged: the pixel centres inside the support (as the table walk), blended where all
            // four corners are non-zero and read from the sampler at the edge.
            let Some(span) = row_pixels(self.sampler.footprint(), center[0], qy) else {
                continue;
            };
            let (lo, hi) = (span.0.max(0), span.1.min(w - 1));
            if lo > hi {
                continue;
            }
            let n = (hi - lo + 1) as usize;
            let ws = &mut weights[..n];
            // The blended part: the stored run inside the support, clipped to the image.
            let blended = walk.clip(row.my, row.first.max(lo), row.last.min(hi));
            if let Some(c) = blended {
                let (r00, r10, r01, r11) = corner_rows(self.data, corners, c.entry, c.n);
                // The row's weights first (a loop the compiler vectorises), then the deposit.
                let out = &mut ws[c.lo - lo as usize..][..c.n];
                for (k, wt) in out.iter_mut().enumerate() {
                    *wt = w00 * r00[k] + w10 * r10[k] + w01 * r01[k] + w11 * r11[k];
                }
            }
            // The edge pixels outside the blended run.
            let (e0, e1) = blended.map_or((0, 0), |c| (c.lo as i64 - lo, c.hi as i64 - lo + 1));
            for k in (0..e0).chain(e1..n as i64) {
                let q = [(lo + k) as f32 + 0.5 - center[0], qy];
                ws[k as usize] = self.sampler.weight(q);
            }
            let start = row.y * stride + lo as usize;
            // Clipped to the image, so the range is inside the buffer ImageMut checked.
            let px = &mut data[start..start + n];
            for (d, &wt) in px.iter_mut().zip(ws.iter()) {
                d.add_weighted(value, wt);
                stats.pixels_updated += u32::from(wt != 0.0);
            }
            stats.pixels_visited += n as u32;
            touched(row.y, lo as usize, hi as usize);
        }
        stats
    }
}
