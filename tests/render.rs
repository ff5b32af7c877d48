//! The sheet renderer: compositing directions, opacity correction, aspect, transparent voxels,
//! gradients on anisotropic grids, and its typed errors.

use footprint::composite::RowSpan;
use footprint::frame::{FrameSetup, Order};
use footprint::geometry::FootprintOptions;
use footprint::render::{
    gradient, RenderBuffers, RenderError, RenderStats, ShadeCacheEntry, SheetRenderer, SheetRing,
    SheetWindow, SHADE_CACHE_LEN,
};
use footprint::shade::{Phong, Shader, Shading, TransferFunction};
use footprint::{GenericTable, Grid, Kernel, Lookup, View, ViewTable};
use footprint_suite::assert_le;
use glam::{Mat3, Vec3};

/// A straight-through lookup: value v in [0, 1] ↦ grey v with opacity `alpha`·v.
fn ramp(alpha: f32) -> Vec<[f32; 4]> {
    (0..256)
        .map(|i| {
            let t = i as f32 / 255.0;
            [t, t, t, alpha * t]
        })
        .collect()
}

struct Scene {
    dims: [usize; 3],
    spacing: [f32; 3],
    data: Vec<f32>,
}

impl Scene {
    fn sheet(&self, frame: &FrameSetup, s: usize, out: &mut [f32]) {
        let (a, b) = frame.in_sheet;
        let stride = [1, self.dims[0], self.dims[0] * self.dims[1]];
        let (na, nb) = (self.dims[a], self.dims[b]);
        for v in 0..nb {
            for u in 0..na {
                out[v * na + u] =
                    self.data[s * stride[frame.sheet_axis] + u * stride[a] + v * stride[b]];
            }
        }
    }
}

/// A smooth blob (values in [0, 1]).
fn blob(dims: [usize; 3], spacing: [f32; 3]) -> Scene {
    let mut data = Vec::new();
    let c = dims.map(|d| (d as f32 - 1.0) / 2.0);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = [
                    (i as f32 - c[0]) * spacing[0],
                    (j as f32 - c[1]) * spacing[1],
                    (k as f32 - c[2]) * spacing[2],
                ];
                let r2 = p[0] * p[0] + 2.0 * p[1] * p[1] + 0.5 * p[2] * p[2];
                data.push((-r2 / 40.0).exp() + 0.3 * (p[0] * 0.4).sin().abs() * (-r2 / 80.0).exp());
            }
        }
    }
    Scene {
        dims,
        spacing,
        data,
    }
}

fn constant(dims: [usize; 3], spacing: [f32; 3], v: f32) -> Scene {
    Scene {
        dims,
        spacing,
        data: vec![v; dims.iter().product()],
    }
}

struct Out {
    image: Vec<[f32; 4]>,
    stats: RenderStats,
    frame: FrameSetup,
}

fn render(
    scene: &Scene,
    view: Mat3,
    size: usize,
    shading: Shading,
    order: Order,
    lut: &[[f32; 4]],
    bg: Option<&[[f32; 4]]>,
) -> Out {
    render_cached(scene, view, size, shading, order, lut, bg, None)
}

