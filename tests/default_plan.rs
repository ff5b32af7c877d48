//! The default plan, `--slicing auto` (issue 42): object slicing where the pilot measures it at
//! `DEFAULT_TARGET_DB` or more against the continuous model, the thickest slabs that reach it
//! otherwise; each choice checked on the whole image, the frame the pilot rendered checked to be
//! the plan's frame bit for bit, and the flags that leave nothing to choose checked to skip it.

use footprint::stencil::PhaseLookup;
use footprint_harness::args::plan;
use footprint_harness::args::{parse_args, Supersample};
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::stages::visible::FrameCache;
use footprint_harness::pipeline::{prepare, render_continuous_ref, render_frame, Prepared};
use footprint_harness::plan::{End, DEFAULT_TARGET_DB};
use footprint_harness::reference::continuous::Reconstruction;
use footprint_suite::{apply_quality, json_number, path_str as s, run_cli as run, tmpdir};

const HEART: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/heart_32x32x12_float32_le.nhdr"
);

/// The default plan for `a`: the plan chosen, its frame as the pilot left it, the whole image's
/// PSNR against the continuous integral, and the prepared render.
fn chosen(a: &[&str]) -> (footprint_harness::plan::Plan, Vec<[f32; 4]>, f64, Prepared) {
    let args = parse_args(a).unwrap();
    let asked = plan(&args).unwrap();
    assert_eq!(asked.auto_slicing, Some(DEFAULT_TARGET_DB), "{a:?}");
    let (p, chosen, choice) = apply_quality(prepare(&args).unwrap(), &args).unwrap();
    let mut choice = choice.expect("the default plan measured a choice");
    assert!(choice.by_default && chosen.auto_slicing.is_none());
    let frame = choice
        .frame
        .take()
        .expect("the pilot keeps the chosen frame");
    let (whole, _) = render_continuous_ref(&p, Reconstruction::Kernel).unwrap();
    let db = compare(&frame.image, &whole.image).1.psnr_db;
    (chosen, frame.image, db, p)
}

/// The built-in scene is far from opaque: object slicing read at the nearest phase (the first
/// candidate) reaches the target and is kept, and its frame is the one `--slicing object
/// --phase-lookup nearest` renders, which differs from the blended one's.
#[test]
fn object_slicing_is_kept_where_it_reaches_the_target() {
    let (plan_chosen, image, db, p) = chosen(&["--size", "200x200", "--view", "30,20,0"]);
    assert!(
        matches!(plan_chosen.end, End::Sheets(_)),
        "{:?}",
        plan_chosen.end
    );
    assert_eq!(plan_chosen.phase_lookup, Some(PhaseLookup::Nearest));
    assert!(db >= DEFAULT_TARGET_DB, "whole image {db:.2} dB");
    let object = |lookup: &str| {
        let a = [
            "--size",
            "200x200",
            "--view",
            "30,20,0",
            "--slicing",
            "object",
            "--phase-lookup",
            lookup,
        ];
        let explicit = plan(&parse_args(&a).unwrap()).unwrap();
        render_frame(&p, &explicit, &mut FrameCache::default())
            .unwrap()
            .image
    };
    assert!(
        object("nearest") == image,
        "the pilot's frame is --slicing object --phase-lookup nearest's"
    );
    let blended = object("blend");
    assert!(blended != image, "the nearest phase moved no pixel");
    // `auto` outside the default plan blends.
    assert!(object("auto") == blended);
}

/// The heart seen obliquely (12 slices 4 spacings apart): object slicing, compositing each kernel
/// whole, measures about 28–32 dB, so the default takes slabs, and they reach the target on the
/// whole image; the pilot's frame is the one those slabs render, for every thread count.
#[test]
fn slabs_are_taken_where_object_slicing_falls_short() {
    let base = [HEART, "--size", "128x96", "--view", "30,20,0"];
    let (plan_chosen, image, db, p) = chosen(&base);
    let End::Slabs { thickness } = plan_chosen.end else {
        panic!("expected slabs, got {:?}", plan_chosen.end);
    };
    assert!(db >= DEFAULT_TARGET_DB, "whole image {db:.2} dB");
    let t = thickness.to_string();
    for threads in ["1", "3"] {
        let mut a = base.to_vec();
        a.extend_from_slice(&["--slicing", "image", "--slab", &t, "--threads", threads]);
        let explicit = plan(&parse_args(&a).unwrap()).unwrap();
        let again = render_frame(&p, &explicit, &mut FrameCache::default()).unwrap();
        assert!(
            again.image == image,
            "--threads {threads}: the pilot's frame is the slabs'"
        );
    }
    // The choice is the same at any thread count (the frames are the same bits).
    let mut a = base.to_vec();
    a.extend_from_slice(&["--threads", "3"]);
    let (three, image3, _, _) = chosen(&a);
    assert_eq!(three.end, plan_chosen.end);
    assert!(image3 == image);
}

