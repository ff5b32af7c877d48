//! Perspective projection (the paper's first enhancement): every voxel gets its own screen
//! position and its own footprint, from the local affine approximation (the Jacobian) of the
//! projection at the voxel.
//!
//! # Camera
//! A pinhole with its eye on the view axis through the volume's centre, `eye_distance` world units
//! in front of it, looking at it. Screen coordinates extend the orthographic ones of
//! [`super::View`]: with s the view's scale (pixels per world unit) and `p` a point's *affine*
//! screen position (what the orthographic frame gives it: x, y in pixels with the volume's centre
//! at the image centre c, z in pixels along the view, 0 at the centre), the eye sits at affine
//! position (c, −f), f = s·D pixels (the focal length), and the point projects to
//!
//! ```text
//! screen = c + f·(p.xy − c) / Z,   Z = f + p.z   (the point's depth in front of the eye, px at scale s)
//! ```
//!
//! so points at the centre's depth keep their orthographic position and size, nearer ones grow.
//!
//! # The local affine map
//! With `p` affine in the grid index i (p = origin + V·G·i), the Jacobian of the projection is
//!
//! ```text
//! d screen / d i = (f/Z) · (VG_xy − (q/Z) ⊗ VG_z),   q = p.xy − c,
//! ```
//!
//! a 2×3 map whose null vector is the ray through the point, so a kernel's footprint under it is
//! the orthographic construction of [`super::Footprint`] with N = (that map)·R. Its third row here
//! is (f/Z)·VG_z (the depth row, which only needs to keep the matrix regular).

use glam::{Mat3, Vec3};

/// A pinhole camera in the frame's screen units (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perspective {
    /// Distance from the eye to the volume's centre, world units.
    pub eye_distance: f32,
    /// Focal length f = s·D, pixels.
    pub focal_px: f32,
    /// The image centre c, pixels (where the view axis meets the image).
    pub centre: [f32; 2],
}

/// A point as the camera sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projected {
    /// Screen position, pixels.
    pub center: [f32; 2],
    /// d screen / d grid index (rows x, y; row z their normal, see the module docs), pixels per
    /// grid step.
    pub jacobian: Mat3,
    /// The ray from the eye to the point, in affine screen units: (q, Z).
    pub ray: Vec3,
}

impl Perspective {
    /// Projects the point at affine screen position `p` (see the module docs) for a frame whose
    /// grid-to-screen map is `grid_to_screen` = V·G. `None` if the point is not in front of the
    /// eye (Z ≤ 0) or the result is not finite.
    #[inline]
    pub fn project(&self, p: Vec3, grid_to_screen: &Mat3) -> Option<Projected> {
        let f = self.focal_px;
        let z = f + p.z;
        if !(z > 0.0) {
            return None;
        }
        let k = f / z;
        let q = [p.x - self.centre[0], p.y - self.centre[1]];
        let (qx, qy) = (q[0] / z, q[1] / z);
        let g = grid_to_screen;
        let row = |r: usize, q: f32| (g.row(r) - g.row(2) * q) * k;
        let (rx, ry) = (row(0, qx), row(1, qy));
        // The third row only keeps the matrix regular: the normal of the first two, at their
        // scale (a row along VG_z would be nearly parallel to them for grazing rays).
        let n = rx.cross(ry);
        let rz = n * (0.5 * (rx.length() + ry.length()) / n.length());
        let jacobian = Mat3::from_cols(rx, ry, rz).transpose();
        let center = [self.centre[0] + k * q[0], self.centre[1] + k * q[1]];
        (center[0].is_finite() && center[1].is_finite()).then_some(Projected {
            center,
            jacobian,
            ray: Vec3::new(q[0], q[1], z),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Jacobian matches central differences of the projection.
    #[test]
    fn jacobian_matches_finite_differences() {
        let g2s = Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(-0.4) * 3.0;
        let cam = Perspective {
            eye_distance: 80.0,
            focal_px: 240.0,
            centre: [100.0, 90.0],
        };
        let origin = Vec3::new(20.0, 170.0, -35.0);
        for i in [[0.0f32, 0.0, 0.0], [10.0, 3.0, 7.0], [40.0, 50.0, 12.0]] {
            let i = Vec3::from_array(i);
            let at = |i: Vec3| cam.project(origin + g2s * i, &g2s).unwrap();
            let j = at(i).jacobian;
            for (axis, col) in [j.x_axis, j.y_axis, j.z_axis].into_iter().enumerate() {
                let mut e = Vec3::ZERO;
                e[axis] = 1e-2;
                let (a, b) = (at(i + e).center, at(i - e).center);
                let d = [(a[0] - b[0]) / 2e-2, (a[1] - b[1]) / 2e-2];
                assert!(
                    (d[0] - col.x).abs() < 2e-3 * col.length().max(1.0),
                    "{d:?} {col}"
                );
                assert!(
                    (d[1] - col.y).abs() < 2e-3 * col.length().max(1.0),
                    "{d:?} {col}"
                );
            }
        }
    }

    /// Behind the eye: refused.
    #[test]
    fn behind_the_eye_is_none() {
        let cam = Perspective {
            eye_distance: 10.0,
            focal_px: 100.0,
            centre: [0.0, 0.0],
        };
        assert!(cam
            .project(Vec3::new(0.0, 0.0, -100.0), &Mat3::IDENTITY)
            .is_none());
        assert!(cam
            .project(Vec3::new(0.0, 0.0, -99.0), &Mat3::IDENTITY)
            .is_some());
    }
}
