//! Clipping planes (issue 77, item 1): `--clip NX,NY,NZ,D` keeps the world points with n·x ≤ D.
//! The cut model is the continuous model times the kept region's indicator; a kernel a plane
//! crosses is cut where the plane crosses each ray (image-aligned slabs). Away from the cut the
//! picture is the unclipped one bit for bit; against the cut model it meets the 44 dB target.

use super::cut::{frame, unchanged_away, HEADSQ, HEART};
use footprint_harness::args::{parse_args, plan, scene};
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::{render, render_continuous_ref};
use footprint_harness::plan::DEFAULT_TARGET_DB;
use footprint_harness::reference::continuous::Reconstruction;

/// Away from the cut, bit for bit: headsq (spacing 3.2 : 3.2 : 1.5, the default kernel reaching
/// 1.6 grid steps, 5.12 world units along x) clipped to x ≤ 10 against the unclipped slabs,
/// every pixel that a render kept to x ≥ 10 − 2·5.12 − 1 leaves clear (it holds, whole, every
/// kernel the plane cuts or removes), two views, emission and Phong.
#[test]
fn a_clip_leaves_the_picture_away_from_the_cut_bit_identical() {
    for view in ["0,0,0", "30,20,0"] {
        for shading in ["emission", "phong"] {
            let base = [
                HEADSQ,
                "--size",
                "96x96",
                "--view",
                view,
                "--slicing",
                "image",
                "--shading",
                shading,
                "--lod",
                "0",
            ];
            // Clipped, and x ≥ −1.24: every kernel that reaches past x = 10 − 5.12, whole.
            let planes = ["1,0,0,10", "-1,0,0,1.24"];
            unchanged_away(&base, "--clip", planes, &format!("{view} {shading}"));
        }
    }
}

/// The clipped frame meets the target against the cut model (the continuous integral over the
/// kept region only): headsq and the heart, one plane and two oblique ones, two views.
#[test]
fn a_clip_meets_the_target_against_the_cut_model() {
    let planes: [&[&str]; 2] = [
        &["--clip", "1,0,0,2"],
        &["--clip", "1,1,0.5,5", "--clip", "-0.3,0.2,-1,8"],
    ];
    for volume in [HEADSQ, HEART] {
        for view in ["0,0,0", "30,20,0"] {
            for clip in planes {
                let mut a = vec![volume, "--size", "96x96", "--view", view];
                a.extend_from_slice(clip);
                let args = parse_args(&a).unwrap();
                let (f, r) = render(&scene(&args).unwrap(), &plan(&args).unwrap()).unwrap();
                let (truth, _) =
                    render_continuous_ref(r.prepared(), Reconstruction::Kernel).unwrap();
                let db = compare(&f.image, &truth.image).1.psnr_db;
                eprintln!("{volume} {view} {clip:?}: {db:.2} dB against the cut model");
                assert!(
                    db >= DEFAULT_TARGET_DB,
                    "{volume} {view} {clip:?}: {db:.2} dB against the cut model"
                );
                let unclipped = frame(&[volume, "--size", "96x96", "--view", view]);
                let moved = compare(&unclipped, &truth.image).1.psnr_db;
                assert!(
                    moved < 35.0,
                    "{volume} {view} {clip:?}: the clip cut little ({moved:.1} dB)"
                );
            }
        }
    }
}
