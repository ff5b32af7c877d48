//! The screen ellipse of one view's footprint: its covariance Σ = N Nᵀ, extent, the robust
//! (Cholesky) and separable (parallelogram) maps to unit coordinates, the minimum-radius widening,
//! and the exact support per pixel row. Derivation in the [module docs](super).

use super::mat2::{mul2, Mat2, Sym2};
use super::paper::paper_decomposition;
use super::{
    all_finite, in_sheet_axes, sheet_axis, well_conditioned, FootprintOptions, GeometryError,
    Mapping, MAX_HALF_EXTENT_PX, MIN_MIN_RADIUS_PX, RENORMALISE_BELOW_PX,
};
use crate::kernel::{Kernel, Shape};
use crate::math::{self, sq};
use glam::Mat3;

fn inverse2(m: &Mat2) -> (Mat2, f32) {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = 1.0 / det;
    (
        [
            [m[1][1] * inv, -m[0][1] * inv],
            [-m[1][0] * inv, m[0][0] * inv],
        ],
        det,
    )
}

/// One view's footprint: where it reaches on screen and how a screen offset maps into the generic
/// table. Weight at screen offset q (pixels, from the voxel's projected centre) is
/// `scale × T(to_unit · q)`, T the generic table (normalised to unit integral), so the footprint
/// integrates to one over the screen plane (units: px⁻²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// 2×2 map from a screen offset (px) to unit coordinates u.
    pub to_unit: Mat2,
    /// Half-width and half-height of the axis-aligned bounding box, px.
    pub half_extent: [f32; 2],
    /// |det to_unit|, px⁻²: turns table values (per unit u-area) into per-pixel² weights.
    pub scale: f32,
    /// Renormalise each splat's sampled weights to sum to one (small footprints).
    pub renormalise: bool,
    /// Whether a semi-axis was lengthened to `min_radius_px`.
    pub clamped: bool,
    /// The shorter semi-axis before any lengthening, px (0 for a singular footprint): how far
    /// below `min_radius_px` the voxels project when [`Footprint::clamped`] (a caller can render
    /// that much larger instead).
    pub natural_minor_px: f32,
    /// Whether the paper method needed its rotation cheat.
    pub cheated: bool,
    /// Screen covariance Σ of the (clamped) footprint region, px².
    pub covariance: Sym2,
    /// The sheet axis this footprint was oriented for (used by separable kernels).
    pub sheet_axis: usize,
    /// Radial (ellipse support) or separable (parallelogram support).
    pub shape: Shape,
    /// Radial support per image row, precomputed so a row costs one square root and no division:
    /// the row at offset qy spans qx ∈ m·qy ± √(c₀ + c₂·qy²), as `[m, c₀, c₂]` (see
    /// [`Footprint::row_span`]). Unused for separable shapes.
    pub row_coefficients: [f32; 3],
}

impl Footprint {
    /// A footprint that covers nothing (zero box, zero weight): the placeholder in a `static`
    /// [`crate::ViewTable::zeroed`] before the first build.
    pub const EMPTY: Footprint = Footprint {
        to_unit: [[0.0; 2]; 2],
        half_extent: [0.0; 2],
        scale: 0.0,
        renormalise: false,
        clamped: false,
        cheated: false,
        covariance: Sym2 {
            xx: 0.0,
            xy: 0.0,
            yy: 0.0,
        },
        sheet_axis: 2,
        shape: Shape::Radial,
        row_coefficients: [0.0, -1.0, 0.0],
        natural_minor_px: 0.0,
    };

    /// Sets up the footprint of `kernel` for `grid_to_screen` = V·G (see [`View::grid_to_screen`](super::View::grid_to_screen)).
    pub fn new(
        kernel: &Kernel,
        grid_to_screen: &Mat3,
        options: FootprintOptions,
    ) -> Result<Self, GeometryError> {
        Self::with_sheet_axis(kernel, grid_to_screen, options, sheet_axis(grid_to_screen))
    }

