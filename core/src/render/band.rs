//! Which voxels of a sheet can reach a band of image rows (see [`super::SheetRenderer`]'s
//! "Bands"): a conservative test per voxel, and per sheet row the range of voxels to visit; and
//! what sheet and slab renderers share when they start on a band (its checks, its first image);
//! and the slab renderers' compositing order ([`SlabQueue`]).

use super::RenderError;
use crate::frame::{FrameSetup, Order};
use crate::math;
use crate::splat::BufferError;

/// Which voxels of a sheet can reach a band's rows. Screen y of voxel (u, v) is affine in u and
/// v; the test is conservative by a pixel and more, so it never drops a voxel that a
/// whole-image render would splat into the band. A whole-image renderer tests nothing.
pub(super) struct BandReach {
    /// `None` for the whole image.
    test: Option<BandTest>,
}

struct BandTest {
    y_sheet: f32,
    ya: f32,
    yb: f32,
    reach: f32,
    top: f32,
    bottom: f32,
    /// The row ranges in integers, where they fit: per row v the range of u is [lo + v·step,
    /// hi + v·step] (Q32 voxels), so a row costs an integer multiply and no float (a core
    /// without an FPU pays a library call per float operation).
    fixed: Option<RowLine>,
}

/// The u range of sheet row v, [lo + v·step, hi + v·step], in Q32 voxels, lo widened down and
/// hi up by [`ROW_MARGIN`] against the rounding of the float set-up and of the steps.
#[derive(Clone, Copy)]
struct RowLine {
    lo: i64,
    hi: i64,
    step: i64,
}

/// One sheet row's counts, kept locally and added to the frame's 64-bit [`super::RenderStats`]
/// once per row (on a 32-bit core a 64-bit add in memory per voxel is four instructions and two
/// stores).
pub(super) struct RowCounts {
    visited: usize,
    pub culled: usize,
    pub splatted: usize,
    pub updates: u64,
}

impl RowCounts {
    /// A row of `visited` voxels (the culled ones are taken off when added).
    pub fn visiting(visited: usize) -> Self {
        RowCounts {
            visited,
            culled: 0,
            splatted: 0,
            updates: 0,
        }
    }

    /// Adds the row to the frame's counts.
    pub fn add_to(&self, stats: &mut super::RenderStats) {
        stats.voxels += (self.visited - self.culled) as u64;
        stats.culled_voxels += self.culled as u64;
        stats.voxels_splatted += self.splatted as u64;
        stats.pixel_updates += self.updates;
    }
}

/// Fraction bits of [`RowLine`].
const ROW_FRAC: u32 = 32;
/// Widening of each end of a [`RowLine`]: 2⁻⁸ voxel, far above the rounding (f32 set-up to
/// within 2⁻²⁰ of the value for the |values| ≤ 2¹² it takes; Q32 steps, off by 2⁻³³ each, over
/// at most 2¹⁶ rows).
const ROW_MARGIN: i64 = 1 << (ROW_FRAC - 8);
/// Largest |value| (voxels) a [`RowLine`] takes, and most rows: beyond, rows use floats.
const ROW_LIMIT: f32 = 4096.0;
const ROW_MAX_ROWS: usize = 1 << 16;

impl BandReach {
    pub(super) fn new(f: &FrameSetup, band: (usize, usize), index: usize) -> Self {
        // A perspective frame's voxels do not lie on an affine lattice on screen: no test (each
        // splat still clips to the band).
        if (band.0 == 0 && band.1 == f.size[1]) || f.camera().is_some() {
            return BandReach { test: None };
        }
        let cols = f.grid_to_screen;
        let (ia, ib) = f.in_sheet;
        let mut t = BandTest {
            y_sheet: f.origin.y + cols.col(f.sheet_axis).y * index as f32,
            ya: cols.col(ia).y,
            yb: cols.col(ib).y,
            reach: f.footprint.half_extent[1] + 2.0,
            top: band.0 as f32,
            bottom: (band.0 + band.1) as f32,
            fixed: None,
        };
        t.fixed = t.line(f.sheet_shape().2);
        BandReach { test: Some(t) }
    }

