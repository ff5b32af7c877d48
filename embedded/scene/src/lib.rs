//! The embedded demo scene, shared by the firmware (`embedded/firmware`) and the host
//! (`embedded/host`) so both render exactly the same thing: a 32×32×32 volume of `u8` samples,
//! generated voxel by voxel from integer formulas (the volume is never in memory, as if streamed
//! from a sensor), seen at azimuth 30°, elevation 20°, with the paper's Gaussian and a 33×33
//! table: 64×64 on the MPS2 boards and the host, 48×48 on the micro:bit.
//!
//! **Memory follows the target, not the image.** The generic table is `const` data (flash),
//! read from the table file `footprint tables` wrote ([`GENERIC`]). Each voxel is shaded
//! straight from its sample through a 256-entry integer table as it is splatted
//! ([`SheetRenderer::render_sheet_with`]): no sheet of shaded values is stored. The image is
//! rendered in bands of rows, as many as the caller's buffers hold ([`FixedBuffers::rows`]), the
//! volume streamed once per band; each finished band is handed to the caller (`emit`) and its
//! buffers reused. Bands are bit-identical to a whole-image render, so the checksum does not
//! depend on the band height.
//!
//! Every buffer is borrowed through [`FixedBuffers`] / [`FloatBuffers`]; the firmware keeps them
//! in `static`s: no heap. The fixed path's per-voxel and per-pixel work is integer only.
#![no_std]
#![forbid(unsafe_code)]

use footprint::composite::RowSpan;
use footprint::fixed::compact::{self, CompactError, CompactStencils};
use footprint::fixed::{self, FixedTable};
use footprint::frame::{FrameSetup, Order};
use footprint::geometry::FootprintOptions;
use footprint::math;
use footprint::render::{
    CompactPath, FixedPath, Precision, RenderBuffers, RenderStats, SheetRenderer,
};
use footprint::shade::{Lighting, Shader, Shading, TransferFunction};
use footprint::splat::Direct;
use footprint::table::Crc32;
use footprint::{GenericTable, Grid, Kernel, Lookup, View, ViewTable};
use glam::{Mat3, Vec3};

pub mod display;

/// Voxels along each axis.
pub const DIM: usize = 32;
/// Image width and height on the MPS2 boards and the host, pixels.
pub const SIDE: usize = 64;
/// Image width and height on the micro:bit (16 KiB of RAM), pixels.
pub const SIDE_MICROBIT: usize = 48;
/// Image width and height on the STM32F100 (8 KiB of RAM), pixels.
pub const SIDE_STM32: usize = 32;
/// Image side of the M4F's bigger picture (QEMU mps2-an386, `--features side128`), pixels.
pub const SIDE_M4F_LARGE: usize = 128;
/// Generic and view table size (N×N nodes).
pub const N: usize = 33;

/// The paper Gaussian's generic table, from the table file `footprint tables --kernel
/// gaussian:spread=1.6,sigmas=2.5 --size 33` wrote, checked and decoded at compile time: it
/// lives in flash. (`tests/table_format.rs` checks it equals the table the core builds for that
/// kernel, and what the run-time loader reads from the file.)
pub static GENERIC: GenericTable<N> =
    GenericTable::from_file_const(Kernel::PAPER_GAUSSIAN, include_bytes!("../gaussian-33.fpt"));
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
        // 255 − ⌊r2 · 200 / 400⌋, written as the shift it is (a Cortex-M0 has no divider).
        (255 - r2 / 2) as u8
    } else {
        0
    }
}

/// Degrees the orbit turns the view (about the vertical axis) from one frame to the next.
pub const ORBIT_STEP_DEG: f32 = 5.0;

/// The voxels `u` of row `v` of sheet `s` that can be non-zero: those inside the shell's outer
/// sphere, (2r)² < 900 (the source knows where it is empty, so the renderer skips the rest in
/// bulk, unvisited). The sphere is symmetric in the axes, so whichever axes the sheets run
/// along, the range is the same. Integer arithmetic only.
pub fn occupied(s: usize, v: usize) -> core::ops::Range<usize> {
    let d = |x: usize| (2 * x as i32 - (DIM as i32 - 1)).pow(2);
    let rest = 900 - d(s) - d(v);
    if rest <= 0 {
        return 0..0;
    }
    // |2u − 31| ≤ m, m the largest with m² < rest.
    let m = (rest as u32 - 1).isqrt() as i32;
    let lo = (DIM as i32 - 1 - m + 1) / 2;
    let hi = (DIM as i32 - 1 + m) / 2;
    lo.max(0) as usize..(hi + 1).clamp(0, DIM as i32) as usize
}

