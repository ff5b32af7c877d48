//! Projections (issue 77, item 2): `--blend mip|minip|average` projects the normalised value
//! reconstruction along each ray (maximum, minimum, average over the chord through the sample
//! box) and classifies the projection. Each meets the 40 dB target against its continuous model
//! (an f64 march of the same field), threads and compositing orders give the same picture, and
//! the projections order as they must (maximum ≥ average ≥ minimum under a rising ramp).

use super::cut::{frame, HEADSQ, HEART};
use footprint::render::Blend;
use footprint_harness::args::{parse_args, plan, scene};
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::{render, render_continuous_as};
use footprint_harness::reference::continuous::{Model, Reconstruction, DEFAULT_CAP};

/// The projections' target against their models (issue 77), dB.
const TARGET_DB: f64 = 40.0;

/// `a` rendered, and its figure against the continuous model of `blend`.
fn against_model(a: &[&str], blend: Blend) -> (Vec<[f32; 4]>, f64) {
    let args = parse_args(a).unwrap();
    let (f, r) = render(&scene(&args).unwrap(), &plan(&args).unwrap()).unwrap();
    let model = Model::Projection(blend);
    let (truth, _) =
        render_continuous_as(r.prepared(), Reconstruction::Kernel, model, DEFAULT_CAP).unwrap();
    assert!(truth.converged, "{a:?}: the model's march did not converge");
    let db = compare(&f.image, &truth.image).1.psnr_db;
    (f.image, db)
}

/// Every projection meets its target on headsq (anisotropic, 3.2 : 3.2 : 1.5) and the heart,
/// two views, and none is the composited picture.
#[test]
fn projections_meet_the_target_against_their_models() {
    for volume in [HEADSQ, HEART] {
        for view in ["0,0,0", "30,20,0"] {
            let composite = frame(&[volume, "--size", "96x96", "--view", view]);
            for blend in [Blend::Maximum, Blend::Minimum, Blend::Average] {
                let a = [
                    volume,
                    "--size",
                    "96x96",
                    "--view",
                    view,
                    "--blend",
                    blend.name(),
                ];
                let (image, db) = against_model(&a, blend);
                eprintln!("{volume} {view} {}: {db:.2} dB", blend.name());
                assert!(
                    db >= TARGET_DB,
                    "{volume} {view} {}: {db:.2} dB",
                    blend.name()
                );
                let composite: Vec<[f64; 4]> = composite.iter().map(|c| c.map(f64::from)).collect();
                let apart = compare(&image, &composite).1.psnr_db;
                assert!(
                    apart < 40.0,
                    "{}: the composited picture ({apart:.1} dB)",
                    blend.name()
                );
            }
        }
    }
}

/// The projections of one view order as their values do under a rising ramp: per pixel the
/// maximum's opacity is at least the average's, the average's at least the minimum's.
#[test]
fn maximum_average_minimum_order_under_a_rising_ramp() {
    let frame = |blend: &str| {
        frame(&[
            HEADSQ, "--size", "64x64", "--view", "30,20,0", "--tf", "grey", "--blend", blend,
        ])
    };
    let (max, avg, min) = (frame("mip"), frame("average"), frame("minip"));
    let lit = max.iter().filter(|p| p[3] > 0.0).count();
    assert!(lit * 4 > max.len(), "the MIP lights {lit} pixels");
    for ((a, b), c) in max.iter().zip(&avg).zip(&min) {
        assert!(
            a[3] + 1e-6 >= b[3] && b[3] + 1e-6 >= c[3],
            "{a:?} {b:?} {c:?}"
        );
    }
}

/// Threads and compositing orders render the same projection: bit for bit across thread counts,
/// within rounding front to back against back to front (the parabola is symmetric).
#[test]
fn projections_are_the_same_for_every_thread_count_and_order() {
    for blend in ["mip", "minip", "average"] {
        let frame = |more: &[&str]| {
            let base = [
                HEADSQ, "--size", "80x64", "--view", "30,20,0", "--blend", blend,
            ];
            frame(&[&base[..], more].concat())
        };
        let one = frame(&["--threads", "1"]);
        assert_eq!(one, frame(&["--threads", "3"]), "{blend}: threads");
        let back = frame(&["--order", "back-to-front"]);
        let worst = one
            .iter()
            .zip(&back)
            .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-5, "{blend}: the orders differ by {worst}");
    }
}

/// Where the minimum shows (inside a crop, under the grey ramp, rays crossing tissue only) the
/// minimum and the average meet the target too, and light pixels.
#[test]
fn minimum_and_average_inside_a_crop_meet_the_target() {
    for (volume, crop) in [(HEART, "8:23,8:23,3:8"), (HEADSQ, "16:47,16:47,23:69")] {
        for view in ["0,0,0", "30,20,0"] {
            for blend in [Blend::Minimum, Blend::Average] {
                let a = [
                    volume,
                    "--size",
                    "96x96",
                    "--view",
                    view,
                    "--tf",
                    "grey",
                    "--crop",
                    crop,
                    "--blend",
                    blend.name(),
                ];
                let (image, db) = against_model(&a, blend);
                let lit = image.iter().filter(|p| p[3] > 0.0).count();
                eprintln!(
                    "{volume} {crop} {view} {}: {db:.2} dB, {lit} lit",
                    blend.name()
                );
                assert!(
                    db >= TARGET_DB,
                    "{volume} {view} {}: {db:.2} dB",
                    blend.name()
                );
                assert!(lit * 50 > image.len(), "{volume} {view}: {lit} pixels lit");
            }
        }
    }
}
