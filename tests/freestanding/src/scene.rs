// The freestanding program's scene, shared with the host test `tests/freestanding_scene.rs` via
// `include!`: the paper Gaussian, spacing 3,1.5,1.5, a view turned 30° about the view axis and 20°
// about x (literal cosines, so no trig backend is involved), zoom 4, one voxel at (32.25, 31.5)
// in a 64×64 image.

use footprint::geometry::{Footprint, FootprintOptions};
use footprint::splat::{splat, ImageMut};
use footprint::{GenericTable, Grid, Kernel, Lookup, View, ViewTable};

/// Image side, pixels.
pub const SIDE: usize = 64;

/// FNV-1a over the little-endian bytes of every pixel.
pub fn checksum(pixels: &[f32]) -> u32 {
    let mut h = 0x811c_9dc5u32;
    for p in pixels {
        for b in p.to_le_bytes() {
            h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
        }
    }
    h
}

/// Renders the scene into `pixels` (SIDE × SIDE, zeroed) and returns the sum of the weights,
/// which should be one to within the table's error.
pub fn render(pixels: &mut [f32]) -> Result<f32, footprint::Error> {
    let kernel = Kernel::parse("gaussian:spread=1.6,sigmas=2.5")?;
    let generic = GenericTable::<33>::build(kernel);
    let grid = Grid::from_spacing([3.0, 1.5, 1.5])?;
    let (c30, s30, c20, s20) = (0.866_025_4f32, 0.5f32, 0.939_692_6f32, 0.342_020_15f32);
    let rz = glam::Mat3::from_cols_array(&[c30, s30, 0.0, -s30, c30, 0.0, 0.0, 0.0, 1.0]);
    let rx = glam::Mat3::from_cols_array(&[1.0, 0.0, 0.0, 0.0, c20, s20, 0.0, -s20, c20]);
    let view = View::new(rz * rx * 4.0)?;
    let fp = Footprint::new(&kernel, &view.grid_to_screen(&grid), FootprintOptions::default())?;
    let table = ViewTable::<33>::build(&fp, &generic, Lookup::Bilinear, Lookup::Bilinear);
    let mut image = ImageMut::new(pixels, SIDE, SIDE, SIDE)?;
    splat(&table, [32.25, 31.5], &1.0f32, &mut image)?;
    Ok(pixels.iter().sum())
}
