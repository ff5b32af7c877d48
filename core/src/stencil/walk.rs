//! The span walk both stencil splats share: the float one ([`super::Stencils::splat`]) and the
//! integer one ([`crate::fixed::stencil::FixedStencils::splat`]) differ only in how they weigh a
//! pixel; where a voxel's box lies, which of its rows are in the image, which pixels of a row the
//! phase cell's stored run covers, and which stencil entries sit under them are found here, once.
//!
//! Conventions: a voxel's box is B × B pixels with its corner at pixel (x0, y0) (absolute, may
//! lie outside the image); box row `my` is image row y0 + my. A phase cell's run per box row is
//! packed as `first | last << 16` (box columns, first > last when the row is empty), and the
//! per-cell runs are found when the stencils are built ([`pack_runs`]). No floating point here:
//! the integer path uses it under `deny(clippy::float_arithmetic)`.

use super::{cell_corners, PhaseLookup};

impl PhaseLookup {
    /// The lookup that stencils asked to read by this one use: [`PhaseLookup::Blend`] if `edged`
    /// (an edged footprint's phases are too few for the nearest), else this one. The float and
    /// the fixed stencils both decide it here.
    pub(crate) fn unless_edged(self, edged: bool) -> Self {
        if edged {
            PhaseLookup::Blend
        } else {
            self
        }
    }
}

/// Where one voxel's box of stencil entries falls in an image of `width` × `height` pixels.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpanWalk {
    /// The box's corner pixel, absolute.
    pub x0: i64,
    pub y0: i64,
    /// Box side B, pixels.
    pub side: usize,
    width: i64,
    /// Box rows inside the image: `rows.0 .. rows.1`.
    rows: (usize, usize),
    /// The whole box lies inside the image.
    pub inside: bool,
}

/// One box row of the walk: box row `my`, image row `y`, and the phase cell's stored run as
/// absolute pixel columns (first > last when the row is empty), not yet clipped to the image.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Row {
    pub my: usize,
    pub y: usize,
    pub first: i64,
    pub last: i64,
}

/// Pixels `lo ..= hi` of an image row (`n` = hi − lo + 1 of them), whose stencil entries start
/// at `entry` within each stencil (box row × B + box column).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Clip {
    pub lo: usize,
    pub hi: usize,
    pub n: usize,
    pub entry: usize,
}

impl SpanWalk {
    /// The box of side `side` whose centre pixel is `pixel` (its corner `reach` = B / 2 pixels up
    /// and left), or `None` when it misses the image.
    #[inline(always)]
    pub fn new(pixel: [i64; 2], side: usize, width: usize, height: usize) -> Option<Self> {
        let reach = (side / 2) as i64;
        let (x0, y0) = (pixel[0] - reach, pixel[1] - reach);
        let (b, w, h) = (side as i64, width as i64, height as i64);
        if x0 + b <= 0 || y0 + b <= 0 || x0 >= w || y0 >= h {
            return None;
        }
        Some(SpanWalk {
            x0,
            y0,
            side,
            width: w,
            rows: ((-y0).max(0) as usize, (h - y0).min(b) as usize),
            inside: x0 >= 0 && y0 >= 0 && x0 + b <= w && y0 + b <= h,
        })
    }

    /// The box rows inside the image, with their stored runs: `spans` holds the phase cell's B
    /// packed runs, `bits` reads one as `first | last << 16`.
    #[inline(always)]
    pub fn rows<'s, T: Copy>(
        &self,
        spans: &'s [T],
        bits: impl Fn(T) -> u32 + 's,
    ) -> impl Iterator<Item = Row> + 's {
        let (x0, y0) = (self.x0, self.y0);
        let (my0, my1) = self.rows;
        spans
            .iter()
            .enumerate()
            .take(my1)
            .skip(my0)
            .map(move |(my, &span)| {
                let packed = bits(span);
                Row {
                    my,
                    y: (y0 + my as i64) as usize,
                    first: x0 + i64::from(packed & 0xffff),
                    last: x0 + i64::from(packed >> 16),
                }
            })
    }

    /// Columns `first ..= last` (absolute) of box row `my`, clipped to the image; `None` when
    /// nothing is left. `first` and `last` must lie in the box for [`Clip::entry`] to be
    /// meaningful (a row's run does).
    #[inline(always)]
    pub fn clip(&self, my: usize, first: i64, last: i64) -> Option<Clip> {
        let (lo, hi) = (first.max(0), last.min(self.width - 1));
        if lo > hi {
            return None;
        }
        Some(Clip {
            lo: lo as usize,
            hi: hi as usize,
            n: (hi - lo + 1) as usize,
            entry: my * self.side + (lo - self.x0) as usize,
        })
    }
}