    /// The voxels `u` of sheet row `v` (of `na`) that may reach the band: a superset of those
    /// [`BandReach::may_reach`] accepts (widened by a voxel each side against rounding), found
    /// with a few float operations per row rather than per voxel.
    pub(super) fn row(&self, v: usize, na: usize) -> core::ops::Range<usize> {
        let Some(t) = &self.test else {
            return 0..na;
        };
        if let Some(l) = t.fixed {
            // |v·step| < 2¹⁶ · 2¹² · 2³² = 2⁶⁰ (checked in `line`).
            let shift = v as i64 * l.step;
            let (lo, hi) = (l.lo + shift, l.hi + shift);
            let n = na as i64;
            if hi < -(1i64 << ROW_FRAC) || lo > n << ROW_FRAC {
                return 0..0;
            }
            let first = (lo.max(0) >> ROW_FRAC) as usize;
            let last = ((hi.clamp(0, n << ROW_FRAC) >> ROW_FRAC) as usize + 2).min(na);
            return first.saturating_sub(1)..last;
        }
        let c = t.y_sheet + t.yb * v as f32;
        let (lo, hi) = (t.top - t.reach - c, t.bottom + t.reach - c);
        // c + ya·u must lie in [lo + c, hi + c], i.e. ya·u in [lo, hi].
        if !(t.ya.abs() > 1e-6) {
            // The row is (nearly) level on screen: all of it or none (`!` keeps NaN out).
            let margin = t.ya.abs() * na as f32;
            return if lo <= margin && hi >= -margin {
                0..na
            } else {
                0..0
            };
        }
        let (a, b) = (lo / t.ya, hi / t.ya);
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        if !(b >= -1.0) || !(a <= na as f32) {
            return 0..0;
        }
        let first = math::floor(a.max(0.0)) as usize;
        // floor + 2 ≥ ceil + 1: one voxel past the last that may reach.
        let last = (math::floor(b.min(na as f32)) as usize + 2).min(na);
        first.saturating_sub(1)..last
    }

    /// The voxels of sheet row `v` (of `na`) to visit: those of [`BandReach::row`] within `held`
    /// (the source's non-empty ones).
    #[inline(always)]
    pub(super) fn row_within(
        &self,
        v: usize,
        na: usize,
        held: core::ops::Range<usize>,
    ) -> core::ops::Range<usize> {
        let reached = self.row(v, na);
        reached.start.max(held.start)..reached.end.min(held.end)
    }

    /// [`BandReach::row`] computed in floats, as before the integer lines (the reference the
    /// tests hold those lines to).
    #[cfg(test)]
    fn row_float(&self, v: usize, na: usize) -> core::ops::Range<usize> {
        let Some(t) = &self.test else {
            return 0..na;
        };
        let float = BandReach {
            test: Some(BandTest { fixed: None, ..*t }),
        };
        float.row(v, na)
    }

    pub(super) fn may_reach(&self, u: usize, v: usize) -> bool {
        match &self.test {
            None => true,
            Some(t) => {
                let y = t.y_sheet + t.ya * u as f32 + t.yb * v as f32;
                !(y + t.reach < t.top || y - t.reach > t.bottom)
            }
        }
    }
}

impl BandTest {
    /// The integer form of [`BandReach::row`] for sheets of `nb` rows, where every value fits
    /// (see [`ROW_LIMIT`]); `None` keeps the float rows.
    fn line(&self, nb: usize) -> Option<RowLine> {
        let (lo, hi) = (
            self.top - self.reach - self.y_sheet,
            self.bottom + self.reach - self.y_sheet,
        );
        // A level row is all or nothing: the float branch handles it.
        if !(math::abs(self.ya) > 1e-6) || nb > ROW_MAX_ROWS {
            return None;
        }
        let (a, b) = (lo / self.ya, hi / self.ya);
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        let step = -self.yb / self.ya;
        let fits = |x: f32| math::abs(x) <= ROW_LIMIT;
        if !(fits(a) && fits(b) && fits(step)) {
            return None;
        }
        let q = |x: f32| {
            // Exact in two parts: the whole voxels, then the fraction (|x| ≤ 2¹²).
            let whole = math::floor(x);
            ((whole as i64) << ROW_FRAC) + ((x - whole) * (1u64 << ROW_FRAC) as f32) as i64
        };
        Some(RowLine {
            lo: q(a) - ROW_MARGIN,
            hi: q(b) + ROW_MARGIN,
            step: q(step),
        })
    }
}

