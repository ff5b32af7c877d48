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
    /// A zoom factor that is not a positive finite number ([`View::from_vtk_camera`],
    /// [`View::looking`], [`View::from_angles`]).
    BadZoom {
        /// The value given.
        value: f32,
    },
    /// Nothing to fit: a zero volume dimension or image side ([`View::from_vtk_camera`],
    /// [`View::looking`], [`View::from_angles`]).
    EmptyFit,
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
            Self::BadZoom { value } => {
                write!(f, "zoom must be a positive finite number, got {value}")
            }
            Self::EmptyFit => f.write_str("cannot fit a view to a zero-sized volume or image"),
        }
    }
}

impl core::error::Error for GeometryError {}

pub(super) fn all_finite(m: &Mat3) -> bool {
    m.to_cols_array().iter().all(|v| v.is_finite())
}

/// |det m| ≥ 1e-6 × product of its column lengths (a scale-free test for a singular matrix).
pub(super) fn well_conditioned(m: &Mat3) -> bool {
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

    /// A turntable view, fitted to an image (the CLI's `--view` before it took VTK's camera, see
    /// [`View::from_vtk_camera`]; kept for library callers): rotation
    /// R = Rz(roll)·Rx(elevation)·Ry(azimuth) (degrees; azimuth turns the volume about the screen's
    /// vertical axis, elevation about its horizontal axis, roll about the view direction; all zero
    /// looks along +k with +i to the right and +j down), scaled so the volume's box (voxel centres
    /// ± half a voxel, `dims` voxels on `grid`) fills 90 % of the tighter image side, times `zoom`.
    /// The renderer centres the volume on the image.
    pub fn from_angles(
        [azimuth, elevation, roll]: [f32; 3],
        zoom: f32,
        dims: [usize; 3],
        grid: &Grid,
        image: [usize; 2],
    ) -> Result<Self, GeometryError> {
        if !(zoom.is_finite() && zoom > 0.0) {
            return Err(GeometryError::BadZoom { value: zoom });
        }
        if !(azimuth.is_finite() && elevation.is_finite() && roll.is_finite()) {
            return Err(GeometryError::NonFinite);
        }
        if dims.contains(&0) || image.contains(&0) {
            return Err(GeometryError::EmptyFit);
        }
        let rad = core::f32::consts::PI / 180.0;
        let r = Mat3::from_rotation_z(roll * rad)
            * Mat3::from_rotation_x(elevation * rad)
            * Mat3::from_rotation_y(azimuth * rad);
        let half = Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32) * 0.5;
        let mut ext = Vec3::ZERO;
        for corner in 0..8 {
            let c = Vec3::new(
                if corner & 1 == 0 { -half.x } else { half.x },
                if corner & 2 == 0 { -half.y } else { half.y },
                if corner & 4 == 0 { -half.z } else { half.z },
            );
            ext = ext.max((r * (grid.to_world * c)).abs());
        }
        let (w, h) = (image[0] as f32, image[1] as f32);
        let fit = 0.9 * (w / (2.0 * ext.x)).min(h / (2.0 * ext.y));
        View::new(r * (fit * zoom))
    }

    /// The view of VTK's and ParaView's camera, as the CLI's `--view AZ,EL,ROLL` builds it: the
    /// camera starts on +z looking toward −z with +y up (ParaView's default view), then
    /// `vtkCamera::Azimuth(azimuth)` turns its position about the view-up vector,
    /// `Elevation(elevation)` about its right axis (positive raises it toward view-up) and
    /// `Roll(roll)` turns view-up about the direction of projection (degrees, right-handed, as
    /// VTK's `RotateWXYZ`). As in VTK, Elevation keeps the original view-up, which the view then
    /// orthogonalises: past ±90° of elevation the picture stays upright (the camera flips over),
    /// and at exactly ±90° (where VTK's view is undefined) the up vector is the limit from below.
    /// See [`View::looking`] for the fit.
    pub fn from_vtk_camera(
        [azimuth, elevation, roll]: [f32; 3],
        zoom: f32,
        dims: [usize; 3],
        grid: &Grid,
        image: [usize; 2],
    ) -> Result<Self, GeometryError> {
        if !(azimuth.is_finite() && elevation.is_finite() && roll.is_finite()) {
            return Err(GeometryError::NonFinite);
        }
        let rad = core::f32::consts::PI / 180.0;
        let up0 = Vec3::Y;
        // Azimuth: the position (relative to the focal point) about view-up.
        let p1 = Mat3::from_axis_angle(up0, azimuth * rad) * Vec3::Z;
        // Elevation: about −right, right = dop × up with dop = −position.
        let right1 = (-p1).cross(up0).normalize();
        let turn = Mat3::from_axis_angle(-right1, elevation * rad);
        let dop = -(turn * p1);
        // VTK restores the original view-up; the view uses its part orthogonal to dop.
        let proj = up0 - dop * up0.dot(dop);
        let up = if proj.length() > 1e-4 {
            proj.normalize()
        } else {
            turn * up0
        };
        // Roll: view-up about the direction of projection.
        let up = Mat3::from_axis_angle(dop, roll * rad) * up;
        View::looking(dop, up, zoom, dims, grid, image)
    }

    /// The view looking along `direction` (world; into the screen) with `up` (world; need not be
    /// orthogonal to `direction`, only not parallel) pointing up on the image: screen x is
    /// direction × up (right), screen y is down, screen z is `direction`, as VTK's view transform
    /// builds them. The scale is VTK's `ResetCamera` for a parallel projection: the sphere
    /// around the bounds of the voxel centres (the axis-aligned box of the grid's corners, as VTK
    /// bounds an oriented image; radius 0.5 for a single voxel) fits the image's shorter side,
    /// i.e. `min(W, H) / (2 · radius)` pixels per world unit, times `zoom`.
    pub fn looking(
        direction: Vec3,
        up: Vec3,
        zoom: f32,
        dims: [usize; 3],
        grid: &Grid,
        image: [usize; 2],
    ) -> Result<Self, GeometryError> {
        if !(zoom.is_finite() && zoom > 0.0) {
            return Err(GeometryError::BadZoom { value: zoom });
        }
        if !(direction.is_finite() && up.is_finite()) {
            return Err(GeometryError::NonFinite);
        }
        if dims.contains(&0) || image.contains(&0) {
            return Err(GeometryError::EmptyFit);
        }
        let dop = direction.normalize_or_zero();
        let right = dop.cross(up).normalize_or_zero();
        if dop == Vec3::ZERO || right == Vec3::ZERO {
            return Err(GeometryError::SingularView);
        }
        let up = right.cross(dop);
        let radius = bounding_radius(dims, grid);
        let scale = image[0].min(image[1]) as f32 / (2.0 * radius) * zoom;
        View::new(Mat3::from_cols(right, -up, dop).transpose() * scale)
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

/// The eight corners of the voxel-centre box of a `dims` grid, in grid coordinates, widened by
/// `pad` grid steps on every side: corner c lies at the high end of axis a when bit a of c is set.
pub fn box_corners(dims: [usize; 3], pad: f32) -> [Vec3; 8] {
    core::array::from_fn(|c| {
        Vec3::from_array(core::array::from_fn(|a| {
            if c >> a & 1 == 0 {
                -pad
            } else {
                dims[a].saturating_sub(1) as f32 + pad
            }
        }))
    })
}

/// Half the diagonal of the voxel-centre box, world units: the axis-aligned world box of the grid's
/// corner voxels (as VTK bounds an oriented image), 0.5 for a single voxel. VTK's `ResetCamera`
/// fits the sphere of this radius: [`View::looking`] in parallel projection, the harness's
/// `--perspective` for the eye's distance. `dims` must be non-zero.
pub fn bounding_radius(dims: [usize; 3], grid: &Grid) -> f32 {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for c in box_corners(dims, 0.0) {
        let w = grid.to_world * c;
        lo = lo.min(w);
        hi = hi.max(w);
    }
    let diameter = (hi - lo).length();
    if diameter > 0.0 {
        0.5 * diameter
    } else {
        0.5
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

mod ellipse;
mod mat2;
mod paper;
mod perspective;
mod sampler;

pub use ellipse::{conic_of, covariance, Footprint};
pub(crate) use mat2::mul2;
pub use mat2::{Mat2, Sym2};
pub use paper::{
    paper_decomposition, PaperDecomposition, PAPER_MAX_CHEAT_DEG, PAPER_ROUND_CONIC,
    PAPER_SINGULAR_COS2,
};
pub use perspective::{Perspective, Projected};
pub use sampler::Sampler;