    /// [`Footprint::new`] for sheets along `axis` (0, 1 or 2; separable kernels are oriented by
    /// it) rather than the axis `grid_to_screen` itself would choose: a perspective frame's
    /// per-voxel maps ([`super::Perspective`]) keep the frame's sheet axis.
    pub fn with_sheet_axis(
        kernel: &Kernel,
        grid_to_screen: &Mat3,
        options: FootprintOptions,
        axis: usize,
    ) -> Result<Self, GeometryError> {
        let axis = axis.min(2);
        let mr = options.min_radius_px;
        if !mr.is_finite() || mr < MIN_MIN_RADIUS_PX {
            return Err(GeometryError::BadMinRadius { value: mr });
        }
        if !all_finite(grid_to_screen) {
            return Err(GeometryError::NonFinite);
        }
        if !well_conditioned(grid_to_screen) {
            return Err(GeometryError::SingularView);
        }
        let r = kernel.spread();
        let cols = [
            grid_to_screen.x_axis,
            grid_to_screen.y_axis,
            grid_to_screen.z_axis,
        ];
        // N: 2×3 (radial) or B: 2×2 (separable), rows = screen x and y, scaled by R.
        let mut n = [[0.0f32; 3]; 2];
        match kernel.shape() {
            Shape::Radial => {
                for (c, col) in cols.iter().enumerate() {
                    n[0][c] = r * col.x;
                    n[1][c] = r * col.y;
                }
            }
            Shape::Separable => {
                // Third column zero: the same formulas then give B Bᵀ and det(B)².
                let (a, b) = in_sheet_axes(axis);
                n = [
                    [r * cols[a].x, r * cols[b].x, 0.0],
                    [r * cols[a].y, r * cols[b].y, 0.0],
                ];
            }
        }
        let (clamped, natural_minor_sq) = clamp_min_radius(&mut n, mr * mr);
        let cov = covariance(&n);
        let det = cauchy_binet_det(&n);
        if !(det > 0.0) || !det.is_finite() {
            return Err(GeometryError::SingularView);
        }
        let mut cheated = false;
        let to_unit = match (options.mapping, kernel.shape()) {
            (Mapping::Robust, Shape::Radial) => cholesky_map(&cov, det),
            (Mapping::Robust, Shape::Separable) => {
                inverse2(&[[n[0][0], n[0][1]], [n[1][0], n[1][1]]]).0
            }
            (Mapping::Paper { cheat_deg }, _) => {
                let conic = conic_of(&cov, det);
                let d = paper_decomposition(&conic, cheat_deg)?;
                cheated = d.cheated;
                d.to_unit
            }
        };
        let (from_unit, det_map) = inverse2(&to_unit);
        let half_extent = match kernel.shape() {
            // The ellipse {q : |A q| ≤ 1} has covariance A⁻¹A⁻ᵀ: half-extents are row norms of A⁻¹.
            Shape::Radial => [
                math::sqrt(sq(from_unit[0][0]) + sq(from_unit[0][1])),
                math::sqrt(sq(from_unit[1][0]) + sq(from_unit[1][1])),
            ],
            // The square |u|∞ ≤ 1 maps to a parallelogram: half-extents are row abs-sums of A⁻¹.
            Shape::Separable => [
                math::abs(from_unit[0][0]) + math::abs(from_unit[0][1]),
                math::abs(from_unit[1][0]) + math::abs(from_unit[1][1]),
            ],
        };
        let scale = math::abs(det_map);
        let finite = to_unit.iter().flatten().all(|v| v.is_finite())
            && half_extent.iter().all(|v| v.is_finite())
            && scale.is_finite()
            && scale > 0.0;
        if !finite {
            return Err(GeometryError::PaperSingular {
                theta_deg: f32::NAN,
            });
        }
        let largest = half_extent[0].max(half_extent[1]);
        if largest > MAX_HALF_EXTENT_PX {
            return Err(GeometryError::TooLarge {
                half_extent_px: largest,
            });
        }
        // |A q|² = P_xx qx² + 2 P_xy qx qy + P_yy qy² ≤ 1 with P = AᵀA, solved for qx:
        // qx = (−P_xy qy ± √((P_xy² − P_xx P_yy) qy² + P_xx)) / P_xx.
        let pxx = sq(to_unit[0][0]) + sq(to_unit[1][0]);
        let pxy = to_unit[0][0] * to_unit[0][1] + to_unit[1][0] * to_unit[1][1];
        let pyy = sq(to_unit[0][1]) + sq(to_unit[1][1]);
        let row_coefficients = [-pxy / pxx, 1.0 / pxx, (sq(pxy) - pxx * pyy) / sq(pxx)];
        Ok(Footprint {
            to_unit,
            half_extent,
            scale,
            renormalise: largest <= RENORMALISE_BELOW_PX,
            clamped,
            natural_minor_px: math::sqrt(natural_minor_sq),
            cheated,
            covariance: cov,
            sheet_axis: axis,
            shape: kernel.shape(),
            row_coefficients,
        })
    }

    /// Whether screen offset `q` (pixels from the centre) lies in the footprint's support:
    /// |A q| ≤ 1 for a radial kernel, |A q|∞ ≤ 1 for a separable one.
    #[inline]
    pub fn contains(&self, q: [f32; 2]) -> bool {
        let u = mul2(&self.to_unit, q);
        match self.shape {
            Shape::Radial => u[0] * u[0] + u[1] * u[1] <= 1.0,
            Shape::Separable => math::abs(u[0]) <= 1.0 && math::abs(u[1]) <= 1.0,
        }
    }

