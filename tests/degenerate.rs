//! Degenerate inputs: each is a typed error or a correct result, never a panic or a NaN.

use footprint::geometry::{Footprint, FootprintOptions, GeometryError, MAX_HALF_EXTENT_PX};
use footprint::splat::{splat, BufferError, ImageMut};
use footprint::{GenericTable, Grid, Kernel, KernelSpecError, Lookup, View, ViewTable};
use footprint_harness::args::MethodArg;
use footprint_suite::{assert_le, max_rel_diff, rows, splat_args, with_reference};
use glam::Mat3;
use proptest::prelude::*;

#[test]
fn bad_view_matrices_are_typed_errors() {
    let rank2 = Mat3::from_cols_array(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
    assert_eq!(View::new(rank2), Err(GeometryError::SingularView));
    assert_eq!(View::new(Mat3::ZERO), Err(GeometryError::SingularView));
    let mut nan = Mat3::IDENTITY;
    nan.x_axis.y = f32::NAN;
    assert_eq!(View::new(nan), Err(GeometryError::NonFinite));
    let mut inf = Mat3::IDENTITY;
    inf.z_axis.z = f32::INFINITY;
    assert_eq!(View::new(inf), Err(GeometryError::NonFinite));
    // Nearly singular: two columns parallel to 1e-7.
    let sliver = Mat3::from_cols_array(&[1.0, 1.0, 0.0, 1.0, 1.0 + 1e-7, 0.0, 0.0, 0.0, 1.0]);
    assert_eq!(View::new(sliver), Err(GeometryError::SingularView));
    // Squashing depth is not singular: an orthographic footprint does not depend on it.
    assert!(View::new(Mat3::from_diagonal(glam::Vec3::new(1.0, 1.0, 1e-9))).is_ok());
}

#[test]
fn bad_spacings_and_grids_are_typed_errors() {
    assert_eq!(
        Grid::from_spacing([1.0, 0.0, 1.0]),
        Err(GeometryError::NonPositiveSpacing {
            axis: 1,
            value: 0.0
        })
    );
    assert_eq!(
        Grid::from_spacing([1.0, 1.0, -2.0]),
        Err(GeometryError::NonPositiveSpacing {
            axis: 2,
            value: -2.0
        })
    );
    assert_eq!(
        Grid::from_spacing([f32::NAN, 1.0, 1.0]),
        Err(GeometryError::NonFinite)
    );
    let flat = Mat3::from_cols_array(&[1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    assert_eq!(Grid::from_matrix(flat), Err(GeometryError::SingularGrid));
    // A sheared, rotated grid is fine.
    assert!(Grid::from_matrix(Mat3::from_cols_array(&[
        1.0, 0.2, 0.0, 0.0, 1.0, 0.3, 0.1, 0.0, 2.0
    ]))
    .is_ok());
}

#[test]
fn bad_options_are_typed_errors() {
    let g = Mat3::IDENTITY * 4.0;
    let k = Kernel::PAPER_GAUSSIAN;
    for bad in [0.5f32, 0.0, -1.0, f32::NAN, f32::INFINITY] {
        let r = Footprint::new(
            &k,
            &g,
            FootprintOptions {
                min_radius_px: bad,
                ..Default::default()
            },
        );
        assert!(
            matches!(r, Err(GeometryError::BadMinRadius { .. })),
            "min radius {bad}: {r:?}"
        );
    }
    let huge = Mat3::IDENTITY * (MAX_HALF_EXTENT_PX * 2.0);
    assert!(matches!(
        Footprint::new(&k, &huge, FootprintOptions::default()),
        Err(GeometryError::TooLarge { .. })
    ));
}

#[test]
fn bad_buffers_are_typed_errors() {
    let mut px = [0.0f32; 99];
    assert_eq!(
        ImageMut::new(&mut px, 10, 10, 10).unwrap_err(),
        BufferError::TooSmall {
            needed: 100,
            got: 99
        }
    );
    assert_eq!(
        ImageMut::new(&mut px, 10, 5, 9).unwrap_err(),
        BufferError::StrideTooSmall {
            stride: 9,
            width: 10
        }
    );
    assert!(matches!(
        ImageMut::new(&mut px, usize::MAX, 2, usize::MAX).unwrap_err(),
        BufferError::TooLarge { .. }
    ));
    // Exactly enough with a stride: stride × (h − 1) + w.
    assert!(ImageMut::new(&mut px, 9, 10, 10).is_ok());
    assert!(ImageMut::new(&mut px[..0], 0, 0, 0).is_ok());
    // A NaN centre is refused, not silently dropped.
    let k = Kernel::PAPER_GAUSSIAN;
    let fp = Footprint::new(&k, &(Mat3::IDENTITY * 4.0), FootprintOptions::default()).unwrap();
    let table = ViewTable::<9>::build(
        &fp,
        &GenericTable::<9>::build(k),
        Lookup::Bilinear,
        Lookup::Bilinear,
    );
    let mut img = ImageMut::new(&mut px, 9, 11, 9).unwrap();
    assert_eq!(
        splat(&table, [f32::NAN, 1.0], &1.0, &mut img),
        Err(BufferError::NonFiniteCenter)
    );
    // A zero-size image takes splats and does nothing.
    let mut empty: [f32; 0] = [];
    let mut img = ImageMut::new(&mut empty, 0, 0, 0).unwrap();
    assert_eq!(
        splat(&table, [0.0, 0.0], &1.0, &mut img)
            .unwrap()
            .pixels_updated,
        0
    );
}

#[test]
fn bad_kernel_specs_are_typed_errors() {
    use KernelSpecError::*;
    assert_eq!(Kernel::parse("gauss"), Err(UnknownKernel));
    assert_eq!(Kernel::parse(""), Err(BadLength { len: 0 }));
    assert!(matches!(
        Kernel::parse(&"x".repeat(65)),
        Err(BadLength { len: 65 })
    ));
    assert_eq!(
        Kernel::parse("gaussian:spread=abc"),
        Err(BadNumber { at: 16 })
    );
    assert_eq!(Kernel::parse("gaussian:spread"), Err(BadNumber { at: 9 }));
    assert_eq!(
        Kernel::parse("gaussian:width=2"),
        Err(UnknownParameter { at: 9 })
    );
    assert_eq!(
        Kernel::parse("cone:spread=1,spread=2"),
        Err(DuplicateParameter { at: 14 })
    );
    assert!(matches!(
        Kernel::parse("gaussian:spread=0"),
        Err(OutOfRange {
            param: "spread",
            ..
        })
    ));
    assert!(matches!(
        Kernel::parse("gaussian:spread=NaN"),
        Err(OutOfRange {
            param: "spread",
            ..
        })
    ));
    assert!(matches!(
        Kernel::parse("gaussian:sigmas=inf"),
        Err(OutOfRange {
            param: "sigmas",
            ..
        })
    ));
    assert_eq!(Kernel::parse("sinc:lobes=4"), Err(EvenLobes));
    assert!(matches!(
        Kernel::parse("sinc:lobes=2.5"),
        Err(OutOfRange { param: "lobes", .. })
    ));
    assert!(matches!(
        Kernel::parse("sinc:lobes=99"),
        Err(OutOfRange { param: "lobes", .. })
    ));
}

proptest! {
    #![proptest_config(footprint_suite::proptest_config(256))]

    #[test]
    fn any_spec_string_parses_or_errors_without_panic(s in ".{0,80}") {
        let _ = Kernel::parse(&s);
    }

    #[test]
    fn any_matrix_sets_up_or_errors_without_nan(m in proptest::array::uniform9(-1e6f32..1e6)) {
        let g = Mat3::from_cols_array(&m);
        for k in footprint_suite::default_kernels() {
            if let Ok(fp) = Footprint::new(&k, &g, FootprintOptions::default()) {
                prop_assert!(fp.half_extent.iter().all(|v| v.is_finite() && *v > 0.0));
                prop_assert!(fp.scale.is_finite() && fp.scale > 0.0);
            }
        }
    }
}

/// A footprint of 1e-3 px is widened to the minimum radius and renormalised: it keeps exactly its
/// weight wherever it lands, and matches the f64 reference (which applies the same model).
#[test]
fn footprint_of_a_thousandth_of_a_pixel_keeps_its_weight() {
    for method in [MethodArg::Robust, MethodArg::Direct, MethodArg::Paper] {
        for center in [
            [16.0f32, 16.0],
            [16.37, 15.81],
            [16.5, 16.5],
            [16.999, 16.001],
        ] {
            let mut a = splat_args();
            a.size = (32, 32);
            a.spacing = [1.0, 1.0, 1.0];
            a.view_matrix = Some(rows(&(Mat3::IDENTITY * (1e-3 / 1.6))));
            a.center = Some(center);
            a.footprint.method = method;
            let (img, r) = with_reference(&a);
            assert!(img.data.iter().all(|v| v.is_finite() && *v >= 0.0));
            let sum: f64 = img.data.iter().map(|&v| f64::from(v)).sum();
            assert_le(
                (sum - 1.0).abs(),
                1e-5,
                &format!("{method:?} at {center:?}: total weight"),
            );
            assert_le(
                max_rel_diff(&img, &r),
                0.01,
                &format!("{method:?} at {center:?}: vs reference"),
            );
        }
    }
}

/// A footprint of radius 1e4 px (far larger than the 256² image) is right where it is seen.
#[test]
fn footprint_of_ten_thousand_pixels_is_right_on_screen() {
    for method in [MethodArg::Robust, MethodArg::Direct, MethodArg::Paper] {
        let mut a = splat_args();
        a.spacing = [1.0, 1.0, 1.0];
        a.view_matrix = Some(rows(&(Mat3::from_rotation_z(0.3) * (1e4 / 1.6))));
        a.center = Some([100.0, 40.0]);
        a.footprint.method = method;
        let (img, r) = with_reference(&a);
        assert!(img.data.iter().all(|v| v.is_finite()));
        assert_le(
            max_rel_diff(&img, &r),
            0.01,
            &format!("{method:?}: 1e4 px footprint vs reference"),
        );
        let (s, sr): (f64, f64) = (
            img.data.iter().map(|&v| f64::from(v)).sum(),
            r.data.iter().map(|&v| f64::from(v)).sum(),
        );
        assert_le(
            (s - sr).abs() / sr,
            0.01,
            &format!("{method:?}: on-screen weight"),
        );
    }
}

#[test]
fn cli_reports_bad_input_with_exit_code_2_and_writes_nothing() {
    let dir = footprint_suite::tmpdir("degenerate");
    let out = dir.join("x.pfm");
    let o = out.to_str().unwrap();
    let (tiff, missing) = (dir.join("x.tiff"), dir.join("missing.fpt"));
    let (tiff, missing) = (tiff.to_str().unwrap(), missing.to_str().unwrap());
    let cases: &[&[&str]] = &[
        &[
            "footprint",
            "splat",
            "--view-matrix",
            "1,0,0,0,1,0,0,0,0",
            "--out",
            o,
        ],
        &["footprint", "splat", "--spacing", "1,0,1", "--out", o],
        &["footprint", "splat", "--spacing", "1,nan,1", "--out", o],
        &["footprint", "splat", "--kernel", "gauss", "--out", o],
        &["footprint", "splat", "--table", "64", "--out", o],
        &["footprint", "splat", "--size", "0x10", "--out", o],
        &["footprint", "splat", "--out", tiff],
        &["footprint", "splat", "--table-file", missing, "--out", o],
        &["footprint", "splat"],
    ];
    for args in cases {
        assert_eq!(footprint_harness::run(*args), 2, "{args:?}");
        assert!(!out.exists(), "{args:?} left an output behind");
    }
    assert_eq!(
        footprint_harness::run(["footprint", "splat", "--size", "16x16", "--out", o]),
        0
    );
    assert!(out.exists());
}
