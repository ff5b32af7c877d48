//! Helpers the fuzz targets share: rendering through the core with caller-owned buffers, as an
//! embedding would, and a scratch folder for targets that load whole files by path.

use footprint::composite::RowSpan;
use footprint::frame::{FrameSetup, Order};
use footprint::render::{Precision, RenderBuffers, SheetRenderer, SheetRing};
use footprint::shade::{Shader, Shading, TransferFunction};
use footprint::source::render_from;
use footprint::splat::ImageMut;
use footprint::volume::MemoryVolume;
use std::path::PathBuf;

/// Renders `samples` (u8, x fastest, `frame.dims`) through `lut` (straight RGBA over 0..=255),
/// emission, with `path`; returns the image. Any renderer error is a failure: the frame is valid.
pub fn render_volume<P: Precision>(
    frame: &FrameSetup,
    path: P,
    order: Order,
    samples: &[u8],
    lut: &[[f32; 4]],
) -> Vec<P::Pixel> {
    let shader = Shader {
        tf: TransferFunction {
            lut,
            lo: 0.0,
            hi: 255.0,
        },
        shading: Shading::Emission,
    };
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
    let mut r = SheetRenderer::with_path(frame, path, shader, order, buffers, None)
        .expect("buffers sized for the frame");
    let mut storage = vec![0u8; 3 * frame.sheet_shape().0];
    let mut ring = SheetRing::new(&mut storage, frame, order).expect("ring sized for the frame");
    let mut volume = MemoryVolume::new(samples, frame.dims).expect("samples match dims");
    render_from(&mut r, &mut ring, &mut volume).expect("in-memory source");
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