/// The four corner stencils' entries under a clipped run: `n` entries of each, starting at
/// `entry` in the stencils at offsets `corners` (in the order of
/// [`super::corner_offsets`]). Four slices written out, so the caller's loop sees their
/// lengths and indexes them without checks (an array of slices measured 22 % slower on the
/// walnut).
#[inline(always)]
pub(crate) fn corner_rows<T>(
    data: &[T],
    [s00, s10, s01, s11]: [usize; 4],
    entry: usize,
    n: usize,
) -> (&[T], &[T], &[T], &[T]) {
    (
        &data[s00 + entry..][..n],
        &data[s10 + entry..][..n],
        &data[s01 + entry..][..n],
        &data[s11 + entry..][..n],
    )
}

/// Stores each phase cell's run per box row into `spans` (P² cells of B packed runs, see the
/// module docs): `run(corners, my)` gives the first and last box column of row `my` for the cell
/// whose four corner stencils are `corners` (indices into the (P + 1)² grid), or first > last
/// for none; `pack` stores `first | last << 16`. Returns the longest run stored (0 if none).
pub(crate) fn pack_runs<T>(
    spans: &mut [T],
    side: usize,
    phases: usize,
    mut run: impl FnMut([usize; 4], usize) -> (usize, usize),
    pack: impl Fn(u32) -> T,
) -> usize {
    let mut longest = 0;
    for (c, cell) in spans.chunks_exact_mut(side).enumerate() {
        let corners = cell_corners(c, phases);
        for (my, packed) in cell.iter_mut().enumerate() {
            let (first, last) = run(corners, my);
            // B ≤ 129: both fit 16 bits.
            *packed = pack(first as u32 | (last as u32) << 16);
            if first <= last {
                longest = longest.max(last - first + 1);
            }
        }
    }
    longest
}

#[cfg(test)]
mod tests {
    use super::SpanWalk;

    /// The walk's rows and clipped runs against brute force: every box position around and
    /// inside a small image, every packed run.
    #[test]
    fn the_walk_visits_exactly_the_box_pixels_in_the_image() {
        let (w, h, side) = (7usize, 5usize, 5usize);
        let runs: [(u32, u32); 5] = [(0, 4), (1, 3), (2, 2), (3, 1), (0, 0)];
        let spans: [u32; 5] = runs.map(|(f, l)| f | l << 16);
        for cy in -4i64..10 {
            for cx in -4i64..12 {
                let mut seen = [[false; 7]; 5];
                if let Some(walk) = SpanWalk::new([cx, cy], side, w, h) {
                    for row in walk.rows(&spans, |s| s) {
                        if let Some(c) = walk.clip(row.my, row.first, row.last) {
                            assert_eq!(c.n, c.hi - c.lo + 1);
                            assert_eq!(c.entry, row.my * side + (c.lo as i64 - walk.x0) as usize);
                            for s in &mut seen[row.y][c.lo..=c.hi] {
                                assert!(!*s);
                                *s = true;
                            }
                        }
                    }
                }
                for (y, line) in seen.iter().enumerate() {
                    for (x, &s) in line.iter().enumerate() {
                        let (mx, my) = (x as i64 - (cx - 2), y as i64 - (cy - 2));
                        let want = (0..5).contains(&my) && (0..5).contains(&mx) && {
                            let (f, l) = runs[my as usize];
                            (i64::from(f)..=i64::from(l)).contains(&mx)
                        };
                        assert_eq!(s, want, "box at {cx},{cy}, pixel {x},{y}");
                    }
                }
            }
        }
    }
}
