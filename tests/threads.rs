//! Threads, visible-voxel lists and `footprint bench`: the image does not depend on the number of
//! threads (bit for bit, float and fixed), rendering the cached visible lists gives the image of a
//! full scan of every voxel, and `bench` writes the keys the issue names.

use footprint_harness::args::parse_args;
use footprint_harness::args::plan;
use footprint_harness::pipeline::stages::visible::FrameCache;
use footprint_harness::pipeline::{prepare, render_frame};
use footprint_suite::tmpdir;

/// The core's image of the built-in scene with `extra` flags on `threads` threads, as bits, and
/// the frame's counts: voxels, voxels splatted, pixel updates, pixels composited.
fn frame(extra: &[&str], threads: usize) -> (Vec<[u32; 4]>, [u64; 4]) {
    let t = threads.to_string();
    let mut a = vec!["--size", "97x61", "--threads", &t];
    a.extend_from_slice(extra);
    let args = parse_args(&a).unwrap();
    let p = prepare(&args).unwrap();
    let f = render_frame(&p, &plan(&args).unwrap(), &mut FrameCache::default()).unwrap();
    assert_eq!(f.threads, threads, "bands used");
    let s = f.stats;
    (
        f.image.iter().map(|c| c.map(f32::to_bits)).collect(),
        [
            s.voxels,
            s.voxels_splatted,
            s.pixel_updates,
            s.pixels_composited,
        ],
    )
}

#[test]
fn every_thread_count_gives_the_same_bits() {
    // Stencil splats (small and wide footprints, blended and nearest), the per-pixel table walk
    // (--phases 0), the direct method, fixed point; phong needs gradients; front to back composites under; a view whose
    // sheets run along i.
    let cases: [&[&str]; 13] = [
        // Perspective: a footprint per voxel, no band test.
        &["--view", "30,20,0", "--perspective", "60"],
        &[
            "--view",
            "75,-40,20",
            "--perspective",
            "40",
            "--shading",
            "phong",
            "--order",
            "front-to-back",
        ],
        &["--view", "30,20,0"],
        // Zoomed so the footprints are wide (box over 16 px): stencils with exact edges.
        &["--view", "30,20,0", "--zoom", "12"],
        &["--view", "30,20,0", "--phases", "0"],
        // Stencils read at the nearest phase: the windowed and clipped loops at band edges.
        &["--view", "30,20,0", "--phase-lookup", "nearest"],
        &[
            "--view",
            "75,-40,20",
            "--phase-lookup",
            "nearest",
            "--zoom",
            "3",
            "--shading",
            "phong",
        ],
        &[
            "--view",
            "75,-40,20",
            "--method",
            "direct",
            "--shading",
            "phong",
        ],
        &["--view", "30,20,0", "--accum", "fixed"],
        // The fixed path's integer stencils read at the nearest phase.
        &[
            "--view",
            "30,20,0",
            "--accum",
            "fixed",
            "--phase-lookup",
            "nearest",
        ],
        &[
            "--view",
            "75,-40,20",
            "--accum",
            "fixed",
            "--shading",
            "phong",
        ],
        &[
            "--view",
            "10,5,0",
            "--order",
            "front-to-back",
            "--zoom",
            "0.4",
        ],
        &["--view", "80,0,0", "--accum", "fixed", "--zoom", "3"],
    ];
    for case in cases {
        let (one, counts) = frame(case, 1);
        assert!(
            one.iter().any(|p| p[3] != 0),
            "{case:?}: the scene is visible"
        );
        for threads in [2, 3, 7] {
            let (many, many_counts) = frame(case, threads);
            let differ = one.iter().zip(&many).filter(|(a, b)| a != b).count();
            assert_eq!(
                differ, 0,
                "{case:?}: {threads} threads differ in {differ} pixels"
            );
            // The frame's counts too, but for voxels splatted, which counts a voxel once in
            // each band it reaches.
            let [v, s, u, c] = counts;
            let [mv, ms, mu, mc] = many_counts;
            assert_eq!(
                (mv, mu, mc),
                (v, u, c),
                "{case:?}: {threads} threads: voxels, pixel updates, composites"
            );
            assert!(
                ms >= s,
                "{case:?}: {threads} threads: {ms} splats, {s} voxels"
            );
        }
    }
}

