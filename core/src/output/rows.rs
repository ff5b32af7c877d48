//! A finished band as rows a display takes: each image row encoded to RGB565 in a one-row buffer
//! of the caller's and handed to a [`RowSink`] (a display driver's window write, an SPI
//! transfer, a checksum). No frame buffer is needed: a band of a few rows is all the image that
//! is ever in memory.
//!
//! The float path's pixels encode with [`super::rgb565`]; the fixed path's Q24 pixels with
//! [`rgb565_q24`], which uses no floating point (a core without an FPU pays no `powf` per
//! channel). Both put the sRGB-encoded colour over black, red in bits 15–11.

/// Where encoded rows go: row `y` (absolute image row, top first) of RGB565 pixels, left to
/// right, rows in increasing order within a band.
pub trait RowSink {
    /// What a failed write reports (`Infallible` for a sink that cannot fail).
    type Error;
    /// Takes one row.
    fn row(&mut self, y: usize, pixels: &[u16]) -> Result<(), Self::Error>;
}

/// A closure `f(y, pixels)` as a sink that cannot fail.
pub struct RowFn<F>(pub F);

impl<F: FnMut(usize, &[u16])> RowSink for RowFn<F> {
    type Error = core::convert::Infallible;
    fn row(&mut self, y: usize, pixels: &[u16]) -> Result<(), Self::Error> {
        (self.0)(y, pixels);
        Ok(())
    }
}

/// Why a band was not handed over.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowError<E> {
    /// The row buffer is shorter than the image width.
    RowBuffer {
        /// Pixels needed (the width).
        needed: usize,
        /// Pixels given.
        got: usize,
    },
    /// The band's length is not a whole number of rows of `width` pixels (or `width` is 0).
    PartialRow {
        /// Pixels in the band.
        len: usize,
        /// Image width, pixels.
        width: usize,
    },
    /// The sink refused a row.
    Sink(E),
}

impl<E: core::fmt::Display> core::fmt::Display for RowError<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::RowBuffer { needed, got } => {
                write!(f, "the row buffer holds {got} pixels, a row needs {needed}")
            }
            Self::PartialRow { len, width } => {
                write!(f, "a band of {len} pixels is not whole rows of {width}")
            }
            Self::Sink(e) => write!(f, "the display refused a row: {e}"),
        }
    }
}

impl<E: core::fmt::Debug + core::fmt::Display> core::error::Error for RowError<E> {}

/// Encodes `band` (whole rows of `width` pixels, row-major, the first being image row `first`)
/// row by row into `row` with `encode` and hands each row to `sink`. Stops at the first row the
/// sink refuses.
pub fn band_rows<P: Copy, S: RowSink>(
    first: usize,
    width: usize,
    band: &[P],
    encode: impl Fn(P) -> u16,
    row: &mut [u16],
    sink: &mut S,
) -> Result<(), RowError<S::Error>> {
    if width == 0 || !band.len().is_multiple_of(width) {
        return Err(RowError::PartialRow {
            len: band.len(),
            width,
        });
    }
    let Some(row) = row.get_mut(..width) else {
        return Err(RowError::RowBuffer {
            needed: width,
            got: row.len(),
        });
    };
    for (k, pixels) in band.chunks_exact(width).enumerate() {
        for (o, &p) in row.iter_mut().zip(pixels) {
            *o = encode(p);
        }
        sink.row(first + k, row).map_err(RowError::Sink)?;
    }
    Ok(())
}

/// The least Q24 linear value (2²⁴ = 1) whose sRGB encoding reaches each 5-bit code 1…31: code k
/// from ⌈srgb⁻¹((k − ½) / 31) · 2²⁴⌉ (the exact curve, in f64; `tests` recomputes them).
const SRGB5: [u32; 31] = [
    20945, 63626, 122092, 203731, 310618, 444598, 607344, 800393, 1025173, 1283023, 1575204,
    1902910, 2267279, 2669399, 3110310, 3591015, 4112478, 4675632, 5281378, 5930589, 6624114,
    7362778, 8147384, 8978712, 9857526, 10784572, 11760576, 12786252, 13862296, 14989391, 16168207,
];

