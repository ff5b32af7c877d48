//! The f64 reference for perspective frames: every voxel's weight at a pixel is the exact
//! integral of its kernel along that pixel's own ray from the eye (no affine approximation), so
//! `verify` measures the core's per-voxel affine footprints
//! ([`footprint::render::PerVoxel`]).
//!
//! In the frame's affine screen units (see [`footprint::geometry::Perspective`]) the eye is the
//! origin and the ray through pixel centre (X, Y) runs along d = (X − cₓ, Y − c_y, f)/|…|. With
//! M = R·V·G (kernel unit coordinates → affine screen units) and the voxel at P = (q, Z), the ray
//! is the line u(t) = M⁻¹(t·d − P) in unit coordinates; its distance ρ from the origin and its
//! chord give `∫h dt = chord(ρ) / |M⁻¹d|`. A voxel's weight there is
//!
//! ```text
//! W = ∫h dt · |n·d| / (|det M| · ∫_ball h),   n = V·G·e_a × V·G·e_b  (the sheet cell),
//! ```
//!
//! the kernel's share of the ray times the sheet cell's area across the ray, so a flat sheet sums
//! to one at every pixel whatever the ray's direction (the orthographic reference is the case
//! d = e_z). The opacity is corrected per voxel for the distance between sheets along its central
//! ray, exactly as the core does (that is part of the model both render, not the approximation
//! under test). Footprints clamped to the minimum radius, small renormalised ones (renormalised
//! here to the voxel's cell area) and the 2D kernel models (cone, sinc, bilinear: footprint models,
//! not 3D kernels) are evaluated as the core defines them, from the voxel's own affine map, in f64.

use super::{gaussian_chord, integral_f64, ReferenceFootprint, ReferenceMode};
use footprint::frame::FrameSetup;
use footprint::geometry::{GeometryError, Perspective};
use footprint::Kernel;
use glam::{DMat3, DVec3};

/// One voxel of a perspective frame, as the reference evaluates it.
pub struct PerspectiveVoxel {
    /// Screen position, pixels.
    pub center: [f64; 2],
    /// The sheet cell's screen area under the voxel's affine map, px².
    pub area: f64,
    /// The opacity exponent Δ/Δ₀ (distance between sheets along the voxel's ray over the central
    /// ray's).
    pub exponent: f64,
    affine: ReferenceFootprint,
    exact: Option<Exact>,
}

struct Exact {
    sigmas: f64,
    m_inv: DMat3,
    /// −M⁻¹P: the voxel's centre seen from the eye, in unit coordinates (relative, negated).
    p_unit: DVec3,
    normal: DVec3,
    norm: f64,
    focal: f64,
    centre: [f64; 2],
    /// Half-extents of the box searched for pixels, px.
    reach: [f64; 2],
}

impl PerspectiveVoxel {
    /// Sets up grid point `index` of `frame` (seen by `camera`) for `kernel`.
    pub fn new(
        frame: &FrameSetup,
        camera: &Perspective,
        kernel: &Kernel,
        min_radius_px: f64,
        index: [f64; 3],
    ) -> Result<Self, GeometryError> {
        let g2s = frame.grid_to_screen.as_dmat3();
        let p = frame.origin.as_dvec3() + g2s * DVec3::from_array(index);
        let f = f64::from(camera.focal_px);
        let c = camera.centre.map(f64::from);
        let z = f + p.z;
        if !(z > 0.0) {
            return Err(GeometryError::NonFinite);
        }
        let k = f / z;
        let q = [p.x - c[0], p.y - c[1]];
        let col = |v: DVec3| {
            DVec3::new(
                k * (v.x - q[0] / z * v.z),
                k * (v.y - q[1] / z * v.z),
                k * v.z,
            )
        };
        let jac = DMat3::from_cols(col(g2s.x_axis), col(g2s.y_axis), col(g2s.z_axis));
        let affine =
            ReferenceFootprint::with_sheet_axis(kernel, &jac, min_radius_px, frame.sheet_axis)?;
        let (a, b) = frame.in_sheet;
        let (ja, jb) = (jac.col(a), jac.col(b));
        let area = (ja.x * jb.y - ja.y * jb.x).abs();
        let ray = DVec3::new(q[0], q[1], z);
        let inv_k = g2s.inverse().row(frame.sheet_axis);
        let exponent = ray.length() * inv_k.z.abs() / inv_k.dot(ray).abs();
        let center = [c[0] + k * q[0], c[1] + k * q[1]];
        let exact = match (*kernel, affine.mode()) {
            (Kernel::Gaussian { sigmas, .. }, ReferenceMode::LineIntegral3d) => {
                let m = g2s * f64::from(kernel.spread());
                let m_inv = m.inverse();
                let h = affine.half_extent;
                let grow = |e: f64| 1.25 * e + 2.0 + 2.0 * e * e / f;
                Some(Exact {
                    sigmas: f64::from(sigmas),
                    m_inv,
                    p_unit: m_inv * ray,
                    normal: g2s.col(a).cross(g2s.col(b)),
                    norm: 1.0 / (m.determinant().abs() * integral_f64(kernel)),
                    focal: f,
                    centre: c,
                    reach: [grow(h[0]), grow(h[1])],
                })
            }
            _ => None,
        };
        Ok(PerspectiveVoxel {
            center,
            area,
            exponent,
            affine,
            exact,
        })
    }

