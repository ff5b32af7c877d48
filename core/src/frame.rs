//! Per-frame set-up: where every voxel lands on screen, which grid axis the sheets run along and
//! in which order, the footprint of this view, and the buffer sizes the caller must supply.
//!
//! # Placement
//! Voxel (i, j, k) of a volume with `dims` voxels lands at screen position
//! `V·G·((i, j, k) − c) + (W/2, H/2, 0)` pixels, c = (dims − 1)/2: the volume's centre sits at the
//! image centre. (The single-sample convention of the `splat` command is the case c = voxel.)
//!
//! # Sheets
//! A sheet is the set of voxels with one index along the *sheet axis*, the grid axis whose sheets are
//! most parallel to the image plane ([`crate::geometry::sheet_axis`]). A sheet's samples are stored
//! row-major over its two in-sheet axes (a, b), a < b: `sheet[v·dims[a] + u]` is the voxel with
//! index u along a and v along b. For sheet axis k (z) that is exactly a z-slice of an x-fastest file.

use crate::geometry::{
    box_corners, in_sheet_axes, Footprint, FootprintOptions, GeometryError, Grid, Perspective, View,
};
use crate::kernel::Kernel;
use crate::math;
use glam::{Mat3, Vec3};

/// How the frame projects: orthographic (the paper's main case) or a pinhole
/// ([`FrameSetup::perspective`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Parallel rays along screen z: one footprint for every voxel ([`FrameSetup::footprint`]).
    Orthographic,
    /// Rays from an eye: every voxel has its own footprint (see [`crate::geometry::Perspective`]).
    Perspective(Perspective),
}

/// The compositing direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// Farthest sheet first, each composited *over* the working image (the paper's order).
    BackToFront,
    /// Nearest sheet first, each composited *under* the working image.
    FrontToBack,
}

/// Everything about one view of one volume that stays fixed while its sheets are rendered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSetup {
    /// Voxels along i, j, k.
    pub dims: [usize; 3],
    /// Image width and height, pixels.
    pub size: [usize; 2],
    /// V·G: grid steps to screen offsets, pixels.
    pub grid_to_screen: Mat3,
    /// Screen position (pixels, absolute; z in pixels along the view) of voxel (0, 0, 0).
    pub origin: Vec3,
    /// Sheet axis (0 = i, 1 = j, 2 = k).
    pub sheet_axis: usize,
    /// The two in-sheet axes (a, b), a < b.
    pub in_sheet: (usize, usize),
    /// The view's footprint.
    pub footprint: Footprint,
    /// Screen area of one sheet cell, px²: |det| of the in-sheet axes' screen images. Splatted
    /// values are multiplied by it so that a flat sheet accumulates to its value.
    pub cell_area: f32,
    /// Distance between consecutive sheets along a view ray, world units.
    pub sheet_distance: f32,
    /// The distance a transfer function's opacity refers to, world units: always 1 (opacity per
    /// unit length), so that resampling a volume along the view changes nothing.
    pub reference_distance: f32,
    /// Whether increasing sheet index moves away from the viewer (screen z grows).
    pub ascending_recedes: bool,
    /// G⁻ᵀ, for world-space gradients from grid-space differences.
    pub grid_inverse_transpose: Mat3,
    /// Unit vector toward the viewer (and the head-light), world coordinates.
    pub to_viewer_world: Vec3,
    /// Each grid axis's world spacing (column lengths of G).
    pub spacing: [f32; 3],
    /// Orthographic or perspective. For a perspective frame, `grid_to_screen`, `origin`,
    /// `footprint`, `cell_area` and `sheet_distance` describe the affine approximation at the
    /// volume's centre (exact there); per-voxel values come from
    /// [`crate::geometry::Perspective::project`].
    pub projection: Projection,
}

/// Why a frame could not be set up.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum FrameError {
    /// A dimension is zero, or their product overflows.
    BadDims {
        /// The dimensions given.
        dims: [usize; 3],
    },
    /// Image width or height is zero or above [`crate::splat::MAX_IMAGE_SIDE`].
    BadImageSize {
        /// Width, height.
        size: [usize; 2],
    },
    /// The view or grid is unusable.
    Geometry(GeometryError),
    /// A perspective eye distance that is not a positive finite number (world units).
    BadEyeDistance {
        /// The distance given.
        value: f32,
    },
    /// A perspective view whose matrix is not a rotation times one scale (shear or unequal
    /// scales have no pinhole meaning).
    NotARotation,
    /// The eye lies inside the volume, or so near it that a voxel's kernel reaches behind the eye
    /// or to within 1/1000 of the eye's distance from the volume's centre.
    EyeInsideVolume {
        /// The eye's distance from the volume's centre, world units.
        eye_distance: f32,
    },
    /// The eye lies between the first and last sheet (within a kernel radius), so no order of
    /// the sheets runs from far to near: seen from there, sheets along this axis face the eye
    /// edge-on. Move the eye farther away or narrow the field of view.
    EyeAmongSheets {
        /// The sheet axis (0 = i, 1 = j, 2 = k).
        axis: usize,
        /// The eye's grid coordinate along it.
        eye_index: f32,
        /// Sheets along it.
        sheets: usize,
    },
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::BadDims { dims } => write!(f, "volume dimensions {dims:?} are zero or too large"),
            Self::BadImageSize { size } => {
                write!(f, "image size {}x{} is not usable", size[0], size[1])
            }
            Self::Geometry(e) => e.fmt(f),
            Self::BadEyeDistance { value } => {
                write!(f, "eye distance {value} is not a positive finite number")
            }
            Self::NotARotation => f.write_str(
                "a perspective view must be a rotation times one scale (no shear, equal scales)",
            ),
            Self::EyeInsideVolume { eye_distance } => write!(
                f,
                "the eye, {eye_distance} world units from the volume's centre, is inside the \
                 volume or within a kernel radius of it: move it farther away"
            ),
            Self::EyeAmongSheets {
                axis,
                eye_index,
                sheets,
            } => write!(
                f,
                "the eye lies among the sheets along {} (at index {eye_index:.1} of 0..{sheets}, \
                 within a kernel radius), so they have no far-to-near order: move the eye \
                 farther away or narrow the field of view",
                ["i", "j", "k"][(*axis).min(2)]
            ),
        }
    }
}

