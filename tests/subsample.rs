//! `--subsample`: a magnified frame rendered at 1/s of the size and resampled is close to the
//! full-size render (against it, pixel by pixel), costs fewer pixel updates, does not depend on the
//! thread count, composites a background at the output size, leaves small footprints alone under
//! `auto`, and refuses what it cannot honour with a typed error.

use footprint_harness::args::parse_args;
use footprint_harness::args::plan;
use footprint_harness::pipeline::stages::visible::FrameCache;
use footprint_harness::pipeline::{prepare, render_frame, stages::subsample, CoreFrame};
use footprint_suite::{rgb_psnr, tmpdir};

/// The built-in scene with `extra` flags.
fn frame(extra: &[&str]) -> Result<CoreFrame, String> {
    let args = parse_args(extra).map_err(|e| e.to_string())?;
    let plan = plan(&args).map_err(|e| e.to_string())?;
    let p = prepare(&args).map_err(|e| e.to_string())?;
    render_frame(&p, &plan, &mut FrameCache::default()).map_err(|e| e.to_string())
}

/// A magnified view (footprints about 8 px in semi-axis at 150×110).
const MAGNIFIED: [&str; 6] = ["--size", "150x110", "--view", "30,20,0", "--zoom", "5"];

/// [`MAGNIFIED`] followed by `extra`.
fn with<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = MAGNIFIED.to_vec();
    a.extend_from_slice(extra);
    a
}

#[test]
fn subsampled_frames_are_close_to_the_full_size_render() {
    for accum in ["float", "fixed"] {
        let full = frame(&with(&["--accum", accum])).unwrap();
        assert!(full.image.iter().any(|p| p[3] > 0.1), "the scene shows");
        let mut last = f64::INFINITY;
        for s in ["2", "3", "4"] {
            let sub = frame(&with(&["--accum", accum, "--subsample", s])).unwrap();
            assert_eq!(sub.image.len(), full.image.len(), "the output size");
            let db = rgb_psnr(&sub.image, &full.image);
            // Opacity on its own (RGB leaves it out), as an image whose channels all hold it.
            let alpha = |i: &[[f32; 4]]| i.iter().map(|p| [p[3]; 4]).collect::<Vec<_>>();
            let db_alpha = rgb_psnr(&alpha(&sub.image), &alpha(&full.image));
            // Measured on this scene (float and fixed alike; RGB, as `verify` reports): 69.0 /
            // 66.0 / 61.7 dB at s = 2 / 3 / 4 (opacity 67.1 / 65.0 / 62.8 dB), with 3.5 / 7.4 /
            // 12.2 times fewer pixel updates.
            let floor = match s {
                "2" => 64.0,
                "3" => 61.0,
                _ => 57.0,
            };
            assert!(
                db >= floor,
                "{accum} s = {s}: {db:.1} dB against the full size"
            );
            assert!(
                db_alpha >= floor,
                "{accum} s = {s}: opacity {db_alpha:.1} dB against the full size"
            );
            assert!(
                db < 200.0,
                "{accum} s = {s}: not the full-size image itself"
            );
            assert!(
                db <= last + 0.5,
                "coarser is not closer: s = {s} {db:.1} dB"
            );
            last = db;
            let (n, m) = (sub.stats.pixel_updates, full.stats.pixel_updates);
            let k: f64 = s.parse().unwrap();
            assert!(
                (n as f64) * k * k < 1.5 * m as f64,
                "{accum} s = {s}: {n} pixel updates against {m} at full size"
            );
        }
    }
}

#[test]
fn subsampled_frames_do_not_depend_on_threads() {
    for accum in ["float", "fixed"] {
        let bits = |t: &str| -> Vec<[u32; 4]> {
            frame(&with(&[
                "--accum",
                accum,
                "--subsample",
                "3",
                "--threads",
                t,
            ]))
            .unwrap()
            .image
            .iter()
            .map(|c| c.map(f32::to_bits))
            .collect()
        };
        let one = bits("1");
        for t in ["2", "5"] {
            assert!(one == bits(t), "{accum}: {t} threads differ from 1");
        }
    }
}

#[test]
fn auto_picks_by_footprint_size() {
    let args = parse_args(&with(&["--subsample", "auto"])).unwrap();
    let p = prepare(&args).unwrap();
    let s = p.subsample_factor(&plan(&args).unwrap()).unwrap();
    let r = p.frame.footprint.natural_minor_px;
    assert_eq!(
        s,
        (r / subsample::AUTO_MIN_RADIUS_PX) as usize,
        "semi-axis {r} px"
    );
    assert!(s >= 2);
    // Small footprints (the scene fitted to 200×150): auto is off, the same bits as without it.
    let small = ["--size", "200x150", "--view", "30,20,0"];
    let mut a = small.to_vec();
    a.extend(["--subsample", "auto"]);
    let bits = |f: CoreFrame| {
        f.image
            .iter()
            .map(|c| c.map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert!(bits(frame(&small).unwrap()) == bits(frame(&a).unwrap()));
    // A perspective view: auto is off too.
    let persp = with(&["--perspective", "40"]);
    let mut a = persp.clone();
    a.extend(["--subsample", "auto"]);
    assert!(bits(frame(&persp).unwrap()) == bits(frame(&a).unwrap()));
}

#[test]
fn what_cannot_be_honoured_is_refused() {
    let refused = |extra: &[&str], why: &str| {
        let e = frame(&with(extra))
            .err()
            .unwrap_or_else(|| panic!("{extra:?} accepted"));
        assert!(e.contains(why), "{extra:?}: {e}");
    };
    refused(&["--subsample", "2", "--perspective", "40"], "orthographic");
    refused(&["--subsample", "8"], "--min-radius");
    refused(&["--subsample", "2", "--refine", "0.1"], "--refine");
    refused(&["--subsample", "auto", "--quality", "40"], "--quality");
    for bad in ["0", "9", "1.5", "x"] {
        assert!(
            parse_args(&with(&["--subsample", bad])).is_err(),
            "--subsample {bad} parsed"
        );
    }
}

#[test]
fn a_background_is_composited_at_the_output_size() {
    let d = tmpdir("subsample-background");
    let bg_path = d.join("bg.png");
    let (w, h) = (150, 110);
    // Opaque, with detail on the scale of one output pixel (a checker in red); every value a
    // whole number of 1/255, so the 8-bit PNG holds it exactly.
    let bg: Vec<[f32; 4]> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            [
                ((x + y) % 2) as f32,
                ((x * 7) % 256) as f32 / 255.0,
                128.0 / 255.0,
                1.0,
            ]
        })
        .collect();
    std::fs::write(
        &bg_path,
        footprint_harness::io::image::encode_png_rgb(&bg, w, h).unwrap(),
    )
    .unwrap();
    let b = bg_path.to_str().unwrap();
    let over = frame(&with(&["--subsample", "2", "--background", b])).unwrap();
    let alone = frame(&with(&["--subsample", "2"])).unwrap();
    for (i, (o, a)) in over.image.iter().zip(&alone.image).enumerate() {
        for c in 0..3 {
            let want = a[c] + (1.0 - a[3]) * bg[i][c];
            assert!(
                (o[c] - want).abs() < 2e-3,
                "pixel {i} channel {c}: {} against {want}",
                o[c]
            );
        }
    }
}
