//! Minification: a volume rendered small agrees with its large render box-filtered down (mean
//! brightness and PSNR), because `--supersample auto` renders at k× and averages when voxels
//! project closer than the smallest footprint. Without it (`--supersample 1`) the widened
//! footprints blur each sheet before the (non-linear) compositing and the small render is too
//! bright: the test shows that too, so it can fail.

use footprint_harness::args::parse_args;
use footprint_harness::args::plan;
use footprint_harness::pipeline::{prepare, render_core};
use std::path::PathBuf;

/// A 128³ u8 volume with detail finer than the small render's pixels: three thin concentric
/// shells (2 voxels thick) and a hashed speckle inside, written raw to a temporary file.
fn volume_file() -> PathBuf {
    let n = 128usize;
    let mut v = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = [i, j, k].map(|x| x as f32 - 63.5);
                let r = (p[0] * p[0] + 0.8 * p[1] * p[1] + 1.2 * p[2] * p[2]).sqrt();
                let shell = [30.0f32, 42.0, 55.0]
                    .iter()
                    .map(|s| (1.0 - (r - s).abs()).max(0.0))
                    .fold(0.0, f32::max);
                let h = ((i * 73_856_093) ^ (j * 19_349_663) ^ (k * 83_492_791)) % 997;
                let speckle = if r < 25.0 && h < 120 { 0.7 } else { 0.0 };
                v.push((255.0 * shell.max(speckle)) as u8);
            }
        }
    }
    let path = std::env::temp_dir().join(format!("fp-minify-{}.raw", std::process::id()));
    std::fs::write(&path, v).unwrap();
    path
}

/// Renders `volume` with the flags, returns premultiplied RGB as f64 and the supersampling used.
fn render<S: AsRef<str>>(volume: &str, extra: &[S]) -> (Vec<[f64; 3]>, usize) {
    let mut args = vec![volume];
    args.extend(extra.iter().map(AsRef::as_ref));
    let args = parse_args(&args).unwrap();
    let p = prepare(&args).unwrap();
    let (img, _, _) = render_core(&p, &plan(&args).unwrap()).unwrap();
    (
        img.iter()
            .map(|c| [c[0], c[1], c[2]].map(f64::from))
            .collect(),
        p.supersample,
    )
}

/// Mean of each f×f block of a `side × side` image.
fn box_down(img: &[[f64; 3]], side: usize, f: usize) -> Vec<[f64; 3]> {
    let n = side / f;
    let mut out = vec![[0.0; 3]; n * n];
    for y in 0..side {
        for x in 0..side {
            let o = &mut out[(y / f) * n + x / f];
            for c in 0..3 {
                o[c] += img[y * side + x][c] / (f * f) as f64;
            }
        }
    }
    out
}

/// (small mean / reference mean − 1, PSNR of small against reference), RGB in [0, 1].
fn compare(small: &[[f64; 3]], reference: &[[f64; 3]]) -> (f64, f64) {
    let mean = |v: &[[f64; 3]]| v.iter().flatten().sum::<f64>() / (3 * v.len()) as f64;
    let mse = small
        .iter()
        .flatten()
        .zip(reference.iter().flatten())
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / (3 * small.len()) as f64;
    (mean(small) / mean(reference) - 1.0, -10.0 * mse.log10())
}

fn check(volume: &str, raw: &[&str], view: &str) {
    let flags = |size: &str, ss: &str| -> Vec<String> {
        let mut v: Vec<String> = raw.iter().map(|s| s.to_string()).collect();
        v.extend(
            [
                "--view",
                view,
                "--size",
                size,
                "--supersample",
                ss,
                "--tf",
                "grey",
                // Supersampling at full resolution is what this measures (`auto` would coarsen).
                "--lod",
                "0",
            ]
            .iter()
            .map(|s| s.to_string()),
        );
        v
    };
    let (big, k_big) = render(volume, &flags("512x512", "1"));
    assert_eq!(k_big, 1);
    let reference = box_down(&big, 512, 8);
    let (small, k) = render(volume, &flags("64x64", "auto"));
    let (bias, psnr) = compare(&small, &reference);
    let (plain, _) = render(volume, &flags("64x64", "1"));
    let (plain_bias, plain_psnr) = compare(&plain, &reference);
    eprintln!(
        "{volume} view {view}: supersampled {k}x: mean {:+.2} %, {psnr:.1} dB; \
         without: {:+.2} %, {plain_psnr:.1} dB",
        100.0 * bias,
        100.0 * plain_bias
    );
    assert!(k > 1, "auto did not supersample a minified render");
    assert!(
        bias.abs() < 0.03,
        "mean brightness off by {:.2} %",
        100.0 * bias
    );
    assert!(psnr > 40.0, "PSNR {psnr:.1} dB");
    assert!(
        plain_bias > bias.abs() && psnr > plain_psnr,
        "supersampling did not help"
    );
}

#[test]
fn a_128_cubed_volume_rendered_at_64_matches_its_512_render_box_filtered() {
    let path = volume_file();
    let p = path.to_str().unwrap();
    let raw = ["--dims", "128,128,128", "--type", "u8"];
    check(p, &raw, "0,0,0");
    check(p, &raw, "30,20,0");
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn a_ct_head_rendered_small_matches_its_large_render_box_filtered() {
    let head = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/headsq_64x64x93_int16_le.nhdr"
    );
    check(head, &[], "60,40,20");
}

/// A render that needs no widening is not supersampled: the images of the README and every
/// magnified render stay bit for bit what they were.
#[test]
fn unminified_renders_are_not_supersampled() {
    let head = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/headsq_64x64x93_int16_le.nhdr"
    );
    let (auto, k) = render(head, &["--size", "256x256", "--view", "30,20,0"]);
    assert_eq!(k, 1);
    let (off, _) = render(
        head,
        &[
            "--size",
            "256x256",
            "--view",
            "30,20,0",
            "--supersample",
            "1",
        ],
    );
    assert_eq!(auto, off);
}