/// [`render`], remembering shaded values in `cache` when given
/// (`SheetRenderer::with_shade_cache`).
#[allow(clippy::too_many_arguments)]
fn render_cached(
    scene: &Scene,
    view: Mat3,
    size: usize,
    shading: Shading,
    order: Order,
    lut: &[[f32; 4]],
    bg: Option<&[[f32; 4]]>,
    cache: Option<&mut [ShadeCacheEntry]>,
) -> Out {
    let kernel = Kernel::PAPER_GAUSSIAN;
    let grid = Grid::from_spacing(scene.spacing).unwrap();
    let frame = FrameSetup::new(
        scene.dims,
        &grid,
        &View::new(view).unwrap(),
        &kernel,
        FootprintOptions::default(),
        [size, size],
    )
    .unwrap();
    let generic = GenericTable::<65>::build(kernel);
    let table = ViewTable::<65>::build(
        &frame.footprint,
        &generic,
        Lookup::Bilinear,
        Lookup::Bilinear,
    );
    let n = frame.image_len();
    let (mut acc, mut img, mut rows) = (
        vec![[0.0f32; 4]; n],
        vec![[0.0f32; 4]; n],
        vec![RowSpan::EMPTY; size],
    );
    let shader = Shader {
        labels: None,
        tf: TransferFunction {
            lut,
            lo: 0.0,
            hi: 1.0,
        },
        shading,
    };
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    let mut r = SheetRenderer::new(&frame, &table, shader, order, buffers, bg).unwrap();
    if let Some(c) = cache {
        r = r.with_shade_cache(c);
    }
    let mut storage = vec![0.0f32; 3 * frame.sheet_shape().0];
    let mut ring = SheetRing::new(&mut storage, &frame, order).unwrap();
    let mut tmp = vec![0.0f32; frame.sheet_shape().0];
    for step in 0..frame.sheet_count() {
        scene.sheet(&frame, ring.sheet_index(step), &mut tmp);
        if let Some(done) = ring.push(&tmp).unwrap() {
            r.render_sheet(ring.sheet_index(done), ring.window(done))
                .unwrap();
        }
    }
    let last = ring.last().unwrap();
    r.render_sheet(ring.sheet_index(last), ring.window(last))
        .unwrap();
    let stats = r.finish();
    assert!(
        acc.iter().all(|p| *p == [0.0; 4]),
        "the accumulator is left clear"
    );
    Out {
        image: img,
        stats,
        frame,
    }
}

fn max_diff(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..4).map(move |c| (x[c] - y[c]).abs()))
        .fold(0.0, f32::max)
}

fn oblique(zoom: f32) -> Mat3 {
    footprint_suite::view(20.0, 30.0, 10.0, zoom)
}

/// Over (back to front) and under (front to back) composite the same sheets in opposite orders.
/// Porter–Duff over is associative, so the images agree up to f32 rounding: with at most ~40
/// sheets each adding a relative rounding of 2⁻²⁴ per operation, 1e-5 is a generous bound.
#[test]
fn over_and_under_give_the_same_image() {
    let scene = blob([24, 20, 16], [1.0, 1.0, 2.0]);
    let lut = ramp(0.6);
    let bg: Vec<[f32; 4]> = (0..96 * 96)
        .map(|i| [0.1 * (i % 7) as f32 / 7.0, 0.05, 0.2, 1.0])
        .collect();
    for shading in [
        Shading::Emission,
        Shading::Phong(Phong::default()),
        Shading::Texture(Phong::default()),
    ] {
        for view in [Mat3::IDENTITY * 3.0, oblique(3.0)] {
            for background in [None, Some(&bg[..])] {
                let a = render(
                    &scene,
                    view,
                    96,
                    shading,
                    Order::BackToFront,
                    &lut,
                    background,
                );
                let b = render(
                    &scene,
                    view,
                    96,
                    shading,
                    Order::FrontToBack,
                    &lut,
                    background,
                );
                let d = max_diff(&a.image, &b.image);
                assert_le(
                    f64::from(d),
                    1e-5,
                    &format!("{shading:?}, background {}", background.is_some()),
                );
                assert!(a.image.iter().any(|p| p[3] > 0.1), "something was rendered");
            }
        }
    }
}

