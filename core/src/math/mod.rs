//! The one door to floating-point functions in the core.
//!
//! Every transcendental or rounding function the core uses is a free function here; nothing else in
//! the crate calls `f32::sqrt` and friends (with `std` linked, as in unit tests, inherent `f32`
//! methods would silently replace the no_std functions, so a test would measure code the embedded
//! build never runs).
//!
//! Two backends, chosen by cargo feature:
//! - `libm` (default): correctly rounded or nearly so (libm's `f32` functions are accurate to
//!   about 1 ulp). See [`libm_backend`](self) for the per-function bound.
//! - `micromath`: small, fast approximations for cores without an FPU or with a single-precision
//!   one. `micromath` is used for the seeds; where its raw error would break the geometry (its
//!   `sqrt` is only good to 5 %), this module refines the result. The bounds are stated in the
//!   backend's doc comment and checked against `libm` in `tests/math_backends.rs`.
//!
//! If both features are enabled, `micromath` wins: `libm` is the default, so asking for
//! `micromath` is the explicit choice.

#[cfg(not(any(feature = "libm", feature = "micromath")))]
compile_error!(
    "footprint needs a float backend: enable the `libm` (default) or `micromath` feature"
);

#[cfg(all(feature = "libm", not(feature = "micromath")))]
mod libm_backend;
#[cfg(all(feature = "libm", not(feature = "micromath")))]
use libm_backend as backend;

#[cfg(feature = "micromath")]
mod micromath_backend;
#[cfg(feature = "micromath")]
use micromath_backend as backend;

/// Name of the active backend (`"libm"` or `"micromath"`), for reports and benchmark labels.
pub const BACKEND: &str = backend::NAME;

/// Documented worst-case errors of the active backend, checked in `tests/math_backends.rs`.
pub use backend::ERROR_BOUNDS;

/// Worst-case error bounds of one backend: relative error for `sqrt` and `exp`, absolute error for
/// the others (`sin`/`cos` over |x| ≤ 2π, `atan` in radians, `erf` over all x).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorBounds {
    /// Relative error of [`sqrt`].
    pub sqrt_rel: f32,
    /// Relative error of [`exp`] for results in the normal range.
    pub exp_rel: f32,
    /// Absolute error of [`sin`] and [`cos`] for |x| ≤ 2π.
    pub sin_cos_abs: f32,
    /// Absolute error of [`atan`], radians.
    pub atan_abs: f32,
    /// Absolute error of [`erf`].
    pub erf_abs: f32,
    /// Absolute error of [`powf`] for x in (0, 1] and y in [0, 64] (the range opacity correction
    /// and specular highlights use).
    pub powf_unit_abs: f32,
}

/// Square root. NaN for negative input.
#[inline]
pub fn sqrt(x: f32) -> f32 {
    backend::sqrt(x)
}

/// e^x.
#[inline]
pub fn exp(x: f32) -> f32 {
    backend::exp(x)
}

/// The error function erf(x) = 2/√π ∫₀ˣ e^(−t²) dt.
#[inline]
pub fn erf(x: f32) -> f32 {
    backend::erf(x)
}

/// Sine of an angle in radians.
#[inline]
pub fn sin(x: f32) -> f32 {
    backend::sin(x)
}

/// Cosine of an angle in radians.
#[inline]
pub fn cos(x: f32) -> f32 {
    backend::cos(x)
}

/// Arctangent in radians, in (−π/2, π/2).
#[inline]
pub fn atan(x: f32) -> f32 {
    backend::atan(x)
}

/// xʸ for x > 0 (NaN for x < 0, as libm).
#[inline]
pub fn powf(x: f32, y: f32) -> f32 {
    backend::powf(x, y)
}