/// Where `--subsample` is unset and `auto` would render at 1/s of the size with s > 1 (the
/// built-in scene magnified twice: s = 2), the pilot tries each candidate subsampled first and
/// keeps the first that reaches the target: its frame is `--slicing object --phase-lookup nearest
/// --subsample auto`'s, bit for bit, it reaches the target on the whole image, and it stays
/// within a decibel of the full-size frame there. `--subsample 1` keeps the full size (a frame of
/// its own), and flags that skip the pilot do not subsample.
#[test]
fn the_default_subsamples_where_the_footprints_allow_it() {
    let base = ["--size", "160x160", "--zoom", "2", "--view", "30,20,0"];
    let (plan_chosen, image, db, p) = chosen(&base);
    assert_eq!(plan_chosen.subsample, Supersample::Auto);
    assert!(matches!(plan_chosen.end, End::Sheets(_)));
    assert_eq!(p.subsample_factor(&plan_chosen).unwrap(), 2);
    assert!(db >= DEFAULT_TARGET_DB, "whole image {db:.2} dB");
    let with = |extra: &[&'static str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        a
    };
    let explicit = plan(
        &parse_args(&with(&[
            "--slicing",
            "object",
            "--phase-lookup",
            "nearest",
            "--subsample",
            "auto",
        ]))
        .unwrap(),
    )
    .unwrap();
    let again = render_frame(&p, &explicit, &mut FrameCache::default()).unwrap();
    assert!(
        again.image == image,
        "the pilot's frame is the subsampled one"
    );
    let (full_plan, full_image, full_db, _) = chosen(&with(&["--subsample", "1"]));
    assert_eq!(full_plan.subsample, Supersample::Fixed(1));
    assert!(full_image != image, "subsampling moved no pixel");
    assert!(
        db > full_db - 1.0,
        "subsampled {db:.2} dB, full size {full_db:.2} dB"
    );
    for skip in [&["--slicing", "object"][..], &["--quality", "40"]] {
        let p = plan(&parse_args(&with(skip)).unwrap()).unwrap();
        assert!(
            !p.auto_subsample && p.subsample == Supersample::Fixed(1),
            "{skip:?}"
        );
    }
}

/// Where the flags fix the end point or slabs cannot draw the frame there is no pilot: the JSON
/// has no `quality` record and the frame is object slicing.
#[test]
fn nothing_is_measured_where_there_is_nothing_to_choose() {
    let d = tmpdir("default-plan");
    let (out, json) = (d.join("o.png"), d.join("o.json"));
    let cases: [&[&str]; 5] = [
        &[HEART, "--slicing", "object"],
        &["--stream", HEART, "--slicing", "object", "--lod", "0"],
        &[HEART, "--perspective", "40"],
        &[HEART, "--accum", "fixed"],
        &[HEART, "--kernel", "bilinear"],
    ];
    for extra in cases {
        let mut a = vec!["render", "--size", "64x48", "--view", "30,20,0"];
        a.extend_from_slice(extra);
        a.extend_from_slice(&["--out", s(&out), "--json", s(&json)]);
        assert_eq!(run(&a), 0, "{a:?}");
        let j = std::fs::read_to_string(&json).unwrap();
        assert!(!j.contains("\"quality\""), "{extra:?}: {j}");
        assert!(j.contains("\"slicing\": \"object\""), "{extra:?}: {j}");
    }
}

/// `bench --json` records the pilot as `plan_ms`; a fresh volume's `first_ms` is the pilot (which
/// rendered frame 1), and the `plan` record says what it chose.
#[test]
fn bench_counts_the_pilot_in_the_fresh_frame() {
    let d = tmpdir("default-plan-bench");
    let json = d.join("b.json");
    let a = [
        "bench",
        HEART,
        "--size",
        "128x96",
        "--view",
        "30,20,0",
        "--frames",
        "2",
        "--json",
        s(&json),
    ];
    assert_eq!(run(&a), 0);
    let j = std::fs::read_to_string(&json).unwrap();
    let num = |key: &str| json_number(&j, key);
    assert!(num("plan_ms") > 0.0);
    assert_eq!(num("first_ms"), num("plan_ms"));
    assert!(
        j.contains("\"by\": \"default\"") && j.contains("\"end\": \"slabs\""),
        "{j}"
    );
}

/// `--phase-lookup nearest` where nothing reads phase stencils is refused before anything is
/// drawn, naming the flag; where they are read it renders, and the JSON's `plan` says how.
#[test]
fn the_nearest_phase_is_refused_where_no_stencils_are_read() {
    let d = tmpdir("phase-lookup");
    let (out, json) = (d.join("x.png"), d.join("x.json"));
    let (o, j) = (s(&out), s(&json));
    for bad in [
        &["--slicing", "image"][..],
        &["--perspective", "40"],
        &["--method", "direct"],
        &["--phases", "0"],
        &["--refine", "0.1"],
        &["--method", "reference"],
        &["--classification", "post"],
    ] {
        let mut a = vec![
            "render",
            "-s",
            "32x32",
            "-o",
            o,
            "--phase-lookup",
            "nearest",
        ];
        a.extend_from_slice(bad);
        assert_eq!(run(&a), 2, "{bad:?} is refused");
    }
    assert!(!out.exists(), "no image from a refused render");
    // Float object slicing and the fixed path's integer stencils read either way.
    for (lookup, want, accum) in [
        ("nearest", "nearest", "float"),
        ("blend", "blend", "float"),
        ("nearest", "nearest", "fixed"),
        ("blend", "blend", "fixed"),
    ] {
        let a = [
            "render",
            "-s",
            "32x32",
            "-o",
            o,
            "--json",
            j,
            "--slicing",
            "object",
            "--accum",
            accum,
            "--phase-lookup",
            lookup,
        ];
        assert_eq!(run(&a), 0, "{a:?}");
        let text = std::fs::read_to_string(&json).unwrap();
        let key = format!("\"phase_lookup\": \"{want}\"");
        assert!(text.contains(&key), "{lookup}: {text}");
    }
}