/// Only the sampling along the view changes (twice the sheets at half the spacing, same world
/// extent): the opacity correction keeps the picture. Interior pixels agree to 1e-3 (the
/// residue is the in-sheet ripple, identical in both, and f32 rounding).
#[test]
fn resampling_along_the_view_keeps_the_picture() {
    let lut = ramp(0.3);
    let a = render(
        &constant([12, 12, 8], [1.0, 1.0, 1.0], 0.8),
        Mat3::IDENTITY * 4.0,
        64,
        Shading::Emission,
        Order::BackToFront,
        &lut,
        None,
    );
    let b = render(
        &constant([12, 12, 16], [1.0, 1.0, 0.5], 0.8),
        Mat3::IDENTITY * 4.0,
        64,
        Shading::Emission,
        Order::BackToFront,
        &lut,
        None,
    );
    // Analytic interior: 8 world units of opacity 0.24 per unit.
    let alpha: f32 = 1.0 - (1.0f32 - 0.3 * 0.8).powf(8.0);
    let mut worst = (0.0f32, 0.0f32);
    for y in 24..40 {
        for x in 24..40 {
            let (pa, pb) = (a.image[y * 64 + x], b.image[y * 64 + x]);
            worst.0 = worst.0.max((pa[3] - pb[3]).abs());
            worst.1 = worst.1.max((pa[3] - alpha).abs());
        }
    }
    assert_le(
        f64::from(worst.0),
        1e-3,
        "8 sheets vs 16 sheets at half spacing",
    );
    // Against the analytic value the kernel's flat-field ripple (2.6 % per sheet, see
    // tests/flat_field.rs) enters through the clamp-free compositing: allow 2 %.
    assert_le(
        f64::from(worst.1),
        0.02,
        "interior opacity vs 1 − (1 − α)^8",
    );
    assert_eq!(a.frame.sheet_distance, 1.0);
    assert_eq!(b.frame.sheet_distance, 0.5);
}

/// Anisotropic spacing is honoured: a constant 8×8×8 box with spacing 1,1,4 seen from the side is
/// four times taller than wide. The box is nearly transparent (α = 0.02 per unit), so compositing
/// stays close to linear and the half-of-interior level marks the nominal edge of the blur.
#[test]
fn anisotropic_spacing_sets_the_aspect() {
    let lut = vec![[1.0, 1.0, 1.0, 0.02], [1.0, 1.0, 1.0, 0.02]];
    // Look along +j: screen x = i, screen y = k (rotation about x by 90°).
    let view = Mat3::from_rotation_x(std::f32::consts::FRAC_PI_2) * 2.0;
    let out = render(
        &constant([8, 8, 8], [1.0, 1.0, 4.0], 1.0),
        view,
        96,
        Shading::Emission,
        Order::BackToFront,
        &lut,
        None,
    );
    assert_eq!(out.frame.sheet_axis, 1);
    let interior = out.image[48 * 96 + 48][3];
    let covered = |p: &[f32; 4]| p[3] > 0.5 * interior;
    let cols: Vec<usize> = (0..96)
        .filter(|&x| (0..96).any(|y| covered(&out.image[y * 96 + x])))
        .collect();
    let rows: Vec<usize> = (0..96)
        .filter(|&y| (0..96).any(|x| covered(&out.image[y * 96 + x])))
        .collect();
    let (w, h) = (cols.len() as f32, rows.len() as f32);
    // 8 world units wide and 32 tall at 2 px per unit: 16 × 64 px, each edge blurred by about a
    // pixel either way at the half-opacity threshold.
    assert!(
        (w - 16.0).abs() <= 2.0 && (h - 64.0).abs() <= 2.0,
        "box is {w} x {h} px, expected 16 x 64"
    );
}

/// Voxels classified transparent cost only the test: none is splatted, the image is the
/// background.
#[test]
fn transparent_voxels_are_skipped() {
    let lut = ramp(1.0);
    let bg = vec![[0.2, 0.1, 0.0, 1.0]; 48 * 48];
    let out = render(
        &constant([10, 10, 10], [1.0; 3], 0.0),
        Mat3::IDENTITY * 3.0,
        48,
        Shading::Phong(Phong::default()),
        Order::BackToFront,
        &lut,
        Some(&bg),
    );
    assert_eq!(out.stats.voxels, 1000);
    assert_eq!(out.stats.voxels_splatted, 0);
    assert_eq!(out.stats.pixel_updates, 0);
    assert_eq!(out.image, bg);
}