/// As [`SRGB5`], for the 6-bit codes 1…63 (green).
const SRGB6: [u32; 63] = [
    10306, 30918, 51530, 74733, 103120, 136968, 176540, 222085, 273834, 332010, 396822, 468469,
    547145, 633033, 726310, 827149, 935714, 1052167, 1176662, 1309352, 1450383, 1599899, 1758040,
    1924943, 2100740, 2285563, 2479540, 2682794, 2895450, 3117627, 3349443, 3591015, 3842456,
    4103878, 4375391, 4657104, 4949123, 5251554, 5564499, 5888061, 6222339, 6567434, 6923443,
    7290463, 7668588, 8057912, 8458529, 8870530, 9294006, 9729046, 10175738, 10634171, 11104431,
    11586603, 12080773, 12587023, 13105437, 13636097, 14179084, 14734479, 15302362, 15882810,
    16475904,
];

/// The code of Q24 linear value `v`: how many thresholds it reaches (a binary search).
#[inline]
fn srgb_code(v: u32, thresholds: &[u32]) -> u32 {
    thresholds.partition_point(|&t| t <= v) as u32
}

/// Q24 premultiplied RGBA (the fixed path's image, [`crate::fixed`]) → RGB565, sRGB colour over
/// black, in integers only: each channel's code is the nearest to the exact sRGB encoding of
/// its value (values above 1 clamp to the top code). Against [`super::rgb565`] of the same
/// colour in f32 it differs by at most one code, where the float curve rounds the other way.
#[inline]
pub fn rgb565_q24(p: [u32; 4]) -> u16 {
    let r = srgb_code(p[0], &SRGB5);
    let g = srgb_code(p[1], &SRGB6);
    let b = srgb_code(p[2], &SRGB5);
    ((r << 11) | (g << 5) | b) as u16
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode(e: f64) -> f64 {
        if e <= 0.04045 {
            e / 12.92
        } else {
            libm::pow((e + 0.055) / 1.055, 2.4)
        }
    }

    /// The thresholds are the exact curve's, and the integer codes agree with the float
    /// encoding within one code everywhere (sampled every 97 Q24 steps and at each threshold).
    #[test]
    fn integer_codes_follow_the_srgb_curve() {
        for (table, max) in [(&SRGB5[..], 31.0), (&SRGB6[..], 63.0)] {
            for (k, &t) in table.iter().enumerate() {
                let want = libm::ceil(decode((k as f64 + 0.5) / max) * 16_777_216.0) as u32;
                assert_eq!(t, want, "code {} of {max}", k + 1);
            }
        }
        let float = |v: u32| super::super::rgb565(crate::fixed::to_f32([v, v, v, 0]));
        let fields = |c: u16| [c >> 11, (c >> 5) & 63, c & 31].map(i32::from);
        let check = |v: u32| {
            let (i, f) = (fields(rgb565_q24([v, v, v, 0])), fields(float(v)));
            for ch in 0..3 {
                assert!((i[ch] - f[ch]).abs() <= 1, "{v}: {i:?} against {f:?}");
            }
        };
        for v in (0..=(1u32 << 24) + 5000).step_by(97) {
            check(v);
        }
        for t in SRGB5.iter().chain(&SRGB6) {
            check(t - 1);
            check(*t);
        }
        assert_eq!(rgb565_q24([0; 4]), 0);
        assert_eq!(rgb565_q24([1 << 24; 4]), 0xffff);
        assert_eq!(rgb565_q24([u32::MAX; 4]), 0xffff);
    }

    #[test]
    fn bands_leave_as_whole_rows_in_order() {
        let band: [u32; 6] = [1, 2, 3, 4, 5, 6];
        let mut row = [0u16; 3];
        let mut seen = [(0usize, [0u16; 3]); 2];
        let mut n = 0;
        let mut sink = RowFn(|y: usize, px: &[u16]| {
            seen[n] = (y, px.try_into().unwrap());
            n += 1;
        });
        band_rows(7, 3, &band, |p| p as u16 * 10, &mut row, &mut sink).unwrap();
        assert_eq!(seen, [(7, [10, 20, 30]), (8, [40, 50, 60])]);
        let mut sink = RowFn(|_: usize, _: &[u16]| {});
        assert_eq!(
            band_rows(0, 4, &band, |p| p as u16, &mut row, &mut sink),
            Err(RowError::PartialRow { len: 6, width: 4 })
        );
        assert_eq!(
            band_rows(0, 6, &band, |p| p as u16, &mut row, &mut sink),
            Err(RowError::RowBuffer { needed: 6, got: 3 })
        );
    }
}
