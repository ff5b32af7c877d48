//! A volume in memory to a PNG, the same bytes as `footprint render V.raw --dims 64,64,48 --type u16
//! --spacing 1,1,1.5 --view 30,20,0 --tf ct-bone-skin --window 0,4000 --shading phong --size 256x256
//! --slicing object` (the core renders object slicing; the CLI's default plan measures its choice)
#![allow(clippy::disallowed_types)] // core/clippy.toml bans floats in the fixed-point modules.
use footprint::prelude::*;

pub const DIMS: [usize; 3] = [64, 64, 48];

/// A dense core (3000) in an ellipsoid shell (1200), x fastest (tests/library.rs renders it both ways).
pub fn volume() -> Vec<u16> {
    let t = |n: usize, d: usize| ((n % d) as f32 / (d - 1) as f32 * 2.0 - 1.0).powi(2);
    let r = |n: usize| (t(n, 64) + t(n / 64, 64) + t(n / 4096, 48)).sqrt();
    let v = |r: f32| 3000 * u16::from(r < 0.4) + 1200 * u16::from((r - 0.85).abs() < 0.08);
    (0..64 * 64 * 48).map(|n| v(r(n))).collect()
}

pub fn render_png(path: &str) -> Result<(), Box<dyn std::error::Error>> {
    let mut s = Settings::new([256, 256], Preset::CtBoneSkin.lut());
    (s.spacing, s.view, s.window) = ([1.0, 1.0, 1.5], [30.0, 20.0, 0.0], [0.0, 4000.0]);
    s.shading = Shading::Phong(Phong::default());
    let (n, generic) = (s.lengths(DIMS)?, GenericTable::<129>::build(s.kernel)); // CLI's --table
    let (mut image, mut work) = (vec![[0.0; 4]; n.pixels], vec![0.0; n.work]);
    let (mut rows, mut sheets) = (vec![RowSpan::EMPTY; n.rows], vec![0; n.sheets]);
    let buffers = Buffers::new(&mut image, &mut work, &mut rows, &mut sheets);
    render_volume(&volume(), DIMS, &s, &generic, buffers)?;
    let rgb: Vec<u8> = image
        .iter()
        .flat_map(|&p| linear8(p).into_iter().take(3))
        .collect();
    let mut png = png::Encoder::new(std::fs::File::create(path)?, 256, 256);
    png.set_color(png::ColorType::Rgb);
    Ok(png.write_header()?.write_image_data(&rgb)?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1);
    render_png(path.as_deref().unwrap_or("in_memory.png"))
}
