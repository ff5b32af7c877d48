//! The small-box splat: [`Stencils::splat`] of a blended footprint whose box lies wholly inside
//! the image and whose row runs are at most 15 px, over windows of a fixed width.
//!
//! Measured (`footprint bench --frames 8 --orbit 2 --threads 1`, 512×512, builds alternated):
//! - Rows of the whole box's width, against the general loop: 18 % off a blobs frame (box side
//!   7), 19 % off the walnut (11), about 20 % at sides 13 and 15 (the walnut at 640² and 760²); at
//!   side 19 (headsq, half-extents 7.4 × 8.0 px) padding the rows to the box cost 21 %.
//! - Windows as wide as the view's longest row run, against whole-box rows: blobs 65.6 → 59.3
//!   ms (runs ≤ 5 px in a box of 7), walnut 40.6 → 37.4 ms, and the CT head, whose runs fit 15 px
//!   in its box of 19, 47.3 → 36.0 ms against the general loop. Windows of 17–32 px were slower
//!   than the general loop (headsq at 1024²: 151 → 188 ms), so longer runs take it.

use super::Stencils;
use crate::splat::{Pixel, SplatStats};

/// Magnitudes below which [`small_floor`] is exact: 2²².
pub(super) const SMALL_FLOOR_MAX: f32 = 4_194_304.0;

/// ⌊x⌋ for |x| < [`SMALL_FLOOR_MAX`] without a float-to-integer conversion: adding 1.5·2²³ rounds
/// x to a whole number (to nearest, the default rounding) held in the sum's low mantissa bits,
/// read as an integer; one less where that rounded up.
#[inline]
pub(super) fn small_floor(x: f32) -> i64 {
    const MAGIC: f32 = 12_582_912.0; // 1.5·2²³
    let s = x + MAGIC;
    let rounded = i64::from(s.to_bits() as i32 - MAGIC.to_bits() as i32);
    rounded - i64::from(s - MAGIC > x)
}

/// Where a small box goes: the four corner stencils' offsets, their blend weights, the phase
/// cell's row runs and the box's corner pixel.
type SmallBox<'s> = ([usize; 4], [f32; 4], &'s [f32], (usize, usize));

/// The window for row runs of at most `run` px in a box of `side`: `run` itself, one pixel wider
/// at 7 and 12 (those two instances compile to slower code than the next width's), and 0 (no
/// window: the general loop, [`super::row`]) from 16 px up, where that loop is faster.
///
/// Measured by splatting 200 000 voxels on a lattice into a 512² image per footprint size (ns
/// per voxel, window of the run's width against the next wider window and the general loop):
/// run 7 67.8–73.4 against 61.5–65.3 at width 8; run 12 162–171 against 136 at 13 and 134–143
/// general; run 15 173–178 against 199–202 general; run 16 267–273 against 213–218 general; run
/// 17 general 217–222.
fn window_for(run: usize, side: usize) -> usize {
    match run {
        7 | 12 if run < side => run + 1,
        1..=15 => run,
        _ => 0,
    }
}

impl<S: ?Sized> Stencils<'_, S> {
    /// [`Stencils::splat_window`] for this view's longest row run if [`window_for`] gives it a
    /// window (one instance per width, each with a fixed trip count), else `None`; `NEAREST` as
    /// in [`super::row::blend_row`].
    #[inline(always)]
    pub(super) fn splat_small<const NEAREST: bool, P: Pixel>(
        &self,
        (corners, blend, spans, at): SmallBox<'_>,
        value: &P,
        data: &mut [P],
        stride: usize,
        touched: &mut impl FnMut(usize, usize, usize),
    ) -> Option<SplatStats> {
        let width = window_for(self.run_width, self.side);
        macro_rules! by_width {
            ($($w:literal)*) => {
                match width {
                    $($w => self.splat_window::<$w, NEAREST, P>(
                        corners, blend, spans, at, value, data, stride, touched,
                    ),)*
                    _ => None,
                }
            };
        }
        by_width!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15)
    }

    /// [`Stencils::splat`] of a blended footprint whose box lies wholly inside the image with its
    /// corner at pixel `at` and whose row runs are at most `W` px: each row's weights are blended
    /// over a window of `W` pixels that holds the row's run (starting at the run, moved left to
    /// stay inside the box; a fixed-length loop the compiler vectorises) and added across it.
    /// Outside a row's stored run all four corner stencils are zero, so the weight there is +0
    /// and the pixel is unchanged: the same sums, statistics and touched runs as the general loop.
    /// `None` (nothing added) if a run is longer than `W` or `W` exceeds the box. `NEAREST`: the
    /// weight is the first corner's entry itself ([`super::row::blend_row`]).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn splat_window<const W: usize, const NEAREST: bool, P: Pixel>(
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
        let side = self.side;
        if W > side || self.run_width > W || spans.len() != side {
            return None;
        }
        let cells = side * side;
        let grid = |s: usize| self.data.get(s..s + cells);
        let (g00, g10, g01, g11) = (
            grid(corners[0])?,
            grid(corners[1])?,
            grid(corners[2])?,
            grid(corners[3])?,
        );
        let window =
            |g: &[f32], o: usize| -> [f32; W] { g[o..o + W].try_into().unwrap_or([0.0; W]) };
        let mut stats = SplatStats::default();
        for (my, span) in spans.iter().enumerate() {
            let bits = span.to_bits();
            let (first, last) = ((bits & 0xffff) as usize, (bits >> 16) as usize);
            if first > last {
                continue;
            }
            // last − first < run_width ≤ W, and start ≤ B − W: the window holds the run and
            // lies inside the box row.
            let start = first.min(side - W);
            let o = my * side + start;
            let (a, b, c, d) = (
                window(g00, o),
                window(g10, o),
                window(g01, o),
                window(g11, o),
            );
            let mut wt = [0.0f32; W];
            for (k, o) in wt.iter_mut().enumerate() {
                *o = if NEAREST {
                    a[k]
                } else {
                    w00 * a[k] + w10 * b[k] + w01 * c[k] + w11 * d[k]
                };
            }
            let y = y0 + my;
            let begin = y * stride + x0 + start;
            // The box is inside the image, so the window is inside the buffer ImageMut checked.
            let px = &mut data[begin..begin + W];
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

#[cfg(test)]
mod tests {
    /// `small_floor` is ⌊x⌋ over its whole range: every whole number and half-way point near the
    /// edges, values just either side of whole numbers, and a million spread over the range.
    #[test]
    fn small_floor_is_floor() {
        let max = super::SMALL_FLOOR_MAX;
        let mut xs = std::vec![0.0f32, -0.0, 0.5, -0.5, 1.0, -1.0, max - 0.5, -max + 0.5];
        for n in [-4_194_303i32, -1000, -2, -1, 0, 1, 2, 1000, 4_194_303] {
            let v = n as f32;
            xs.extend([v, v + 0.5, v.next_up(), v.next_down()]);
        }
        let mut bits = 0x2545_f491u32;
        for _ in 0..1_000_000 {
            bits ^= bits << 13;
            bits ^= bits >> 17;
            bits ^= bits << 5;
            xs.push((bits as f32 / u32::MAX as f32 * 2.0 - 1.0) * max);
        }
        for x in xs.into_iter().filter(|x| x.abs() < max) {
            assert_eq!(super::small_floor(x), x.floor() as i64, "{x}");
        }
    }
}
