//! The 2×2 matrices the screen ellipse and the paper's decomposition share (a leaf: it imports
//! nothing of the crate, so `ellipse.rs` and `paper.rs` both stand on it).

/// A symmetric 2×2 matrix [[xx, xy], [xy, yy]].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sym2 {
    /// Entry (0, 0).
    pub xx: f32,
    /// Entries (0, 1) and (1, 0).
    pub xy: f32,
    /// Entry (1, 1).
    pub yy: f32,
}

/// A 2×2 matrix in row-major order: `m[row][col]`.
pub type Mat2 = [[f32; 2]; 2];

/// m · v.
#[inline]
pub(crate) fn mul2(m: &Mat2, v: [f32; 2]) -> [f32; 2] {
    [
        m[0][0] * v[0] + m[0][1] * v[1],
        m[1][0] * v[0] + m[1][1] * v[1],
    ]
}
