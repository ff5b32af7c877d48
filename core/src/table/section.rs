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
//! The e^(−ρ²s²/2) factor depends on the ray only, and the erf(s·c/√2) term cancels in any
//! difference of two depths along one ray, so a section needs only two one-dimensional tables:
//!
//! ```text
//! G(ρ², t_b) − G(ρ², t_a) = radial(ρ²) · [C(clamp(t_b, −c, c)) − C(clamp(t_a, −c, c))]
//! radial(ρ²) = e^(−ρ²s²/2),   C(x) = √(π/2)/s · erf(s·x/√2) / ∫_ball h
//! ```
//!
//! [`SectionTable::build_into`] evaluates radial at R nodes ρ² = i/(R−1) and C at T nodes
//! x = −1 + 2j/(T−1), both read linearly; per pixel a splat takes one square root (c) and no
//! division. The other kernels are 2D footprint models with no 3D profile to cut, and are refused
//! ([`SectionError::NotAVolumeKernel`]).
//!
//! # The chord's ends in one read
//! A splat whose slab boundaries sit at the same chord positions for every pixel (no shear: see
//! the slab renderer) needs per pixel only radial(ρ²) and the depth integral at the chord's ends,
//! C(±c) (C is odd, so C(−c) = −C(c)). Read as above that is three table walks. The table also
//! holds both as functions of the half-chord c, at T nodes c = j/(T−1): radial(1 − c²) and C(c),
//! side by side, so [`SectionTable::chord`] reads them with one index and one pair of loads.
//! Both are smooth in c (C(c) in ρ² is not: it has a square-root edge at ρ² = 1), so reading
//! them linearly in c is as accurate as the two tables above (measured in the tests below).
//!
//! # Size and accuracy
//! 4·(R + 3T) bytes (257 + 3 × 1025: 13 KiB, so it stays in the L1 cache). With R = 257 and
//! T = 1025 and the default Gaussian (2.5 σ per radius) a section is within 2.4·10⁻⁶ of the peak footprint
//! of the f64 closed form (measured in this module's tests). (A first version tabulated G over
//! (ρ², t) in two dimensions: a kink where t = ±c and the square-root edge at ρ² = 1 cost 0.4 %
//! of the peak under bilinear interpolation, and its lookups cost a division and four loads per
//! depth.)

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

/// A Gaussian's section integral as two tables (see the module docs): the radial factor at R
/// nodes over ρ² ∈ [0, 1] and the cumulative depth integral C at T nodes over [−1, 1]. R, T ≥ 2.
/// Build it in place ([`SectionTable::build_into`]) or in a `static` on small targets.
#[derive(Clone, Debug, PartialEq)]
pub struct SectionTable<const R: usize, const T: usize> {
    kernel: Kernel,
    /// `radial[i]` = e^(−ρ²s²/2) at ρ² = i/(R−1).
    radial: [f32; R],
    /// `depth[j]` = C(−1 + 2j/(T−1)).
    depth: [f32; T],
    /// `chord[j]` = [radial(1 − c²), C(c)] at half-chord c = j/(T−1).
    chord: [[f32; 2]; T],
}

impl<const R: usize, const T: usize> SectionTable<R, T> {
    const VALID: () = assert!(
        R >= 2 && T >= 2,
        "a section table needs at least 2 nodes a side"
    );

