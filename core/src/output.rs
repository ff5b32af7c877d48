//! The renderer's result as pixels a display or a file takes: 8-bit sRGB RGBA and RGB565.
//!
//! The working image holds linear, premultiplied RGBA in [0, 1] (see [`crate::render`]). Its colour
//! channels are the picture composited over black; these conversions encode them with the sRGB
//! transfer curve (IEC 61966-2-1: 12.92·c below 0.0031308, else 1.055·c^(1/2.4) − 0.055), clamped
//! to [0, 1], and round to the nearest code. Alpha stays linear (coverage, not a colour).
//! `srgb8` differs from an exact f64 evaluation by at most one code; `rgb565` quantises the same
//! sRGB values to 5, 6 and 5 bits with rounding.

use crate::math;

/// sRGB encoding of one linear channel, clamped to [0, 1]; NaN gives 0.
#[inline]
pub fn srgb_encode(c: f32) -> f32 {
    let c = if c > 0.0 { c.min(1.0) } else { 0.0 };
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * math::powf(c, 1.0 / 2.4) - 0.055
    }
}

#[inline]
fn code(v: f32, max: f32) -> u32 {
    // v in [0, 1] (clamped above); + ½ then truncation rounds to nearest.
    (v.clamp(0.0, 1.0) * max + 0.5) as u32
}

/// Premultiplied linear RGBA → 8-bit sRGB colour (over black) and 8-bit linear alpha.
#[inline]
pub fn srgb8(p: [f32; 4]) -> [u8; 4] {
    [
        code(srgb_encode(p[0]), 255.0) as u8,
        code(srgb_encode(p[1]), 255.0) as u8,
        code(srgb_encode(p[2]), 255.0) as u8,
        code(if p[3] > 0.0 { p[3] } else { 0.0 }, 255.0) as u8,
    ]
}

/// Premultiplied linear RGBA → RGB565 (sRGB colour over black): red in bits 15–11, green 10–5,
/// blue 4–0, the layout of most small TFT displays.
#[inline]
pub fn rgb565(p: [f32; 4]) -> u16 {
    let r = code(srgb_encode(p[0]), 31.0);
    let g = code(srgb_encode(p[1]), 63.0);
    let b = code(srgb_encode(p[2]), 31.0);
    ((r << 11) | (g << 5) | b) as u16
}

/// [`srgb8`] over a whole image: `out[i] = srgb8(image[i])` for the common length.
pub fn to_srgb8(image: &[[f32; 4]], out: &mut [[u8; 4]]) {
    for (o, p) in out.iter_mut().zip(image) {
        *o = srgb8(*p);
    }
}

/// [`rgb565`] over a whole image: `out[i] = rgb565(image[i])` for the common length.
pub fn to_rgb565(image: &[[f32; 4]], out: &mut [u16]) {
    for (o, p) in out.iter_mut().zip(image) {
        *o = rgb565(*p);
    }
}