/// xʸ for x ≥ 0, by repeated squaring when y is a whole number from 0 to [`MAX_WHOLE_POWER`]
/// (at most 14 multiplies), else [`powf`]. For Phong's specular term (`shininess` is usually a
/// whole number, 24 by default): libm's `powf` was 42 % of a Phong frame (`perf`, the 256³ blobs
/// at 512²). Relative error at most (y − 1)·2⁻²⁴ to first order, while the result is normal: the
/// squarings expand to a tree of y − 1 products, each rounded once (tested against f64 below;
/// 1.4·10⁻⁶ at the default 24, far below an 8-bit step). The same on every math backend.
#[inline]
pub fn powi_or_powf(x: f32, y: f32) -> f32 {
    let n = y as u32; // saturating; NaN gives 0, which then differs from y
    if n as f32 != y || n > MAX_WHOLE_POWER {
        return powf(x, y);
    }
    let (mut base, mut n, mut acc) = (x, n, 1.0f32);
    while n > 0 {
        if n & 1 == 1 {
            acc *= base;
        }
        base *= base;
        n >>= 1;
    }
    acc
}

/// The largest exponent [`powi_or_powf`] takes by squaring (its error bound grows with y).
pub const MAX_WHOLE_POWER: u32 = 128;

/// Natural logarithm for x > 0 (NaN for x < 0, −∞ at 0).
#[inline]
pub fn ln(x: f32) -> f32 {
    backend::ln(x)
}

/// Largest integer value not greater than `x`.
#[inline]
pub fn floor(x: f32) -> f32 {
    backend::floor(x)
}

/// |x|, by clearing the sign bit (exact, no backend needed).
#[inline]
pub fn abs(x: f32) -> f32 {
    f32::from_bits(x.to_bits() & 0x7fff_ffff)
}

/// `x` clamped to [`lo`, `hi`] by compare-and-select (maxss/minss, no branch): a NaN `x` reads
/// as `lo`. `f32::clamp` keeps the NaN.
#[inline]
pub fn select_clamp(x: f32, lo: f32, hi: f32) -> f32 {
    let x = if x > lo { x } else { lo };
    if x < hi {
        x
    } else {
        hi
    }
}

/// x², spelled out so call sites read like the formulas they implement.
#[inline]
pub fn sq(x: f32) -> f32 {
    x * x
}

#[cfg(test)]
mod tests {
    //! Each backend against f64 references (`libm`'s f64 functions), at its stated bounds. Run for
    //! both: `cargo test -p footprint --lib` and
    //! `cargo test -p footprint --lib --no-default-features --features micromath`.
    use super::*;

    fn worst(
        points: impl Iterator<Item = f32>,
        f: fn(f32) -> f32,
        r: fn(f64) -> f64,
        rel: bool,
    ) -> f64 {
        points
            .map(|x| {
                let (got, want) = (f64::from(f(x)), r(f64::from(x)));
                let err = (got - want).abs();
                if rel {
                    err / want.abs()
                } else {
                    err
                }
            })
            .fold(0.0, f64::max)
    }

    fn grid(lo: f32, hi: f32, n: usize) -> impl Iterator<Item = f32> {
        (0..=n).map(move |i| lo + (hi - lo) * i as f32 / n as f32)
    }

