//! The core as a library: an in-memory volume source, the view helper, output conversions, typed
//! errors for bad transfer functions, and a ring that refuses a frame it was not given whole.

use footprint::composite::RowSpan;
use footprint::frame::{FrameSetup, Order};
use footprint::output::{rgb565, srgb8, srgb_encode};
use footprint::render::{RenderBuffers, RenderError, SheetRenderer, SheetRing};
use footprint::shade::{Shader, Shading, TransferFunction, TransferFunctionError};
use footprint::source::{render_from, SheetSource};
use footprint::volume::{MemoryVolume, VolumeError};
use footprint::{FootprintOptions, GenericTable, Grid, Kernel, Lookup, View, ViewTable};

/// A `dims` volume whose sample at (i, j, k) is f(i, j, k), x fastest.
fn volume<T>(dims: [usize; 3], f: impl Fn(usize, usize, usize) -> T) -> Vec<T> {
    let mut v = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                v.push(f(i, j, k));
            }
        }
    }
    v
}

/// Every sheet of every axis, against indexing by hand: element (u, v) of sheet s along `axis` is
/// the voxel with index s on `axis`, u on the lower in-sheet axis, v on the upper.
fn check_sheets<T: footprint::shade::Sample + PartialEq + std::fmt::Debug>(
    dims: [usize; 3],
    f: impl Fn(usize, usize, usize) -> T + Copy,
) {
    let data = volume(dims, f);
    let mut vol = MemoryVolume::new(&data, dims).unwrap();
    for axis in 0..3 {
        let (a, b) = footprint::geometry::in_sheet_axes(axis);
        let mut out = vec![f(0, 0, 0); dims[a] * dims[b]];
        for s in 0..dims[axis] {
            vol.read_sheet(axis, s, &mut out).unwrap();
            for v in 0..dims[b] {
                for u in 0..dims[a] {
                    let mut idx = [0; 3];
                    idx[axis] = s;
                    idx[a] = u;
                    idx[b] = v;
                    assert_eq!(
                        out[v * dims[a] + u],
                        f(idx[0], idx[1], idx[2]),
                        "axis {axis} sheet {s} ({u}, {v})"
                    );
                }
            }
        }
        // Wrong sheet length and index are typed errors.
        let mut short = vec![f(0, 0, 0); dims[a] * dims[b] - 1];
        assert!(matches!(
            vol.read_sheet(axis, 0, &mut short),
            Err(RenderError::SheetLength { .. })
        ));
        assert!(matches!(
            vol.read_sheet(axis, dims[axis], &mut out),
            Err(RenderError::SheetIndex { .. })
        ));
    }
}

#[test]
fn memory_volumes_deliver_every_sheet_of_every_axis() {
    let dims = [5, 3, 4];
    check_sheets(dims, |i, j, k| (i + 10 * j + 100 * k) as u8);
    check_sheets(dims, |i, j, k| {
        (i as i16) - (j as i16) * 7 + (k as i16) * 300
    });
    check_sheets(dims, |i, j, k| (i * 65_000 + j * 3 + k) as u32);
    check_sheets(dims, |i, j, k| i as f32 * 0.5 - j as f32 + k as f32 * 1e3);
    check_sheets(dims, |i, j, k| (i + j + k) as f64 / 3.0);
    check_sheets([1, 1, 1], |_, _, _| 7i8);
}

#[test]
fn memory_volume_errors_are_typed() {
    let data = [0u8; 24];
    assert_eq!(
        MemoryVolume::new(&data, [2, 3, 5]).unwrap_err(),
        VolumeError::Length {
            dims: [2, 3, 5],
            got: 24
        }
    );
    assert!(matches!(
        MemoryVolume::new(&data, [0, 3, 8]),
        Err(VolumeError::EmptyDimension { .. })
    ));
    assert!(matches!(
        MemoryVolume::new(&data, [usize::MAX, 2, 2]),
        Err(VolumeError::Length { .. })
    ));
    let v = MemoryVolume::new(&data, [2, 3, 4]).unwrap();
    assert_eq!(v.range(), Some((0.0, 0.0)));
    let nan = [f32::NAN, 2.0, -1.0, f32::INFINITY];
    assert_eq!(
        MemoryVolume::new(&nan, [4, 1, 1]).unwrap().range(),
        Some((-1.0, 2.0))
    );
}

