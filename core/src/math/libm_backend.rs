//! `libm` backend: a port of musl's libm. Its `f32` functions are accurate to about 1 ulp
//! (relative error ≤ 1.2e-7 for `sqrt`, which is correctly rounded, and a few ulp elsewhere).
//! Note for single-precision FPUs: several of libm's `f32` functions compute in `f64` internally,
//! which a Cortex-M4F runs in software.

use super::ErrorBounds;

pub const NAME: &str = "libm";

/// This backend's bounds: a few ulp, checked against f64 references in `tests/math_backends.rs`.
pub const ERROR_BOUNDS: ErrorBounds = ErrorBounds {
    sqrt_rel: 1.2e-7,
    exp_rel: 4.0e-7,
    sin_cos_abs: 4.0e-7,
    atan_abs: 4.0e-7,
    erf_abs: 4.0e-7,
    powf_unit_abs: 4.0e-7,
};

#[inline]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}
#[inline]
pub fn exp(x: f32) -> f32 {
    libm::expf(x)
}
#[inline]
pub fn erf(x: f32) -> f32 {
    libm::erff(x)
}
#[inline]
pub fn sin(x: f32) -> f32 {
    libm::sinf(x)
}
#[inline]
pub fn cos(x: f32) -> f32 {
    libm::cosf(x)
}
#[inline]
pub fn atan(x: f32) -> f32 {
    libm::atanf(x)
}
#[inline]
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}
#[inline]
pub fn floor(x: f32) -> f32 {
    libm::floorf(x)
}
#[inline]
pub fn powf(x: f32, y: f32) -> f32 {
    libm::powf(x, y)
}