/// The view: V = zoom · Rx(20°) · Ry(30°) from the core's own `sin`/`cos` (the same bits on
/// every target).
pub fn view_matrix() -> Mat3 {
    view_matrix_at(SIDE, 0)
}

/// The view of orbit frame `step` at `side`² pixels: V = zoom · Rx(20°) · Ry(30° + step ·
/// [`ORBIT_STEP_DEG`]), zoom 1.3 px per voxel from 48² to 64² (the volume fits), scaled with
/// the image below that (32² on the 8 KiB board) and above it (the M4F's 128²: 2.6 px per
/// voxel, the 64² picture at twice the resolution).
pub fn view_matrix_at(side: usize, step: usize) -> Mat3 {
    let turn = ORBIT_STEP_DEG * step as f32;
    let zoom = if side > SIDE {
        1.3 * side as f32 / SIDE as f32
    } else if side >= SIDE_MICROBIT {
        1.3f32
    } else {
        1.3 * side as f32 / SIDE_MICROBIT as f32
    };
    let (az, el) = ((30.0f32 + turn).to_radians(), 20.0f32.to_radians());
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

/// The frame of the scene at `side`×`side` pixels.
pub fn frame(side: usize) -> Result<FrameSetup, footprint::Error> {
    frame_at(side, 0)
}

/// The frame of orbit frame `step` at `side`×`side` pixels ([`view_matrix_at`]).
pub fn frame_at(side: usize, step: usize) -> Result<FrameSetup, footprint::Error> {
    Ok(FrameSetup::new(
        [DIM; 3],
        &Grid::from_spacing([1.0; 3])?,
        &View::new(view_matrix_at(side, step))?,
        &Kernel::PAPER_GAUSSIAN,
        FootprintOptions::default(),
        [side; 2],
    )?)
}

fn shader() -> Shader<'static> {
    Shader {
        labels: None,
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
    /// CRC-32 of the whole image, rows top to bottom ([`fixed::checksum`] for fixed; the f32
    /// bits for float).
    pub checksum: u32,
    /// Counts, summed over bands (a voxel that reaches two bands is counted in both).
    pub stats: RenderStats,
    /// Bands rendered (times the volume was streamed).
    pub bands: usize,
}

/// Every buffer of a fixed-point render, borrowed (the firmware's are separate `static`s, so the
/// all-zero ones land in `.bss` and cost no flash). A band is `rows.len()` image rows (at most
/// the image's); `acc` and `image` hold at least that many rows of `side` pixels. Bytes: see
/// README "Embedding".
pub struct FixedBuffers<'a> {
    /// The view's integer table.
    pub table: &'a mut FixedTable<N>,
    /// Shaded value per sample value, Q24 premultiplied RGBA (built per view).
    pub lut: &'a mut [[u32; 4]; 256],
    /// Sheet accumulator for one band; all zero at the start (left all zero).
    pub acc: &'a mut [[i64; 4]],
    /// Working image for one band (Q24 premultiplied RGBA).
    pub image: &'a mut [[u32; 4]],
    /// Touched span per band row; its length is the band height.
    pub rows: &'a mut [RowSpan],
}

/// The bands of a `side`-row image for buffers of `band` rows: each band's first row and height.
fn bands(side: usize, band: usize) -> impl Iterator<Item = core::ops::Range<usize>> {
    let band = band.clamp(1, side.max(1));
    (0..side)
        .step_by(band)
        .map(move |start| start..(start + band).min(side))
}

