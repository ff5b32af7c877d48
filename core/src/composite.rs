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
    // max/min, not clamp: a NaN alpha becomes 0 (clamp would keep it NaN, and a NaN bound
    // would make the colour clamps panic).
    #[allow(clippy::manual_clamp)]
    let a = c[3].max(0.0).min(1.0);
    [
        c[0].max(0.0).min(a),
        c[1].max(0.0).min(a),
        c[2].max(0.0).min(a),
        a,
    ]
}