    /// Whole exponents against f64's power at the stated bound; other exponents are [`powf`]'s.
    #[test]
    fn powi_or_powf_meets_its_bound() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let xs: [f32; 4097] = core::array::from_fn(|i| match i {
            0..=2047 => i as f32 / 2047.0,
            2048..=2051 => [1.0 + f32::EPSILON, 1.5, 2.0, 0.999_999_9][i - 2048],
            _ => {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 40) as f32 / (1u64 << 24) as f32
            }
        });
        let mut worst_24 = 0.0f64;
        for n in 0..=MAX_WHOLE_POWER {
            let bound = (f64::from(n.max(1) - 1) + 1e-3) * f64::from(f32::EPSILON) / 2.0;
            for &x in &xs {
                let got = f64::from(powi_or_powf(x, n as f32));
                let want = libm::pow(f64::from(x), f64::from(n));
                if !(1e-30..=1e30).contains(&want) {
                    // Where f32 underflows or overflows: only the limits matter.
                    assert!(got < 1e-29 || want > 1e30, "{x}^{n}: {got} against {want}");
                    continue;
                }
                let rel = (got - want).abs() / want;
                assert!(
                    rel <= bound,
                    "{x}^{n}: {got} against {want}, {rel:e} > {bound:e}"
                );
                if n == 24 {
                    worst_24 = worst_24.max(rel);
                }
            }
        }
        assert!(worst_24 > 0.0, "the squarings do round");
        for y in [0.5f32, 24.5, 129.0, 1e9, -2.0, f32::NAN] {
            for x in [0.0f32, 0.3, 0.9, 1.0] {
                let (a, b) = (powi_or_powf(x, y), powf(x, y));
                assert!(
                    a.to_bits() == b.to_bits(),
                    "{x}^{y}: {a} against powf's {b}"
                );
            }
        }
    }

    #[test]
    fn backend_meets_its_stated_bounds() {
        let b = ERROR_BOUNDS;
        let sqrt_e = worst(grid(1e-6, 1e6, 100_000), sqrt, libm::sqrt, true);
        let exp_e = worst(grid(-80.0, 80.0, 100_000), exp, libm::exp, true);
        // Underflow and overflow are exact limits, not approximations.
        assert!(exp(-100.0) < 1e-40 && exp(-500.0) == 0.0 && exp(100.0) == f32::INFINITY);
        let sin_e = worst(
            grid(-core::f32::consts::TAU, core::f32::consts::TAU, 100_000),
            sin,
            libm::sin,
            false,
        );
        let cos_e = worst(
            grid(-core::f32::consts::TAU, core::f32::consts::TAU, 100_000),
            cos,
            libm::cos,
            false,
        );
        let atan_e = worst(grid(-1e3, 1e3, 100_000), atan, libm::atan, false);
        let erf_e = worst(grid(-6.0, 6.0, 100_000), erf, libm::erf, false);
        let mut pow_e = 0.0f64;
        for x in grid(1e-3, 1.0, 400) {
            for y in grid(0.0, 64.0, 400) {
                pow_e = pow_e
                    .max((f64::from(powf(x, y)) - libm::pow(f64::from(x), f64::from(y))).abs());
            }
        }
        // Printed with --nocapture; docs/embedded.md's backend table quotes these.
        std::println!(
            "{BACKEND}: sqrt {sqrt_e:.2e} rel, exp {exp_e:.2e} rel, sin {sin_e:.2e}, cos {cos_e:.2e}, atan {atan_e:.2e}, erf {erf_e:.2e}, powf {pow_e:.2e}"
        );
        assert!(sqrt_e <= f64::from(b.sqrt_rel), "sqrt {sqrt_e:e}");
        assert!(exp_e <= f64::from(b.exp_rel), "exp {exp_e:e}");
        assert!(sin_e <= f64::from(b.sin_cos_abs), "sin {sin_e:e}");
        assert!(cos_e <= f64::from(b.sin_cos_abs), "cos {cos_e:e}");
        assert!(atan_e <= f64::from(b.atan_abs), "atan {atan_e:e}");
        assert!(erf_e <= f64::from(b.erf_abs), "erf {erf_e:e}");
        assert!(pow_e <= f64::from(b.powf_unit_abs), "powf {pow_e:e}");
        assert_eq!(floor(-2.5), -3.0);
        assert_eq!(floor(2.5), 2.0);
    }

    /// `floor` is exact over the whole f32 range under either backend: against libm's f64 floor
    /// on values spread over every binade (both signs), the integers near 2²³ and 2³¹ where a
    /// conversion through `i32` would saturate, and ±∞ and NaN (their own floor).
    #[test]
    fn floor_is_exact_everywhere() {
        let mut cases = std::vec![
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            8_388_607.5,
            -8_388_607.5,
            8_388_608.0,
            16_777_217.0,
            2_147_483_520.0,
            2_147_483_648.0,
            -2_147_483_648.0,
            4.0e9,
            -4.0e9,
            1.0e30,
            -1.0e30,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        let mut bits = 0x9e37_79b9u32;
        for _ in 0..200_000 {
            bits ^= bits << 13;
            bits ^= bits >> 17;
            bits ^= bits << 5;
            let x = f32::from_bits(bits);
            if x.is_finite() {
                cases.push(x);
            }
        }
        for x in cases {
            let want = libm::floor(f64::from(x)) as f32;
            let got = floor(x);
            assert!(got == want, "floor({x:e}) = {got:e}, want {want:e}");
        }
        assert!(floor(f32::NAN).is_nan());
        assert_eq!(abs(-0.0f32).to_bits(), 0);
        assert!(sqrt(-1.0).is_nan());
        assert_eq!(sqrt(0.0), 0.0);
    }
}
