//! `--quality DB --quality-reference continuous` (issue 12): the pilot's sampled reference is the
//! whole reference at those pixels, and the choice reaches its target on the whole image, with
//! object slicing when it suffices and image slicing when only slabs do.

use footprint_harness::args::parse_args;
use footprint_harness::args::QualityReferenceArg::Continuous;
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::ends::continuous::{continuous_at, PilotReference};
use footprint_harness::pipeline::quality::pilot::{sample_pixels, PILOT_RAYS};
use footprint_harness::pipeline::{prepare, render_continuous_ref, render_core, Prepared};
use footprint_harness::reference::continuous::Reconstruction;
use footprint_suite::{choose_continuous, plan_with};

const HEART: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/heart_32x32x12_float32_le.nhdr"
);

fn heart(extra: &[&str]) -> (footprint_harness::args::RenderArgs, Prepared) {
    let mut a = vec![HEART, "--size", "128x96", "--view", "30,20,0"];
    a.extend_from_slice(extra);
    let args = parse_args(&a).unwrap();
    let p = prepare(&args).unwrap();
    (args, p)
}

/// The pilot marches only the sampled rays; their values must be the whole reference's there
/// (both converged to `CONVERGED_DB`, so they agree to about that).
#[test]
fn the_pilot_reference_is_the_whole_reference_at_its_pixels() {
    // Supersampled 2x as well: the pilot averages each pixel's k×k rays as the renders do.
    for extra in [&["--supersample", "1"][..], &["--supersample", "2"][..]] {
        let (_, p) = heart(extra);
        let (w, h) = p.out_size();
        let (pixels, stride) = sample_pixels(w, h, PILOT_RAYS / 4);
        assert!(stride > 1, "the test must sample, not take every pixel");
        let (pilot, _) = continuous_at(&p, &pixels, 1).unwrap();
        // Each ray is marched by one thread alone: any thread count gives the same bytes.
        let (threaded, _) = continuous_at(&p, &pixels, 3).unwrap();
        assert_eq!(pilot.image, threaded.image, "{extra:?}: 1 vs 3 threads");
        // The two stages march one field twice: the same values as one march through all.
        let field = PilotReference::new(&p, 2).unwrap();
        let half = pixels.len() / 3;
        let mut staged = field.at(&pixels[..half]).unwrap().image;
        staged.extend(field.at(&pixels[half..]).unwrap().image);
        assert_eq!(staged.len(), pilot.image.len());
        let worst_stage = staged
            .iter()
            .zip(&pilot.image)
            .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
            .fold(0.0f64, f64::max);
        assert!(
            worst_stage < 2e-3,
            "{extra:?}: staged vs one march: {worst_stage:e}"
        );
        let (whole, _) = render_continuous_ref(&p, Reconstruction::Kernel).unwrap();
        let mut worst = 0.0f64;
        for (&[x, y], v) in pixels.iter().zip(&pilot.image) {
            for (a, b) in v.iter().zip(&whole.image[y * w + x]) {
                worst = worst.max((a - b).abs());
            }
        }
        assert!(pilot.converged, "{extra:?}");
        assert!(
            worst < 2e-3,
            "{extra:?}: pilot vs whole reference: {worst:e}"
        );
    }
}

/// The whole image's PSNR against the continuous integral with `args`.
fn actual_db(p: &Prepared, plan: &footprint_harness::plan::Plan) -> f64 {
    let (img, _, _) = render_core(p, plan).unwrap();
    let (whole, _) = render_continuous_ref(p, Reconstruction::Kernel).unwrap();
    compare(&img, &whole.image).1.psnr_db
}

