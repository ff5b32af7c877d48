//! The f64 reference footprint: no tables, every pixel's weight computed from the kernel itself.
//!
//! For an unclamped Gaussian the weight is the literal line integral of the 3D kernel along the
//! pixel's view ray, found through M⁻¹ (M = R·V·G): the ray `(q, z)` maps to the line
//! `u(z) = M⁻¹(q, 0) + z·M⁻¹e_z` in unit coordinates; its distance ρ from the origin and its chord
//! through the unit ball give the integral in closed form,
//! `∫h dz = e^(−ρ²/2σ²)·σ√(2π)·erf(√(1−ρ²)/(σ√2)) / |M⁻¹e_z|`, divided by `|det M|·∫_ball h` so the
//! footprint integrates to one over the screen. This shares nothing with the core's 2D ellipse
//! code, so agreement checks the geometry as well as the tables.
//!
//! The 2D models (cone, sinc, bilinear) and footprints whose semi-axes were lengthened to the
//! minimum radius are defined by their 2D map, so for them the reference evaluates the model
//! exactly (f64) at the mapped point. Small footprints are renormalised to sum to one, as in the
//! core: that is part of the model, not an approximation.

pub mod continuous;
pub mod field;
pub mod perspective;
mod projection;
pub mod render;
mod sparse;
pub mod warp;

use footprint::geometry::{in_sheet_axes, sheet_axis, RENORMALISE_BELOW_PX};
use footprint::{GeometryError, Kernel};
use glam::{DMat3, DVec3};
use std::f64::consts::PI;

/// The kernel's unnormalised footprint F(u) in f64 (see `footprint::kernel` for the formulas).
pub fn footprint_f64(kernel: &Kernel, u: [f64; 2]) -> f64 {
    let rho2 = u[0] * u[0] + u[1] * u[1];
    match *kernel {
        Kernel::Bilinear { .. } => {
            let (a, b) = (u[0].abs(), u[1].abs());
            if a >= 1.0 || b >= 1.0 {
                0.0
            } else {
                (1.0 - a) * (1.0 - b)
            }
        }
        _ if rho2 >= 1.0 => 0.0,
        Kernel::Gaussian { sigmas, .. } => gaussian_chord(rho2, f64::from(sigmas)),
        Kernel::Cone { .. } => 1.0 - rho2.sqrt(),
        Kernel::Sinc { lobes, .. } => {
            let x = PI * f64::from(lobes) * rho2.sqrt();
            if x == 0.0 {
                1.0
            } else {
                x.sin() / x
            }
        }
    }
}

/// ∫ e^(−(ρ² + s²)/2σ²) ds over the chord |s| ≤ √(1−ρ²), σ = 1/sigmas.
fn gaussian_chord(rho2: f64, sigmas: f64) -> f64 {
    let sigma = 1.0 / sigmas;
    (-rho2 / (2.0 * sigma * sigma)).exp()
        * sigma
        * (2.0 * PI).sqrt()
        * libm::erf((1.0 - rho2).sqrt() / (sigma * std::f64::consts::SQRT_2))
}

/// ∫∫ F over the footprint's domain, f64 (for the Gaussian, the kernel's integral over the ball).
pub fn integral_f64(kernel: &Kernel) -> f64 {
    match *kernel {
        Kernel::Gaussian { sigmas, .. } => {
            let a = f64::from(sigmas) / std::f64::consts::SQRT_2;
            4.0 * PI
                * (PI.sqrt() * libm::erf(a) / (4.0 * a.powi(3)) - (-a * a).exp() / (2.0 * a * a))
        }
        Kernel::Cone { .. } => PI / 3.0,
        Kernel::Sinc { lobes, .. } => 4.0 / (PI * f64::from(lobes).powi(2)),
        Kernel::Bilinear { .. } => 1.0,
    }
}

/// How a reference weight is evaluated (for reports).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReferenceMode {
    /// Literal 3D line integral through M⁻¹.
    LineIntegral3d,
    /// Exact 2D model at the mapped point.
    Model2d,
}

/// One view's reference footprint, f64.
#[derive(Clone, Debug)]
pub struct ReferenceFootprint {
    kernel: Kernel,
    mode: ReferenceMode,
    /// M⁻¹, for the 3D line integral.
    m_inv: DMat3,
    /// 1 / (|det M| · ∫_ball h), for the 3D line integral.
    norm3d: f64,
    /// 2×2 screen → unit map (row-major) and |det| / ∫F, for the 2D model.
    to_unit: [[f64; 2]; 2],
    norm2d: f64,
    /// Half-extents of the bounding box, pixels.
    pub half_extent: [f64; 2],
    /// Whether each splat is renormalised to sum to one.
    pub renormalise: bool,
    /// Whether a semi-axis was lengthened to the minimum radius.
    pub clamped: bool,
}

