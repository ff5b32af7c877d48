//! The display end of the demo (issue 44): each finished band leaves as RGB565 rows
//! ([`footprint::output::band_rows`]) drawn through the core's `embedded-graphics` adaptor
//! ([`DisplaySink`]) into [`CrcDisplay`], a `DrawTarget` with no frame buffer that keeps only the
//! CRC-32 of the pixels it receives, in order. The firmware and the host send the same rows to
//! it, so the CRC it reports is what a real display behind the same adaptor would have been sent.

use core::convert::Infallible;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, Point, Size};
use embedded_graphics_core::pixelcolor::{IntoStorage, Rgb565};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use footprint::output::{band_rows, rgb565_q24, DisplaySink, RowError};
use footprint::table::Crc32;

/// A `side`×`side` display that stores nothing: the CRC-32 of every pixel drawn inside it (each
/// as its RGB565 value in two little-endian bytes), and how many were drawn.
pub struct CrcDisplay {
    side: u32,
    crc: Crc32,
    drawn: usize,
}

impl CrcDisplay {
    /// An empty display of `side`×`side` pixels.
    pub fn new(side: usize) -> Self {
        CrcDisplay {
            side: side as u32,
            crc: Crc32::new(),
            drawn: 0,
        }
    }

    /// The CRC of what was drawn, and how many pixels.
    pub fn finish(&self) -> (u32, usize) {
        (self.crc.finish(), self.drawn)
    }
}

impl Dimensions for CrcDisplay {
    fn bounding_box(&self) -> Rectangle {
        Rectangle::new(Point::zero(), Size::new(self.side, self.side))
    }
}

impl DrawTarget for CrcDisplay {
    type Color = Rgb565;
    type Error = Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb565>>>(
        &mut self,
        pixels: I,
    ) -> Result<(), Infallible> {
        let area = self.bounding_box();
        for Pixel(p, c) in pixels {
            if area.contains(p) {
                self.crc.update(&c.into_storage().to_le_bytes());
                self.drawn += 1;
            }
        }
        Ok(())
    }
}

/// Sends a finished fixed-point band (rows from `first`, `width` pixels each, Q24) to `display`
/// through the core's adaptor, encoded in `row` (at least `width` long).
pub fn send_band(
    first: usize,
    width: usize,
    band: &[[u32; 4]],
    row: &mut [u16],
    display: &mut CrcDisplay,
) -> Result<(), RowError<Infallible>> {
    let mut sink = DisplaySink::new(display, Point::zero());
    band_rows(first, width, band, rgb565_q24, row, &mut sink)
}

/// [`send_band`] for a compact (Q15) band: each pixel widened to Q24 (exact) and encoded as
/// [`send_band`] encodes it, so equal images send equal rows.
pub fn send_band_q15(
    first: usize,
    width: usize,
    band: &[[u16; 4]],
    row: &mut [u16],
    display: &mut CrcDisplay,
) -> Result<(), RowError<Infallible>> {
    let mut sink = DisplaySink::new(display, Point::zero());
    let encode = |p: [u16; 4]| rgb565_q24(footprint::fixed::compact::to_q24(p));
    band_rows(first, width, band, encode, row, &mut sink)
}