    /// The range of screen x offsets (pixels, relative to the voxel's projected centre) where the
    /// footprint's support meets the row at y offset `qy`: the ellipse `|A q| ≤ 1` (radial) or
    /// the parallelogram `|A q|∞ ≤ 1` (separable), A = [`Footprint::to_unit`]. `None` if the row
    /// misses it. Splatting visits only these pixels, so table interpolation never leaks weight
    /// past the support, and a quarter of an ellipse's bounding box is never touched.
    #[inline]
    pub fn row_span(&self, qy: f32) -> Option<(f32, f32)> {
        let a = &self.to_unit;
        match self.shape {
            Shape::Radial => {
                let [m, c0, c2] = self.row_coefficients;
                let disc = c0 + c2 * qy * qy;
                if !(disc > 0.0) {
                    return None;
                }
                let half = math::sqrt(disc);
                let mid = m * qy;
                Some((mid - half, mid + half))
            }
            Shape::Separable => {
                // |a_r0 qx + a_r1 qy| ≤ 1 for both rows r: intersect two slabs.
                let (mut lo, mut hi) = (f32::NEG_INFINITY, f32::INFINITY);
                for row in a {
                    let rest = row[1] * qy;
                    if row[0] == 0.0 {
                        if !(math::abs(rest) < 1.0) {
                            return None;
                        }
                    } else {
                        let (p, q) = ((-1.0 - rest) / row[0], (1.0 - rest) / row[0]);
                        lo = lo.max(p.min(q));
                        hi = hi.min(p.max(q));
                    }
                }
                (lo < hi).then_some((lo, hi))
            }
        }
    }
}

/// Σ = N Nᵀ for a 2×3 N.
pub fn covariance(n: &[[f32; 3]; 2]) -> Sym2 {
    let dot = |a: &[f32; 3], b: &[f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    Sym2 {
        xx: dot(&n[0], &n[0]),
        xy: dot(&n[0], &n[1]),
        yy: dot(&n[1], &n[1]),
    }
}

/// det(N Nᵀ) by Cauchy–Binet: the sum of the squares of N's three 2×2 minors. No cancellation.
pub(crate) fn cauchy_binet_det(n: &[[f32; 3]; 2]) -> f32 {
    let minor = |a: usize, b: usize| n[0][a] * n[1][b] - n[0][b] * n[1][a];
    sq(minor(0, 1)) + sq(minor(0, 2)) + sq(minor(1, 2))
}

/// The conic Σ⁻¹ of the footprint ellipse `qᵀ Σ⁻¹ q = 1` (px⁻²).
pub fn conic_of(cov: &Sym2, det: f32) -> Sym2 {
    Sym2 {
        xx: cov.yy / det,
        xy: -cov.xy / det,
        yy: cov.xx / det,
    }
}

/// A = C⁻¹ for Σ = C Cᵀ (C lower-triangular), so AᵀA = Σ⁻¹. Defined for every positive-definite Σ:
/// no angle is special.
fn cholesky_map(cov: &Sym2, det: f32) -> Mat2 {
    let c00 = math::sqrt(cov.xx);
    let c10 = cov.xy / c00;
    // Σyy − Σxy²/Σxx = det/Σxx, taken from the cancellation-free determinant.
    let c11 = math::sqrt(det / cov.xx);
    [[1.0 / c00, 0.0], [-c10 / (c00 * c11), 1.0 / c11]]
}

/// Lengthens every semi-axis (singular value) of the 2×ncols map `n` shorter than √`min_r2` to it,
/// keeping the ellipse's orientation: n ← K n with K = U diag(max(1, r/sᵢ)) Uᵀ, Σ = U S² Uᵀ.
/// Returns whether anything changed, and the smaller squared semi-axis before (0 when singular).
fn clamp_min_radius(n: &mut [[f32; 3]; 2], min_r2: f32) -> (bool, f32) {
    let cov = covariance(n);
    let det = cauchy_binet_det(n);
    let half_tr = 0.5 * (cov.xx + cov.yy);
    let disc = math::sqrt(sq(0.5 * (cov.xx - cov.yy)) + sq(cov.xy));
    let l1 = half_tr + disc;
    if !(det > 0.0) || !l1.is_finite() {
        return (false, 0.0); // Singular or non-finite: rejected by the caller.
    }
    let l2 = det / l1; // The smaller eigenvalue, without cancellation.
    if l2 >= min_r2 {
        return (false, l2);
    }
    // Unit eigenvector of l1; for a circle any direction will do.
    let (vx, vy) = if cov.xx >= cov.yy {
        (l1 - cov.yy, cov.xy)
    } else {
        (cov.xy, l1 - cov.xx)
    };
    let len = math::sqrt(vx * vx + vy * vy);
    let (vx, vy) = if len > 0.0 {
        (vx / len, vy / len)
    } else {
        (1.0, 0.0)
    };
    let k1 = if l1 < min_r2 {
        math::sqrt(min_r2 / l1)
    } else {
        1.0
    };
    let k2 = math::sqrt(min_r2 / l2);
    // K = k1 v vᵀ + k2 w wᵀ with w = (−vy, vx).
    let k = [
        [k1 * vx * vx + k2 * vy * vy, (k1 - k2) * vx * vy],
        [(k1 - k2) * vx * vy, k1 * vy * vy + k2 * vx * vx],
    ];
    let old = *n;
    for c in 0..3 {
        n[0][c] = k[0][0] * old[0][c] + k[0][1] * old[1][c];
        n[1][c] = k[1][0] * old[0][c] + k[1][1] * old[1][c];
    }
    (true, l2)
}