/// Renders the scene at `side`×`side` with fixed-point accumulation, band by band, handing each
/// finished band to `emit(first_row, pixels)` (Q24 premultiplied RGBA, rows top to bottom).
#[inline(never)]
pub fn render_fixed(
    side: usize,
    b: FixedBuffers<'_>,
    emit: impl FnMut(usize, &[[u32; 4]]),
) -> Result<Report, footprint::Error> {
    let f = frame(side)?;
    // Per-view set-up (float): the view table and the shading lookup.
    b.table
        .build_view(&f, &GENERIC, Lookup::Bilinear, Lookup::Bilinear)?;
    let (shader, lighting) = (shader(), Lighting::new(&f));
    for (v, entry) in b.lut.iter_mut().enumerate() {
        let rgba = shader.shade(&lighting, v as f32, || Vec3::ZERO, [0; 3], f.dims);
        *entry = fixed::quantise(rgba);
    }
    // Per voxel and per pixel: integers only.
    let (lut, path) = (&*b.lut, FixedPath::new(&f, &*b.table)?);
    let buffers = (&mut *b.acc, &mut *b.image, &mut *b.rows);
    render_bands(
        &f,
        path,
        shader,
        buffers,
        |x| lut[usize::from(x)],
        emit,
        |c, crc| crc.update(&c.to_le_bytes()),
    )
}

/// The band loop both precisions share: for each band of `rows.len()` rows, every sheet in
/// order with each voxel shaded by `shade(sample)`, then the band's pixels into the checksum
/// (each channel by `bytes`) and out through `emit(first_row, pixels)`.
fn render_bands<P: Precision + Copy, C: Copy>(
    f: &FrameSetup,
    path: P,
    shader: Shader<'_>,
    (acc, image, rows): (&mut [P::Acc], &mut [P::Pixel], &mut [RowSpan]),
    shade: impl Fn(u8) -> P::Value,
    mut emit: impl FnMut(usize, &[P::Pixel]),
    mut bytes: impl FnMut(C, &mut Crc32),
) -> Result<Report, footprint::Error>
where
    P::Pixel: AsRef<[C]>,
{
    let side = f.size[0];
    let mut crc = Crc32::new();
    let mut report = Report {
        checksum: 0,
        stats: RenderStats::default(),
        bands: 0,
    };
    for band in bands(side, rows.len()) {
        let n = band.len() * side;
        let buffers = RenderBuffers {
            accumulator: &mut acc[..],
            image: &mut image[..],
            rows: &mut rows[..band.len()],
        };
        let mut r = SheetRenderer::with_band(f, path, shader, ORDER, buffers, None, band.clone())?;
        for step in 0..f.sheet_count() {
            let s = f.sheet_at(ORDER, step);
            r.render_sheet_rows_with(
                s,
                |v| occupied(s, v),
                |u, v| {
                    let [i, j, k] = f.grid_index(s, u, v);
                    shade(sample(i, j, k))
                },
            )?;
        }
        add(&mut report.stats, r.finish());
        report.bands += 1;
        for px in &image[..n] {
            for &c in px.as_ref() {
                bytes(c, &mut crc);
            }
        }
        emit(band.start, &image[..n]);
    }
    report.checksum = crc.finish();
    Ok(report)
}

fn add(total: &mut RenderStats, s: RenderStats) {
    total.sheets += s.sheets;
    total.voxels += s.voxels;
    total.voxels_splatted += s.voxels_splatted;
    total.pixel_updates += s.pixel_updates;
    total.pixels_composited += s.pixels_composited;
}

/// Every buffer of a float render, borrowed (bands as in [`FixedBuffers`]).
pub struct FloatBuffers<'a> {
    /// The view table.
    pub table: &'a mut ViewTable<N>,
    /// Sheet accumulator for one band.
    pub acc: &'a mut [[f32; 4]],
    /// Working image for one band.
    pub image: &'a mut [[f32; 4]],
    /// Touched span per band row; its length is the band height.
    pub rows: &'a mut [RowSpan],
}

/// [`render_fixed`] with float accumulation (the same shading, unquantised, per voxel).
#[inline(never)]
pub fn render_float(
    side: usize,
    b: FloatBuffers<'_>,
    emit: impl FnMut(usize, &[[f32; 4]]),
) -> Result<Report, footprint::Error> {
    let f = frame(side)?;
    b.table
        .build_into(&f.footprint, &GENERIC, Lookup::Bilinear, Lookup::Bilinear);
    let (shader, lighting) = (shader(), Lighting::new(&f));
    let path = footprint::render::FloatPath::new(&*b.table);
    let buffers = (&mut *b.acc, &mut *b.image, &mut *b.rows);
    let shade = |x: u8| shader.shade(&lighting, f32::from(x), || Vec3::ZERO, [0; 3], f.dims);
    render_bands(&f, path, shader, buffers, shade, emit, |c: f32, crc| {
        crc.update(&c.to_bits().to_le_bytes())
    })
}

