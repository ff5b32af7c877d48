//! `micromath` backend: fast approximations for small cores.
//!
//! | function | method | worst-case error |
//! |---|---|---|
//! | `sqrt` | micromath's bit-trick seed (5 %), then two Newton–Raphson steps | relative 2e-6 |
//! | `exp` | micromath (`exp_ln2_approx`); exact 0 / ∞ beyond f32's range | relative 3e-3 (micromath states 1e-3 for its test vectors; measured 2.4e-3 over [−80, 80]) |
//! | `sin`, `cos` | micromath's parabolic approximation | absolute 2e-3 (measured 1.1e-3 on ±2π) |
//! | `atan` | micromath | absolute 2.9e-3 rad, 0.162° (measured 2.8e-3) |
//! | `erf` | Abramowitz & Stegun 7.1.26 on top of this `exp` | absolute 1.5e-7 + 3e-3 × p(t)e^(−x²) ≤ 3e-3, since p(t)e^(−x²) ≤ 1 (measured 5.7e-4 on ±6) |
//! | `powf` | exp(y · ln x) with this backend's own `ln` (micromath's `ln` is 2× off near 1, its `powf` 0.24 off) and this `exp` | absolute 1e-2 for x ∈ (0, 1], y ∈ [0, 64] (measured 1.2e-3) |
//! | `floor` | micromath below 2²³ in magnitude; the value itself from there (every f32 is whole), and for ±∞ and NaN | exact |
//!
//! `sqrt` is refined because a 5 % error in an ellipse axis would move every footprint edge by
//! 5 %; the other bounds are what micromath states. The table in `tests/math_backends.rs` measures
//! them against f64 references.

use super::ErrorBounds;
// Every call goes through micromath's `F32` wrapper: `x.exp()` on a plain f32 would silently
// resolve to std's inherent method whenever std is linked (as in unit tests).
use micromath::F32;

pub const NAME: &str = "micromath";

/// This backend's bounds (see the table above).
pub const ERROR_BOUNDS: ErrorBounds = ErrorBounds {
    sqrt_rel: 2.0e-6,
    exp_rel: 3.0e-3,
    sin_cos_abs: 2.0e-3,
    atan_abs: 2.9e-3,
    erf_abs: 3.0e-3,
    powf_unit_abs: 1.0e-2,
};

#[inline]
pub fn sqrt(x: f32) -> f32 {
    if !(x > 0.0) {
        // 0 → 0, negative or NaN → NaN, matching libm.
        return if x == 0.0 { x } else { f32::NAN };
    }
    if x == f32::INFINITY {
        return x;
    }
    let mut y = F32(x).sqrt().0;
    y = 0.5 * (y + x / y);
    0.5 * (y + x / y)
}
/// micromath's approximation inside f32's range; outside it, the exact limits (its bit trick
/// returns garbage below −87.3, where e^x underflows).
#[inline]
pub fn exp(x: f32) -> f32 {
    if x < -87.3 {
        0.0
    } else if x > 88.7 {
        f32::INFINITY
    } else {
        F32(x).exp().0
    }
}
/// Abramowitz & Stegun 7.1.26: erf(x) = 1 − (a₁t + a₂t² + … + a₅t⁵)e^(−x²), t = 1/(1+px),
/// |error| ≤ 1.5e-7 with an exact exponential; the `exp` error adds at most 3e-3 × p(t)e^(−x²),
/// and p(t)e^(−x²) = 1 − erf(|x|) ≤ 1.
#[inline]
pub fn erf(x: f32) -> f32 {
    const P: f32 = 0.327_591_1;
    const A: [f32; 5] = [
        0.254_829_6,
        -0.284_496_74,
        1.421_413_8,
        -1.453_152_1,
        1.061_405_4,
    ];
    let ax = super::abs(x);
    let t = 1.0 / (1.0 + P * ax);
    let poly = t * (A[0] + t * (A[1] + t * (A[2] + t * (A[3] + t * A[4]))));
    let y = 1.0 - poly * exp(-ax * ax);
    if x < 0.0 {
        -y
    } else {
        y
    }
}
#[inline]
pub fn sin(x: f32) -> f32 {
    F32(x).sin().0
}
#[inline]
pub fn cos(x: f32) -> f32 {
    F32(x).cos().0
}
#[inline]
pub fn atan(x: f32) -> f32 {
    F32(x).atan().0
}
/// micromath's floor goes through `i32`, so it saturates at ±2³¹ (4·10⁹ came out as 2.1·10⁹) and
/// turns NaN into 0: from 2²³ up every f32 is whole already, and ±∞ and NaN are their own floor,
/// so those are returned as they are.
#[inline]
pub fn floor(x: f32) -> f32 {
    if !(x.abs() < 8_388_608.0) {
        return x;
    }
    F32(x).floor().0
}
/// exp(y · ln x) with [`ln`] below and this backend's `exp`. (micromath's own `powf` and `ln` are
/// off by 0.24 and by 2× respectively near x = 1: ln 0.99001 came out as −0.0198.)
#[inline]
pub fn powf(x: f32, y: f32) -> f32 {
    if x == 0.0 {
        return if y == 0.0 { 1.0 } else { 0.0 };
    }
    exp(y * ln(x))
}

/// Natural logarithm for x > 0 (NaN otherwise): x = 2ᵉ·m with m ∈ [√½, √2) from the bits, then
/// ln m = 2 atanh(s), s = (m−1)/(m+1) ∈ [−0.172, 0.172], by its series to s⁹ (truncation
/// < 2·s¹¹/11 ≈ 7e-10; f32 rounding dominates, ~1e-7 absolute). Subnormal x is not supported
/// (returns the value for the smallest normal).
#[inline]
pub fn ln(x: f32) -> f32 {
    if !(x > 0.0) {
        return f32::NAN;
    }
    if x == f32::INFINITY {
        return x;
    }
    let bits = x.max(f32::MIN_POSITIVE).to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000); // [1, 2)
    if m > core::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let series =
        s * (2.0 + s2 * (2.0 / 3.0 + s2 * (2.0 / 5.0 + s2 * (2.0 / 7.0 + s2 * (2.0 / 9.0)))));
    e as f32 * core::f32::consts::LN_2 + series
}
