//! The embedded demo scene, shared by the firmware (`embedded/firmware`) and the host
//! (`embedded/host`) so both render exactly the same thing: a 32×32×32 volume of `u8` samples,
//! generated sheet by sheet from integer formulas (the volume is never in memory, as if streamed
//! from a sensor), seen at azimuth 30°, elevation 20°, into a 64×64 image, with the paper's
//! Gaussian and a 33×33 table.
//!
//! Every buffer is borrowed through [`FixedBuffers`] / [`FloatBuffers`]; the firmware keeps them
//! in `static`s: no heap. The fixed path shades through a 256-entry integer lookup table built once
//! per view, so its per-voxel and per-pixel work is integer only.
#![no_std]
#![forbid(unsafe_code)]

use footprint::composite::RowSpan;
use footprint::fixed::{self, FixedTable};
use footprint::frame::{FrameSetup, Order};
use footprint::geometry::FootprintOptions;
use footprint::math;
use footprint::render::{FixedPath, RenderBuffers, RenderStats, SheetRenderer};
use footprint::shade::{Lighting, Shader, Shading, TransferFunction};
use footprint::{GenericTable, Grid, Kernel, Lookup, View, ViewTable};
use glam::{Mat3, Vec3};

/// Voxels along each axis.
pub const DIM: usize = 32;
/// Image width and height, pixels.
pub const SIDE: usize = 64;
/// Pixels in the image.
pub const PIXELS: usize = SIDE * SIDE;
/// Generic and view table size (N×N nodes).
pub const N: usize = 33;
/// Compositing order.
pub const ORDER: Order = Order::BackToFront;

/// The transfer function over sample values 0…255 (straight RGBA).
const TF: [[f32; 4]; 5] = [
    [0.0, 0.0, 0.0, 0.0],
    [0.9, 0.3, 0.1, 0.02],
    [1.0, 0.7, 0.2, 0.08],
    [0.6, 0.8, 1.0, 0.3],
    [1.0, 1.0, 1.0, 0.6],
];

/// Sample (i, j, k): a shell with a striped band, around a soft core. Integer arithmetic only.
pub fn sample(i: usize, j: usize, k: usize) -> u8 {
    let d = |x: usize| (2 * x as i32 - (DIM as i32 - 1)).pow(2);
    let r2 = d(i) + d(j) + d(k); // (2r)², 0 … 2883
    if (700..900).contains(&r2) {
        (150 + ((i + 2 * j + 3 * k) % 16) * 6) as u8
    } else if r2 < 400 {
        (255 - r2 * 200 / 400) as u8
    } else {
        0
    }
}

/// The view: V = zoom · Rx(20°) · Ry(30°) from the core's own `sin`/`cos` (the same bits on
/// every target).
pub fn view_matrix() -> Mat3 {
    let (az, el, zoom) = (30.0f32.to_radians(), 20.0f32.to_radians(), 1.3f32);
    let (sa, ca, se, ce) = (math::sin(az), math::cos(az), math::sin(el), math::cos(el));
    let ry = Mat3::from_cols(
        Vec3::new(ca, 0.0, -sa),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(sa, 0.0, ca),
    );
    let rx = Mat3::from_cols(
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, ce, se),
        Vec3::new(0.0, -se, ce),
    );
    rx * ry * zoom
}

/// The frame of the scene.
pub fn frame() -> Result<FrameSetup, footprint::Error> {
    Ok(FrameSetup::new(
        [DIM; 3],
        &Grid::from_spacing([1.0; 3])?,
        &View::new(view_matrix())?,
        &Kernel::PAPER_GAUSSIAN,
        FootprintOptions::default(),
        [SIDE; 2],
    )?)
}

fn shader() -> Shader<'static> {
    Shader {
        tf: TransferFunction {
            lut: &TF,
            lo: 0.0,
            hi: 255.0,
        },
        shading: Shading::Emission,
    }
}

/// What a render reports.
#[derive(Clone, Copy, Debug)]
pub struct Report {
    /// CRC-32 of the image ([`fixed::checksum`] for fixed; the f32 bits for float).
    pub checksum: u32,
    /// Counts.
    pub stats: RenderStats,
}

