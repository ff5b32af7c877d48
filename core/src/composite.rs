//! Porter–Duff compositing of premultiplied RGBA, and the row spans that limit it to the pixels a
//! sheet actually covered.

/// Inclusive pixel range [lo, hi] of one image row; empty when lo > hi.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RowSpan {
    /// First pixel.
    pub lo: u32,
    /// Last pixel.
    pub hi: u32,
}

impl RowSpan {
    /// The empty span.
    pub const EMPTY: RowSpan = RowSpan {
        lo: u32::MAX,
        hi: 0,
    };

    /// Widens the span to include [lo, hi].
    #[inline]
    pub fn include(&mut self, lo: usize, hi: usize) {
        self.lo = self.lo.min(lo as u32);
        self.hi = self.hi.max(hi as u32);
    }

    /// Whether the span holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.lo > self.hi
    }
}

impl Default for RowSpan {
    fn default() -> Self {
        RowSpan::EMPTY
    }
}

/// `front` over `back`: front + (1 − α_front) · back (premultiplied).
#[inline]
pub fn over(front: [f32; 4], back: [f32; 4]) -> [f32; 4] {
    let k = 1.0 - front[3];
    [
        front[0] + k * back[0],
        front[1] + k * back[1],
        front[2] + k * back[2],
        front[3] + k * back[3],
    ]
}

/// A sheet's accumulated value made a valid premultiplied colour: alpha clamped to [0, 1], each
/// colour channel to [0, alpha]. (Kernel ripple and negative lobes can push sums outside, and
/// not in step: where voxels of different colours overlap, a negative lobe can take alpha below
/// zero while colour stays positive — colour without coverage, which `over` would add as light.)
#[inline]
pub fn clamp_unit(c: [f32; 4]) -> [f32; 4] {
    // Comparisons, not clamp or max/min: a NaN alpha or colour becomes 0 (clamp would keep it
    // NaN, and a NaN bound would make the colour clamps panic), and each select is one SSE
    // max/min (`f32::max` adds a NaN fix-up the compiler cannot vectorise; the same values).
    let (lo, hi) = (
        |x: f32| if x > 0.0 { x } else { 0.0 },
        |x: f32, m: f32| if x < m { x } else { m },
    );
    let a = hi(lo(c[3]), 1.0);
    // hi(lo(c[3]), a) is a itself (for c[3] in [0, 1] both are c[3]; above, 1; at or below zero
    // or NaN, +0), so all four lanes take one formula, which the compiler does as one max and
    // one min of 4 lanes.
    c.map(|x| hi(lo(x), a))
}