/// `View::from_angles` (the core's own turntable convention, kept for library users): at zero
/// angles +i runs right and +j down; the fitted box fills 90 % of the tighter side; azimuth 90°
/// turns +k to the right.
#[test]
fn view_from_angles_is_the_turntable_convention() {
    let grid = Grid::from_spacing([1.0, 1.0, 1.0]).unwrap();
    let v = View::from_angles([0.0; 3], 1.0, [10, 20, 5], &grid, [200, 100]).unwrap();
    let m = v.to_screen();
    // Box 10 × 20 (half 5 × 10): the height is tighter: 0.9 · 100 / 20 = 4.5 px per unit.
    assert!((m.x_axis.x - 4.5).abs() < 1e-5 && m.x_axis.y.abs() < 1e-6);
    assert!((m.y_axis.y - 4.5).abs() < 1e-5 && m.y_axis.x.abs() < 1e-6);
    let v = View::from_angles([90.0, 0.0, 0.0], 2.0, [10, 10, 10], &grid, [100, 100]).unwrap();
    let k_on_screen = v.to_screen().z_axis;
    assert!(k_on_screen.x.abs() > 0.99 * k_on_screen.length());
    assert!(View::from_angles([0.0; 3], 0.0, [2; 3], &grid, [8, 8]).is_err());
    assert!(View::from_angles([f32::NAN, 0.0, 0.0], 1.0, [2; 3], &grid, [8, 8]).is_err());
    assert!(View::from_angles([0.0; 3], 1.0, [0, 2, 2], &grid, [8, 8]).is_err());
    // glam is the core's own, re-exported.
    let _: footprint::glam::Mat3 = m;
}

/// Rotation of `v` by `deg` degrees about `axis` (right-handed; VTK's `RotateWXYZ`), in f64.
fn rotate(v: [f64; 3], axis: [f64; 3], deg: f64) -> [f64; 3] {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let k = axis.map(|a| a / n);
    let (s, c) = deg.to_radians().sin_cos();
    let dot = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    let cross = [
        k[1] * v[2] - k[2] * v[1],
        k[2] * v[0] - k[0] * v[2],
        k[0] * v[1] - k[1] * v[0],
    ];
    [0, 1, 2].map(|i| v[i] * c + cross[i] * s + k[i] * dot * (1.0 - c))
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|x| x / n)
}

/// vtkCamera, step by step as VTK 9 does it (focal point at the origin): position (0, 0, 1),
/// view-up +y; `Azimuth` turns the position about view-up; `Elevation` turns it about minus the
/// first row of the view transform and restores view-up; `Roll` turns view-up about the
/// direction of projection; `SetupCamera` builds the rows sideways = up × n, orthoUp = n ×
/// sideways, n (n = position − focal point). Returns the rows of the world-to-screen rotation
/// (x right, y down, z away: sideways, −orthoUp, −n).
fn vtk_camera(az: f64, el: f64, roll: f64) -> [[f64; 3]; 3] {
    let rows = |pos: [f64; 3], up: [f64; 3]| {
        let n = unit(pos);
        let side = unit(cross(up, n));
        (side, cross(n, side), n)
    };
    let up = [0.0, 1.0, 0.0];
    let pos = rotate([0.0, 0.0, 1.0], up, az);
    let (side, _, _) = rows(pos, up);
    let pos = rotate(pos, side.map(|x| -x), el);
    let dop = unit(pos).map(|x| -x);
    let up = rotate(up, dop, roll);
    let (side, ortho, n) = rows(pos, up);
    [side, ortho.map(|x| -x), n.map(|x| -x)]
}

