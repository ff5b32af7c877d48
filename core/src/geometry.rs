//! Ellipse geometry: from grid spacing and view to the screen-space footprint ellipse, its extent in
//! pixels, and the 2×2 map from a screen offset back to the kernel's unit coordinates.
//!
//! # Frames and units
//! - **Grid**: voxel indices (i, j, k), unitless.
//! - **World**: `world = G · (i, j, k)`, G the *grid-to-world* matrix ([`Grid`]); for a diagonal
//!   G the diagonal is the voxel spacing (e.g. millimetres).
//! - **Screen**: `screen = V · world + (W/2, H/2, 0)`, V the *world-to-screen* linear map
//!   ([`View`]), in pixels; x to the right, y down, z away from the viewer. Pixel (x, y) has its
//!   centre at (x + 0.5, y + 0.5).
//! - **Unit**: the kernel's coordinates u = grid offset / R, R = the kernel's spread.
//!
//! # Derivation (checked against brute force in `tests/ellipse_geometry.rs`)
//! Let `M = R · V · G` (3×3): it maps the unit ball |u| ≤ 1 onto the kernel's region ellipsoid in
//! screen space, `{M u}`. Orthographic projection drops z, so the footprint's support is
//! `{N u : |u| ≤ 1}` with `N` the top two rows of M (2×3). That set is the ellipse
//! `qᵀ Σ⁻¹ q ≤ 1` with **Σ = N Nᵀ** (for any q on its boundary, maximise the linear form over the
//! ball). Hence:
//! - half-extents (the axis-aligned bounding box) are `√Σxx` and `√Σyy` pixels;
//! - the conic is Σ⁻¹, and any A with AᵀA = Σ⁻¹ maps the ellipse to the unit circle;
//! - for a radial kernel h(|u|), the screen line integral at offset q is `F(|A q|) / |d|` with
//!   d = M⁻¹ e_z: the ray maps to a line in u-space whose distance from the origin ρ satisfies
//!   ρ² = qᵀΣ⁻¹q (both are quadratic forms with the same unit level set), so every A above is
//!   right and only |det A| matters for normalisation.
//!
//! `det Σ` is computed by Cauchy–Binet as the sum of the squared 2×2 minors of N, which has no
//! cancellation even for a needle-thin ellipse.
//!
//! **Robust map** (default): A = C⁻¹ with Σ = C Cᵀ the Cholesky factorisation; it has no singular
//! angle. **Paper map** ([`Mapping::Paper`]): Westover's θ/Sx/Sy decomposition (see
//! [`paper_decomposition`]), kept so its failure near 45° can be measured.
//!
//! ## Misprints in the paper, corrected here
//! 1. "E = S * U": transforming a quadric by S gives E = S⁻ᵀ U S⁻¹, not S·U.
//! 2. The matrix P puts Z on the off-diagonal, but equation (2) defines Z as the coefficient of
//!    xy; the off-diagonal must be Z/2 (and equation (5) must read ac + bd = Z/2).
//! 3. Equations (6)–(7) give ac + bd = SxSy(cos θ sin θ − sin θ cos θ) ≡ 0, so T cannot be
//!    "scale, then rotation" in that form; with T = R(θ)·diag(Sx, Sy) (rows a b / c d =
//!    Sx cos θ, −Sy sin θ / Sx sin θ, Sy cos θ) the stated G = w − 1/w relation holds.
//!
//! ## Separable footprints
//! The bilinear model is oriented along the sheet's two in-sheet grid axes, so for it the map is
//! the parallelogram map A = B⁻¹, B = R·[screen image of grid axis a, of grid axis b] (2×2), not
//! "any A with AᵀA = Σ⁻¹": a rotation in u-space would turn the tent's square.
//!
//! ## Sub-pixel footprints
//! A footprint narrower than a pixel would fall between pixel centres and vanish. Any semi-axis
//! shorter than `min_radius_px` is lengthened to it (the ellipse's singular values are clamped,
//! its orientation kept), which is the screen-space low-pass filter of EWA splatting; the default
//! 1.5 px keeps every point within 0.71 px of a pixel centre well inside the footprint. Footprints
//! whose half-extents are both at most [`RENORMALISE_BELOW_PX`] are renormalised per splat so their
//! weights sum to exactly one: no weight is lost however small the voxel.

