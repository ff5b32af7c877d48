//! Crop (issue 77, item 1): `--crop X0:X1,Y0:Y1,Z0:Z1` renders only the box's voxels, in their
//! places. The cut model is the continuous model of the volume whose samples outside the box are
//! missing (NaN); away from the cut the picture is the uncut one bit for bit, and the default plan
//! meets its 44 dB against the cut model.

use footprint_harness::args::keywords::from_keywords;
use footprint_harness::args::{parse_args, plan, scene, RenderArgs, Value};
use footprint_harness::io::formats::load_array;
use footprint_harness::io::stream::InMemory;
use footprint_harness::io::volume::{Data, Samples, Volume};
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::{render, render_continuous_ref};
use footprint_harness::plan::DEFAULT_TARGET_DB;
use footprint_harness::reference::continuous::Reconstruction;
use footprint_suite::{path_str as s, run_cli, tmpdir};
use std::sync::Arc;

pub(crate) const HEADSQ: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/headsq_64x64x93_int16_le.nhdr"
);
pub(crate) const HEART: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/heart_32x32x12_float32_le.nhdr"
);

/// The frame `args` renders (through the pipeline's door, every choice made).
pub(crate) fn frame_of(args: &RenderArgs) -> Vec<[f32; 4]> {
    render(&scene(args).unwrap(), &plan(args).unwrap())
        .unwrap()
        .0
        .image
}

/// The frame of `footprint render` with flags `a`.
pub(crate) fn frame(a: &[&str]) -> Vec<[f32; 4]> {
    frame_of(&parse_args(a).unwrap())
}

/// `base` rendered uncut, with `flag` `cut`, and with `flag` `near` (a render holding every
/// voxel the cut removes or changes): every pixel `near` leaves clear is the same uncut and cut,
/// bit for bit; at least a fifth of the
/// picture is such, and the cut changed more than 100 pixels.
pub(crate) fn unchanged_away(base: &[&str], flag: &str, [cut, near]: [&str; 2], what: &str) {
    let with = |value: &str| frame(&[base, &[flag, value][..]].concat());
    let (whole, kept, near) = (frame(base), with(cut), with(near));
    let (mut away, mut changed) = (0, 0);
    for ((w, k), n) in whole.iter().zip(&kept).zip(&near) {
        if *n == [0.0; 4] {
            assert!(
                w.map(f32::to_bits) == k.map(f32::to_bits),
                "{what}: {w:?} became {k:?} away from the cut"
            );
            away += 1;
        }
        changed += usize::from(w != k);
    }
    assert!(away > whole.len() / 5, "{what}: only {away} pixels away");
    assert!(changed > 100, "{what}: the cut changed {changed} pixels");
}

/// Away from the cut the cropped picture is the uncut one, bit for bit: every pixel that the
/// voxels from one before the cut onward leave clear (so no removed voxel, and no kept voxel
/// whose gradient reads a removed one, reaches it) is unchanged, for object and image slicing,
/// emission and Phong, two views. The crop keeps i ≤ 40 of headsq's 64.
#[test]
fn a_crop_leaves_the_picture_away_from_the_cut_bit_identical() {
    for view in ["0,0,0", "30,20,0"] {
        for (slicing, shading) in [
            ("object", "emission"),
            ("object", "phong"),
            ("image", "emission"),
            ("image", "phong"),
        ] {
            let base = [
                HEADSQ,
                "--size",
                "96x96",
                "--view",
                view,
                "--slicing",
                slicing,
                "--shading",
                shading,
                "--lod",
                "0",
            ];
            // Cut, and the removed voxels with the kept one next to them (its gradient reads
            // the cut).
            let boxes = ["0:40,0:63,0:92", "40:63,0:63,0:92"];
            unchanged_away(
                &base,
                "--crop",
                boxes,
                &format!("{view} {slicing} {shading}"),
            );
        }
    }
}

/// The default plan meets its target against the cut model on the whole image: headsq and the
/// heart, each cropped to a box that cuts through dense tissue, two views.
#[test]
fn a_crop_meets_the_target_against_the_cut_model() {
    for (volume, crop) in [(HEADSQ, "8:55,0:37,20:92"), (HEART, "4:27,10:31,2:9")] {
        for view in ["0,0,0", "30,20,0"] {
            let args =
                parse_args(&[volume, "--size", "96x96", "--view", view, "--crop", crop]).unwrap();
            let (f, r) = render(&scene(&args).unwrap(), &plan(&args).unwrap()).unwrap();
            let (truth, _) = render_continuous_ref(r.prepared(), Reconstruction::Kernel).unwrap();
            let db = compare(&f.image, &truth.image).1.psnr_db;
            assert!(
                db >= DEFAULT_TARGET_DB,
                "{volume} {view} --crop {crop}: {db:.2} dB against the cut model"
            );
        }
    }
}