/// Checks that `rows` is a band of an image `height` rows high, and that every (length, needed)
/// pair of a renderer's buffers holds what it needs (the first short one is the error).
pub(crate) fn check_band(
    rows: &core::ops::Range<usize>,
    height: usize,
    buffers: &[(usize, usize)],
) -> Result<(), RenderError> {
    if rows.start > rows.end || rows.end > height {
        return Err(RenderError::Band {
            start: rows.start,
            end: rows.end,
            height,
        });
    }
    for &(got, needed) in buffers {
        if got < needed {
            return Err(BufferError::TooSmall { needed, got }.into());
        }
    }
    Ok(())
}

/// A band's starting working image: the background when compositing back to front (the far
/// layers go over it), else `clear` (front to back, the background goes under at the end).
pub(crate) fn start_image<X: Copy>(
    image: &mut [X],
    background: Option<&[X]>,
    order: Order,
    clear: X,
) {
    match (order, background) {
        (Order::BackToFront, Some(bg)) => image.copy_from_slice(&bg[..image.len()]),
        _ => image.fill(clear),
    }
}

/// Which slab composites next, in compositing order, and the refusal of a voxel that reaches a
/// slab already composited: what the slab renderers share.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SlabQueue {
    count: usize,
    order: Order,
    done: usize,
}

impl SlabQueue {
    pub(crate) fn new(count: usize, order: Order) -> Self {
        SlabQueue {
            count,
            order,
            done: 0,
        }
    }

    /// The next slab to composite (`None` when all are done): slab 0 first front to back.
    pub(crate) fn next(&self) -> Option<usize> {
        (self.done < self.count).then(|| match self.order {
            Order::FrontToBack => self.done,
            Order::BackToFront => self.count - 1 - self.done,
        })
    }

    /// Refuses a voxel reaching slabs `first..=last` if one of them is already composited.
    pub(crate) fn admit(&self, first: usize, last: usize) -> Result<(), RenderError> {
        let late = match (self.order, self.next()) {
            (_, None) => true,
            (Order::FrontToBack, Some(n)) => first < n,
            (Order::BackToFront, Some(n)) => last > n,
        };
        if late {
            return Err(RenderError::SlabOrder {
                first,
                last,
                composited: self.done,
            });
        }
        Ok(())
    }

    /// One more slab composited.
    pub(crate) fn advance(&mut self) {
        self.done += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::BandReach;
    use crate::frame::FrameSetup;
    use crate::geometry::FootprintOptions;
    use crate::{Grid, Kernel, View};
    use glam::Mat3;

    /// A row's range holds every voxel the per-voxel test accepts, over many views and bands.
    #[test]
    fn a_rows_range_holds_every_voxel_that_may_reach_the_band() {
        let (mut checked, mut skipped) = (0, 0);
        for a in 0..24 {
            let (az, el) = (a as f32 * 0.29, a as f32 * 0.41 - 1.3);
            let m = Mat3::from_rotation_x(el) * Mat3::from_rotation_y(az) * 1.7;
            let Ok(view) = View::new(m) else { continue };
            let grid = Grid::from_spacing([1.0, 1.3, 2.0]).unwrap();
            let f = FrameSetup::new(
                [20, 17, 11],
                &grid,
                &view,
                &Kernel::PAPER_GAUSSIAN,
                FootprintOptions::default(),
                [48, 40],
            )
            .unwrap();
            let (_, na, nb) = f.sheet_shape();
            for band in [(0, 1), (7, 3), (20, 5), (39, 1), (0, 40)] {
                for s in 0..f.sheet_count() {
                    let r = BandReach::new(&f, band, s);
                    for v in 0..nb {
                        let range = r.row(v, na);
                        // The integer rows hold the float rows' voxels.
                        let float = r.row_float(v, na);
                        assert!(
                            float.is_empty()
                                || (range.start <= float.start && range.end >= float.end),
                            "view {a}, band {band:?}, sheet {s}, row {v}: {range:?} inside {float:?}"
                        );
                        skipped += na - range.len();
                        for u in 0..na {
                            if r.may_reach(u, v) {
                                assert!(range.contains(&u), "view {a}, band {band:?}, sheet {s}, ({u}, {v}) outside {range:?}");
                                checked += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(checked > 10_000, "{checked}");
        // And the ranges do leave voxels out: narrow bands skip most of a sheet.
        assert!(skipped > checked, "{skipped} skipped, {checked} checked");
    }
}
