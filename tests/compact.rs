//! The compact fixed path (`footprint::fixed::compact`, the boards' path): against the float path
//! on the same frames (PSNR), bands bit-identical to the whole image, and a caller's promise of
//! occupied rows (`render_sheet_rows_with`) giving the same bits without visiting the rest.

use footprint::composite::RowSpan;
use footprint::fixed::compact::{self, len_for, CompactStencils};
use footprint::frame::{FrameSetup, Order};
use footprint::geometry::FootprintOptions;
use footprint::render::{CompactPath, RenderBuffers, SheetRenderer};
use footprint::shade::{Shader, Shading, TransferFunction};
use footprint::splat::Direct;
use footprint::{GenericTable, Grid, Kernel, Lookup, View, ViewTable};
use footprint_harness::metrics::compare;
use footprint_suite::render_with;
use glam::Mat3;

const SIDE: usize = 40;

fn frame(az: f32, zoom: f32) -> FrameSetup {
    let view = View::new(Mat3::from_rotation_x(0.4) * Mat3::from_rotation_y(az) * zoom).unwrap();
    FrameSetup::new(
        [14, 12, 10],
        &Grid::from_spacing([1.0, 1.0, 1.4]).unwrap(),
        &view,
        &Kernel::PAPER_GAUSSIAN,
        FootprintOptions::default(),
        [SIDE, SIDE],
    )
    .unwrap()
}

/// A blob with a soft edge, emission RGBA per voxel of sheet `s` (premultiplied).
fn sheet(f: &FrameSetup, s: usize) -> Vec<[f32; 4]> {
    let (_, na, nb) = f.sheet_shape();
    let mut out = vec![[0.0; 4]; na * nb];
    for v in 0..nb {
        for u in 0..na {
            let [i, j, k] = f.grid_index(s, u, v);
            let d = [i, j, k]
                .iter()
                .zip(&f.dims)
                .map(|(&x, &n)| (x as f32 - (n as f32 - 1.0) / 2.0) / n as f32)
                .map(|x| x * x)
                .sum::<f32>();
            let a = (0.35 - d).clamp(0.0, 0.2);
            out[v * na + u] = [a * 0.9, a * (i as f32 / 14.0), a * 0.4, a];
        }
    }
    out
}

/// Within 40 dB of the float path (view table) on several views, at 8 phases, in RGB and in
/// alpha; more phases do not do worse than fewer.
#[test]
fn the_compact_path_is_within_40_db_of_float() {
    let generic = GenericTable::<33>::build(Kernel::PAPER_GAUSSIAN);
    for (az, zoom) in [(0.3, 1.3), (1.2, 0.9), (2.4, 1.8)] {
        let f = frame(az, zoom);
        let view =
            ViewTable::<33>::build(&f.footprint, &generic, Lookup::Bilinear, Lookup::Bilinear);
        let float = render_with(
            &f,
            footprint::render::FloatPath::new(&view),
            Order::BackToFront,
            &|s| sheet(&f, s),
        );
        assert!(float.iter().any(|p| p[3] > 0.3), "the scene is not empty");
        let float: Vec<[f64; 4]> = float.iter().map(|p| p.map(f64::from)).collect();
        let sampler = Direct {
            footprint: f.footprint,
            table: &generic,
            lookup: Lookup::Bilinear,
        };
        let mut last = 0.0;
        for phases in [2, 8] {
            let mut buf = vec![0i16; len_for(&f, phases).unwrap()];
            let st = CompactStencils::build(&f, &sampler, phases, &mut buf).unwrap();
            let path = CompactPath::new(&f, st).unwrap();
            let img: Vec<[f32; 4]> = render_with(&f, path, Order::BackToFront, &|s| sheet(&f, s))
                .into_iter()
                .map(compact::to_f32)
                .collect();
            // The lower of RGB together and alpha (`metrics::compare`: PSNR, peak 1).
            let (channels, rgb) = compare(&img, &float);
            let db = rgb.psnr_db.min(channels[3].psnr_db);
            eprintln!("compact, az {az}, zoom {zoom}, {phases} phases: {db:.1} dB against float");
            assert!(
                db >= last - 0.5,
                "az {az}: {phases} phases {db:.1} dB, fewer {last:.1} dB"
            );
            last = db;
        }
        assert!(last >= 40.0, "az {az}, zoom {zoom}: {last:.1} dB");
    }
}