/// The cut model is the model of the volume with the rest missing: the cropped render and its
/// continuous reference are those of headsq with every sample outside the box set to NaN, bit
/// for bit (the same window given to both).
#[test]
fn a_crop_is_the_volume_with_the_rest_missing() {
    let v = load_array(std::path::Path::new(HEADSQ), None, None).unwrap();
    let (lo, hi) = ([5, 0, 30], [50, 40, 80]);
    let [nx, ny, _] = v.dims;
    let masked: Vec<f32> = (0..v.len())
        .map(|n| {
            let g = [n % nx, (n / nx) % ny, n / (nx * ny)];
            if (0..3).all(|c| lo[c] <= g[c] && g[c] <= hi[c]) {
                v.value(n)
            } else {
                f32::NAN
            }
        })
        .collect();
    let mut nan = Volume::new(v.dims, v.spacing, Samples::F32(Data::from(masked)));
    nan.directions = v.directions;
    let flags = [
        "--size",
        "64x64",
        "--view",
        "30,20,0",
        "--window",
        "500,3000",
        "--slicing",
        "object",
        "--lod",
        "0",
        "--shading",
        "phong",
    ];
    let mut a = vec![HEADSQ, "--crop", "5:50,0:40,30:80"];
    a.extend_from_slice(&flags);
    let cropped = parse_args(&a).unwrap();
    let mut missing = parse_args(&flags).unwrap();
    missing.memory = Some(InMemory {
        volume: Arc::new(nan),
        name: "masked".into(),
    });
    let open = |args: &RenderArgs| render(&scene(args).unwrap(), &plan(args).unwrap()).unwrap();
    let ((fc, rc), (fm, rm)) = (open(&cropped), open(&missing));
    assert!(
        fc.image == fm.image,
        "the cropped frame is the masked volume's"
    );
    assert!(
        fc.image.iter().any(|p| p[3] > 0.1),
        "the crop keeps something"
    );
    let (tc, _) = render_continuous_ref(rc.prepared(), Reconstruction::Kernel).unwrap();
    let (tm, _) = render_continuous_ref(rm.prepared(), Reconstruction::Kernel).unwrap();
    assert!(tc.image == tm.image, "the cut model is the masked volume's");
}

/// `--stream FILE` reads only the box (positioned reads) and renders the same picture as the
/// file loaded whole and cropped; Python's keyword (nested pairs or the flag's text) is the flag.
#[test]
fn a_crop_is_the_same_by_every_door() {
    let d = tmpdir("crop");
    let png = |source: &[&str], name: &str| {
        let out = d.join(name);
        let mut a = vec!["footprint", "render"];
        a.extend_from_slice(source);
        a.extend_from_slice(&[
            "--crop",
            "3:20,0:31,1:10",
            "--slicing",
            "object",
            "--lod",
            "0",
            "--size",
            "48x48",
            "--out",
            s(&out),
        ]);
        assert_eq!(run_cli(&a[1..]), 0, "{a:?}");
        std::fs::read(out).unwrap()
    };
    assert!(png(&[HEART], "a.png") == png(&["--stream", HEART], "b.png"));
    // A program's pipe streamed through (nothing to choose: --window given), cropped as it
    // streams (footprint::source::Cropped), against the file loaded whole and cropped.
    let raw = std::fs::read(HEART.replace(".nhdr", ".raw")).unwrap();
    let flags = [
        "--stream",
        "-",
        "--dims",
        "32,32,12",
        "--type",
        "f32",
        "--spacing",
        "1,1,4",
        "--window",
        "97.8,234",
        "--crop",
        "3:20,0:31,1:10",
        "--slicing",
        "object",
        "--lod",
        "0",
        "--size",
        "48x48",
    ];
    let mut piped = parse_args(&flags).unwrap();
    piped.stdin = Some(footprint_harness::io::stream::Pipe::new(
        std::io::Cursor::new(raw),
    ));
    let file = parse_args(&[&[HEART][..], &flags[8..]].concat()).unwrap();
    let (a, b) = (frame_of(&piped), frame_of(&file));
    assert!(a == b, "the pipe cropped as it streams is the file cropped");
    let uncut = [&[HEART][..], &flags[8..10], &flags[12..]].concat();
    assert!(a != frame(&uncut), "the crop cut nothing");
    let pair = |a: i64, b: i64| Value::List(vec![Value::Int(a), Value::Int(b)]);
    let nested = Value::List(vec![pair(3, 20), pair(0, 31), pair(1, 10)]);
    let by_list: RenderArgs = from_keywords([("crop", &nested)]).unwrap();
    let by_text: RenderArgs =
        from_keywords([("crop", &Value::Text("3:20,0:31,1:10".into()))]).unwrap();
    let by_flag = parse_args(&["--crop", "3:20,0:31,1:10"]).unwrap();
    assert_eq!(by_list.crop, by_flag.crop);
    assert_eq!(by_text.crop, by_flag.crop);
    let empty = Value::List(vec![pair(3, 2), pair(0, 31), pair(1, 10)]);
    let e = from_keywords::<RenderArgs>([("crop", &empty)]).unwrap_err();
    assert!(e.message.contains("empty"), "{}", e.message);
}