    /// An all-zero table, to be filled by [`SectionTable::build_into`]. Usable in `static`
    /// initialisers.
    pub const fn zeroed(kernel: Kernel) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::VALID;
        SectionTable {
            kernel,
            radial: [0.0; R],
            depth: [0.0; T],
            chord: [[0.0; 2]; T],
        }
    }

    /// Fills the table for `kernel` (a Gaussian) in place.
    pub fn build_into(&mut self, kernel: Kernel) -> Result<(), SectionError> {
        let Kernel::Gaussian { sigmas, .. } = kernel else {
            return Err(SectionError::NotAVolumeKernel);
        };
        self.kernel = kernel;
        let k = sigmas * core::f32::consts::FRAC_1_SQRT_2;
        let scale = math::sqrt(core::f32::consts::PI * 0.5) / sigmas / kernel.integral();
        let radial = |rho2: f32| math::exp(-0.5 * rho2 * sigmas * sigmas);
        let depth = |x: f32| scale * math::erf(k * x);
        for (i, r) in self.radial.iter_mut().enumerate() {
            *r = radial(i as f32 / (R - 1) as f32);
        }
        for (j, d) in self.depth.iter_mut().enumerate() {
            *d = depth(-1.0 + 2.0 * j as f32 / (T - 1) as f32);
        }
        for (j, e) in self.chord.iter_mut().enumerate() {
            let c = j as f32 / (T - 1) as f32;
            *e = [radial(1.0 - c * c), depth(c)];
        }
        Ok(())
    }

    /// The kernel the table was built for.
    pub fn kernel(&self) -> &Kernel {
        &self.kernel
    }

    /// G(ρ², t_b) − G(ρ², t_a): the share of the kernel (over its integral) that a ray at squared
    /// unit distance `rho2` from its centre meets between chord positions `t_a` and `t_b` (unit
    /// radii; anything beyond the chord reads as its end). Zero for ρ² ≥ 1 or NaN input.
    #[inline]
    pub fn section(&self, rho2: f32, t_a: f32, t_b: f32) -> f32 {
        self.ray(rho2).map_or(0.0, |r| r.at(t_b) - r.at(t_a))
    }

    /// C(clamp(t, −1, 1)): the depth integral on its own, the same for every ray (a section is
    /// radial · [C(t_b) − C(t_a)] with both depths clamped to the ray's chord: see
    /// [`SectionRay::depth_ends`]). A NaN depth reads as node 0.
    #[inline]
    pub fn depth(&self, t: f32) -> f32 {
        depth_at(&self.depth, math::select_clamp(t, -1.0, 1.0))
    }

    /// The part of the table one ray reads (a ray at squared unit distance `rho2` from the
    /// kernel's centre), for evaluating G at several depths: `None` when it misses the kernel.
    #[inline]
    pub fn ray(&self, rho2: f32) -> Option<SectionRay<'_, T>> {
        if !(0.0..1.0).contains(&rho2) {
            return None;
        }
        let ri = rho2 * (R - 1) as f32;
        let i = (ri as u32 as usize).min(R - 2);
        let radial = self.radial[i] + (ri - i as f32) * (self.radial[i + 1] - self.radial[i]);
        Some(SectionRay {
            depth: &self.depth,
            radial,
            c: math::sqrt(1.0 - rho2),
        })
    }

    /// The ray at squared unit distance `rho2` from the kernel's centre as its radial factor and
    /// the depth integral at its chord's end, [radial(ρ²), C(c)] (C(−c) = −C(c)), read from the
    /// half-chord table in one walk (see the module docs); the same values as
    /// [`SectionRay::radial`] and [`SectionRay::depth_ends`] to within the tables' interpolation
    /// error, not bit for bit. `None` when the ray misses the kernel (ρ² ∉ [0, 1), NaN).
    #[inline]
    pub fn chord(&self, rho2: f32) -> Option<[f32; 2]> {
        if !(0.0..1.0).contains(&rho2) {
            return None;
        }
        // c ∈ (0, 1]: tj ∈ (0, T − 1], a 32-bit conversion as in `depth_at`.
        let tj = math::sqrt(1.0 - rho2) * (T - 1) as f32;
        let j = (tj as u32 as usize).min(T - 2);
        let (a, b, f) = (self.chord[j], self.chord[j + 1], tj - j as f32);
        Some([a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])])
    }
}

/// One ray's view of a [`SectionTable`] ([`SectionTable::ray`]).
#[derive(Clone, Copy, Debug)]
pub struct SectionRay<'a, const T: usize> {
    depth: &'a [f32; T],
    radial: f32,
    /// Half the chord, unit radii.
    c: f32,
}

impl<const T: usize> SectionRay<'_, T> {
    /// G(ρ², t) up to a constant of the ray (which cancels in differences): the share of the
    /// kernel in front of chord position `t` (unit radii).
    #[inline]
    pub fn at(&self, t: f32) -> f32 {
        // A NaN depth reads as node 0.
        self.radial * depth_at(self.depth, math::select_clamp(t, -self.c, self.c))
    }

    /// The radial factor e^(−ρ²s²/2) of this ray: G(ρ², t) = radial · C(clamp(t, −c, c)).
    #[inline]
    pub fn radial(&self) -> f32 {
        self.radial
    }

    /// C(−c) and C(c): the depth integral at the chord's ends, between which
    /// C(clamp(t, −c, c)) = clamp(C(t), C(−c), C(c)) lies (C is increasing, and so is its
    /// piecewise-linear table).
    #[inline]
    pub fn depth_ends(&self) -> (f32, f32) {
        (depth_at(self.depth, -self.c), depth_at(self.depth, self.c))
    }
}

