//! The pre-integrated section table of image-aligned slicing (Mueller and Crawfis 1998): how much
//! of a kernel's line integral lies in front of a given depth, per distance of the ray from the
//! kernel's centre.
//!
//! # What it holds
//! For a radial kernel with unit-radius profile h (the 3D kernel of [`Kernel::Gaussian`], truncated
//! at radius one), a ray passing at distance ρ from the centre meets the kernel along the chord
//! τ ∈ [−c, c], c = √(1 − ρ²) (τ in unit radii, 0 at the point nearest the centre). The table
//! holds the cumulative section integral
//!
//! ```text
//! G(ρ², t) = ∫_{−c}^{clamp(t, −c, c)} h(√(ρ² + τ²)) dτ  /  ∫_ball h
//! ```
//!
//! at R×T nodes: ρ² = i/(R−1) (i = 0 … R−1; indexed by ρ², so the splat needs no square root)
//! and t = −1 + 2j/(T−1) (j = 0 … T−1). The part of the kernel between depths t_a < t_b along a ray
//! is G(ρ², t_b) − G(ρ², t_a); G(ρ², 1) is the whole footprint (the generic table's F/∫∫F
//! at |u| = ρ). For the Gaussian, h(r) = exp(−r²s²/2) with s the kernel's `sigmas`, the section
//! integral has a closed form:
//!
//! ```text
//! G(ρ², t) = e^(−ρ²s²/2) · √(π/2)/s · [erf(s·clamp(t)/√2) + erf(s·c/√2)]  /  ∫_ball h
//! ```
//!
//! which is what [`SectionTable::build_into`] evaluates at the nodes. The other kernels are 2D
//! footprint models with no 3D profile to cut, and are refused ([`SectionError::NotAVolumeKernel`]).
//!
//! # Size and accuracy
//! 4·R·(T + 1) bytes (129 × 129: 65 KiB). Read (bi)linearly; with R = T = 129 and the default
//! Gaussian (2.5 σ per radius) the interpolation error of a section is 3.4·10⁻⁵ of the
//! peak footprint at worst (measured against the f64 closed form in this module's tests).

use crate::kernel::Kernel;
use crate::math;
use core::fmt;

/// Why a section table could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum SectionError {
    /// The kernel is a 2D footprint model (cone, sinc, bilinear), not a 3D kernel that a slab can
    /// cut: image-aligned slicing needs a Gaussian.
    NotAVolumeKernel,
}

impl fmt::Display for SectionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotAVolumeKernel => f.write_str(
                "image-aligned slicing cuts the 3D kernel into slab sections, which only a \
                 gaussian kernel is (cone, sinc and bilinear are 2D footprint models)",
            ),
        }
    }
}

impl core::error::Error for SectionError {}

/// R×T samples of a kernel's cumulative section integral G(ρ², t) (see the module docs).
/// R ≥ 2, T ≥ 2. Build it in place ([`SectionTable::build_into`]) or in a `static` on small targets.
#[derive(Clone, Debug, PartialEq)]
pub struct SectionTable<const R: usize, const T: usize> {
    kernel: Kernel,
    /// `data[i][j]` = G(1 − c², s·c) / radial(1 − c²), c = i/(R−1), s = −1 + 2j/(T−1).
    data: [[f32; T]; R],
    /// `radial[i]` = e^(−ρ²s²/2) at ρ² = i/(R−1).
    radial: [f32; R],
}

impl<const R: usize, const T: usize> SectionTable<R, T> {
    const VALID: () = assert!(R >= 2 && T >= 2, "a section table needs at least 2×2 nodes");