use crate::kernel::{Kernel, Shape};
use crate::math::{self, sq};
use core::fmt;
use glam::{Mat3, Vec3};

/// Footprints whose half-extents are both at most this many pixels have their sampled weights
/// renormalised to sum to one (see the module docs).
pub const RENORMALISE_BELOW_PX: f32 = 4.0;

/// Default smallest footprint semi-axis, pixels.
pub const DEFAULT_MIN_RADIUS_PX: f32 = 1.5;

/// Largest footprint half-extent accepted, pixels (beyond 2²² px, f32 pixel coordinates lose the
/// fractional part that sampling relies on).
pub const MAX_HALF_EXTENT_PX: f32 = 4_194_304.0;

/// Smallest allowed `min_radius_px`: a disc of radius √2/2 just covers the unit pixel cell, so any
/// smaller floor could let a footprint miss every pixel centre.
pub const MIN_MIN_RADIUS_PX: f32 = 0.75;

/// Why the geometry of a view could not be set up.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum GeometryError {
    /// A matrix or spacing entry is NaN or infinite.
    NonFinite,
    /// A spacing is zero or negative.
    NonPositiveSpacing {
        /// Grid axis (0 = i, 1 = j, 2 = k).
        axis: u8,
        /// The value given.
        value: f32,
    },
    /// The grid-to-world matrix is singular (|det| is below 1e-6 of the product of column norms).
    SingularGrid,
    /// The world-to-screen map is singular (same test).
    SingularView,
    /// The footprint is larger than [`MAX_HALF_EXTENT_PX`].
    TooLarge {
        /// The larger half-extent, pixels.
        half_extent_px: f32,
    },
    /// `min_radius_px` is not finite or below [`MIN_MIN_RADIUS_PX`].
    BadMinRadius {
        /// The value given.
        value: f32,
    },
    /// The paper's θ decomposition produced a non-finite or non-positive scale (its 45°
    /// singularity, with the cheat disabled or not enough to escape it).
    PaperSingular {
        /// θ in degrees where it failed.
        theta_deg: f32,
    },
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NonFinite => f.write_str("matrix or spacing contains NaN or infinity"),
            Self::NonPositiveSpacing { axis, value } => {
                write!(
                    f,
                    "spacing along grid axis {axis} must be positive, got {value}"
                )
            }
            Self::SingularGrid => f.write_str("grid-to-world matrix is singular"),
            Self::SingularView => f.write_str("world-to-screen matrix is singular"),
            Self::TooLarge { half_extent_px } => write!(
                f,
                "footprint half-extent {half_extent_px} px exceeds {MAX_HALF_EXTENT_PX} px"
            ),
            Self::BadMinRadius { value } => {
                write!(
                    f,
                    "minimum footprint radius must be >= {MIN_MIN_RADIUS_PX} px, got {value}"
                )
            }
            Self::PaperSingular { theta_deg } => {
                write!(f, "paper θ decomposition is singular at θ = {theta_deg}°")
            }
        }
    }
}

impl core::error::Error for GeometryError {}

fn all_finite(m: &Mat3) -> bool {
    m.to_cols_array().iter().all(|v| v.is_finite())
}

/// |det m| ≥ 1e-6 × product of its column lengths (a scale-free test for a singular matrix).
fn well_conditioned(m: &Mat3) -> bool {
    let norms = m.x_axis.length_squared() * m.y_axis.length_squared() * m.z_axis.length_squared();
    let det = m.determinant();
    det * det >= 1e-12 * norms && norms > 0.0
}

