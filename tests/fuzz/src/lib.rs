//! Helpers the fuzz targets share: rendering through the core with caller-owned buffers, as an
//! embedding would, and a scratch folder for targets that load whole files by path.

use footprint::composite::RowSpan;
use footprint::frame::{FrameSetup, Order};
use footprint::lod::{Averaging, Coarsened, Extinction, Linear};
use footprint::refine::RefinedAxis;
use footprint::render::{
    sheet_map, spacing_key, FloatPath, Precision, RefineTables, RefinedGrid, RenderBuffers,
    ScaledFootprint, SheetRenderer, SheetRing, SlabBuffers, SlabRenderer, SlabSetup, SlabVoxel,
    SPACING_KEYS,
};
use footprint::shade::Lighting;
use footprint::shade::{Shader, Shading, TransferFunction};
use footprint::source::{render_from, SheetSource};
use footprint::splat::ImageMut;
use footprint::stencil::{self, Stencils};
use footprint::table::SectionTable;
use footprint::volume::MemoryVolume;
use footprint::ViewTable;
use std::path::PathBuf;

/// Emission through `lut` (straight RGBA over sample values 0..=255).
fn emission(lut: &[[f32; 4]]) -> Shader<'_> {
    Shader { labels: None,
        tf: TransferFunction {
            lut,
            lo: 0.0,
            hi: 255.0,
        },
        shading: Shading::Emission,
    }
}

/// Renders every sheet `source` delivers for `frame` through `lut` (straight RGBA over
/// 0..=255), emission, with `path`, through a sheet ring; returns the image. Any renderer error
/// is a failure: the frame is valid.
fn render_source<P: Precision, S: SheetSource>(
    frame: &FrameSetup,
    path: P,
    order: Order,
    lut: &[[f32; 4]],
    mut source: S,
) -> Vec<P::Pixel>
where
    S::Sample: Default,
    S::Error: std::fmt::Debug,
{
    let n = frame.image_len();
    let (mut acc, mut img, mut rows) = (
        vec![P::ACC_ZERO; n],
        vec![P::CLEAR; n],
        vec![RowSpan::EMPTY; frame.size[1]],
    );
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    let mut r = SheetRenderer::with_path(frame, path, emission(lut), order, buffers, None)
        .expect("buffers sized for the frame");
    let mut storage = vec![S::Sample::default(); 3 * frame.sheet_shape().0];
    let mut ring = SheetRing::new(&mut storage, frame, order).expect("ring sized for the frame");
    render_from(&mut r, &mut ring, &mut source).expect("in-memory source");
    r.finish();
    img
}

/// Renders `samples` (u8, x fastest, `frame.dims`) through `lut` (straight RGBA over 0..=255),
/// emission, with `path`; returns the image. Any renderer error is a failure: the frame is valid.
pub fn render_volume<P: Precision>(
    frame: &FrameSetup,
    path: P,
    order: Order,
    samples: &[u8],
    lut: &[[f32; 4]],
) -> Vec<P::Pixel> {
    let volume = MemoryVolume::new(samples, frame.dims).expect("samples match dims");
    render_source(frame, path, order, lut, volume)
}

/// Renders level 1 of `samples` (u8, x fastest, `fine_dims`) through `lut`, emission, with
/// `path` and `frame` (level 1's, `footprint::lod::level_frame`): the level is built as it
/// streams by [`Coarsened`], averaging by extinction when the opacity never falls. Any renderer
/// error is a failure: the frame is valid.
pub fn render_level<P: Precision>(
    frame: &FrameSetup,
    fine_dims: [usize; 3],
    path: P,
    order: Order,
    samples: &[u8],
    lut: &[[f32; 4]],
) -> Vec<P::Pixel> {
    let extinction = Extinction::new(emission(lut).tf);
    let averaging: &dyn Averaging = match &extinction {
        Some(e) => e,
        None => &Linear,
    };
    let volume = MemoryVolume::new(samples, fine_dims).expect("samples match dims");
    let len = Coarsened::<MemoryVolume<u8>>::scratch_len(fine_dims, frame.sheet_axis);
    let (mut lower, mut upper) = (vec![0u8; len], vec![0u8; len]);
    let source = Coarsened::new(volume, fine_dims, &mut lower, &mut upper).averaging(averaging);
    render_source(frame, path, order, lut, source)
}