#[test]
fn cached_lists_render_what_a_full_scan_renders() {
    // A streamed volume is scanned voxel by voxel through a sheet ring; a loaded one renders its
    // visible lists (the re-render path). Same bits.
    let d = tmpdir("lists");
    let raw = d.join("v.raw");
    // A 24×20×16 u8 volume: a ramp with a hollow, so some voxels are transparent.
    let mut bytes = Vec::new();
    for k in 0..16u32 {
        for j in 0..20u32 {
            for i in 0..24u32 {
                let r2 = (i as i32 - 12).pow(2) + (j as i32 - 10).pow(2) + (k as i32 - 8).pow(2);
                bytes.push(if r2 < 20 {
                    0
                } else {
                    ((i * 7 + j * 5 + k * 3) % 256) as u8
                });
            }
        }
    }
    std::fs::write(&raw, &bytes).unwrap();
    let r = raw.to_str().unwrap();
    // Sheets along z, and along x (read in blocks of sheets: 24 sheets, two blocks, split
    // between threads).
    for (view, axis) in [("30,20,0", 2), ("85,10,0", 0)] {
        for accum in ["float", "fixed"] {
            for shading in ["emission", "phong"] {
                let common = [
                    "--dims",
                    "24,20,16",
                    "--type",
                    "u8",
                    "--window",
                    "40,255",
                    "--size",
                    "80x64",
                    "--view",
                    view,
                    "--accum",
                    accum,
                    "--shading",
                    shading,
                ];
                let mut loaded = vec![r];
                loaded.extend_from_slice(&common);
                // Nothing left to a pilot, so the stream is not held (`pipeline::stages::hold`).
                let fixed = ["--slicing", "object", "--lod", "0"];
                loaded.extend_from_slice(&fixed);
                let mut streamed = vec!["--stream", r];
                streamed.extend_from_slice(&common);
                streamed.extend_from_slice(&fixed);
                let render_with = |a: &[&str], cache: &mut FrameCache| {
                    let args = parse_args(a).unwrap();
                    let p = prepare(&args).unwrap();
                    assert_eq!(p.frame.sheet_axis, axis, "view {view}");
                    let f = render_frame(&p, &plan(&args).unwrap(), cache).unwrap();
                    (
                        f.image
                            .iter()
                            .map(|c| c.map(f32::to_bits))
                            .collect::<Vec<_>>(),
                        f.visible,
                    )
                };
                let render = |a: &[&str]| render_with(a, &mut FrameCache::default());
                let (a, visible) = render(&loaded);
                let (b, none) = render(&streamed);
                assert!(visible.is_some_and(|n| n > 0) && none.is_none());
                assert!(
                    a == b,
                    "{view} {accum} {shading}: lists and full scan differ"
                );
                // A volume whose lists pass the budget (here 0 bytes) is classified by each band
                // as it goes: the same bits and count, on one thread and on three.
                for threads in ["1", "3"] {
                    let mut a3 = loaded.clone();
                    a3.extend_from_slice(&["--threads", threads]);
                    let mut cache = FrameCache::with_list_budget(0);
                    for frame in 0..2 {
                        let (c, n) = render_with(&a3, &mut cache);
                        assert!(
                            c == a && n == visible,
                            "{view} {accum} {shading}, {threads} thread(s), frame {frame}: \
                             classified as it goes, differs from the kept lists ({n:?}, {visible:?})"
                        );
                    }
                }
            }
        }
    }
}

/// Frames that reuse a cache's kept buffers (the bands' accumulators, and an image given back,
/// here one full of NaN) render what a fresh cache renders, bit for bit: float and fixed, both
/// compositing orders, one and two threads.
#[test]
fn kept_buffers_render_what_fresh_ones_render() {
    for accum in ["float", "fixed"] {
        for order in ["back-to-front", "front-to-back"] {
            for threads in ["1", "2"] {
                let args = parse_args(&[
                    "--scene-size",
                    "24",
                    "--size",
                    "64x48",
                    "--view",
                    "30,20,0",
                    "--accum",
                    accum,
                    "--order",
                    order,
                    "--threads",
                    threads,
                ])
                .unwrap();
                let p = prepare(&args).unwrap();
                let bits = |f: footprint_harness::pipeline::CoreFrame| {
                    f.image
                        .iter()
                        .map(|c| c.map(f32::to_bits))
                        .collect::<Vec<_>>()
                };
                let fresh = bits(
                    render_frame(&p, &plan(&args).unwrap(), &mut FrameCache::default()).unwrap(),
                );
                let mut cache = FrameCache::default();
                for k in 0..3 {
                    cache.recycle(vec![[f32::NAN; 4]; 64 * 48]);
                    let again = bits(render_frame(&p, &plan(&args).unwrap(), &mut cache).unwrap());
                    assert!(
                        again == fresh,
                        "{accum} {order} {threads} threads, frame {k}"
                    );
                }
            }
        }
    }
}

#[test]
fn bench_writes_the_named_keys() {
    let d = tmpdir("bench");
    let json = d.join("b.json");
    let code = footprint_harness::run([
        "footprint",
        "bench",
        "--size",
        "64x64",
        "--view",
        "30,20,0",
        "--frames",
        "4",
        "--orbit",
        "30",
        "--threads",
        "1",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    let j = std::fs::read_to_string(&json).unwrap();
    for key in [
        "\"first_ms\"",
        "\"median_ms\"",
        "\"min_ms\"",
        "\"max_ms\"",
        "\"threads\": 1",
        "\"phases_ms\"",
        "\"classify\"",
        "\"tables\"",
        "\"splat\"",
        "\"composite\"",
        "\"frames_ms\"",
        "\"plan\"",
        "\"end\": \"sheets\"",
        "\"culled_voxels\": 0",
    ] {
        assert!(j.contains(key), "{key} missing from {j}");
    }
    // Frame 1 classifies; turning 30° per frame switches the sheet axis at least once, so a later
    // frame classifies again, and the others reuse the lists.
    assert!(!j.contains("\"median_ms\": null"));
    assert_eq!(
        footprint_harness::run(["footprint", "bench", "--frames", "0"]),
        2,
        "--frames 0 is refused"
    );
}