impl core::error::Error for FrameError {}

impl From<GeometryError> for FrameError {
    fn from(e: GeometryError) -> Self {
        FrameError::Geometry(e)
    }
}

impl FrameSetup {
    /// Sets up a frame: `dims` voxels on `grid`, seen through `view`, into a `size[0] × size[1]`
    /// image, reconstructed with `kernel`.
    pub fn new(
        dims: [usize; 3],
        grid: &Grid,
        view: &View,
        kernel: &Kernel,
        options: FootprintOptions,
        size: [usize; 2],
    ) -> Result<Self, FrameError> {
        let count = dims.iter().try_fold(1usize, |acc, &d| acc.checked_mul(d));
        if dims.contains(&0) || count.is_none() || dims.iter().any(|&d| d > (1 << 24)) {
            return Err(FrameError::BadDims { dims });
        }
        if size
            .iter()
            .any(|&s| s == 0 || s > crate::splat::MAX_IMAGE_SIDE)
        {
            return Err(FrameError::BadImageSize { size });
        }
        let g2s = view.grid_to_screen(grid);
        let footprint = Footprint::new(kernel, &g2s, options)?;
        let k = footprint.sheet_axis;
        let (a, b) = in_sheet_axes(k);
        let col = |c: usize| g2s.col(c);
        let cell_area = math::abs(col(a).x * col(b).y - col(a).y * col(b).x);
        let centre = Vec3::new(
            dims[0] as f32 - 1.0,
            dims[1] as f32 - 1.0,
            dims[2] as f32 - 1.0,
        ) * 0.5;
        let origin = Vec3::new(size[0] as f32 * 0.5, size[1] as f32 * 0.5, 0.0) - g2s * centre;
        let g = grid.to_world();
        // A view ray's world direction is V⁻¹e_z; in grid steps, (VG)⁻¹e_z. One sheet step along
        // it (Δk = 1) covers world length |G d| / |d_k| with d = (VG)⁻¹e_z.
        let d = g2s.inverse() * Vec3::Z;
        let dw = g * d;
        let sheet_distance = dw.length() / math::abs(d[k]);
        let spacing = [g.x_axis.length(), g.y_axis.length(), g.z_axis.length()];
        let reference_distance = 1.0;
        let to_viewer_world = -(dw / dw.length());
        Ok(FrameSetup {
            dims,
            size,
            grid_to_screen: g2s,
            origin,
            sheet_axis: k,
            in_sheet: (a, b),
            footprint,
            cell_area,
            sheet_distance,
            reference_distance,
            ascending_recedes: col(k).z > 0.0,
            grid_inverse_transpose: g.inverse().transpose(),
            to_viewer_world,
            spacing,
            projection: Projection::Orthographic,
        })
    }