/// Renders `f` on the compact path in bands of `band` rows, each sheet through
/// `render_sheet_rows_with` (rows `occupied`) or `render_sheet_with`; counts the voxels shaded.
fn banded(
    f: &FrameSetup,
    band: usize,
    occupied: Option<&dyn Fn(usize, usize) -> std::ops::Range<usize>>,
) -> (Vec<[u16; 4]>, usize) {
    let generic = GenericTable::<33>::build(Kernel::PAPER_GAUSSIAN);
    let sampler = Direct {
        footprint: f.footprint,
        table: &generic,
        lookup: Lookup::Bilinear,
    };
    let mut buf = vec![0i16; len_for(f, 4).unwrap()];
    let st = CompactStencils::build(f, &sampler, 4, &mut buf).unwrap();
    let lut = [[0.0f32; 4], [1.0; 4]];
    let shader = Shader {
        labels: None,
        tf: TransferFunction {
            lut: &lut,
            lo: 0.0,
            hi: 1.0,
        },
        shading: Shading::Emission,
    };
    let sheets: Vec<Vec<[u16; 4]>> = (0..f.sheet_count())
        .map(|s| {
            sheet(f, s)
                .into_iter()
                .map(compact::quantise_value)
                .collect()
        })
        .collect();
    let mut image = vec![[0u16; 4]; SIDE * SIDE];
    let mut shaded = 0;
    for first in (0..SIDE).step_by(band) {
        let rows = first..(first + band).min(SIDE);
        let (mut acc, mut img, mut spans) = (
            vec![[0i32; 4]; rows.len() * SIDE],
            vec![[0u16; 4]; rows.len() * SIDE],
            vec![RowSpan::EMPTY; rows.len()],
        );
        let buffers = RenderBuffers {
            accumulator: &mut acc,
            image: &mut img,
            rows: &mut spans,
        };
        let path = CompactPath::new(f, st).unwrap();
        let mut r = SheetRenderer::with_band(
            f,
            path,
            shader,
            Order::BackToFront,
            buffers,
            None,
            rows.clone(),
        )
        .unwrap();
        let na = f.sheet_shape().1;
        for step in 0..f.sheet_count() {
            let s = f.sheet_at(Order::BackToFront, step);
            let value = |u: usize, v: usize| {
                shaded += 1;
                sheets[s][v * na + u]
            };
            match occupied {
                Some(o) => r.render_sheet_rows_with(s, |v| o(s, v), value).unwrap(),
                None => r.render_sheet_with(s, value).unwrap(),
            }
        }
        r.finish();
        image[first * SIDE..rows.end * SIDE].copy_from_slice(&img);
    }
    (image, shaded)
}

/// Bands of 1, 3 and 7 rows give the whole image's bits; promising the occupied rows gives the
/// same bits again while shading fewer voxels.
#[test]
fn bands_and_occupied_rows_keep_the_bits() {
    let f = frame(0.7, 1.3);
    let (whole, all) = banded(&f, SIDE, None);
    for band in [1, 3, 7] {
        assert_eq!(banded(&f, band, None).0, whole, "bands of {band}");
    }
    // Per sheet row, the voxels whose value is not transparent (the promise, computed exactly).
    let sheets: Vec<Vec<[f32; 4]>> = (0..f.sheet_count()).map(|s| sheet(&f, s)).collect();
    let na = f.sheet_shape().1;
    let occupied = |s: usize, v: usize| {
        let row = &sheets[s][v * na..(v + 1) * na];
        let opaque = |p: &[f32; 4]| compact::quantise_value(*p)[3] != 0;
        match (row.iter().position(opaque), row.iter().rposition(opaque)) {
            (Some(a), Some(b)) => a..b + 1,
            _ => 0..0,
        }
    };
    let (promised, fewer) = banded(&f, SIDE, Some(&occupied));
    assert_eq!(promised, whole);
    assert!(
        fewer < all,
        "{fewer} voxels shaded with the promise, {all} without"
    );
}