/// Every buffer of a fixed-point render, borrowed (the firmware's are separate `static`s, so the
/// all-zero ones land in `.bss` and cost no flash). Bytes: see README "Embedding".
pub struct FixedBuffers<'a> {
    /// The kernel's generic table (f32, built once).
    pub generic: &'a mut GenericTable<N>,
    /// The view's integer table.
    pub table: &'a mut FixedTable<N>,
    /// Shaded value per sample value, Q24 premultiplied RGBA (built per view).
    pub lut: &'a mut [[u32; 4]; 256],
    /// One sheet of shaded values.
    pub sheet: &'a mut [[u32; 4]; DIM * DIM],
    /// Sheet accumulator.
    pub acc: &'a mut [[i64; 4]; PIXELS],
    /// Working image (Q24 premultiplied RGBA): the result.
    pub image: &'a mut [[u32; 4]; PIXELS],
    /// Touched span per row.
    pub rows: &'a mut [RowSpan; SIDE],
}

/// Renders the scene with fixed-point accumulation into `b.image`.
#[inline(never)]
pub fn render_fixed(b: FixedBuffers<'_>) -> Result<Report, footprint::Error> {
    let f = frame()?;
    // Per-view set-up (float): tables and the shading lookup.
    b.generic.build_into(Kernel::PAPER_GAUSSIAN);
    b.table
        .build_view(&f, b.generic, Lookup::Bilinear, Lookup::Bilinear)?;
    let (shader, lighting) = (shader(), Lighting::new(&f));
    for (v, entry) in b.lut.iter_mut().enumerate() {
        let rgba = shader.shade(&lighting, v as f32, || Vec3::ZERO, [0; 3], f.dims);
        *entry = fixed::quantise(rgba);
    }
    // Per voxel and per pixel: integers only.
    let path = FixedPath::new(&f, b.table)?;
    let buffers = RenderBuffers {
        accumulator: &mut b.acc[..],
        image: &mut b.image[..],
        rows: &mut b.rows[..],
    };
    let mut r = SheetRenderer::with_path(&f, path, shader, ORDER, buffers, None)?;
    for step in 0..f.sheet_count() {
        let s = f.sheet_at(ORDER, step);
        fill_sheet(&f, s, &mut b.sheet[..], |x| b.lut[x as usize]);
        r.render_value_sheet(s, &b.sheet[..])?;
    }
    let stats = r.finish();
    Ok(Report {
        checksum: fixed::checksum(&b.image[..]),
        stats,
    })
}

/// Every buffer of a float render, borrowed.
pub struct FloatBuffers<'a> {
    /// The kernel's generic table.
    pub generic: &'a mut GenericTable<N>,
    /// The view table.
    pub table: &'a mut ViewTable<N>,
    /// One sheet of shaded values.
    pub sheet: &'a mut [[f32; 4]; DIM * DIM],
    /// Sheet accumulator.
    pub acc: &'a mut [[f32; 4]; PIXELS],
    /// Working image: the result.
    pub image: &'a mut [[f32; 4]; PIXELS],
    /// Touched span per row.
    pub rows: &'a mut [RowSpan; SIDE],
}

/// Renders the scene with float accumulation into `b.image` (the same shading, unquantised).
#[inline(never)]
pub fn render_float(b: FloatBuffers<'_>) -> Result<Report, footprint::Error> {
    let f = frame()?;
    b.generic.build_into(Kernel::PAPER_GAUSSIAN);
    b.table
        .build_into(&f.footprint, b.generic, Lookup::Bilinear, Lookup::Bilinear);
    let (shader, lighting) = (shader(), Lighting::new(&f));
    let buffers = RenderBuffers {
        accumulator: &mut b.acc[..],
        image: &mut b.image[..],
        rows: &mut b.rows[..],
    };
    let mut r = SheetRenderer::new(&f, &*b.table, shader, ORDER, buffers, None)?;
    for step in 0..f.sheet_count() {
        let s = f.sheet_at(ORDER, step);
        fill_sheet(&f, s, &mut b.sheet[..], |x| {
            shader.shade(&lighting, f32::from(x), || Vec3::ZERO, [0; 3], f.dims)
        });
        r.render_shaded_sheet(s, &b.sheet[..])?;
    }
    let stats = r.finish();
    let mut crc = footprint::table::Crc32::new();
    for c in b.image.as_flattened() {
        crc.update(&c.to_bits().to_le_bytes());
    }
    Ok(Report {
        checksum: crc.finish(),
        stats,
    })
}

/// Generates sheet `s` in the frame's sheet layout, shading each sample with `shade`.
fn fill_sheet<V>(f: &FrameSetup, s: usize, out: &mut [V], mut shade: impl FnMut(u8) -> V) {
    let na = f.sheet_shape().1;
    for (n, o) in out.iter_mut().enumerate() {
        let [i, j, k] = f.grid_index(s, n % na, n / na);
        *o = shade(sample(i, j, k));
    }
}