/// heart seen obliquely: 12 slices 4 spacings apart, so object slicing, which composites each
/// kernel whole, is far from the integral (about 28 dB) and only slabs reach 45 dB; 20 dB the
/// sheets reach. Each choice is checked on the whole image.
#[test]
fn the_choice_reaches_its_target_with_the_cheapest_slicing_that_does() {
    let (args, p) = heart(&[]);
    let low = choose_continuous(&p, &args, 20.0, Continuous).unwrap();
    assert_eq!(low.config.slab(), None, "20 dB: object slicing suffices");
    assert!(low.predicted_db >= 20.0);
    let high = choose_continuous(&p, &args, 45.0, Continuous).unwrap();
    assert!(high.config.slab().is_some(), "45 dB needs slabs");
    assert!(high.predicted_db >= 45.0, "{:?}", high.pilot);
    let pilot = high.pilot.as_ref().unwrap();
    assert!(
        pilot
            .tried
            .iter()
            .any(|(c, e)| c.slab().is_none() && e.bound_db < 45.0),
        "object slicing was tried first and measured short"
    );
    for (choice, target) in [(&low, 20.0), (&high, 45.0)] {
        let got = actual_db(&p, &plan_with(&args, &choice.config));
        assert!(
            got >= target,
            "{}: {got:.1} dB on the whole image, below {target}",
            choice.config.label()
        );
        // The pilot's estimate is the whole image's figure, sampled: within 2 dB here.
        let est = pilot_estimate(choice);
        assert!((est - got).abs() < 2.0, "estimate {est:.1} vs {got:.1} dB");
    }
    // --slicing image: only slab thicknesses are candidates.
    let (args, p) = heart(&["--slicing", "image"]);
    let c = choose_continuous(&p, &args, 20.0, Continuous).unwrap();
    assert!(c.config.slab().is_some());
}

/// The stages (`pilot.rs`, "Stages"): at 256² the sample is 4 096 pixels, the sixteenth 256. A
/// target far below object slicing's error (about 26.5 dB here) is decided on the sixteenth
/// alone (its bound past the target by more than the sixteenth's margin); one that needs slabs
/// marches further.
#[test]
fn a_target_far_from_the_frame_is_decided_on_the_sixteenth() {
    use footprint_harness::pipeline::quality::pilot::STAGE_MARGINS_DB;
    let a = [HEART, "--size", "256x256", "--view", "30,20,0"];
    let args = parse_args(&a).unwrap();
    let p = prepare(&args).unwrap();
    let low = choose_continuous(&p, &args, 15.0, Continuous).unwrap();
    let pilot = low.pilot.as_ref().unwrap();
    assert_eq!(pilot.first_pixels, 256);
    assert_eq!(pilot.pixels, 256, "decided on the sixteenth: {pilot:?}");
    assert!(low.predicted_db >= 15.0 + STAGE_MARGINS_DB[0], "{pilot:?}");
    assert!(actual_db(&p, &plan_with(&args, &low.config)) >= 15.0);
    let high = choose_continuous(&p, &args, 45.0, Continuous).unwrap();
    let pilot = high.pilot.as_ref().unwrap();
    assert!(
        [256, 1024, 4096].contains(&pilot.pixels),
        "a whole stage: {pilot:?}"
    );
    assert!(high.config.slab().is_some());
    assert!(actual_db(&p, &plan_with(&args, &high.config)) >= 45.0);
}

fn pilot_estimate(c: &footprint_harness::pipeline::quality::model::Choice) -> f64 {
    let pilot = c.pilot.as_ref().unwrap();
    pilot
        .tried
        .iter()
        .find(|t| t.0 == c.config)
        .unwrap()
        .1
        .estimate_db
}

#[test]
fn the_flags_are_checked() {
    // --quality-reference needs --quality; --quality chooses the slab, so --slab conflicts.
    assert!(parse_args(&[HEART, "--quality-reference", "continuous"]).is_err());
    assert!(parse_args(&[HEART, "--quality", "40", "--slab", "1"]).is_err());
    // Image slicing with the default (sheet) reference has no table to choose: a typed error.
    let (args, p) = heart(&["--quality", "40", "--slicing", "image"]);
    let e = footprint_suite::apply_quality(p, &args)
        .err()
        .expect("image slicing has no table to choose");
    assert!(
        e.to_string().contains("--quality-reference continuous"),
        "{e}"
    );
    // A target that is not a PSNR.
    let (args, p) = heart(&[]);
    assert!(choose_continuous(&p, &args, f64::NAN, Continuous).is_err());
    assert!(choose_continuous(&p, &args, -3.0, Continuous).is_err());
}