/// The depth table read linearly at `x` ∈ [−1, 1] (the caller clamps).
#[inline]
fn depth_at<const T: usize>(d: &[f32; T], x: f32) -> f32 {
    let tj = (x + 1.0) * (0.5 * (T - 1) as f32);
    // tj ∈ [0, T − 1]: a 32-bit conversion (one instruction and a clamp) rather than the
    // 64-bit unsigned one, which x86-64 emulates in a dozen.
    let j = (tj as u32 as usize).min(T - 2);
    d[j] + (tj - j as f32) * (d[j + 1] - d[j])
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

    /// The harness's table size for a Gaussian of `radius` voxels and `sigmas`.
    fn built(radius: f32, sigmas: f32) -> (Kernel, SectionTable<257, 1025>) {
        let kernel = Kernel::gaussian(radius, sigmas).unwrap();
        let mut table = SectionTable::<257, 1025>::zeroed(kernel);
        table.build_into(kernel).unwrap();
        (kernel, table)
    }

    #[test]
    fn table_matches_the_closed_form_between_nodes() {
        let (_, table) = built(1.6, 2.5);
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
        eprintln!("worst section error {worst:.2e} of peak");
        // The interpolation's 3·10⁻⁵, plus what the backend's erf and exp cost (micromath's are
        // good to 3·10⁻³; a section is a difference of two erfs over about 2·erf(s/√2)).
        let b = math::ERROR_BOUNDS;
        let bound = 3e-5 + 1.1 * f64::from(b.erf_abs) + f64::from(b.exp_rel);
        assert!(worst < bound, "worst section error {worst} of peak");
    }

    #[test]
    fn the_whole_chord_is_the_footprint() {
        // G(ρ², 1) − G(ρ², −1) is the generic table's normalised footprint at |u| = ρ.
        let (kernel, table) = built(2.0, 2.0);
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

    /// The half-chord table against the f64 closed form and against the two tables it stands in
    /// for, over the whole chord range, its nodes' edge (ρ² → 1) included.
    #[test]
    fn the_chord_table_reads_the_ends_of_the_chord() {
        let (_, table) = built(1.6, 2.5);
        let peak = exact(2.5, 0.0, 1.0);
        // Against the f64 form: this table, and the three walks it stands in for.
        let (mut worst_exact, mut worst_old, mut worst_tables) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..4000 {
            let rho2 = (i as f64 + 0.37) / 4000.0;
            let [radial, hi] = table.chord(rho2 as f32).unwrap();
            // radial · 2·C(c) is the whole chord's section.
            let want = exact(2.5, rho2, 1.0) - exact(2.5, rho2, -1.0);
            let got = 2.0 * f64::from(radial) * f64::from(hi);
            worst_exact = worst_exact.max((got - want).abs() / peak);
            let ray = table.ray(rho2 as f32).unwrap();
            let (lo, hi_ray) = ray.depth_ends();
            let old = f64::from(ray.radial()) * f64::from(hi_ray - lo);
            worst_old = worst_old.max((old - want).abs() / peak);
            for (a, b) in [(radial, ray.radial()), (hi, hi_ray), (-hi, lo)] {
                worst_tables = worst_tables.max(f64::from((a - b).abs() * radial));
            }
        }
        eprintln!("whole chord: {worst_exact:.2e} of peak, three walks {worst_old:.2e}; apart {worst_tables:.2e}");
        let b = math::ERROR_BOUNDS;
        let bound = 3e-5 + 1.1 * f64::from(b.erf_abs) + f64::from(b.exp_rel);
        assert!(
            worst_exact < bound,
            "{worst_exact} of peak against the f64 form"
        );
        assert!(
            worst_tables < bound,
            "{worst_tables} against the two tables"
        );
        // With the default backend (libm) one walk over c is the more accurate (measured 5.5·10⁻⁶
        // against 1.8·10⁻⁵ of the peak): C(c) read linearly in c, not at c's own two nodes.
        assert!(
            worst_exact <= worst_old + f64::from(b.erf_abs),
            "{worst_exact} vs {worst_old}"
        );
        assert_eq!(table.chord(1.0), None);
        assert_eq!(table.chord(-1e-9), None);
        assert_eq!(table.chord(f32::NAN), None);
        assert!(table.chord(0.0).is_some());
    }

    #[test]
    fn footprint_models_are_refused() {
        let cone = Kernel::cone(1.5).unwrap();
        let mut table = SectionTable::<5, 5>::zeroed(cone);
        assert_eq!(table.build_into(cone), Err(SectionError::NotAVolumeKernel));
    }

    /// The shear-free slab splat's form: radial · clamp(C(t), C(−c), C(c)) is G(ρ², t), the
    /// clamp applied to the table's value instead of to t (the table is increasing).
    #[test]
    fn clamping_the_depth_integral_is_clamping_the_depth() {
        let (_, table) = built(1.6, 2.5);
        assert!(table.depth.windows(2).all(|w| w[0] <= w[1]));
        let peak = table.section(0.0, -1.0, 1.0);
        for i in 0..97 {
            let rho2 = i as f32 / 97.0 + 0.003;
            let ray = table.ray(rho2).unwrap();
            let (lo, hi) = ray.depth_ends();
            assert!(lo <= hi);
            for j in 0..400 {
                let t = -1.3 + 2.6 * j as f32 / 400.0;
                let got = ray.radial() * table.depth(t).clamp(lo, hi);
                let want = ray.at(t);
                assert!(
                    (got - want).abs() <= 1e-6 * peak,
                    "ρ²={rho2} t={t}: {got} vs {want}"
                );
            }
        }
        assert_eq!(table.depth(f32::NAN), table.depth[0]);
        assert_eq!(table.depth(-5.0), table.depth[0]);
        assert!((table.depth(5.0) - table.depth[1024]).abs() <= 1e-6 * peak);
    }
}
