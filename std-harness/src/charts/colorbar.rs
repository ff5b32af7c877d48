//! `render --colorbar`: the transfer function's legend drawn into the image. A panel at the right
//! edge, vertically centred, holds a bar of the table's colours (straight, fully opaque: what a
//! sample of that value emits), a white line for its opacity (left edge 0, right edge 1; opacity
//! per world unit, before the renderer's spacing correction) and the window's values at the top,
//! middle and bottom, in data units. The panel is opaque black, drawn over the finished image
//! (and each frame of an `--orbit`), so it reads the same on any volume.

use super::plot::{plot_err, register_font};
use crate::CliError;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// The panel's size and place for a `w` × `h` image: (x, y, width, height), pixels. `None` when
/// the image is too small to hold a legible legend (under 48 × 48).
pub fn panel(w: usize, h: usize) -> Option<(usize, usize, usize, usize)> {
    if w < 48 || h < 48 {
        return None;
    }
    let pw = (w / 5).clamp(40, 140);
    let ph = (h * 7 / 10).max(40);
    Some((w - pw - w / 64, (h - ph) / 2, pw, ph))
}

/// A window value as a short label: at most 4 significant digits, no trailing zeros.
fn label(v: f64) -> String {
    if v != 0.0 && !(1e-3..1e5).contains(&v.abs()) {
        return format!("{v:.2e}");
    }
    let s = format!(
        "{:.*}",
        3usize.saturating_sub(v.abs().log10().floor().max(0.0) as usize),
        v
    );
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    s.to_string()
}

/// Draws the legend of `lut` (straight RGBA, evenly spaced over `window`) into `image`
/// (premultiplied linear RGBA, `w` × `h`, row-major). Too small an image is left as it is, and
/// says so on stderr.
pub fn draw(
    image: &mut [[f32; 4]],
    (w, h): (usize, usize),
    lut: &[[f32; 4]],
    window: [f64; 2],
) -> Result<(), CliError> {
    let Some((x0, y0, pw, ph)) = panel(w, h) else {
        crate::warn!("--colorbar: a {w}x{h} image is too small for a legend (48x48 at least)");
        return Ok(());
    };
    register_font()?;
    let font = (ph / 14).clamp(9, 16) as f64;
    let mut rgb = vec![0u8; pw * ph * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (pw as u32, ph as u32)).into_drawing_area();
        root.fill(&BLACK).map_err(plot_err)?;
        let (pad, bar_w) = (font as i32 / 2 + 2, (pw as i32 / 5).max(6));
        let (top, bottom) = (pad, ph as i32 - pad);
        let x = pw as i32 - bar_w - 3;
        let n = lut.len().max(1);
        let entry = |y: i32| {
            let t = f64::from(bottom - y) / f64::from((bottom - top).max(1));
            lut[((t * (n - 1) as f64).round() as usize).min(n - 1)]
        };
        for y in top..=bottom {
            let c = entry(y).map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8);
            let style = RGBColor(c[0], c[1], c[2]).filled();
            root.draw(&Rectangle::new([(x, y), (x + bar_w, y + 1)], style))
                .map_err(plot_err)?;
        }
        let opacity: Vec<(i32, i32)> = (top..=bottom)
            .map(|y| {
                (
                    x + (entry(y)[3].clamp(0.0, 1.0) * bar_w as f32).round() as i32,
                    y,
                )
            })
            .collect();
        root.draw(&PathElement::new(opacity, WHITE.stroke_width(1)))
            .map_err(plot_err)?;
        let style = ("sans-serif", font).into_font().color(&WHITE);
        let mid = (window[0] + window[1]) / 2.0;
        for (v, y) in [
            (window[1], top),
            (mid, (top + bottom) / 2),
            (window[0], bottom),
        ] {
            let pos = Pos::new(HPos::Right, VPos::Center);
            let text = Text::new(label(v), (x - 4, y), style.clone().pos(pos));
            root.draw(&text).map_err(plot_err)?;
        }
        root.present().map_err(plot_err)?;
    }
    for (row, line) in rgb.chunks_exact(pw * 3).enumerate() {
        let start = (y0 + row) * w + x0;
        for (px, c) in image[start..start + pw]
            .iter_mut()
            .zip(line.chunks_exact(3))
        {
            let v = |i: usize| f32::from(c[i]) / 255.0;
            *px = [v(0), v(1), v(2), 1.0];
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_short() {
        assert_eq!(label(1200.0), "1200");
        assert_eq!(label(0.5), "0.5");
        assert_eq!(label(-1024.0), "-1024");
        assert_eq!(label(12.3456), "12.35");
        assert_eq!(label(3.0e38), "3.00e38");
        assert_eq!(label(0.0), "0");
    }

    #[test]
    fn the_legend_shows_the_table_and_leaves_the_rest() {
        let (w, h) = (200, 160);
        let mut image = vec![[0.1, 0.2, 0.3, 0.5]; w * h];
        let lut = footprint::shade::Preset::Density.lut();
        draw(&mut image, (w, h), lut, [0.0, 1.0]).unwrap();
        let (x0, y0, pw, ph) = panel(w, h).unwrap();
        assert_eq!(
            image[0],
            [0.1, 0.2, 0.3, 0.5],
            "outside the panel untouched"
        );
        assert!(
            (y0..y0 + ph).all(|y| image[y * w + x0][3] == 1.0),
            "the panel is opaque"
        );
        // The bar's colours run from the table's low end (bottom) to its high end (top): the
        // density preset is blue below and red above.
        let col = x0 + pw - 3 - (pw / 5).max(6) / 2 - 2;
        let (low, high) = (image[(y0 + ph - 12) * w + col], image[(y0 + 12) * w + col]);
        assert!(low[2] > low[0] && high[0] > high[2], "{low:?} {high:?}");
        let mut small = vec![[0.0; 4]; 40 * 40];
        draw(&mut small, (40, 40), lut, [0.0, 1.0]).unwrap();
        assert!(small.iter().all(|p| *p == [0.0; 4]));
    }
}
