//! Levels of detail (`--lod`, issue 15): a streamed volume coarsened as it streams renders what
//! the same volume coarsened in memory renders; `auto` coarsens a minified smooth volume and stays
//! close to full resolution; levels are refused where they are not placed (perspective).

use footprint_harness::args::parse_args;
use footprint_harness::args::plan;
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::{prepare, render_core};
use footprint_suite::{rgb_psnr, tmpdir};

const HEADSQ: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/headsq_64x64x93_int16_le.nhdr"
);

fn render(args: &[&str]) -> (Vec<[f32; 4]>, u32) {
    let a = parse_args(args).unwrap();
    let p = prepare(&a).unwrap();
    let level = p.level;
    (render_core(&p, &plan(&a).unwrap()).unwrap().0, level)
}

#[test]
fn streamed_and_in_memory_levels_agree() {
    for view in ["0,0,0", "30,20,0", "100,10,0"] {
        for lod in ["1", "2"] {
            let common = [
                "--size",
                "48x48",
                "--view",
                view,
                "--lod",
                lod,
                "--shading",
                "phong",
            ];
            let mut m = vec![HEADSQ];
            m.extend_from_slice(&common);
            let mut s = vec!["--stream", HEADSQ];
            s.extend_from_slice(&common);
            let ((mem, lm), (streamed, ls)) = (render(&m), render(&s));
            assert_eq!((lm, ls), (lod.parse().unwrap(), lod.parse().unwrap()));
            let db = rgb_psnr(&streamed, &mem);
            assert!(db >= 120.0, "view {view}, lod {lod}: {db:.1} dB");
        }
    }
}

/// A smooth 96³ volume (one wide Gaussian blob) at 96×96: its samples project about 0.6 px apart,
/// so `auto` coarsens, the level is rendered without supersampling (levels and supersampling
/// never act on one frame, issue 41), and the image stays within 38 dB of full resolution. A
/// blob with a thin shell at 32×32 would need a level *and* supersampling: its level alone
/// measures 19.8 dB against full resolution, so `auto` keeps level 0 (supersampled) there.
#[test]
fn auto_coarsens_a_minified_volume_and_stays_close() {
    let d = tmpdir("lod-auto");
    let n = 96usize;
    let mut v = vec![0u8; n * n * n];
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let p = [x, y, z].map(|c| c as f32 / (n - 1) as f32 * 2.0 - 1.0);
                let r2 = p.iter().map(|c| c * c).sum::<f32>();
                v[(z * n + y) * n + x] = ((-(r2) / (2.0 * 0.3f32 * 0.3)).exp() * 255.0) as u8;
            }
        }
    }
    let raw = d.join("blob.raw");
    std::fs::write(&raw, &v).unwrap();
    let raw = raw.to_str().unwrap();
    let base = [
        raw, "--dims", "96,96,96", "--type", "u8", "--size", "96x96", "--view", "30,20,0",
    ];
    let with = |lod: &str| {
        let mut a = base.to_vec();
        a.extend_from_slice(&["--lod", lod]);
        let p = prepare(&parse_args(&a).unwrap()).unwrap();
        (p.level, p.supersample)
    };
    let (l0, _) = with("0");
    let (la, ka) = with("auto");
    assert_eq!(l0, 0);
    assert!(la >= 1, "auto stayed at level {la}");
    assert_eq!(ka, 1, "level {la} was supersampled {ka}x");
    let full = render(&[&base[..], &["--lod", "0"]].concat()).0;
    let auto = render(&[&base[..], &["--lod", "auto"]].concat()).0;
    let db = rgb_psnr(&auto, &full);
    assert!(db >= 38.0, "auto (level {la}) against level 0: {db:.1} dB");
    std::fs::remove_dir_all(&d).unwrap();
}

/// Levels and supersampling never act on one frame (issue 41): a level asked for with a
/// supersampling factor is refused, `auto` with one stays at full resolution, and a level's frame
/// is never supersampled by `--supersample auto`.
#[test]
fn levels_and_supersampling_never_share_a_frame() {
    let a = parse_args(&[
        HEADSQ,
        "--size",
        "64x64",
        "--lod",
        "1",
        "--supersample",
        "2",
    ])
    .unwrap();
    let e = prepare(&a).err().expect("refused").to_string();
    assert!(e.contains("--lod 1 and --supersample 2"), "{e}");
    let a = parse_args(&[
        HEADSQ,
        "--size",
        "32x32",
        "--lod",
        "auto",
        "--supersample",
        "3",
    ])
    .unwrap();
    let p = prepare(&a).unwrap();
    assert_eq!((p.level, p.supersample), (0, 3));
    for lod in ["1", "2"] {
        let a = parse_args(&[HEADSQ, "--size", "32x32", "--lod", lod]).unwrap();
        let p = prepare(&a).unwrap();
        assert_eq!((p.level, p.supersample), (lod.parse().unwrap(), 1));
    }
}