    /// A perspective frame: a pinhole on the view axis, `eye_distance` world units from the
    /// volume's centre, looking at it through `view` (a rotation times a scale s, pixels per world
    /// unit at the centre's depth; focal length s·`eye_distance` pixels). The sheets run along the
    /// axis most parallel to the image plane (as orthographic) and in far-to-near order from the
    /// eye. Refused when the eye is inside the volume, within a kernel radius of a voxel, or among
    /// the sheets (see [`FrameError`]).
    pub fn perspective(
        dims: [usize; 3],
        grid: &Grid,
        view: &View,
        kernel: &Kernel,
        options: FootprintOptions,
        size: [usize; 2],
        eye_distance: f32,
    ) -> Result<Self, FrameError> {
        if !(eye_distance.is_finite() && eye_distance > 0.0) {
            return Err(FrameError::BadEyeDistance {
                value: eye_distance,
            });
        }
        let v = view.to_screen();
        let rows = [v.row(0), v.row(1), v.row(2)];
        let s = rows[0].length();
        let tol = 1e-4 * s * s;
        let orthogonal = (0..3).all(|i| {
            (0..3).all(|j| {
                let want = if i == j { s * s } else { 0.0 };
                math::abs(rows[i].dot(rows[j]) - want) <= tol
            })
        });
        if !orthogonal || !(s > 0.0) {
            return Err(FrameError::NotARotation);
        }
        let mut frame = Self::new(dims, grid, view, kernel, options, size)?;
        let focal_px = s * eye_distance;
        let camera = Perspective {
            eye_distance,
            focal_px,
            centre: [size[0] as f32 * 0.5, size[1] as f32 * 0.5],
        };
        if !focal_px.is_finite() {
            return Err(FrameError::BadEyeDistance {
                value: eye_distance,
            });
        }
        // The kernel's support around the voxel-centre box, in grid steps: its corners must all
        // lie in front of the eye (the box is convex, so then every kernel does).
        let r = kernel.spread();
        let g2s = frame.grid_to_screen;
        for c in box_corners(dims, r) {
            let p = frame.origin + g2s * c;
            // In front of the eye by at least 1/1000 of its distance to the centre, so no
            // footprint is magnified past a thousand times its size there.
            if !(focal_px + p.z >= 1e-3 * focal_px) {
                return Err(FrameError::EyeInsideVolume { eye_distance });
            }
        }
        // The eye in grid coordinates: affine screen position (c, −f).
        let k = frame.sheet_axis;
        let eye = g2s.inverse()
            * (Vec3::new(camera.centre[0], camera.centre[1], -focal_px) - frame.origin);
        let last = (dims[k] - 1) as f32;
        if !(eye[k] <= -r || eye[k] >= last + r) {
            return Err(FrameError::EyeAmongSheets {
                axis: k,
                eye_index: eye[k],
                sheets: dims[k],
            });
        }
        // Far to near: away from the eye's side.
        frame.ascending_recedes = eye[k] < 0.0;
        frame.projection = Projection::Perspective(camera);
        Ok(frame)
    }

    /// The camera of a perspective frame (`None` if orthographic).
    pub fn camera(&self) -> Option<&Perspective> {
        match &self.projection {
            Projection::Perspective(c) => Some(c),
            Projection::Orthographic => None,
        }
    }

    /// Affine screen position of grid point (i, j, k) (see [`crate::geometry::Perspective`]; for an
    /// orthographic frame, the screen position itself, z along the view).
    #[inline]
    pub fn affine_position(&self, index: [f32; 3]) -> Vec3 {
        self.origin + self.grid_to_screen * Vec3::from_array(index)
    }

    /// Screen positions (px, and depth) of the volume's eight corner voxel centres, by the
    /// affine map ([`FrameSetup::affine_position`]): corner `c` takes the last index on axis `i`
    /// where bit `i` of `c` is set. The fixed-point placements check their range on these.
    pub fn voxel_corners(&self) -> [Vec3; 8] {
        let last = self.dims.map(|n| n.saturating_sub(1) as f32);
        core::array::from_fn(|corner| {
            let index = core::array::from_fn(|axis| {
                if corner & (1 << axis) != 0 {
                    last[axis]
                } else {
                    0.0
                }
            });
            self.affine_position(index)
        })
    }

    /// Number of sheets (voxels along the sheet axis).
    pub fn sheet_count(&self) -> usize {
        self.dims[self.sheet_axis]
    }

    /// Samples per sheet, and the sheet's row length (voxels along axis a) and row count (along b).
    pub fn sheet_shape(&self) -> (usize, usize, usize) {
        let (a, b) = self.in_sheet;
        (self.dims[a] * self.dims[b], self.dims[a], self.dims[b])
    }

    /// Pixels in the image (the length of the working image, the sheet accumulator, and any
    /// background the caller supplies): width × height.
    pub fn image_len(&self) -> usize {
        self.size[0] * self.size[1]
    }

    /// Whether sheets must arrive in ascending index order for `order` (else descending).
    pub fn ascending_for(&self, order: Order) -> bool {
        match order {
            Order::FrontToBack => self.ascending_recedes,
            Order::BackToFront => !self.ascending_recedes,
        }
    }

    /// The compositing order that a source delivering sheets in ascending index order (file order,
    /// for sheet axis k) must use.
    pub fn order_for_ascending(&self) -> Order {
        if self.ascending_recedes {
            Order::FrontToBack
        } else {
            Order::BackToFront
        }
    }

    /// The sheet index at position `n` of the sequence for `order`.
    pub fn sheet_at(&self, order: Order, n: usize) -> usize {
        if self.ascending_for(order) {
            n
        } else {
            self.sheet_count() - 1 - n
        }
    }

    /// Grid index of the voxel at (u, v) of sheet `s`.
    pub fn grid_index(&self, s: usize, u: usize, v: usize) -> [usize; 3] {
        let mut idx = [0; 3];
        idx[self.sheet_axis] = s;
        idx[self.in_sheet.0] = u;
        idx[self.in_sheet.1] = v;
        idx
    }
}