    /// Whether the weights are exact ray integrals (else the affine model, see the module docs).
    pub fn is_exact(&self) -> bool {
        self.exact.is_some()
    }

    /// The weight × cell share W at pixel (x, y) (exact mode only; 0 elsewhere).
    fn exact_weight(e: &Exact, x: i64, y: i64) -> f64 {
        let d = DVec3::new(
            x as f64 + 0.5 - e.centre[0],
            y as f64 + 0.5 - e.centre[1],
            e.focal,
        )
        .normalize();
        let u = e.m_inv * d;
        let uu = u.length_squared();
        let pu = e.p_unit.dot(u);
        let rho2 = e.p_unit.length_squared() - pu * pu / uu;
        if rho2 >= 1.0 {
            return 0.0;
        }
        gaussian_chord(rho2.max(0.0), e.sigmas) / uu.sqrt() * e.normal.dot(d).abs() * e.norm
    }

    /// Calls `f(pixel index, W)` for every pixel of rows `rows` of a `width`-wide image that the
    /// voxel reaches, W the weight × cell share (a flat sheet sums to one), renormalised as the
    /// core renormalises small footprints.
    pub fn for_each_weight(
        &self,
        width: usize,
        rows: std::ops::Range<usize>,
        mut f: impl FnMut(usize, f64),
    ) {
        let Some(e) = &self.exact else {
            let area = self.area;
            self.affine
                .for_each_weight(self.center, width, rows, |i, w| f(i, w * area));
            return;
        };
        let span = |c: f64, r: f64| ((c - r - 0.5).ceil() as i64, (c + r - 0.5).floor() as i64);
        let (x0, x1) = span(self.center[0], e.reach[0]);
        let (y0, y1) = span(self.center[1], e.reach[1]);
        let mut factor = 1.0;
        if self.affine.renormalise {
            let mut sum = 0.0;
            for y in y0..=y1 {
                for x in x0..=x1 {
                    sum += Self::exact_weight(e, x, y);
                }
            }
            if sum > 0.0 {
                factor = self.area / sum;
            }
        }
        for y in y0.max(rows.start as i64)..=y1.min(rows.end as i64 - 1) {
            for x in x0.max(0)..=x1.min(width as i64 - 1) {
                let w = Self::exact_weight(e, x, y);
                if w != 0.0 {
                    f(y as usize * width + x as usize, w * factor);
                }
            }
        }
    }

    /// The search box's half-extents, px (for tests: no weight lies outside it).
    pub fn reach(&self) -> Option<[f64; 2]> {
        self.exact.as_ref().map(|e| e.reach)
    }

    /// W at pixel (x, y), exact mode (for tests).
    pub fn weight_at(&self, x: i64, y: i64) -> Option<f64> {
        self.exact.as_ref().map(|e| Self::exact_weight(e, x, y))
    }
}