/// Phases per pixel axis of the compact path's stencils at `side`²: 8 (a voxel moves at most
/// 1/16 px), 4 below 48² (the 8 KiB board's 32², where the stencils must stay small).
pub const fn phases_for(side: usize) -> usize {
    if side > SIDE_MICROBIT {
        8
    } else {
        4
    }
}

/// `i16`s the compact stencils need at `side`² (for sizing a `static`; checked at run time).
pub const fn compact_stencil_len(side: usize) -> usize {
    // The footprint's box is 5×5 at 48² and 64² (half-extent 2.1 px), 4×4 at 32², 9×9 at 128²
    // (4.2 px): 31, 21 or 91 `i16`s per phase (see footprint::fixed::compact).
    let per = if side > SIDE {
        91
    } else if side >= SIDE_MICROBIT {
        31
    } else {
        21
    };
    phases_for(side) * phases_for(side) * per
}

/// Every buffer of a compact render, borrowed (bands as in [`FixedBuffers`]).
pub struct CompactBuffers<'a> {
    /// The view's phase stencils ([`compact_stencil_len`]).
    pub stencils: &'a mut [i16],
    /// Sheet accumulator for one band; all zero at the start (left all zero).
    pub acc: &'a mut [[i32; 4]],
    /// Working image for one band (Q15 premultiplied RGBA).
    pub image: &'a mut [[u16; 4]],
    /// Touched span per band row; its length is the band height.
    pub rows: &'a mut [RowSpan],
}

/// The view-independent part of a compact render: the shaded value per sample value, Q15
/// premultiplied RGBA (emission shading does not depend on the view, so an orbit builds it
/// once).
pub fn compact_lut(lut: &mut [[u16; 4]; 256]) -> Result<(), footprint::Error> {
    let f = frame(SIDE)?;
    let (shader, lighting) = (shader(), Lighting::new(&f));
    for (v, entry) in lut.iter_mut().enumerate() {
        let rgba = shader.shade(&lighting, v as f32, || Vec3::ZERO, [0; 3], f.dims);
        *entry = compact::quantise_value(rgba);
    }
    Ok(())
}

/// Renders orbit frame `step` of the scene at `side`×`side` on the compact fixed path
/// ([`footprint::fixed::compact`]), band by band, each voxel shaded through `lut`
/// ([`compact_lut`]), handing each finished band to `emit(first_row, pixels)` (Q15
/// premultiplied RGBA). Per view it builds only the stencils and the placement.
#[inline(never)]
pub fn render_compact(
    side: usize,
    step: usize,
    lut: &[[u16; 4]; 256],
    b: CompactBuffers<'_>,
    emit: impl FnMut(usize, &[[u16; 4]]),
) -> Result<Report, footprint::Error> {
    let f = frame_at(side, step)?;
    let sampler = Direct {
        footprint: f.footprint,
        table: &GENERIC,
        lookup: Lookup::Bilinear,
    };
    let stencils = CompactStencils::build(&f, &sampler, phases_for(side), b.stencils)
        .map_err(compact_error)?;
    let path = CompactPath::new(&f, stencils).map_err(compact_error)?;
    let buffers = (&mut *b.acc, &mut *b.image, &mut *b.rows);
    render_bands(
        &f,
        path,
        shader(),
        buffers,
        |x| lut[usize::from(x)],
        emit,
        |c: u16, crc| crc.update(&c.to_le_bytes()),
    )
}

/// A compact-path refusal as the core's error (a buffer or a fixed-point range).
fn compact_error(e: CompactError) -> footprint::Error {
    match e {
        CompactError::Buffer(b) => footprint::Error::Buffer(b),
        CompactError::Fixed(f) => footprint::Error::Fixed(f),
        _ => footprint::Error::Fixed(footprint::fixed::FixedError::Range {
            what: "compact stencils (footprint box or phases)",
        }),
    }
}
