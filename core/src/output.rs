//! The renderer's result as pixels a display or a file takes: 8-bit RGBA (linear or sRGB,
//! premultiplied or straight alpha) and RGB565.
//!
//! The working image holds linear, premultiplied RGBA in [0, 1] (see [`crate::render`]). Its colour
//! channels are the picture composited over black.
//! - [`linear8`]: those channels as they are, rounded to the nearest code: what `footprint render`
//!   writes by default (an RGB PNG, as VTK and ParaView store their colours), byte for byte.
//! - [`straight8`]: colour divided by alpha (straight alpha, as PNG's RGBA requires): what
//!   `footprint render --background transparent` writes.
//! - [`srgb8`], [`straight_srgb8`], [`rgb565`]: the same encoded with the sRGB transfer curve
//!   (IEC 61966-2-1: 12.92·c below 0.0031308, else 1.055·c^(1/2.4) − 0.055), for emission that is
//!   linear light; `srgb8` differs from an exact f64 evaluation by at most one code; `rgb565`
//!   quantises the same sRGB values to 5, 6 and 5 bits with rounding.
//!
//! Every value is clamped to [0, 1] (NaN → 0) and rounded half away from zero. Alpha stays linear
//! (coverage, not a colour).
//!
//! A band leaves the renderer as rows: [`band_rows`] encodes each row to RGB565 in a one-row
//! buffer and hands it to a [`RowSink`] (with the `embedded-graphics` feature, `DisplaySink`
//! writes it into any `DrawTarget` of that ecosystem); [`rgb565_q24`] encodes the
//! fixed path's pixels without floating point.

use crate::math;

#[cfg(feature = "embedded-graphics")]
mod display;
mod rows;

#[cfg(feature = "embedded-graphics")]
pub use display::DisplaySink;
pub use rows::{band_rows, rgb565_q24, RowError, RowFn, RowSink};

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

/// The nearest 8-bit code of `v` clamped to [0, 1] (NaN → 0), halves rounded up: exactly
/// `(v · 255).round()`, without `round` (not in `core`).
#[inline]
fn level8(v: f32) -> u8 {
    let x = if v > 0.0 { v.min(1.0) * 255.0 } else { 0.0 };
    let n = x as u32;
    // x − n is exact (n ≤ x < 256), so the half is decided without rounding.
    (if x - n as f32 >= 0.5 { n + 1 } else { n }) as u8
}

/// Alpha clamped to [0, 1] (NaN → 0) and the colour channels to [0, alpha].
#[inline]
fn clamped(p: [f32; 4]) -> ([f32; 3], f32) {
    let a = if p[3] > 0.0 { p[3].min(1.0) } else { 0.0 };
    let c = |v: f32| if v > 0.0 { v.min(1.0) } else { 0.0 };
    ([c(p[0]), c(p[1]), c(p[2])], a)
}

/// Premultiplied linear RGBA → 8-bit linear colour over black and 8-bit alpha, no transfer
/// curve: `footprint render`'s default PNG (its RGB) byte for byte.
#[inline]
pub fn linear8(p: [f32; 4]) -> [u8; 4] {
    let (c, a) = clamped(p);
    [level8(c[0]), level8(c[1]), level8(c[2]), level8(a)]
}

/// Premultiplied linear RGBA → 8-bit straight-alpha RGBA (colour divided by alpha, 0 where alpha
/// is 0), linear: `footprint render --background transparent`'s PNG byte for byte.
#[inline]
pub fn straight8(p: [f32; 4]) -> [u8; 4] {
    let (c, a) = clamped(p);
    let s = |v: f32| if a > 0.0 { (v / a).min(1.0) } else { 0.0 };
    [level8(s(c[0])), level8(s(c[1])), level8(s(c[2])), level8(a)]
}

/// [`straight8`] with the colour encoded by the sRGB curve (alpha linear).
#[inline]
pub fn straight_srgb8(p: [f32; 4]) -> [u8; 4] {
    let (c, a) = clamped(p);
    let s = |v: f32| {
        let v = if a > 0.0 { (v / a).min(1.0) } else { 0.0 };
        code(srgb_encode(v), 255.0) as u8
    };
    [s(c[0]), s(c[1]), s(c[2]), level8(a)]
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_and_straight_levels_round_half_up_and_clamp() {
        assert_eq!(linear8([0.5, 1.5, -1.0, 1.0]), [128, 255, 0, 255]);
        assert_eq!(linear8([f32::NAN, 0.0, 0.0, f32::NAN]), [0, 0, 0, 0]);
        // Just below a half: as round() does (a + ½ then truncation can carry it up).
        for below in [0.5f32.next_down(), 127.5f32.next_down()].map(|x| x / 255.0) {
            assert_eq!(linear8([below; 4])[0], (below * 255.0).round() as u8);
        }
        for i in 0..=2550u32 {
            let v = i as f32 / 2550.0;
            assert_eq!(linear8([v; 4])[0], (v * 255.0).round() as u8, "{v}");
        }
        // Straight alpha: a half-covered pixel of full red is full red at alpha 128.
        assert_eq!(straight8([0.5, 0.0, 0.0, 0.5]), [255, 0, 0, 128]);
        assert_eq!(straight8([0.2, 0.2, 0.2, 0.0]), [0, 0, 0, 0]);
        assert_eq!(
            straight_srgb8([0.25, 0.0, 0.0, 0.5])[0],
            srgb8([0.5, 0.0, 0.0, 1.0])[0]
        );
    }
}