/// Central differences honour anisotropic spacing: f = z (world) on a 1,1,4 grid has world
/// gradient (0, 0, 1) whichever way the sheets run.
#[test]
fn gradient_is_in_world_units() {
    let spacing = [1.0, 2.0, 4.0];
    let dims = [5, 5, 5];
    let grid = Grid::from_spacing(spacing).unwrap();
    for view in [
        Mat3::IDENTITY,
        Mat3::from_rotation_x(1.3),
        Mat3::from_rotation_y(1.3),
    ] {
        let frame = FrameSetup::new(
            dims,
            &grid,
            &View::new(view * 4.0).unwrap(),
            &Kernel::PAPER_GAUSSIAN,
            FootprintOptions::default(),
            [64, 64],
        )
        .unwrap();
        // f = 0.3 x + 0.5 y + z in world coordinates.
        let f = |idx: [usize; 3]| {
            0.3 * idx[0] as f32 * spacing[0]
                + 0.5 * idx[1] as f32 * spacing[1]
                + idx[2] as f32 * spacing[2]
        };
        let (len, na, _) = frame.sheet_shape();
        let sheet = |s: usize| -> Vec<f32> {
            (0..len)
                .map(|n| f(frame.grid_index(s, n % na, n / na)))
                .collect()
        };
        let (lo, cur, hi) = (sheet(1), sheet(2), sheet(3));
        let w = SheetWindow {
            lower: Some(&lo[..]),
            current: &cur[..],
            upper: Some(&hi[..]),
        };
        for (u, v) in [(2, 2), (0, 3), (4, 4)] {
            let g = gradient(&frame, &w, u, v);
            assert!(
                (g - Vec3::new(0.3, 0.5, 1.0)).length() < 1e-5,
                "sheet axis {}: gradient {g} at ({u},{v})",
                frame.sheet_axis
            );
        }
    }
}

