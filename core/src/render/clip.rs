//! Clipping planes (`--clip`): the half-spaces of screen space a frame keeps, and how a kernel that
//! straddles one is cut.
//!
//! # The cut model
//! Planes are given in the frame's screen space (x, y in pixels, z in pixels of depth along the
//! view, growing away from the viewer, as [`FrameSetup::grid_to_screen`] maps the grid): plane
//! `(a, b, c, d)` keeps the points with `a·x + b·y + c·z ≤ d`. The continuous field is multiplied
//! by the indicator of the kept region K (every plane's half-space), so along a pixel's ray the
//! field is integrated over K's chord only: one interval of depth [z_lo, z_hi], since K is convex
//! ([`ClipPlanes::depths`]).
//!
//! # Cutting a kernel
//! A voxel whose kernel lies inside every half-space is splatted as without planes (bit for bit);
//! one whose kernel lies outside any is skipped; one that straddles a plane has each pixel's
//! section cut to the ray's kept interval: the slab renderer reads the kernel's depth integral
//! at max(t_a, t_lo) and min(t_b, t_hi) instead of at the slab's ends t_a, t_b (chord units), so
//! the kernel is cut exactly where the plane crosses each ray, to the section table's accuracy.
//! Which kernels straddle is decided from the kernel's support in screen space, the image of a
//! ball of R grid steps under M = `grid_to_screen`: its reach along a plane's normal n is
//! R·|Mᵀn| (the support function of an ellipsoid), so the test is exact, not a bounding box.
//!
//! Orthographic frames only (a perspective ray's depth is not screen z); at most
//! [`MAX_CLIP_PLANES`] planes.

use crate::frame::FrameSetup;
use core::fmt;

/// The most planes a frame may be clipped by.
pub const MAX_CLIP_PLANES: usize = 8;

/// Why a set of planes cannot clip a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ClipError {
    /// More than [`MAX_CLIP_PLANES`] planes.
    TooMany {
        /// Planes given.
        count: usize,
    },
    /// A plane's normal is zero or not finite, or its offset is not finite (the plane's index).
    BadPlane {
        /// Which plane, from 0.
        index: usize,
    },
    /// The frame is a perspective one.
    Perspective,
}

impl fmt::Display for ClipError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ClipError::TooMany { count } => write!(
                f,
                "{count} clipping planes: at most {MAX_CLIP_PLANES} clip one frame"
            ),
            ClipError::BadPlane { index } => write!(
                f,
                "clipping plane {index}: its normal must be finite and not zero, its offset finite"
            ),
            ClipError::Perspective => write!(
                f,
                "clipping planes cut orthographic frames only (a perspective ray's depth is not \
                 screen z)"
            ),
        }
    }
}

impl core::error::Error for ClipError {}

/// Where a kernel lies against the planes ([`ClipPlanes::side`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClipSide {
    /// Wholly inside every half-space: splatted as without planes.
    Inside,
    /// Wholly outside one half-space at least: nothing of it is kept.
    Outside,
    /// Crossed by a plane: each pixel's section is cut ([`ClipPlanes::depths`]).
    Straddles,
}

/// Up to [`MAX_CLIP_PLANES`] planes in a frame's screen space, with each plane's reach of a
/// kernel (no allocation: the planes are held inline).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipPlanes {
    /// a, b, c, d (a·x + b·y + c·z ≤ d kept) and the kernel's reach R·|Mᵀn| along (a, b, c).
    planes: [[f32; 5]; MAX_CLIP_PLANES],
    count: usize,
}

impl ClipPlanes {
    /// `planes` (each `[a, b, c, d]`, screen pixels: a·x + b·y + c·z ≤ d kept) for `frame`, whose
    /// kernels reach `radius` grid steps from their centres (a Gaussian's truncation radius,
    /// [`crate::Kernel::spread`]).
    pub fn new(frame: &FrameSetup, radius: f32, planes: &[[f32; 4]]) -> Result<Self, ClipError> {
        if planes.is_empty() {
            return Ok(ClipPlanes {
                planes: [[0.0; 5]; MAX_CLIP_PLANES],
                count: 0,
            });
        }
        if frame.camera().is_some() {
            return Err(ClipError::Perspective);
        }
        if planes.len() > MAX_CLIP_PLANES {
            return Err(ClipError::TooMany {
                count: planes.len(),
            });
        }
        let mut out = [[0.0f32; 5]; MAX_CLIP_PLANES];
        let mt = frame.grid_to_screen.transpose();
        for (index, (p, o)) in planes.iter().zip(out.iter_mut()).enumerate() {
            let n = glam::Vec3::new(p[0], p[1], p[2]);
            let reach = radius * (mt * n).length();
            if !(n.length_squared() > 0.0 && n.is_finite() && p[3].is_finite() && reach.is_finite())
            {
                return Err(ClipError::BadPlane { index });
            }
            *o = [p[0], p[1], p[2], p[3], reach];
        }
        Ok(ClipPlanes {
            planes: out,
            count: planes.len(),
        })
    }

    /// The planes, `[a, b, c, d, reach]` each.
    fn planes(&self) -> &[[f32; 5]] {
        &self.planes[..self.count]
    }

    /// Whether there is no plane (everything kept).
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Where the kernel centred at screen point `c` (x, y, z pixels) lies against the planes.
    #[inline]
    pub fn side(&self, c: [f32; 3]) -> ClipSide {
        let mut side = ClipSide::Inside;
        for &[a, b, cz, d, reach] in self.planes() {
            let f = a * c[0] + b * c[1] + cz * c[2] - d;
            if f - reach > 0.0 {
                return ClipSide::Outside;
            }
            if f + reach > 0.0 {
                side = ClipSide::Straddles;
            }
        }
        side
    }

    /// The screen depths [z_lo, z_hi] the planes keep on the ray through screen point (x, y):
    /// (−∞, +∞) with no plane; z_lo ≥ z_hi when the ray keeps nothing (a plane parallel to the
    /// ray with the ray outside it gives (+∞, −∞)).
    #[inline]
    pub fn depths(&self, x: f32, y: f32) -> (f32, f32) {
        let (mut lo, mut hi) = (f32::NEG_INFINITY, f32::INFINITY);
        for &[a, b, c, d, _] in self.planes() {
            let rest = d - a * x - b * y;
            if c > 0.0 {
                hi = hi.min(rest / c);
            } else if c < 0.0 {
                lo = lo.max(rest / c);
            } else if rest < 0.0 {
                return (f32::INFINITY, f32::NEG_INFINITY);
            }
        }
        (lo, hi)
    }
}