/// The grid-to-world map G: world = G · (i, j, k). Columns are the world-space steps of one voxel
/// along i, j and k (their lengths are the spacings, in world units such as mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    to_world: Mat3,
}

impl Grid {
    /// A rectilinear grid with the given spacing (world units per voxel) along i, j, k.
    pub fn from_spacing(spacing: [f32; 3]) -> Result<Self, GeometryError> {
        for (axis, &value) in spacing.iter().enumerate() {
            if !value.is_finite() {
                return Err(GeometryError::NonFinite);
            }
            if value <= 0.0 {
                return Err(GeometryError::NonPositiveSpacing {
                    axis: axis as u8,
                    value,
                });
            }
        }
        Ok(Grid {
            to_world: Mat3::from_diagonal(Vec3::from_array(spacing)),
        })
    }

    /// A general grid (sheared or rotated, e.g. from NRRD `space directions`). Column c is the
    /// world-space step along grid axis c.
    pub fn from_matrix(grid_to_world: Mat3) -> Result<Self, GeometryError> {
        if !all_finite(&grid_to_world) {
            return Err(GeometryError::NonFinite);
        }
        if !well_conditioned(&grid_to_world) {
            return Err(GeometryError::SingularGrid);
        }
        Ok(Grid {
            to_world: grid_to_world,
        })
    }

    /// The grid-to-world matrix.
    pub fn to_world(&self) -> Mat3 {
        self.to_world
    }
}

/// The orthographic world-to-screen linear map V, in pixels per world unit (the offset
/// (W/2, H/2, 0) is added by whoever places voxels on an image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    to_screen: Mat3,
}

impl View {
    /// Validates a world-to-screen matrix (finite, non-singular).
    pub fn new(world_to_screen: Mat3) -> Result<Self, GeometryError> {
        if !all_finite(&world_to_screen) {
            return Err(GeometryError::NonFinite);
        }
        if !well_conditioned(&world_to_screen) {
            return Err(GeometryError::SingularView);
        }
        Ok(View {
            to_screen: world_to_screen,
        })
    }

    /// From nine entries in row-major order (m00, m01, m02, m10, …), as the CLI's `--view-matrix`.
    pub fn from_rows(m: [f32; 9]) -> Result<Self, GeometryError> {
        View::new(Mat3::from_cols_array(&m).transpose())
    }

    /// The world-to-screen matrix.
    pub fn to_screen(&self) -> Mat3 {
        self.to_screen
    }

    /// V · G: maps a grid-index offset to a screen offset in pixels.
    pub fn grid_to_screen(&self, grid: &Grid) -> Mat3 {
        self.to_screen * grid.to_world
    }
}

/// The grid axis whose sheets (planes of constant index along it) are most parallel to the image
/// plane: the one whose in-sheet axes span a plane with the largest |cos| to the screen's xy plane.
/// Ties go to the lower axis. `grid_to_screen` is V·G.
pub fn sheet_axis(grid_to_screen: &Mat3) -> usize {
    let cols = [
        grid_to_screen.x_axis,
        grid_to_screen.y_axis,
        grid_to_screen.z_axis,
    ];
    let mut best = (0, -1.0f32);
    for k in 0..3 {
        let (a, b) = in_sheet_axes(k);
        let n = cols[a].cross(cols[b]);
        let len2 = n.length_squared();
        let cos2 = if len2 > 0.0 { n.z * n.z / len2 } else { 0.0 };
        if cos2 > best.1 {
            best = (k, cos2);
        }
    }
    best.0
}

/// The two grid axes spanning the sheets of `sheet_axis`, in increasing order.
pub fn in_sheet_axes(sheet_axis: usize) -> (usize, usize) {
    match sheet_axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// How the projected ellipse is mapped back to the unit circle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mapping {
    /// Cholesky (radial kernels) or the sheet parallelogram (separable): no singular angle.
    Robust,
    /// The paper's θ/Sx/Sy decomposition, rotating the view by `cheat_deg` degrees (the paper
    /// uses 0.01; 0 disables the cheat) when θ is at 45°.
    Paper {
        /// Extra rotation about the view axis applied at the singularity, degrees.
        cheat_deg: f32,
    },
}

