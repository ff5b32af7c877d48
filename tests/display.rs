//! Output a display takes (issue 44): a render's bands leave as RGB565 rows, and the
//! `embedded-graphics` adaptor (`output::DisplaySink`) draws exactly those rows into a
//! `DrawTarget`, here embedded-graphics' own `MockDisplay` (which also refuses a pixel drawn
//! twice or off its 64×64 area).

use embedded_graphics::mock_display::MockDisplay;
use embedded_graphics::pixelcolor::Rgb565;
use embedded_graphics::prelude::{IntoStorage, Point};
use footprint::output::{band_rows, rgb565, rgb565_q24, DisplaySink, RowFn};
use footprint::prelude::*;

const DIMS: [usize; 3] = [24, 20, 16];
const SIZE: [usize; 2] = [48, 40];

/// A small shaded render (premultiplied linear RGBA, row-major).
fn render() -> Vec<[f32; 4]> {
    let volume: Vec<u16> = (0..DIMS[0] * DIMS[1] * DIMS[2])
        .map(|n| {
            let (i, j, k) = (n % 24, n / 24 % 20, n / 480);
            let d = |x: usize, c: f32| (x as f32 - c).powi(2);
            let r = (d(i, 11.5) + d(j, 9.5) + d(k, 7.5)).sqrt();
            (3000.0 * (1.0 - r / 10.0).max(0.0)) as u16
        })
        .collect();
    let mut s = Settings::new(SIZE, Preset::CtBoneSkin.lut());
    (s.view, s.window) = ([30.0, 20.0, 0.0], [0.0, 3000.0]);
    let generic = GenericTable::<33>::build(s.kernel);
    let n = s.lengths(DIMS).unwrap();
    let (mut image, mut work) = (vec![[0.0; 4]; n.pixels], vec![0.0; n.work]);
    let (mut rows, mut sheets) = (vec![RowSpan::EMPTY; n.rows], vec![0; n.sheets]);
    let buffers = Buffers::new(&mut image, &mut work, &mut rows, &mut sheets);
    render_volume(&volume, DIMS, &s, &generic, buffers).unwrap();
    image
}

#[test]
fn the_display_adaptor_draws_the_band_sinks_rows() {
    let image = render();
    let width = SIZE[0];
    let mut row = [0u16; 64];
    // The band sink: rows collected as they leave, in bands of 7 rows (the last one shorter).
    let mut received: Vec<(usize, Vec<u16>)> = Vec::new();
    let mut sink = RowFn(|y: usize, px: &[u16]| received.push((y, px.to_vec())));
    // The adaptor, into a mock display with the image at (5, 3).
    let mut display = MockDisplay::<Rgb565>::new();
    let origin = Point::new(5, 3);
    let mut panel = DisplaySink::new(&mut display, origin);
    for (b, band) in image.chunks(7 * width).enumerate() {
        band_rows(7 * b, width, band, rgb565, &mut row, &mut sink).unwrap();
        band_rows(7 * b, width, band, rgb565, &mut row, &mut panel).unwrap();
    }
    assert_eq!(received.len(), SIZE[1]);
    let mut lit = 0;
    for (k, (y, px)) in received.iter().enumerate() {
        assert_eq!(*y, k, "rows leave in order");
        for (x, &c) in px.iter().enumerate() {
            assert_eq!(c, rgb565(image[y * width + x]));
            let at = Point::new(origin.x + x as i32, origin.y + *y as i32);
            let drawn = display.get_pixel(at).expect("every pixel drawn");
            assert_eq!(drawn.into_storage(), c, "pixel {x},{y}");
            lit += usize::from(c != 0);
        }
    }
    // Not vacuous: the volume shows.
    assert!(lit > 100, "{lit} lit pixels");
    assert!(display.get_pixel(Point::new(4, 3)).is_none());
    assert!(display
        .get_pixel(Point::new(5 + SIZE[0] as i32, 3))
        .is_none());
}

/// The fixed path's pixels (Q24) encode without floating point to the float encoding of the same
/// colour within one code per channel, on a real render's every pixel.
#[test]
fn fixed_pixels_encode_as_their_float_colour() {
    let image = render();
    for p in image {
        let q = footprint::fixed::quantise(p);
        let (i, f) = (rgb565_q24(q), rgb565(footprint::fixed::to_f32(q)));
        let fields = |c: u16| [c >> 11, (c >> 5) & 63, c & 31].map(i32::from);
        for (a, b) in fields(i).iter().zip(fields(f)) {
            assert!((a - b).abs() <= 1, "{p:?}: {i:#06x} against {f:#06x}");
        }
    }
}