/// `--view AZ,EL,ROLL` is VTK's camera: the core's `View::from_vtk_camera` equals VTK's
/// operations done step by step in f64 (above) for angles all round, elevations past ±90°
/// included; the fit is ResetCamera's (the bounding sphere of the voxel centres fits the shorter
/// image side); ParaView's six direction buttons look where they say; the CLI builds the same.
#[test]
fn view_is_vtks_camera() {
    let grid = Grid::from_spacing([1.0, 1.0, 1.0]).unwrap();
    // Defaults: +i right, +j up (screen y down is −j), looking along −k.
    let m = View::from_vtk_camera([0.0; 3], 1.0, [10, 20, 5], &grid, [200, 100])
        .unwrap()
        .to_screen();
    // Bounds 9 × 19 × 4: radius √458 / 2; the image's shorter side is 100 px.
    let s = 100.0 / 458f32.sqrt();
    assert!((m.x_axis.x - s).abs() < 1e-4, "{m:?}");
    assert!((m.y_axis.y + s).abs() < 1e-4, "{m:?}");
    assert!((m.z_axis.z + s).abs() < 1e-4, "{m:?}");
    // Tall images fit the width (VTK divides the parallel scale by the aspect).
    let tall = View::from_vtk_camera([0.0; 3], 2.0, [10, 20, 5], &grid, [80, 300]).unwrap();
    assert!((tall.to_screen().x_axis.x - 2.0 * 80.0 / 458f32.sqrt()).abs() < 1e-4);
    let mut worst = 0.0f64;
    for az in (-180..=180).step_by(35) {
        for el in (-175..=175).step_by(25) {
            for roll in [-120.0, 0.0, 33.0, 90.0] {
                let (az, el) = (f64::from(az), f64::from(el));
                let want = vtk_camera(az, el, roll);
                let m = View::from_vtk_camera(
                    [az as f32, el as f32, roll as f32],
                    1.0,
                    [2, 2, 2],
                    &grid,
                    [10, 10],
                )
                .unwrap()
                .to_screen();
                // Bounds 1 × 1 × 1: radius √3 / 2, 10 px: 10 / √3 px per unit.
                let m = m * (3f32.sqrt() / 10.0);
                for (r, row) in want.iter().enumerate() {
                    for (c, w) in row.iter().enumerate() {
                        let got = f64::from(m.col(c)[r]);
                        worst = worst.max((got - w).abs());
                    }
                }
            }
        }
    }
    assert!(worst < 1e-5, "worst entry differs by {worst}");
    // ParaView's buttons: the direction of projection and the up vector they set.
    for (name, dop, up) in [
        ("+x", [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ("-x", [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ("+y", [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ("-y", [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]),
        ("+z", [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ("-z", [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
    ] {
        let via_cli = cli_view(&["--view", name, "--size", "64x48"], &grid);
        let want = View::looking(
            footprint::glam::Vec3::from_array(dop),
            footprint::glam::Vec3::from_array(up),
            1.0,
            [10, 20, 5],
            &grid,
            [64, 48],
        )
        .unwrap()
        .to_screen();
        assert!(
            via_cli.abs_diff_eq(want, 1e-5),
            "{name}: {via_cli:?} vs {want:?}"
        );
        // Screen z is the direction of projection, screen y (down) is minus up.
        let inv = via_cli.transpose();
        assert!(inv
            .z_axis
            .normalize()
            .abs_diff_eq(footprint::glam::Vec3::from_array(dop), 1e-5));
        assert!((-inv.y_axis.normalize()).abs_diff_eq(footprint::glam::Vec3::from_array(up), 1e-5));
    }
    // The CLI's angles build the core's view.
    let via_cli = cli_view(
        &["--view", "30,20,10", "--zoom", "1.5", "--size", "64x48"],
        &grid,
    );
    let direct = View::from_vtk_camera([30.0, 20.0, 10.0], 1.5, [10, 20, 5], &grid, [64, 48])
        .unwrap()
        .to_screen();
    assert_eq!(via_cli, direct);
    assert!(View::from_vtk_camera([0.0; 3], 0.0, [2; 3], &grid, [8, 8]).is_err());
    assert!(View::from_vtk_camera([f32::NAN, 0.0, 0.0], 1.0, [2; 3], &grid, [8, 8]).is_err());
    assert!(View::from_vtk_camera([0.0; 3], 1.0, [0, 2, 2], &grid, [8, 8]).is_err());
    assert!(footprint_harness::args::parse_args(&["--view", "+w"]).is_err());
}

/// The screen map the command line's `flags` give a 10×20×5 volume on `grid`.
fn cli_view(flags: &[&str], grid: &Grid) -> footprint::glam::Mat3 {
    let args = footprint_harness::args::parse_args(flags).unwrap();
    let scene = footprint_harness::args::scene(&args).unwrap();
    footprint_harness::pipeline::stages::prepare::view_for(&scene, [10, 20, 5], grid)
        .unwrap()
        .to_screen()
}

#[test]
fn output_conversions_match_the_srgb_curve() {
    let exact = |c: f64| {
        let c = c.clamp(0.0, 1.0);
        if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
    };
    let mut worst = 0.0f64;
    for n in 0..=20_000 {
        let c = n as f32 / 20_000.0;
        let e = exact(f64::from(c));
        worst = worst.max((f64::from(srgb_encode(c)) - e).abs());
        let code = srgb8([c, c, c, c])[0];
        assert!(
            (f64::from(code) - e * 255.0).abs() <= 1.0,
            "{c}: code {code}, exact {}",
            e * 255.0
        );
        let p = rgb565([c, 0.0, 0.0, 1.0]);
        assert!(
            (f64::from(p >> 11) - e * 31.0).abs() <= 1.0,
            "{c}: {p:#06x}"
        );
    }
    // The backend's stated power error (micromath's is larger), times the curve's 1.055.
    let bound = 2e-4 + 1.055 * f64::from(footprint::math::ERROR_BOUNDS.powf_unit_abs);
    assert!(worst < bound, "sRGB curve off by {worst}, bound {bound}");
    assert_eq!(srgb8([0.0; 4]), [0, 0, 0, 0]);
    assert_eq!(srgb8([1.0; 4]), [255; 4]);
    assert_eq!(srgb8([2.0, -1.0, f32::NAN, 0.5]), [255, 0, 0, 128]);
    assert_eq!(rgb565([1.0, 1.0, 1.0, 1.0]), 0xffff);
    assert_eq!(rgb565([0.0, 1.0, 0.0, 1.0]), 0x07e0);
    assert_eq!(rgb565([0.0, 0.0, 1.0, 1.0]), 0x001f);
    assert_eq!(rgb565([f32::NAN, 0.0, 0.0, 1.0]), 0);
}

/// Renders `dims` (value = i + j + k) with `tf`'s LUT and window, pushing `push` sheets by hand.
fn ring_render(
    lut: &[[f32; 4]],
    lo: f32,
    hi: f32,
    push: Option<usize>,
) -> Result<(u32, Vec<[f32; 4]>), RenderError> {
    ring_render_ordered(lut, lo, hi, push, None)
}

/// [`ring_render`] (back to front) through a ring made for `ring_order` (`None`: the renderer's,
/// [`SheetRing::for_renderer`]).
fn ring_render_ordered(
    lut: &[[f32; 4]],
    lo: f32,
    hi: f32,
    push: Option<usize>,
    ring_order: Option<Order>,
) -> Result<(u32, Vec<[f32; 4]>), RenderError> {
    let dims = [6, 5, 8];
    let grid = Grid::from_spacing([1.0; 3]).unwrap();
    let view = View::from_angles([0.0; 3], 1.0, dims, &grid, [24, 24]).unwrap();
    let frame = FrameSetup::new(
        dims,
        &grid,
        &view,
        &Kernel::PAPER_GAUSSIAN,
        FootprintOptions::default(),
        [24, 24],
    )
    .unwrap();
    let generic = GenericTable::<17>::build(Kernel::PAPER_GAUSSIAN);
    let table = ViewTable::<17>::build(
        &frame.footprint,
        &generic,
        Lookup::Bilinear,
        Lookup::Bilinear,
    );
    let shader = Shader {
        labels: None,
        tf: TransferFunction { lut, lo, hi },
        shading: Shading::Emission,
    };
    let n = frame.image_len();
    let (mut acc, mut img, mut rows) = (
        vec![[0.0f32; 4]; n],
        vec![[0.0f32; 4]; n],
        vec![RowSpan::EMPTY; 24],
    );
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    let order = Order::BackToFront;
    let mut r = SheetRenderer::new(&frame, &table, shader, order, buffers, None)?;
    let data = volume(dims, |i, j, k| (i + j + k) as u8);
    let mut vol = MemoryVolume::new(&data, dims).unwrap();
    let mut storage = vec![0u8; 3 * frame.sheet_shape().0];
    let mut ring = match ring_order {
        Some(o) => SheetRing::new(&mut storage, &frame, o)?,
        None => SheetRing::for_renderer(&mut storage, &r)?,
    };
    match push {
        None => render_from(&mut r, &mut ring, &mut vol)?,
        Some(count) => {
            for step in 0..count {
                let s = ring.sheet_index(step);
                let done = ring.push_with(|slot| vol.read_sheet(frame.sheet_axis, s, slot))?;
                if let Some(done) = done {
                    r.render_sheet(ring.sheet_index(done), ring.window(done))?;
                }
            }
            ring.finish(&mut r)?;
        }
    }
    let stats = r.finish();
    Ok((stats.sheets, img))
}

#[test]
fn rings_refuse_a_frame_they_were_not_given_whole() {
    let lut = [[0.0; 4], [1.0, 1.0, 1.0, 0.3]];
    let (sheets, full) = ring_render(&lut, 0.0, 16.0, None).unwrap();
    assert_eq!(sheets, 8);
    // By hand, every sheet pushed and the ring finished: the same image as the driver.
    let (sheets, by_hand) = ring_render(&lut, 0.0, 16.0, Some(8)).unwrap();
    assert_eq!((sheets, &by_hand), (8, &full));
    // The last sheet never pushed: refused, not 7 of 8 rendered in silence.
    assert_eq!(
        ring_render(&lut, 0.0, 16.0, Some(7)).unwrap_err(),
        RenderError::MissingSheets {
            delivered: 7,
            expected: 8
        }
    );
}

#[test]
fn bad_transfer_functions_are_typed_errors() {
    let lut = [[0.0; 4], [1.0; 4]];
    let window = ring_render(&lut, 5.0, 5.0, None).unwrap_err();
    assert!(
        matches!(
            window,
            RenderError::TransferFunction(TransferFunctionError::Window { .. })
        ),
        "{window:?}"
    );
    assert!(window.to_string().contains('5'), "{window}");
    let empty = ring_render(&[], 0.0, 1.0, None).unwrap_err();
    assert!(
        matches!(
            empty,
            RenderError::TransferFunction(TransferFunctionError::TooFewEntries { len: 0 })
        ),
        "{empty:?}"
    );
    let bad = ring_render(&[[0.0; 4], [2.0, 0.0, 0.0, 1.0]], 0.0, 1.0, None).unwrap_err();
    assert!(matches!(
        bad,
        RenderError::TransferFunction(TransferFunctionError::Entry { index: 1 })
    ));
}

#[allow(dead_code)] // its `main` is the example's.
#[path = "../core/examples/in_memory.rs"]
mod in_memory_example;

/// `core/examples/in_memory.rs` (the front door, `footprint::prelude`) and `footprint render` on
/// the same volume written as a raw file, with the flags its doc names (`--slicing object`: the
/// core has no pilot for the default plan) and every other flag at its default (threads, levels,
/// supersampling, table, phases, their lookup): the same PNG bytes.
#[test]
fn the_in_memory_example_writes_the_cli_png_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let [raw, lib, cli] = ["v.raw", "lib.png", "cli.png"].map(|f| dir.path().join(f));
    let data = in_memory_example::volume();
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(&raw, bytes).unwrap();
    in_memory_example::render_png(lib.to_str().unwrap()).unwrap();
    let args = "render RAW --dims 64,64,48 --type u16 --spacing 1,1,1.5 --view 30,20,0 \
                --tf ct-bone-skin --window 0,4000 --shading phong --size 256x256 --slicing object \
                --out OUT";
    let args: Vec<&str> = args
        .split_whitespace()
        .map(|a| match a {
            "RAW" => raw.to_str().unwrap(),
            "OUT" => cli.to_str().unwrap(),
            a => a,
        })
        .collect();
    assert_eq!(footprint_suite::run_cli(&args), 0);
    let (a, b) = (std::fs::read(&lib).unwrap(), std::fs::read(&cli).unwrap());
    assert!(
        a == b,
        "library and CLI PNGs differ ({} and {} bytes)",
        a.len(),
        b.len()
    );
    // And the picture is not empty: bone and skin both show.
    assert!(a.len() > 4000);
}

/// A ring made for the other compositing order than the renderer's is refused (it would feed the
/// sheets in the wrong order: a silently wrong image before); `for_renderer` takes the order from
/// the renderer, so it is given once.
#[test]
fn a_ring_for_another_order_is_refused() {
    let lut = [[0.0; 4], [1.0, 1.0, 1.0, 0.3]];
    let e = ring_render_ordered(&lut, 0.0, 16.0, None, Some(Order::FrontToBack)).unwrap_err();
    assert!(matches!(e, RenderError::RingOrder { .. }), "{e:?}");
    assert!(e.to_string().contains("for_renderer"), "{e}");
    let same = ring_render_ordered(&lut, 0.0, 16.0, None, Some(Order::BackToFront)).unwrap();
    assert_eq!(same, ring_render(&lut, 0.0, 16.0, None).unwrap());
}

/// Every public error of the front door prints a message and is a `std::error::Error`.
#[test]
fn front_door_errors_display() {
    use footprint::prelude::*;
    let s = Settings::new([0, 16], Preset::Grey.lut());
    let e: Error = s.lengths([8, 8, 8]).unwrap_err();
    let _: &dyn std::error::Error = &e;
    assert!(!e.to_string().is_empty());
    let m = footprint::source::OrderMismatch {
        source_axis: 2,
        frame_axis: 0,
    };
    let e: Box<dyn std::error::Error> = Box::new(m);
    assert!(e.to_string().contains("k (z)"), "{e}");
    // Buffers too short are refused, not written past.
    let s = Settings::new([16, 16], Preset::Grey.lut());
    let n = s.lengths([8, 8, 8]).unwrap();
    let (mut image, mut work) = (vec![[0.0; 4]; n.pixels], vec![0.0; n.work - 1]);
    let (mut rows, mut sheets) = (vec![RowSpan::EMPTY; n.rows], vec![0u8; n.sheets]);
    let generic = GenericTable::<17>::build(s.kernel);
    let b = Buffers::new(&mut image, &mut work, &mut rows, &mut sheets);
    assert!(render_volume(&[0u8; 512], [8, 8, 8], &s, &generic, b).is_err());
}
