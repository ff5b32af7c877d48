//! Rendering a volume that is already in memory with the core alone: a `&[u16]` volume (x fastest,
//! as raw files and most formats store it) wrapped as a `MemoryVolume`, a view from angles fitted
//! to the image, and the result converted to 8-bit sRGB and to RGB565 (what a small display
//! takes).
//!
//! `cargo run -p footprint --example in_memory` prints an ASCII picture and the counts.

// `core/clippy.toml` bans floats for the fixed-point modules only.
#![allow(clippy::disallowed_types)]

use footprint::composite::RowSpan;
use footprint::frame::{FrameSetup, Order};
use footprint::output::{rgb565, srgb8};
use footprint::render::{RenderBuffers, SheetRenderer, SheetRing};
use footprint::shade::{Shader, Shading, TransferFunction};
use footprint::source::render_from;
use footprint::volume::MemoryVolume;
use footprint::{FootprintOptions, GenericTable, Grid, Kernel, Lookup, View, ViewTable};

const DIMS: [usize; 3] = [40, 32, 24];
const SIZE: [usize; 2] = [48, 32];

fn main() -> Result<(), footprint::Error> {
    // A hollow ellipsoid shell with a dense core, 40×32×24 samples on a 1:1:1.5 grid.
    let data: Vec<u16> = (0..DIMS[2])
        .flat_map(|k| (0..DIMS[1]).flat_map(move |j| (0..DIMS[0]).map(move |i| (i, j, k))))
        .map(|(i, j, k)| {
            let p = [i, j, k].map(|v| v as f32);
            let c = DIMS.map(|n| (n as f32 - 1.0) / 2.0);
            let r = ((p[0] - c[0]) / c[0])
                .hypot((p[1] - c[1]) / c[1])
                .hypot((p[2] - c[2]) / c[2]);
            let shell = (1.0 - ((r - 0.8) / 0.1).abs()).max(0.0);
            let core = (1.0 - r / 0.3).max(0.0);
            (4000.0 * shell.max(core)) as u16
        })
        .collect();
    let mut volume = MemoryVolume::new(&data, DIMS)?;
    let (lo, hi) = volume.range().unwrap_or((0.0, 1.0));
    let grid = Grid::from_spacing([1.0, 1.0, 1.5])?;
    let view = View::from_angles([35.0, 25.0, 0.0], 1.0, DIMS, &grid, SIZE)?;
    let kernel = Kernel::PAPER_GAUSSIAN;
    let frame = FrameSetup::new(
        DIMS,
        &grid,
        &view,
        &kernel,
        FootprintOptions::default(),
        SIZE,
    )?;
    let generic = GenericTable::<65>::build(kernel);
    let table = ViewTable::<65>::build(
        &frame.footprint,
        &generic,
        Lookup::Bilinear,
        Lookup::Bilinear,
    );
    let lut = [[0.0; 4], [0.9, 0.6, 0.3, 0.15], [1.0, 1.0, 1.0, 0.6]];
    let shader = Shader {
        tf: TransferFunction { lut: &lut, lo, hi },
        shading: Shading::Emission,
    };
    let n = frame.image_len();
    let (mut acc, mut image, mut rows) = (
        vec![[0.0f32; 4]; n],
        vec![[0.0f32; 4]; n],
        vec![RowSpan::EMPTY; SIZE[1]],
    );
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image: &mut image,
        rows: &mut rows,
    };
    let order = Order::BackToFront;
    let mut renderer = SheetRenderer::new(&frame, &table, shader, order, buffers, None)?;
    let mut sheets = vec![0u16; 3 * frame.sheet_shape().0];
    let mut ring = SheetRing::new(&mut sheets, &frame, order)?;
    render_from(&mut renderer, &mut ring, &mut volume)?;
    let stats = renderer.finish();

    let srgb: Vec<[u8; 4]> = image.iter().map(|p| srgb8(*p)).collect();
    let panel: Vec<u16> = image.iter().map(|p| rgb565(*p)).collect();
    for row in srgb.chunks(SIZE[0]) {
        let line: String = row
            .iter()
            .map(|p| b" .:-=+*#%@"[usize::from(p[1]) * 9 / 255] as char)
            .collect();
        println!("{line}");
    }
    let lit = srgb.iter().filter(|p| p[3] > 0).count();
    println!(
        "{} sheets, {} voxels splatted, {} of {} pixels covered; RGB565 of the centre pixel: {:#06x}",
        stats.sheets,
        stats.voxels_splatted,
        lit,
        n,
        panel[n / 2 + SIZE[0] / 2]
    );
    Ok(())
}
