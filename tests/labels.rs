//! Label maps (issue 77, item 3): `--labels` classifies each voxel by its label before
//! reconstruction (`footprint::shade::Labels`), so the picture holds only the labels' colours and
//! their composites, by every plan; the same values through a transfer function, post-classified
//! (as a ray caster that interpolates a label volume does), show a label that is not there.
//! The volume: headsq segmented by value (air 0, soft tissue 1, bone 3; label 2 is in the table,
//! green, and nowhere in the volume).

use crate::cut::{frame_of, HEADSQ};
use footprint_harness::args::{parse_args, plan, scene, RenderArgs};
use footprint_harness::io::formats::load_array;
use footprint_harness::io::stream::InMemory;
use footprint_harness::io::volume::{Data, Samples, Volume};
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::{render, render_continuous_ref};
use footprint_harness::plan::DEFAULT_TARGET_DB;
use footprint_harness::reference::continuous::Reconstruction;
use footprint_suite::{path_str as s, run_cli, tmpdir};
use std::sync::Arc;

/// Soft tissue red, the absent label 2 green, bone blue (opacity per world unit).
const TABLE: &str =
    r#"{"0": [0, 0, 0, 0], "1": [1, 0.2, 0, 0.04], "2": [0, 1, 0, 1], "3": [0.1, 0.3, 1, 0.5]}"#;

/// headsq's samples as labels: below 640 air (0), below 1400 soft tissue (1), else bone (3).
fn labelled() -> Volume {
    let v = load_array(std::path::Path::new(HEADSQ), None, None).unwrap();
    let labels: Vec<u8> = (0..v.len())
        .map(|n| match v.value(n) {
            x if x < 640.0 => 0,
            x if x < 1400.0 => 1,
            _ => 3,
        })
        .collect();
    let mut out = Volume::new(v.dims, v.spacing, Samples::U8(Data::from(labels)));
    out.directions = v.directions;
    out
}

/// `footprint render` flags `a` over the labelled volume in memory.
fn args(a: &[&str]) -> RenderArgs {
    let mut args = parse_args(a).unwrap();
    args.memory = Some(InMemory {
        volume: Arc::new(labelled()),
        name: "headsq-labels".into(),
    });
    args
}

/// How far a pixel's green rises past what the present labels' composites allow, at most over
/// the picture: soft tissue's premultiplied colour has g = 0.2 r and bone's g = 0.3 b, so any
/// composite of the two keeps g ≤ 0.2 r + 0.3 b; label 2 (pure green) would break it.
fn green_excess(image: &[[f32; 4]]) -> f32 {
    image
        .iter()
        .map(|p| p[1] - (0.2 * p[0] + 0.3 * p[2]))
        .fold(f32::NEG_INFINITY, f32::max)
}

/// The picture holds the labels' colours and composites only, by every plan (sheets, slabs,
/// fixed point, perspective, two views); the same values through a transfer function that
/// gives 1, 2 and 3 those colours, post-classified, show label 2's green where soft tissue meets
/// bone: the test can tell.
#[test]
fn labels_show_only_their_colours_and_composites() {
    for view in ["0,0,0", "30,20,0"] {
        for more in [
            &["--slicing", "object"][..],
            &["--slicing", "image"],
            &["--accum", "fixed"],
            &["--perspective", "30"],
        ] {
            let mut a = vec!["--labels", TABLE, "--size", "96x96", "--view", view];
            a.extend_from_slice(more);
            let f = frame_of(&args(&a));
            // Float paths: rounding only; the fixed path rounds each channel to its own grid
            // (Q24 per voxel, then per sheet), a few 2⁻²⁴ steps.
            let tolerance = if more.contains(&"fixed") { 1e-5 } else { 1e-6 };
            let excess = green_excess(&f);
            assert!(
                excess <= tolerance,
                "{view} {more:?}: green {excess} past the labels'"
            );
            let (red, blue) = (
                f.iter().filter(|p| p[0] > 0.05 && p[2] < p[0]).count(),
                f.iter().filter(|p| p[2] > 0.05 && p[0] < p[2]).count(),
            );
            assert!(
                red > 50 && blue > 50,
                "{view} {more:?}: {red} red, {blue} blue"
            );
        }
        // The values 0..3 through a transfer function with the labels' colours at 1, 2 and 3,
        // reconstructed and then classified.
        let dir = tmpdir("labels-tf");
        let tf = dir.join("labels.tf");
        std::fs::write(
            &tf,
            "0 0 0 0 0\n0.3333 1 0.2 0 0.04\n0.6667 0 1 0 1\n1 0.1 0.3 1 0.5\n",
        )
        .unwrap();
        let post = frame_of(&args(&[
            "--tf",
            s(&tf),
            "--window",
            "0,3",
            "--classification",
            "post",
            "--size",
            "96x96",
            "--view",
            view,
        ]));
        let excess = green_excess(&post);
        assert!(
            excess > 0.05,
            "{view}: post-classified values show green {excess}"
        );
    }
}