#[test]
fn renderer_errors_are_typed() {
    let lut = ramp(1.0);
    let kernel = Kernel::PAPER_GAUSSIAN;
    let grid = Grid::from_spacing([1.0; 3]).unwrap();
    let frame = FrameSetup::new(
        [4, 5, 6],
        &grid,
        &View::new(Mat3::IDENTITY * 4.0).unwrap(),
        &kernel,
        FootprintOptions::default(),
        [32, 32],
    )
    .unwrap();
    assert_eq!(frame.sheet_shape(), (20, 4, 5));
    let generic = GenericTable::<9>::build(kernel);
    let table = ViewTable::<9>::build(
        &frame.footprint,
        &generic,
        Lookup::Bilinear,
        Lookup::Bilinear,
    );
    let shader = Shader {
        labels: None,
        tf: TransferFunction {
            lut: &lut,
            lo: 0.0,
            hi: 1.0,
        },
        shading: Shading::Emission,
    };
    let (mut acc, mut img, mut rows) = (
        vec![[0.0f32; 4]; 1023],
        vec![[0.0f32; 4]; 1024],
        vec![RowSpan::EMPTY; 32],
    );
    let small = RenderBuffers {
        accumulator: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    assert!(matches!(
        SheetRenderer::new(&frame, &table, shader, Order::BackToFront, small, None),
        Err(RenderError::Buffer(_))
    ));
    let (mut acc, mut img, mut rows) = (
        vec![[0.0f32; 4]; 1024],
        vec![[0.0f32; 4]; 1024],
        vec![RowSpan::EMPTY; 32],
    );
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    let mut r =
        SheetRenderer::new(&frame, &table, shader, Order::BackToFront, buffers, None).unwrap();
    let short = vec![0.5f32; 19];
    let ok = vec![0.5f32; 20];
    assert_eq!(
        r.render_sheet(
            0,
            SheetWindow {
                lower: None,
                current: &short,
                upper: None
            }
        ),
        Err(RenderError::SheetLength {
            expected: 20,
            got: 19
        })
    );
    assert_eq!(
        r.render_sheet(
            6,
            SheetWindow {
                lower: None,
                current: &ok,
                upper: None
            }
        ),
        Err(RenderError::SheetIndex { index: 6, count: 6 })
    );
    let mut storage = vec![0.0f32; 59];
    assert!(SheetRing::new(&mut storage, &frame, Order::BackToFront).is_err());
    let mut storage = vec![0.0f32; 60];
    let mut ring = SheetRing::new(&mut storage, &frame, Order::BackToFront).unwrap();
    for _ in 0..6 {
        ring.push(&ok).unwrap();
    }
    assert_eq!(ring.push(&ok), Err(RenderError::TooManySheets));
    assert!(FrameSetup::new(
        [0, 5, 6],
        &grid,
        &View::new(Mat3::IDENTITY).unwrap(),
        &kernel,
        FootprintOptions::default(),
        [32, 32]
    )
    .is_err());
    assert!(FrameSetup::new(
        [4, 5, 6],
        &grid,
        &View::new(Mat3::IDENTITY).unwrap(),
        &kernel,
        FootprintOptions::default(),
        [0, 32]
    )
    .is_err());
}

/// Pre-shaded RGBA sheets render exactly like the same colours produced by a transfer function
/// (spacing 1 along the view, so the opacity correction is the identity).
#[test]
fn pre_shaded_sheets_match_classified_sheets() {
    let scene = blob([12, 10, 8], [1.0, 1.0, 1.0]);
    let lut = ramp(0.5);
    let view = Mat3::IDENTITY * 4.0;
    let classified = render(
        &scene,
        view,
        64,
        Shading::Emission,
        Order::BackToFront,
        &lut,
        None,
    );
    let frame = classified.frame;
    let shader = Shader {
        labels: None,
        tf: TransferFunction {
            lut: &lut,
            lo: 0.0,
            hi: 1.0,
        },
        shading: Shading::Emission,
    };
    let generic = GenericTable::<65>::build(Kernel::PAPER_GAUSSIAN);
    let table = ViewTable::<65>::build(
        &frame.footprint,
        &generic,
        Lookup::Bilinear,
        Lookup::Bilinear,
    );
    let n = frame.image_len();
    let (mut acc, mut img, mut rows) = (
        vec![[0.0f32; 4]; n],
        vec![[0.0f32; 4]; n],
        vec![RowSpan::EMPTY; 64],
    );
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    let mut r =
        SheetRenderer::new(&frame, &table, shader, Order::BackToFront, buffers, None).unwrap();
    let (len, _, _) = frame.sheet_shape();
    let mut values = vec![0.0f32; len];
    for step in 0..frame.sheet_count() {
        let s = frame.sheet_at(Order::BackToFront, step);
        scene.sheet(&frame, s, &mut values);
        let rgba: Vec<[f32; 4]> = values
            .iter()
            .map(|&v| {
                let c = shader.tf.lookup(v);
                [c[0] * c[3], c[1] * c[3], c[2] * c[3], c[3]]
            })
            .collect();
        r.render_shaded_sheet(s, &rgba).unwrap();
    }
    assert_eq!(
        r.render_shaded_sheet(0, &[[0.0; 4]; 3]),
        Err(RenderError::SheetLength {
            expected: len,
            got: 3
        })
    );
    r.finish();
    assert_le(
        f64::from(max_diff(&img, &classified.image)),
        1e-6,
        "pre-shaded vs classified",
    );
}

/// Emission shading remembered per sample value (`SheetRenderer::with_shade_cache`) gives the
/// same image bit for bit: on a volume of few distinct values (where it hits) and of many, with a
/// full-size memo and with memos so small that every value collides; other shadings ignore it.
#[test]
fn the_shade_cache_changes_no_bit() {
    let smooth = blob([13, 11, 9], [1.0, 1.2, 0.8]);
    let mut few = blob([13, 11, 9], [1.0, 1.2, 0.8]);
    few.data
        .iter_mut()
        .for_each(|v| *v = (*v * 16.0).round() / 16.0);
    let lut = ramp(0.7);
    let bits = |o: &Out| {
        o.image
            .iter()
            .flat_map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    for scene in [&smooth, &few] {
        for shading in [Shading::Emission, Shading::Phong(Phong::default())] {
            let plain = render(
                scene,
                oblique(3.0),
                48,
                shading,
                Order::FrontToBack,
                &lut,
                None,
            );
            assert!(plain.stats.voxels_splatted > 100);
            for len in [SHADE_CACHE_LEN, 3, 1] {
                let mut cache = vec![ShadeCacheEntry::default(); len];
                let cached = render_cached(
                    scene,
                    oblique(3.0),
                    48,
                    shading,
                    Order::FrontToBack,
                    &lut,
                    None,
                    Some(&mut cache),
                );
                assert_eq!(bits(&plain), bits(&cached), "{shading:?}, {len} entries");
            }
        }
    }
}