/// Renders `samples` (u8, x fastest, `frame.dims`) through `lut`, emission, refined by
/// `factors` (1, 2 or 4 per interval of each grid axis): every sample through the scaled read of
/// `table`, except the border key (1, ½) × (½, ¼), splatted through [`ScaledFootprint`]
/// stencils when they apply. Any renderer error is a failure: the frame and factors are valid.
pub fn render_refined<const N: usize>(
    frame: &FrameSetup,
    table: &ViewTable<N>,
    order: Order,
    samples: &[u8],
    lut: &[[f32; 4]],
    factors: &[Vec<u8>; 3],
) -> Vec<[f32; 4]> {
    let n = frame.image_len();
    let (mut acc, mut img) = (vec![[0.0f32; 4]; n], vec![[0.0f32; 4]; n]);
    let mut rows = vec![RowSpan::EMPTY; frame.size[1]];
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    let path = FloatPath::new(table);
    let mut r = SheetRenderer::with_path(frame, path, emission(lut), order, buffers, None)
        .expect("valid frame");
    let axis = |a: usize| RefinedAxis::new(a, frame.dims[a], &factors[a]).expect("factors 1, 2, 4");
    let grid = RefinedGrid {
        axes: [axis(0), axis(1), axis(2)],
    };
    let scales = [[1.0, 0.5], [0.5, 0.25]];
    let scaled = ScaledFootprint::new(table, sheet_map(frame), scales);
    let mut buffer = vec![
        0.0f32;
        scaled
            .as_ref()
            .and_then(|s| stencil::len_for(footprint::Sampler::footprint(s), 4))
            .unwrap_or(0)
    ];
    let stencils = match &scaled {
        Some(s) if !buffer.is_empty() => Stencils::build(s, 4, &mut buffer).ok(),
        _ => None,
    };
    let mut splatters: Vec<Option<Stencils<'_, ScaledFootprint<'_, ViewTable<N>>>>> =
        (0..SPACING_KEYS).map(|_| None).collect();
    splatters[spacing_key(scales[0], scales[1], 1.0)] = stencils;
    let tables = RefineTables {
        rates: [table; 5],
        splatters: &splatters,
    };
    let d = frame.dims;
    let mut scratch = vec![0.0f32; 2 * frame.sheet_shape().0];
    r.render_refined(
        &grid,
        &tables,
        |[i, j, k]| f32::from(samples[i + d[0] * (j + d[1] * k)]),
        &mut scratch,
    )
    .expect("refined render");
    r.finish();
    img
}

/// Renders `samples` as [`render_volume`] does, with image-aligned slabs: every voxel shaded for
/// one world unit, fed in the order of the slab it reaches first, into a ring of slab
/// accumulators. Any renderer error is a failure: the setup is valid.
pub fn render_slabs<const R: usize, const T: usize>(
    frame: &FrameSetup,
    setup: &SlabSetup,
    table: &SectionTable<R, T>,
    order: Order,
    samples: &[u8],
    lut: &[[f32; 4]],
) -> Vec<[f32; 4]> {
    let shader = emission(lut);
    let lighting = Lighting::per_world_unit(frame);
    let d = frame.dims;
    let mut voxels: Vec<(usize, SlabVoxel)> = Vec::new();
    for k in 0..d[2] {
        for j in 0..d[1] {
            for i in 0..d[0] {
                let value = f32::from(samples[(k * d[1] + j) * d[0] + i]);
                let rgba = shader.shade(
                    &lighting,
                    value,
                    || footprint::glam::Vec3::ZERO,
                    [i, j, k],
                    d,
                );
                let position = frame
                    .affine_position([i, j, k].map(|c| c as f32))
                    .to_array();
                if let Some(v) = SlabVoxel::from_unit_rgba(position, rgba) {
                    let (a, b) = setup.slabs_of(position[2]);
                    let key = match order {
                        Order::FrontToBack => a,
                        Order::BackToFront => setup.slab_count() - 1 - b,
                    };
                    voxels.push((key, v));
                }
            }
        }
    }
    voxels.sort_by_key(|v| v.0);
    let n = frame.image_len();
    let ring = setup.ring();
    let (mut acc, mut img, mut rows) = (
        vec![[0.0f32; 4]; ring * n],
        vec![[0.0f32; 4]; n],
        vec![RowSpan::EMPTY; ring * frame.size[1]],
    );
    let buffers = SlabBuffers {
        accumulators: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    let mut r = SlabRenderer::with_band(setup, table, order, buffers, None, 0..frame.size[1])
        .expect("buffers sized for the setup");
    let mut next = 0;
    for step in 0..setup.slab_count() {
        while next < voxels.len() && voxels[next].0 == step {
            r.splat_voxel(&voxels[next].1)
                .expect("voxels in slab order");
            next += 1;
        }
        r.composite_next();
    }
    r.finish();
    img
}

/// Splats the single voxel of a 1×1×1 `frame` with premultiplied value `[w; 4]` and returns the
/// sheet accumulator (before compositing clamps anything: a kernel with negative lobes leaves
/// negative weights there).
pub fn splat_one<P: Precision>(frame: &FrameSetup, path: &P, w: f32) -> Vec<P::Acc> {
    let [width, height] = frame.size;
    let mut acc = vec![P::ACC_ZERO; width * height];
    let mut image = ImageMut::new(&mut acc, width, height, width).expect("sized for the frame");
    path.splat(
        frame,
        0,
        (0, 0),
        0,
        &path.value([w; 4]),
        &mut image,
        |_, _, _| {},
    )
    .expect("one voxel");
    acc
}

/// Every sample type, for targets that pick one from a byte.
pub const SAMPLE_TYPES: [footprint_harness::io::volume::SampleType; 8] = {
    use footprint_harness::io::volume::SampleType;
    [
        SampleType::U8,
        SampleType::I8,
        SampleType::U16,
        SampleType::I16,
        SampleType::U32,
        SampleType::I32,
        SampleType::F32,
        SampleType::F64,
    ]
};

/// A folder of this process's own for files a target writes and loads back.
pub fn scratch() -> PathBuf {
    let base = std::env::var_os("FUZZ_SCRATCH")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            let shm = PathBuf::from("/dev/shm");
            if shm.is_dir() {
                shm
            } else {
                std::env::temp_dir()
            }
        });
    let d = base.join(format!("footprint-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("scratch folder");
    d
}
