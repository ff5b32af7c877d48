//! Streaming voxels from an outside source with the core alone (no harness, no files): a
//! `SheetSource` standing in for a sensor that produces one z-slice at a time, in order, like a
//! scanner or a camera stack. The renderer keeps three slices; the volume is never in memory.
//!
//! `cargo run -p footprint --example sensor_stream` prints an ASCII picture of the result and its
//! counts. On a small target the same code runs with `static` buffers instead of `Vec`s.

// `core/clippy.toml` bans floats for the fixed-point modules only.
#![allow(clippy::disallowed_types)]

use footprint::composite::RowSpan;
use footprint::frame::{FrameSetup, Order};
use footprint::geometry::FootprintOptions;
use footprint::render::{RenderBuffers, RenderError, SheetRenderer, SheetRing};
use footprint::shade::{Shader, Shading, TransferFunction};
use footprint::source::{order_for, render_from, SheetSource};
use footprint::{GenericTable, Grid, Kernel, Lookup, View, ViewTable};

const N: usize = 48;
const SIDE: usize = 40;

/// A "sensor" that measures a torus, one z-slice per call, in order only.
struct TorusSensor {
    next: usize,
}

#[derive(Debug)]
enum SensorError {
    OutOfOrder,
    Setup(footprint::Error),
    Render(RenderError),
}

impl core::fmt::Display for SensorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SensorError::OutOfOrder => f.write_str("the sensor was asked for a slice out of order"),
            SensorError::Setup(e) => write!(f, "set-up: {e}"),
            SensorError::Render(e) => write!(f, "render: {e}"),
        }
    }
}

impl From<RenderError> for SensorError {
    fn from(e: RenderError) -> Self {
        SensorError::Render(e)
    }
}

impl SheetSource for TorusSensor {
    type Sample = u8;
    type Error = SensorError;

    fn read_sheet(&mut self, axis: usize, index: usize, out: &mut [u8]) -> Result<(), SensorError> {
        if axis != 2 || index != self.next {
            return Err(SensorError::OutOfOrder);
        }
        let c = (N as f32 - 1.0) / 2.0;
        for j in 0..N {
            for i in 0..N {
                let (x, y, z) = (i as f32 - c, j as f32 - c, index as f32 - c);
                let ring = ((x * x + y * y).sqrt() - 14.0).hypot(z * 1.5);
                out[j * N + i] = (255.0 * (1.0 - ring / 7.0).clamp(0.0, 1.0)) as u8;
            }
        }
        self.next += 1;
        Ok(())
    }

    fn sequential_axis(&self) -> Option<usize> {
        Some(2)
    }
}

fn main() {
    if let Err(e) = run() {
        eprintln!("sensor_stream: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), SensorError> {
    let setup = |e: footprint::Error| SensorError::Setup(e);
    let kernel = Kernel::PAPER_GAUSSIAN;
    let grid = Grid::from_spacing([1.0; 3]).map_err(|e| setup(e.into()))?;
    // Tilted 30° about x: sheets still run along z, so a sequential sensor can serve it.
    let view = View::new(glam::Mat3::from_rotation_x(0.52) * 0.8).map_err(|e| setup(e.into()))?;
    let frame = FrameSetup::new(
        [N; 3],
        &grid,
        &view,
        &kernel,
        FootprintOptions::default(),
        [SIDE, SIDE],
    )
    .map_err(|e| setup(e.into()))?;
    let mut sensor = TorusSensor { next: 0 };
    // A sequential sensor imposes the compositing order; a view whose sheets are not z-slices
    // would be refused here.
    let order =
        order_for(&sensor, &frame, Order::BackToFront).map_err(|_| SensorError::OutOfOrder)?;
    let generic = GenericTable::<33>::build(kernel);
    let table = ViewTable::<33>::build(
        &frame.footprint,
        &generic,
        Lookup::Bilinear,
        Lookup::Bilinear,
    );
    let lut: [[f32; 4]; 2] = [[0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 0.35]];
    let shader = Shader {
        labels: None,
        tf: TransferFunction {
            lut: &lut,
            lo: 0.0,
            hi: 255.0,
        },
        shading: Shading::Emission,
    };
    let n = frame.image_len();
    let (mut acc, mut img, mut rows) = (
        vec![[0.0f32; 4]; n],
        vec![[0.0f32; 4]; n],
        vec![RowSpan::EMPTY; SIDE],
    );
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    let mut renderer = SheetRenderer::new(&frame, &table, shader, order, buffers, None)?;
    let mut storage = vec![0u8; 3 * N * N];
    let mut ring = SheetRing::new(&mut storage, &frame, order)?;
    render_from(&mut renderer, &mut ring, &mut sensor)?;
    let stats = renderer.finish();
    for y in (0..SIDE).step_by(2) {
        let line: String = (0..SIDE)
            .map(|x| b" .:-=+*#%@"[((img[y * SIDE + x][3] * 9.99) as usize).min(9)] as char)
            .collect();
        println!("{line}");
    }
    println!(
        "{order:?}: {} sheets, {} voxels, {} splatted, {} pixel updates; the sensor was read {} times",
        stats.sheets, stats.voxels, stats.voxels_splatted, stats.pixel_updates, sensor.next
    );
    Ok(())
}