    /// An all-zero table, to be filled by [`SectionTable::build_into`]. Usable in `static`
    /// initialisers.
    pub const fn zeroed(kernel: Kernel) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::VALID;
        SectionTable {
            kernel,
            data: [[0.0; T]; R],
            radial: [0.0; R],
        }
    }

    /// Fills the table for `kernel` (a Gaussian) in place.
    pub fn build_into(&mut self, kernel: Kernel) -> Result<(), SectionError> {
        let Kernel::Gaussian { sigmas, .. } = kernel else {
            return Err(SectionError::NotAVolumeKernel);
        };
        self.kernel = kernel;
        let inv_integral = 1.0 / kernel.integral();
        let k = sigmas * core::f32::consts::FRAC_1_SQRT_2;
        let half_width = math::sqrt(core::f32::consts::PI * 0.5) / sigmas * inv_integral;
        for (i, (row, radial)) in self.data.iter_mut().zip(&mut self.radial).enumerate() {
            let x = i as f32 / (R - 1) as f32;
            // Row i: ρ² = x for the radial factor, c = x for the chord.
            *radial = math::exp(-0.5 * x * sigmas * sigmas);
            let lower = math::erf(k * x);
            for (j, g) in row.iter_mut().enumerate() {
                let t = (-1.0 + 2.0 * j as f32 / (T - 1) as f32) * x;
                *g = half_width * (math::erf(k * t) + lower);
            }
        }
        Ok(())
    }

    /// The kernel the table was built for.
    pub fn kernel(&self) -> &Kernel {
        &self.kernel
    }

    /// The chord part's samples, row-major (row = c node, column = s node).
    pub fn as_slice(&self) -> &[f32] {
        self.data.as_flattened()
    }

    /// G(ρ², t_b) − G(ρ², t_a): the share of the kernel (over its integral) that a ray at squared
    /// unit distance `rho2` from its centre meets between chord positions `t_a` and `t_b` (unit
    /// radii; anything beyond ±1 reads as the chord's end). Zero for ρ² ≥ 1 or NaN input.
    #[inline]
    pub fn section(&self, rho2: f32, t_a: f32, t_b: f32) -> f32 {
        if !(0.0..1.0).contains(&rho2) {
            return 0.0;
        }
        let last = (R - 1) as f32;
        let ri = rho2 * last;
        let i = (ri as usize).min(R - 2);
        let radial = self.radial[i] + (ri - i as f32) * (self.radial[i + 1] - self.radial[i]);
        let c = math::sqrt(1.0 - rho2);
        let ci = c * last;
        // 0 < ci ≤ R − 1.
        let i = (ci as usize).min(R - 2);
        let fr = ci - i as f32;
        let (lo, hi) = (&self.data[i], &self.data[i + 1]);
        let inv_c = 1.0 / c;
        let at = |t: f32| {
            // max/min, not clamp: `max` ignores NaN, so a NaN depth reads as the chord's near end.
            #[allow(clippy::manual_clamp)]
            let tj = ((t * inv_c).max(-1.0).min(1.0) + 1.0) * 0.5 * (T - 1) as f32;
            let j = (tj as usize).min(T - 2);
            let ft = tj - j as f32;
            let a = lo[j] + ft * (lo[j + 1] - lo[j]);
            let b = hi[j] + ft * (hi[j + 1] - hi[j]);
            a + fr * (b - a)
        };
        radial * (at(t_b) - at(t_a))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f64 closed form of G, for checking the table.
    fn exact(sigmas: f64, rho2: f64, t: f64) -> f64 {
        let c = (1.0 - rho2).max(0.0).sqrt();
        let t = t.clamp(-c, c);
        let k = sigmas / core::f64::consts::SQRT_2;
        let a = k;
        let integral = 4.0
            * core::f64::consts::PI
            * (core::f64::consts::PI.sqrt() * libm::erf(a) / (4.0 * a * a * a)
                - libm::exp(-a * a) / (2.0 * a * a));
        libm::exp(-0.5 * rho2 * sigmas * sigmas) * libm::sqrt(core::f64::consts::PI / 2.0) / sigmas
            * (libm::erf(k * t) + libm::erf(k * c))
            / integral
    }

    #[test]
    fn table_matches_the_closed_form_between_nodes() {
        let kernel = Kernel::gaussian(1.6, 2.5).unwrap();
        let mut table = SectionTable::<129, 129>::zeroed(kernel);
        table.build_into(kernel).unwrap();
        let peak = exact(2.5, 0.0, 1.0);
        let mut worst = 0.0f64;
        for i in 0..200 {
            let rho2 = i as f64 / 200.0 + 0.0013;
            for j in 0..300 {
                let ta = -1.05 + 2.1 * j as f64 / 300.0;
                let tb = ta + 0.137;
                let want = exact(2.5, rho2, tb) - exact(2.5, rho2, ta);
                let got = f64::from(table.section(rho2 as f32, ta as f32, tb as f32));
                worst = worst.max((got - want).abs() / peak);
            }
        }
        assert!(worst < 1e-4, "worst section error {worst} of peak");
    }

    #[test]
    fn the_whole_chord_is_the_footprint() {
        // G(ρ², 1) − G(ρ², −1) is the generic table's normalised footprint at |u| = ρ.
        let kernel = Kernel::gaussian(2.0, 2.0).unwrap();
        let mut table = SectionTable::<129, 129>::zeroed(kernel);
        table.build_into(kernel).unwrap();
        for i in 0..64 {
            let rho2 = i as f32 / 64.0;
            let whole = table.section(rho2, -1.0, 1.0);
            let f = kernel.footprint([math::sqrt(rho2), 0.0]) / kernel.integral();
            assert!(
                (whole - f).abs() < 2e-4 * f.max(1e-3),
                "ρ²={rho2}: {whole} vs {f}"
            );
        }
        assert_eq!(table.section(1.0, -1.0, 1.0), 0.0);
        assert_eq!(table.section(f32::NAN, -1.0, 1.0), 0.0);
    }

    #[test]
    fn footprint_models_are_refused() {
        let cone = Kernel::cone(1.5).unwrap();
        let mut table = SectionTable::<5, 5>::zeroed(cone);
        assert_eq!(table.build_into(cone), Err(SectionError::NotAVolumeKernel));
    }
}