/// The default plan meets its target against the labels' continuous model (the kernels' blend
/// of each voxel's label colour and opacity), two views.
#[test]
fn labels_meet_the_target_against_their_model() {
    for view in ["0,0,0", "30,20,0"] {
        let a = args(&["--labels", TABLE, "--size", "96x96", "--view", view]);
        let (f, r) = render(&scene(&a).unwrap(), &plan(&a).unwrap()).unwrap();
        let (truth, _) = render_continuous_ref(r.prepared(), Reconstruction::Kernel).unwrap();
        let db = compare(&f.image, &truth.image).1.psnr_db;
        assert!(
            db >= DEFAULT_TARGET_DB,
            "{view}: {db:.2} dB against the labels' model"
        );
        assert!(
            f.image.iter().any(|p| p[3] > 0.2),
            "{view}: something shows"
        );
    }
}

/// A voxel whose label the table does not list is transparent: a table of labels the volume
/// does not hold renders nothing, and leaving out soft tissue leaves the bone's picture where
/// nothing lies in front of it.
#[test]
fn unlisted_labels_are_transparent() {
    let none = frame_of(&args(&[
        "--labels",
        r#"{"7": [1, 1, 1, 1]}"#,
        "--size",
        "64x64",
    ]));
    assert!(
        none.iter().all(|p| *p == [0.0; 4]),
        "labels absent: a clear picture"
    );
    let bone = frame_of(&args(&[
        "--labels",
        r#"{"3": [0.1, 0.3, 1, 0.5]}"#,
        "--size",
        "64x64",
    ]));
    let zero_tissue = frame_of(&args(&[
        "--labels",
        r#"{"1": [1, 0.2, 0, 0], "3": [0.1, 0.3, 1, 0.5]}"#,
        "--size",
        "64x64",
    ]));
    assert!(bone.iter().any(|p| p[3] > 0.2));
    let worst = bone
        .iter()
        .zip(&zero_tissue)
        .map(|(a, b)| (0..4).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max))
        .fold(0.0, f32::max);
    assert!(
        worst < 1e-6,
        "an unlisted label is an invisible one: {worst}"
    );
}

/// The same table by every door: inline JSON, a JSON file, ITK-SNAP's label description; the
/// volume from a file, streamed, and on three threads: the same picture, bit for bit.
#[test]
fn labels_are_the_same_by_every_door() {
    let dir = tmpdir("labels-doors");
    let raw = dir.join("labels.raw");
    let v = labelled();
    let bytes: Vec<u8> = (0..v.len()).map(|n| v.value(n) as u8).collect();
    std::fs::write(&raw, bytes).unwrap();
    let json = dir.join("labels.json");
    std::fs::write(&json, TABLE).unwrap();
    let snap = dir.join("labels.txt");
    std::fs::write(
        &snap,
        "# ITK-SNAP Label Description File\n\
         0 0 0 0 0 0 0 \"Clear Label\"\n\
         1 255 51 0 0.04 1 1 \"Soft tissue\"\n\
         2 0 255 0 1 1 1 \"Absent\"\n\
         3 25.5 76.5 255 0.5 1 1 \"Bone\"\n",
    )
    .unwrap();
    let dims = format!("{},{},{}", v.dims[0], v.dims[1], v.dims[2]);
    let spacing = format!("{},{},{}", v.spacing[0], v.spacing[1], v.spacing[2]);
    let flags = [
        "--dims",
        &dims,
        "--type",
        "u8",
        "--spacing",
        &spacing,
        "--size",
        "64x64",
        "--view",
        "30,20,0",
        "--slicing",
        "object",
    ];
    let out = |name: &str, lead: &[&str], table: &str, more: &[&str]| {
        let o = dir.join(name);
        let mut a = vec!["render"];
        a.extend_from_slice(lead);
        a.extend_from_slice(&flags);
        a.extend_from_slice(&["--labels", table, "--out", s(&o)]);
        a.extend_from_slice(more);
        assert_eq!(run_cli(&a), 0, "{a:?}");
        std::fs::read(o).unwrap()
    };
    let base = out("inline.pfm", &[s(&raw)], TABLE, &[]);
    assert_eq!(
        base,
        out("json.pfm", &[s(&raw)], s(&json), &[]),
        "a JSON file"
    );
    assert_eq!(
        base,
        out("snap.pfm", &[s(&raw)], s(&snap), &[]),
        "ITK-SNAP's file"
    );
    assert_eq!(
        base,
        out("stream.pfm", &["--stream", s(&raw)], TABLE, &[]),
        "streamed"
    );
    assert_eq!(
        base,
        out("threads.pfm", &[s(&raw)], TABLE, &["--threads", "3"]),
        "three threads"
    );
}