impl ReferenceFootprint {
    /// Sets up the reference for `kernel` and `grid_to_screen` = V·G (pixels per grid step), with
    /// the same minimum radius as the core (pixels).
    pub fn new(
        kernel: &Kernel,
        grid_to_screen: &DMat3,
        min_radius_px: f64,
    ) -> Result<Self, GeometryError> {
        let axis = sheet_axis(&grid_to_screen.as_mat3());
        Self::with_sheet_axis(kernel, grid_to_screen, min_radius_px, axis)
    }

    /// [`ReferenceFootprint::new`] for sheets along `axis` (which orients separable kernels),
    /// as a perspective frame's per-voxel maps need (the frame's axis, not the map's own).
    pub fn with_sheet_axis(
        kernel: &Kernel,
        grid_to_screen: &DMat3,
        min_radius_px: f64,
        axis: usize,
    ) -> Result<Self, GeometryError> {
        let r = f64::from(kernel.spread());
        let m = *grid_to_screen * r;
        if !m.to_cols_array().iter().all(|v| v.is_finite()) {
            return Err(GeometryError::NonFinite);
        }
        if m.determinant().abs() < 1e-300 {
            return Err(GeometryError::SingularView);
        }
        let cols = [m.x_axis, m.y_axis, m.z_axis];
        let separable = matches!(kernel, Kernel::Bilinear { .. });
        // N (2×3): screen x and y rows of M (or of the two in-sheet columns, for bilinear).
        let mut n = [[0.0f64; 3]; 2];
        if separable {
            let (a, b) = in_sheet_axes(axis);
            n = [[cols[a].x, cols[b].x, 0.0], [cols[a].y, cols[b].y, 0.0]];
        } else {
            for (c, col) in cols.iter().enumerate() {
                n[0][c] = col.x;
                n[1][c] = col.y;
            }
        }
        let clamped = clamp_f64(&mut n, min_radius_px * min_radius_px);
        let (sxx, sxy, syy) = cov(&n);
        let det = minors2(&n);
        let (to_unit, half_extent) = if separable {
            let b = [[n[0][0], n[0][1]], [n[1][0], n[1][1]]];
            let d = b[0][0] * b[1][1] - b[0][1] * b[1][0];
            let inv = [[b[1][1] / d, -b[0][1] / d], [-b[1][0] / d, b[0][0] / d]];
            (
                inv,
                [b[0][0].abs() + b[0][1].abs(), b[1][0].abs() + b[1][1].abs()],
            )
        } else {
            // Cholesky-based map (any A with AᵀA = Σ⁻¹ gives the same radial footprint).
            let c00 = sxx.sqrt();
            let c10 = sxy / c00;
            let c11 = (det / sxx).sqrt();
            (
                [[1.0 / c00, 0.0], [-c10 / (c00 * c11), 1.0 / c11]],
                [sxx.sqrt(), syy.sqrt()],
            )
        };
        let det_map = (to_unit[0][0] * to_unit[1][1] - to_unit[0][1] * to_unit[1][0]).abs();
        let mode = if matches!(kernel, Kernel::Gaussian { .. }) && !clamped {
            ReferenceMode::LineIntegral3d
        } else {
            ReferenceMode::Model2d
        };
        Ok(ReferenceFootprint {
            kernel: *kernel,
            mode,
            m_inv: m.inverse(),
            norm3d: 1.0 / (m.determinant().abs() * integral_f64(kernel)),
            to_unit,
            norm2d: det_map / integral_f64(kernel),
            renormalise: half_extent[0].max(half_extent[1]) <= f64::from(RENORMALISE_BELOW_PX),
            half_extent,
            clamped,
        })
    }

    /// How weights are evaluated.
    pub fn mode(&self) -> ReferenceMode {
        self.mode
    }

    /// Weight (px⁻²) at screen offset `q` pixels from the voxel's projected centre.
    pub fn weight(&self, q: [f64; 2]) -> f64 {
        match self.mode {
            ReferenceMode::LineIntegral3d => {
                let Kernel::Gaussian { sigmas, .. } = self.kernel else {
                    unreachable!()
                };
                let u0 = self.m_inv * DVec3::new(q[0], q[1], 0.0);
                let d = self.m_inv.z_axis;
                let rho2 = u0.length_squared() - u0.dot(d).powi(2) / d.length_squared();
                if rho2 >= 1.0 {
                    return 0.0;
                }
                gaussian_chord(rho2.max(0.0), f64::from(sigmas)) / d.length() * self.norm3d
            }
            ReferenceMode::Model2d => {
                let a = &self.to_unit;
                let u = [
                    a[0][0] * q[0] + a[0][1] * q[1],
                    a[1][0] * q[0] + a[1][1] * q[1],
                ];
                footprint_f64(&self.kernel, u) * self.norm2d
            }
        }
    }

