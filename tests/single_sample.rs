//! The single-sample footprint against the f64 reference (issue "must show" 2): for the paper
//! Gaussian, spacing 60,30,30, table 65, bilinear, robust, at any rotation, the footprint is within
//! 1 % (max abs difference relative to the reference's peak). Also the other methods and kernels,
//! with the measured errors printed (`-- --nocapture`).

use footprint_harness::args::{LookupArg, MethodArg};
use footprint_suite::{assert_le, max_rel_diff, splat_args, with_reference};
use proptest::prelude::*;

proptest! {
    #![proptest_config(footprint_suite::proptest_config(40))]

    #[test]
    fn paper_gaussian_65_bilinear_robust_within_1_percent_at_any_rotation(
        rx in -180.0f32..180.0, ry in -180.0f32..180.0, rz in -180.0f32..180.0,
    ) {
        let mut a = splat_args();
        (a.rotate_x, a.rotate_y, a.rotate_z) = (rx, ry, rz);
        let (img, r) = with_reference(&a);
        let d = max_rel_diff(&img, &r);
        prop_assert!(d <= 0.01, "rotation ({rx}, {ry}, {rz}): {d:.5}");
    }
}

#[test]
fn methods_and_kernels_against_reference() {
    println!("max |core − reference| / peak, spacing 60,30,30, view (20°, 10°, 30°), 256×256");
    println!(
        "{:<32} {:<9} {:<8} {:>9} {:>9} {:>9}",
        "kernel", "lookup", "method", "N=11", "33", "65"
    );
    for kernel in ["gaussian:spread=1.6,sigmas=2.5", "cone", "sinc", "bilinear"] {
        for lookup in [LookupArg::Nearest, LookupArg::Bilinear] {
            for method in [MethodArg::Robust, MethodArg::Paper, MethodArg::Direct] {
                let mut errs = Vec::new();
                for n in [11, 33, 65] {
                    let mut a = splat_args();
                    a.footprint.kernel = kernel.into();
                    (a.rotate_x, a.rotate_y, a.rotate_z) = (20.0, 10.0, 30.0);
                    (a.footprint.table, a.footprint.lookup, a.footprint.method) =
                        (n, lookup, method);
                    if kernel == "sinc" {
                        a.spacing = [20.0, 10.0, 10.0]; // spread 5: keep it on the 256² image
                    }
                    let (img, r) = with_reference(&a);
                    errs.push(max_rel_diff(&img, &r));
                }
                println!(
                    "{:<32} {:<9} {:<8} {:>9.2e} {:>9.2e} {:>9.2e}",
                    kernel,
                    format!("{lookup:?}"),
                    format!("{method:?}"),
                    errs[0],
                    errs[1],
                    errs[2]
                );
                // Every configuration improves from N=11 to N=65, except the separable model on
                // the paper map, which orients the tent along the ellipse's axes rather than the
                // grid's (see `bilinear_model_needs_the_grid_orientation`).
                let wrong_orientation = kernel == "bilinear" && method == MethodArg::Paper;
                if !wrong_orientation {
                    assert!(
                        errs[2] < errs[0],
                        "{kernel} {lookup:?} {method:?}: {errs:?}"
                    );
                }
                if lookup == LookupArg::Bilinear && !wrong_orientation {
                    // The Gaussian is smooth inside its support: within the 1 %. The cone's
                    // apex and the bilinear model's ridges are gradient kinks, and the sinc has
                    // five lobes across its radius; interpolating tables across those costs O(h),
                    // measured 0.9–3.6 % at N = 65 (table above).
                    let bound = match kernel {
                        "sinc" => 0.04,
                        "cone" | "bilinear" => 0.025,
                        _ => 0.01,
                    };
                    assert_le(
                        errs[2],
                        bound,
                        &format!("{kernel} {method:?} N=65 bilinear"),
                    );
                }
            }
        }
    }
}

/// The bilinear model is not radial: its map must keep the sheet's grid axes. Where the projection
/// shears the sheet (in-sheet axes no longer orthogonal on screen), the paper's ellipse map turns
/// the tent to the ellipse's principal axes: measured 8.8 % off at view (40°, 35°, 0°), against
/// 1.5 % for the robust (parallelogram) map. Where the axes project orthogonally the two agree.
#[test]
fn bilinear_model_needs_the_grid_orientation() {
    let run = |rx: f32, ry: f32, method: MethodArg| {
        let mut a = splat_args();
        a.footprint.kernel = "bilinear".into();
        a.spacing = [40.0, 40.0, 40.0];
        (a.rotate_x, a.rotate_y, a.footprint.method) = (rx, ry, method);
        let (img, r) = with_reference(&a);
        max_rel_diff(&img, &r)
    };
    let sheared = (
        run(40.0, 35.0, MethodArg::Robust),
        run(40.0, 35.0, MethodArg::Paper),
    );
    let square = (
        run(0.0, 0.0, MethodArg::Robust),
        run(0.0, 0.0, MethodArg::Paper),
    );
    println!("bilinear model, sheared view: robust {:.2e}, paper {:.2e}; square view: robust {:.2e}, paper {:.2e}", sheared.0, sheared.1, square.0, square.1);
    assert_le(sheared.0, 0.025, "robust map on a sheared sheet");
    assert!(
        sheared.1 > 3.0 * sheared.0,
        "paper map on a sheared sheet should be far worse: {sheared:?}"
    );
    assert_le(
        (square.0 - square.1).abs(),
        1e-3,
        "both maps agree on an unsheared sheet",
    );
}