impl Mapping {
    /// The paper's method with its 0.01° cheat.
    pub const PAPER: Mapping = Mapping::Paper { cheat_deg: 0.01 };
}

/// Options for [`Footprint::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FootprintOptions {
    /// Ellipse-to-circle method.
    pub mapping: Mapping,
    /// Smallest footprint semi-axis in pixels (≥ [`MIN_MIN_RADIUS_PX`]).
    pub min_radius_px: f32,
}

impl Default for FootprintOptions {
    fn default() -> Self {
        FootprintOptions {
            mapping: Mapping::Robust,
            min_radius_px: DEFAULT_MIN_RADIUS_PX,
        }
    }
}

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
pub fn mul2(m: &Mat2, v: [f32; 2]) -> [f32; 2] {
    [
        m[0][0] * v[0] + m[0][1] * v[1],
        m[1][0] * v[0] + m[1][1] * v[1],
    ]
}

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
    /// Whether the paper method needed its rotation cheat.
    pub cheated: bool,
    /// Screen covariance Σ of the (clamped) footprint region, px².
    pub covariance: Sym2,
    /// The sheet axis this footprint was oriented for (used by separable kernels).
    pub sheet_axis: usize,
    /// Radial (ellipse support) or separable (parallelogram support).
    pub shape: Shape,
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
    };

    /// Sets up the footprint of `kernel` for `grid_to_screen` = V·G (see [`View::grid_to_screen`]).
    pub fn new(
        kernel: &Kernel,
        grid_to_screen: &Mat3,
        options: FootprintOptions,
    ) -> Result<Self, GeometryError> {
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
        let axis = sheet_axis(grid_to_screen);
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
        let clamped = clamp_min_radius(&mut n, mr * mr);
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
        Ok(Footprint {
            to_unit,
            half_extent,
            scale,
            renormalise: largest <= RENORMALISE_BELOW_PX,
            clamped,
            cheated,
            covariance: cov,
            sheet_axis: axis,
            shape: kernel.shape(),
        })
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
                // |A q|² = P_xx qx² + 2 P_xy qx qy + P_yy qy² ≤ 1 with P = AᵀA: solve for qx.
                let pxx = sq(a[0][0]) + sq(a[1][0]);
                let pxy = a[0][0] * a[0][1] + a[1][0] * a[1][1];
                let pyy = sq(a[0][1]) + sq(a[1][1]);
                let mid = -pxy * qy / pxx;
                let disc = sq(pxy * qy) - pxx * (pyy * qy * qy - 1.0);
                if !(disc > 0.0) {
                    return None;
                }
                let half = math::sqrt(disc) / pxx;
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
pub fn cauchy_binet_det(n: &[[f32; 3]; 2]) -> f32 {
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
/// Returns whether anything changed.
fn clamp_min_radius(n: &mut [[f32; 3]; 2], min_r2: f32) -> bool {
    let cov = covariance(n);
    let det = cauchy_binet_det(n);
    let half_tr = 0.5 * (cov.xx + cov.yy);
    let disc = math::sqrt(sq(0.5 * (cov.xx - cov.yy)) + sq(cov.xy));
    let l1 = half_tr + disc;
    if !(det > 0.0) || !l1.is_finite() {
        return false; // Singular or non-finite: rejected by the caller.
    }
    let l2 = det / l1; // The smaller eigenvalue, without cancellation.
    if l2 >= min_r2 {
        return false;
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
    true
}

/// The result of [`paper_decomposition`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperDecomposition {
    /// Rotation of the ellipse's first axis, radians.
    pub theta: f32,
    /// Sx and Sy of the paper (the scales of T along its axes), px⁻¹.
    pub scales: [f32; 2],
    /// The map Tᵀ from screen offsets to unit coordinates (T Tᵀ = conic).
    pub to_unit: Mat2,
    /// Whether the 45° rotation cheat was applied.
    pub cheated: bool,
}

/// |cos 2θ| below this is "θ = 45°" for the paper's cheat: f32 evaluates cos²θ − sin²θ with an
/// absolute error of about 6e-8, so below 1e-6 the denominator is mostly rounding noise.
pub const PAPER_SINGULAR_COS2: f32 = 1e-6;

/// Westover's decomposition of the conic P = [[X, Z/2], [Z/2, Y]] (misprints corrected, see the
/// module docs): P = T Tᵀ with T = R(θ)·diag(Sx, Sy), θ from G = (X − Y)/(Z/2) = w − 1/w,
/// w = cot θ = (G + √(G² + 4))/2, then Sx², Sy² from the 2×2 linear system
/// `[c² s²; s² c²]·[Sx²; Sy²] = [X; Y]` whose determinant cos 2θ vanishes at 45°: the paper's
/// singularity. When |cos 2θ| < [`PAPER_SINGULAR_COS2`] the view is rotated by `cheat_deg` about the
/// view axis (the conic rotated by that angle) and the decomposition retried once, as the paper
/// does; `cheat_deg` = 0 disables that.
///
/// Computed in f32 exactly as written, including its cancellations; use the robust map for
/// rendering.
pub fn paper_decomposition(
    conic: &Sym2,
    cheat_deg: f32,
) -> Result<PaperDecomposition, GeometryError> {
    let attempt = |p: &Sym2| -> (f32, f32, f32, f32) {
        if p.xy == 0.0 {
            return (0.0, math::sqrt(p.xx), math::sqrt(p.yy), 1.0);
        }
        let g = (p.xx - p.yy) / p.xy;
        let w = 0.5 * (g + math::sqrt(g * g + 4.0));
        let theta = math::atan(1.0 / w);
        let (s, c) = (math::sin(theta), math::cos(theta));
        let denom = c * c - s * s;
        let sx2 = (p.xx * c * c - p.yy * s * s) / denom;
        let sy2 = (p.yy * c * c - p.xx * s * s) / denom;
        (theta, math::sqrt(sx2), math::sqrt(sy2), denom)
    };
    let (mut theta, mut sx, mut sy, denom) = attempt(conic);
    let mut cheated = false;
    if math::abs(denom) < PAPER_SINGULAR_COS2 && cheat_deg != 0.0 {
        // Rotating the view by δ about z rotates the ellipse by δ: conic' = R P Rᵀ.
        let d = cheat_deg * (core::f32::consts::PI / 180.0);
        let (s, c) = (math::sin(d), math::cos(d));
        let p = conic;
        let rotated = Sym2 {
            xx: c * c * p.xx - 2.0 * c * s * p.xy + s * s * p.yy,
            xy: c * s * (p.xx - p.yy) + (c * c - s * s) * p.xy,
            yy: s * s * p.xx + 2.0 * c * s * p.xy + c * c * p.yy,
        };
        (theta, sx, sy, _) = attempt(&rotated);
        cheated = true;
    }
    if !(sx > 0.0 && sy > 0.0 && sx.is_finite() && sy.is_finite() && theta.is_finite()) {
        return Err(GeometryError::PaperSingular {
            theta_deg: theta * (180.0 / core::f32::consts::PI),
        });
    }
    let (s, c) = (math::sin(theta), math::cos(theta));
    // Tᵀ = diag(Sx, Sy)·R(θ)ᵀ.
    let to_unit = [[sx * c, sx * s], [-sy * s, sy * c]];
    Ok(PaperDecomposition {
        theta,
        scales: [sx, sy],
        to_unit,
        cheated,
    })
}
