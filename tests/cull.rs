//! Occlusion culling (`--cull EPS`, the core's `SheetRenderer::with_occlusion`): the image is the
//! same bit for bit on any number of threads (sheets float and fixed, slabs, with subsampling), each pixel stays
//! within ε per channel of the image without culling, opaque scenes skip voxels, and what culling
//! cannot do is refused with a typed error.

use footprint_harness::args::parse_args;
use footprint_harness::args::plan;
use footprint_harness::pipeline::stages::visible::FrameCache;
use footprint_harness::pipeline::{prepare, render_frame, CoreFrame};
use footprint_suite::{run_cli, tmpdir};

const HEADSQ: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/headsq_64x64x93_int16_le.nhdr"
);

fn frame(args: &[&str]) -> CoreFrame {
    let args = parse_args(args).unwrap();
    let p = prepare(&args).unwrap();
    render_frame(&p, &plan(&args).unwrap(), &mut FrameCache::default()).unwrap()
}

fn bits(f: &CoreFrame) -> Vec<[u32; 4]> {
    f.image.iter().map(|c| c.map(f32::to_bits)).collect()
}

/// The CT head at `size` with `extra` flags, from below (bone and skin in front of each other)
/// unless `extra` gives a view.
fn head(size: &str, extra: &[&str]) -> Vec<String> {
    let view = if extra.contains(&"--view") {
        &[][..]
    } else {
        &["--view", "180,-90,0"][..]
    };
    let mut a: Vec<String> = [&[HEADSQ, "--size", size][..], view]
        .concat()
        .iter()
        .map(|s| s.to_string())
        .collect();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn render(a: &[String]) -> CoreFrame {
    frame(&a.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn culled_frames_are_the_same_on_any_number_of_threads() {
    // Sheets, float and fixed; supersampled (the head minified at this size); subsampled (zoomed, its
    // bands are the low-resolution image's); a view whose sheets run along i; an image height
    // that is not a multiple of the tile.
    let cases: [&[&str]; 7] = [
        &["--cull", "0.02"],
        &["--cull", "0.02", "--accum", "fixed"],
        &["--cull", "0.01", "--subsample", "2", "--zoom", "5"],
        &["--cull", "0.05", "--view", "80,10,0", "--shading", "phong"],
        &[
            "--cull",
            "0.02",
            "--accum",
            "fixed",
            "--subsample",
            "2",
            "--zoom",
            "5",
        ],
        // Image-aligned slabs, and subsampled slabs.
        &["--cull", "0.02", "--slicing", "image"],
        &[
            "--cull",
            "0.02",
            "--slicing",
            "image",
            "--subsample",
            "2",
            "--zoom",
            "5",
        ],
    ];
    for case in cases {
        let one = render(&head("150x93", &[case, &["--threads", "1"]].concat()));
        assert!(one.stats.culled_voxels > 0, "{case:?}: nothing culled");
        for t in ["2", "3", "7"] {
            let many = render(&head("150x93", &[case, &["--threads", t]].concat()));
            let differ = bits(&one)
                .iter()
                .zip(bits(&many))
                .filter(|(a, b)| **a != *b)
                .count();
            assert_eq!(differ, 0, "{case:?}: {t} threads differ in {differ} pixels");
        }
    }
}

#[test]
fn culling_stays_within_eps_and_skips_voxels() {
    for (eps, slicing) in [(0.004f32, "object"), (0.05, "object"), (0.02, "image")] {
        let e = eps.to_string();
        let base = ["--slicing", slicing, "--threads", "2"];
        let full = render(&head(
            "128x128",
            &[&base[..], &["--order", "front-to-back"]].concat(),
        ));
        let culled = render(&head("128x128", &[&base[..], &["--cull", &e]].concat()));
        let worst = full
            .image
            .iter()
            .zip(&culled.image)
            .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
            .fold(0.0f32, f32::max);
        // The bound is ε per channel, plus f32 rounding of the sums the culled image skipped.
        assert!(
            worst <= eps + 1e-5,
            "{slicing}, ε = {eps}: a pixel moved by {worst}"
        );
        assert!(worst > 0.0, "{slicing}, ε = {eps}: culling changed nothing");
        let (s, c) = (full.stats, culled.stats);
        assert!(c.culled_voxels > 0 && c.pixel_updates < s.pixel_updates);
        assert!(c.pixels_composited < s.pixels_composited);
    }
    // The built-in scene, semi-transparent, renders unchanged at a tiny ε where nothing closes.
    let a = frame(&["--size", "64x64", "--order", "front-to-back"]);
    let b = frame(&["--size", "64x64", "--cull", "0.00001"]);
    assert!(bits(&a) == bits(&b));
}

#[test]
fn what_culling_cannot_do_is_refused() {
    let d = tmpdir("cull");
    let out = d.join("x.png");
    let o = out.to_str().unwrap();
    for bad in [
        &["--cull", "0"][..],
        &["--cull", "1"],
        &["--cull", "nan"],
        &["--cull", "half"],
        &["--cull", "0.01", "--classification", "post"],
        &["--cull", "0.01", "--perspective", "40"],
        &["--cull", "0.01", "--order", "back-to-front"],
        &["--cull", "0.01", "--quality", "40"],
    ] {
        let mut a = vec!["render", "-s", "32x32", "-o", o];
        a.extend_from_slice(bad);
        assert_eq!(run_cli(&a), 2, "{bad:?} is refused");
    }
    assert!(!out.exists(), "no image from a refused render");
    let mut a = vec!["render", "-s", "32x32", "-o", o, "--cull", "off"];
    assert_eq!(run_cli(&a), 0);
    a.truncate(5);
    a.extend_from_slice(&["--cull", "0.01"]);
    assert_eq!(run_cli(&a), 0);
}