    /// The x offsets (pixels from the centre) where the support meets the row at y offset `qy`:
    /// the ellipse |A q| ≤ 1 or the parallelogram |A q|∞ ≤ 1 (exact, f64). `None` if it misses.
    fn row_span(&self, qy: f64) -> Option<(f64, f64)> {
        let a = &self.to_unit;
        if matches!(self.kernel, Kernel::Bilinear { .. }) {
            let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
            for row in a {
                let rest = row[1] * qy;
                if row[0] == 0.0 {
                    if rest.abs() >= 1.0 {
                        return None;
                    }
                } else {
                    let (p, q) = ((-1.0 - rest) / row[0], (1.0 - rest) / row[0]);
                    lo = lo.max(p.min(q));
                    hi = hi.min(p.max(q));
                }
            }
            return (lo < hi).then_some((lo, hi));
        }
        let pxx = a[0][0] * a[0][0] + a[1][0] * a[1][0];
        let pxy = a[0][0] * a[0][1] + a[1][0] * a[1][1];
        let pyy = a[0][1] * a[0][1] + a[1][1] * a[1][1];
        let disc = (pxy * qy).powi(2) - pxx * (pyy * qy * qy - 1.0);
        if disc <= 0.0 {
            return None;
        }
        let (mid, half) = (-pxy * qy / pxx, disc.sqrt() / pxx);
        Some((mid - half, mid + half))
    }

    /// Calls `f(pixel index, weight)` for every pixel with row in `rows` of a `width × height` image
    /// (row-major, top row first) that a voxel at screen position `center` (pixels) reaches, with
    /// the core's pixel-centre and renormalisation rules; weights are already renormalised.
    /// Pixels outside the support (where every weight is exactly zero) are not visited.
    pub fn for_each_weight(
        &self,
        center: [f64; 2],
        width: usize,
        rows: std::ops::Range<usize>,
        mut f: impl FnMut(usize, f64),
    ) {
        let span = |lo: f64, hi: f64| ((lo - 0.5).ceil() as i64, (hi - 0.5).floor() as i64);
        let (y0, y1) = span(
            center[1] - self.half_extent[1],
            center[1] + self.half_extent[1],
        );
        let each = |ylo: i64, yhi: i64, xmin: i64, xmax: i64, f: &mut dyn FnMut(i64, i64, f64)| {
            for y in ylo..=yhi {
                let qy = y as f64 + 0.5 - center[1];
                let Some((lo, hi)) = self.row_span(qy) else {
                    continue;
                };
                let (x0, x1) = span(center[0] + lo, center[0] + hi);
                for x in x0.max(xmin)..=x1.min(xmax) {
                    f(x, y, self.weight([x as f64 + 0.5 - center[0], qy]));
                }
            }
        };
        let mut factor = 1.0;
        if self.renormalise {
            let mut sum = 0.0;
            each(y0, y1, i64::MIN, i64::MAX, &mut |_, _, w| sum += w);
            if sum > 0.0 {
                factor = 1.0 / sum;
            }
        }
        let (ylo, yhi) = (y0.max(rows.start as i64), y1.min(rows.end as i64 - 1));
        each(ylo, yhi, 0, width as i64 - 1, &mut |x, y, w| {
            if w != 0.0 {
                f(y as usize * width + x as usize, w * factor);
            }
        });
    }

    /// Splats one voxel of value 1 at screen position `center` (pixels) into a `width × height`
    /// image (row-major, top row first).
    pub fn splat(&self, center: [f64; 2], width: usize, height: usize, out: &mut [f64]) {
        self.for_each_weight(center, width, 0..height, |i, w| out[i] += w);
    }
}

fn cov(n: &[[f64; 3]; 2]) -> (f64, f64, f64) {
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    (dot(&n[0], &n[0]), dot(&n[0], &n[1]), dot(&n[1], &n[1]))
}

fn minors2(n: &[[f64; 3]; 2]) -> f64 {
    let m = |a: usize, b: usize| n[0][a] * n[1][b] - n[0][b] * n[1][a];
    m(0, 1).powi(2) + m(0, 2).powi(2) + m(1, 2).powi(2)
}

/// Lengthens semi-axes shorter than √min_r2 (same rule as the core, f64).
fn clamp_f64(n: &mut [[f64; 3]; 2], min_r2: f64) -> bool {
    let (sxx, sxy, syy) = cov(n);
    let det = minors2(n);
    let l1 = 0.5 * (sxx + syy) + (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt();
    let l2 = det / l1;
    if l2 >= min_r2 {
        return false;
    }
    let (vx, vy) = if sxx >= syy {
        (l1 - syy, sxy)
    } else {
        (sxy, l1 - sxx)
    };
    let len = (vx * vx + vy * vy).sqrt();
    let (vx, vy) = if len > 0.0 {
        (vx / len, vy / len)
    } else {
        (1.0, 0.0)
    };
    let k1 = if l1 < min_r2 {
        (min_r2 / l1).sqrt()
    } else {
        1.0
    };
    let k2 = (min_r2 / l2).sqrt();
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