#[test]
fn levels_are_refused_where_they_are_not_placed() {
    assert!(parse_args(&[HEADSQ, "--lod", "17"]).is_err());
    assert!(parse_args(&[HEADSQ, "--lod", "-1"]).is_err());
    let a = parse_args(&[HEADSQ, "--lod", "1", "--perspective", "30"]).unwrap();
    let e = prepare(&a)
        .err()
        .expect("perspective with a level is refused");
    assert!(e.to_string().contains("orthographic"), "{e}");
    // auto keeps a perspective view at level 0.
    let a = parse_args(&[
        HEADSQ,
        "--lod",
        "auto",
        "--perspective",
        "30",
        "--size",
        "16x16",
    ])
    .unwrap();
    assert_eq!(prepare(&a).unwrap().level, 0);
}

/// The chart's levels sweep on a scene levels are not placed for (perspective) charts level 0
/// alone instead of failing.
#[test]
fn the_levels_sweep_stops_where_levels_stop() {
    let a = parse_args(&[HEADSQ, "--perspective", "30", "--size", "24x24"]).unwrap();
    let (rows, auto) = footprint_harness::charts::lod::sweep(&a, 1).unwrap();
    assert_eq!((rows.len(), auto), (1, 0));
    assert!(rows[0].psnr_db.is_infinite());
    let a = parse_args(&[HEADSQ, "--size", "24x24"]).unwrap();
    let (rows, _) = footprint_harness::charts::lod::sweep(&a, 1).unwrap();
    assert!(rows.len() >= 3, "levels 0, 1, 2 at least: {}", rows.len());
    assert!(rows[1].psnr_db.is_finite() && rows[1].dims == [32, 32, 47]);
}

/// `auto` is the default and holds on a real CT (headsq) at 64×64: with a grey ramp over the data's
/// range it coarsens to level 1 within 38 dB of level 0 (measured 43.1 dB at view 30,20,0); with
/// the default window and transfer function (`ct-bone-skin`, sharp opacity steps), where level 1
/// measured 30.9 dB, the pilot keeps level 0 and auto is level 0's image.
#[test]
fn auto_is_the_default_and_holds_on_real_data() {
    let a = parse_args(&[HEADSQ]).unwrap();
    assert_eq!(a.lod, footprint_harness::args::Lod::Auto);
    let grey = [
        HEADSQ, "--size", "64x64", "--view", "30,20,0", "--tf", "grey", "--window", "0,3926",
    ];
    let defaults = [HEADSQ, "--size", "64x64", "--view", "30,20,0"];
    for (common, level) in [(&grey[..], 1), (&defaults[..], 0)] {
        let (auto, la) = render(common);
        let (full, _) = render(&[common, &["--lod", "0"]].concat());
        assert_eq!(la, level, "{common:?}");
        let db = rgb_psnr(&auto, &full);
        assert!(db >= 38.0, "auto (level {la}) against level 0: {db:.1} dB");
    }
}

/// The f64 reference shades a level's samples with the colours they carry, as the core does:
/// the two agree to the table error (a reference using the transfer function's colours differs
/// by the colour change itself).
#[test]
fn the_reference_renders_a_level_with_its_colours() {
    for shading in ["emission", "phong"] {
        let a = parse_args(&[
            HEADSQ,
            "--size",
            "48x48",
            "--view",
            "30,20,0",
            "--lod",
            "1",
            "--shading",
            shading,
        ])
        .unwrap();
        let p = prepare(&a).unwrap();
        assert_eq!(p.level, 1);
        let core = render_core(&p, &plan(&a).unwrap()).unwrap().0;
        let (reference, _) = footprint_harness::pipeline::render_ref(&p).unwrap();
        let db = compare(&core, &reference).1.psnr_db;
        assert!(
            db >= 45.0,
            "{shading}: core against the reference at level 1: {db:.1} dB"
        );
    }
}

/// Refinement starts from full resolution: `auto` means level 0 with `--refine`, and an explicit
/// level is refused.
#[test]
fn refinement_renders_full_resolution() {
    let a = parse_args(&[HEADSQ, "--size", "48x48", "--refine", "0.1"]).unwrap();
    assert_eq!(prepare(&a).unwrap().level, 0);
    let a = parse_args(&[HEADSQ, "--size", "48x48", "--refine", "0.1", "--lod", "1"]).unwrap();
    let e = prepare(&a).err().expect("a level with --refine is refused");
    assert!(e.to_string().contains("--lod 0"), "{e}");
}

const HEART: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/heart_32x32x12_float32_le.nhdr"
);

