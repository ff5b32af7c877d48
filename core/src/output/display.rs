//! Rows into an `embedded-graphics` display (the `embedded-graphics` feature): any
//! `DrawTarget<Color = Rgb565>`, the trait display drivers of that ecosystem implement, takes a
//! band's rows as they are encoded ([`super::band_rows`]), each as one `fill_contiguous` of a
//! one-row rectangle, so a driver with a window write sends it in one transfer and no frame
//! buffer is needed.

use super::RowSink;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::pixelcolor::raw::RawU16;
use embedded_graphics_core::pixelcolor::Rgb565;
use embedded_graphics_core::primitives::Rectangle;

/// A [`RowSink`] that draws image row y at display row `origin.y + y`, from column `origin.x`.
pub struct DisplaySink<'d, D> {
    display: &'d mut D,
    origin: Point,
}

impl<'d, D: DrawTarget<Color = Rgb565>> DisplaySink<'d, D> {
    /// Draws into `display` with the image's top-left pixel at `origin` (display pixels).
    pub fn new(display: &'d mut D, origin: Point) -> Self {
        DisplaySink { display, origin }
    }
}

impl<D: DrawTarget<Color = Rgb565>> RowSink for DisplaySink<'_, D> {
    type Error = D::Error;

    fn row(&mut self, y: usize, pixels: &[u16]) -> Result<(), D::Error> {
        // Rows and widths beyond i32 / u32 cannot be on a display; they saturate and the target
        // clips them.
        let y = i32::try_from(y).unwrap_or(i32::MAX);
        let width = u32::try_from(pixels.len()).unwrap_or(u32::MAX);
        let area = Rectangle::new(
            Point::new(self.origin.x, self.origin.y.saturating_add(y)),
            Size::new(width, 1),
        );
        let colours = pixels.iter().map(|&c| Rgb565::from(RawU16::new(c)));
        self.display.fill_contiguous(&area, colours)
    }
}