/// Defaults compose (issue 41, "must show" 4, on the repository's volumes): with no flag but the
/// size and the view, a 64×64 render (levels, supersampling and the default window all chosen
/// for it) keeps the mean brightness of its 512×512 render box-filtered down within 3 % and is
/// within 38 dB of it. Measured (release, 2026-11-26) on every shared volume and these two views:
/// within 0.7 % and at least 40.6 dB; here the CT head and the heart.
#[test]
fn default_flags_at_64_match_512_box_filtered() {
    for vol in [HEADSQ, HEART] {
        for view in ["0,0,0", "30,20,0"] {
            let (small, _) = render(&[vol, "--size", "64x64", "--view", view]);
            let (large, _) = render(&[vol, "--size", "512x512", "--view", view]);
            let down: Vec<[f32; 4]> = (0..64 * 64)
                .map(|i| {
                    let (x, y) = (i % 64, i / 64);
                    let mut sum = [0.0f64; 4];
                    for dy in 0..8 {
                        for dx in 0..8 {
                            let p = large[(8 * y + dy) * 512 + 8 * x + dx];
                            for c in 0..4 {
                                sum[c] += f64::from(p[c]);
                            }
                        }
                    }
                    sum.map(|s| (s / 64.0) as f32)
                })
                .collect();
            let mean = |im: &[[f32; 4]]| {
                im.iter()
                    .map(|p| f64::from(p[0] + p[1] + p[2]))
                    .sum::<f64>()
                    / im.len() as f64
            };
            let bias = mean(&small) / mean(&down) - 1.0;
            let db = rgb_psnr(&small, &down);
            assert!(
                bias.abs() <= 0.03,
                "{vol} {view}: brightness {:+.1} %",
                bias * 100.0
            );
            assert!(
                db >= 38.0,
                "{vol} {view}: {db:.1} dB against 512² box-filtered"
            );
        }
    }
}

/// `render` and `verify` with the same flags, defaults included, write byte-identical images
/// (issue 41, "must show" 3): verify checks the image render draws, its level of detail, its
/// supersampling, its window and transfer function.
#[test]
fn render_and_verify_write_the_same_image() {
    let dir = tmpdir("render-verify");
    let cases: [&[&str]; 5] = [
        &[HEADSQ, "--size", "64x64"],
        &[
            HEADSQ, "--size", "64x64", "--tf", "grey", "--window", "0,3926",
        ],
        &[
            HEADSQ,
            "--size",
            "96x96",
            "--view",
            "30,20,0",
            "--shading",
            "phong",
            "--accum",
            "fixed",
        ],
        &[
            HEADSQ,
            "--size",
            "96x96",
            "--view",
            "30,20,0",
            "--slicing",
            "image",
        ],
        &[HEART, "--size", "128x128", "--view", "150,-20,180"],
    ];
    for (n, flags) in cases.iter().enumerate() {
        let (r, v) = (dir.join(format!("r{n}.png")), dir.join(format!("v{n}.png")));
        let go = |cmd: &str, out: &std::path::Path| {
            footprint_suite::run_cli(&[&[cmd], *flags, &["--out", out.to_str().unwrap()]].concat())
        };
        assert_eq!(go("render", &r), 0, "{flags:?}");
        assert_eq!(go("verify", &v), 0, "{flags:?}");
        let (a, b) = (std::fs::read(&r).unwrap(), std::fs::read(&v).unwrap());
        assert!(a == b, "render and verify differ with {flags:?}");
    }
}

/// Every rule the flags alone decide is the plan's (issue 41): refused by `plan` before anything
/// is loaded (the volume named here does not exist, so a rule checked later would report the
/// missing file instead).
#[test]
fn the_plan_refuses_what_the_flags_decide_before_loading() {
    let missing = "/nonexistent/volume.nhdr";
    let cases: [(&[&str], &str); 9] = [
        (
            &["--lod", "1", "--supersample", "2"],
            "--lod 1 and --supersample 2",
        ),
        (&["--lod", "2", "--perspective", "30"], "--lod 2"),
        (&["--lod", "1", "--refine", "0.1"], "--refine adds samples"),
        (
            &["--subsample", "2", "--perspective", "30"],
            "orthographic views only",
        ),
        (&["--subsample", "2", "--supersample", "3"], "supersampled"),
        (&["--subsample", "2", "--lod", "1"], "coarser level"),
        (&["--refine", "0.1"], "in memory"),
        (&["--slicing", "image"], "drop --stream"),
        (&["--quality", "40", "--lod", "1"], "streamed volume"),
    ];
    for (k, (flags, says)) in cases.iter().enumerate() {
        // The last three are rules of a streamed volume.
        let source: &[&str] = if k >= 6 {
            &["--stream", missing, "--dims", "8,8,8", "--type", "uint8"]
        } else {
            &[missing]
        };
        let a = parse_args(&[source, &["--size", "32x32"], *flags].concat()).unwrap();
        let e = plan(&a).expect_err("refused by the plan").to_string();
        assert!(e.contains(says), "{flags:?}: {e}");
        assert!(!e.contains("nonexistent"), "{flags:?}: {e}");
    }
    // And the same combinations in memory, or without the clash, plan.
    let ok = parse_args(&[missing, "--lod", "1", "--subsample", "auto"]).unwrap();
    assert!(plan(&ok).is_ok());
}
