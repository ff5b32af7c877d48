//! The floor of a frame splatted at image resolution: the work the paper's pipeline cannot avoid
//! for a given scene, done by the simplest loops the compiler vectorises and nothing else.
//!
//! A sheet-buffer splatter (Westover's, and Footprint's) makes, per frame, one *pixel update*
//! for every non-zero weight of every visible voxel's footprint (a weighted add of the voxel's
//! colour into the sheet accumulator) and one *composite* for every sheet pixel a footprint
//! touched (the accumulator "over" the image, front to back, and the accumulator cleared). Both
//! counts are fixed by the scene, the kernel and the image size: `footprint render --json`
//! reports them (`pixel_updates`, `pixels_composited`, `voxels_splatted`, `sheets`). This bench
//! times that work alone, with nothing the renderer adds:
//! - each update reads its weight from one row of a box (no blend of four phase stencils, no
//!   table, no per-voxel position, classification or clipping) and adds weight × colour into
//!   an f32 pixel: `rgba` (four channels, 16 bytes, the renderer's pixel) and `la` (luminance
//!   and alpha, 8 bytes: the cheapest pixel a grey scene could use);
//! - footprints are square boxes whose side is the scene's mean footprint width, √(updates /
//!   voxels), so every row is as long as the scene's average row or longer (longer rows cost
//!   less per update, which favours the floor); each sheet's voxels sit 3 px apart along rows
//!   of the sheet, so the accumulator stays in cache as a real sheet's does;
//! - each sheet composites one contiguous run of pixels (the scene's composites ÷ sheets).
//!
//! The figure is a lower bound on what any implementation of this pipeline at this resolution
//! spends on the scene on this machine with baseline x86-64 code (the loops compile to one
//! load, a broadcast, a multiply, an add and a store per update; `objdump -d` shows them), up to
//! hand-written vector code for wider instruction sets. `benches/peers.sh` runs it beside
//! VolPack and VTK on the peers' scenes and `docs/performance.md` shows the ratios.
//!
//! `cargo bench --bench floor -- UPDATES COMPOSITES VOXELS SHEETS [REPS]` prints, per pixel
//! type, `floor PIXEL: box S px, accumulate A ms (… ns/update), composite C ms (… ns/pixel),
//! floor F ms` (medians of REPS frames, default 9). Without the four counts (as `cargo test
//! --benches` runs it) it times one small scene once.

use std::hint::black_box;
use std::time::Instant;

/// Image side, pixels (the peers' frames are 512²).
const SIDE: usize = 512;

/// Adds `weights[k] · value` to pixel k of each of `s` rows of `s` pixels, for `voxels` boxes
/// laid 3 px apart along the sheet's rows (wrapping to the next row at the right edge, and to
/// the top at the bottom).
fn accumulate<const C: usize>(sheet: &mut [[f32; C]], s: usize, voxels: usize, weights: &[f32]) {
    let value = black_box([0.5f32; C]);
    let (mut x, mut y) = (0usize, 0usize);
    for _ in 0..voxels {
        for r in 0..s {
            let row = &mut sheet[(y + r) * SIDE + x..][..s];
            for (p, &w) in row.iter_mut().zip(&weights[..s]) {
                let mut q = *p;
                for c in 0..C {
                    q[c] += w * value[c];
                }
                *p = q;
            }
        }
        x += 3;
        if x + s >= SIDE {
            x = 0;
            y += 1;
            if y + s >= SIDE {
                y = 0;
            }
        }
    }
}

/// Front to back over the first `n` pixels (alpha last): image += (1 − image alpha) · sheet,
/// and the sheet pixel cleared.
fn composite<const C: usize>(image: &mut [[f32; C]], sheet: &mut [[f32; C]], n: usize) {
    for (d, s) in image[..n].iter_mut().zip(&mut sheet[..n]) {
        let (mut q, t) = (*d, *s);
        let k = 1.0 - q[C - 1];
        for c in 0..C {
            q[c] += k * t[c];
        }
        *d = q;
        *s = [0.0; C];
    }
}

/// The scene's counts, from `footprint render --json`.
#[derive(Clone, Copy)]
struct Scene {
    updates: u64,
    composites: u64,
    voxels: u64,
    sheets: u64,
}

/// Median accumulate and composite seconds per frame over `reps` frames, and the box side.
fn floor<const C: usize>(scene: Scene, reps: usize) -> (f64, f64, usize) {
    let mut sheet = vec![[0.0f32; C]; SIDE * SIDE];
    let mut image = vec![[0.0f32; C]; SIDE * SIDE];
    let s = ((scene.updates as f64 / scene.voxels.max(1) as f64)
        .sqrt()
        .round() as usize)
        .clamp(1, SIDE / 2);
    let weights: Vec<f32> = (0..s).map(|i| 1e-3 + i as f32 * 1e-4).collect();
    let sheets = scene.sheets.max(1) as usize;
    // Whole boxes of s² updates, split evenly over the sheets (the rest spread one a sheet).
    let boxes = (scene.updates / (s * s) as u64) as usize;
    let per_sheet = |k: usize| boxes / sheets + usize::from(k < boxes % sheets);
    let run = ((scene.composites / scene.sheets.max(1)) as usize).min(SIDE * SIDE);
    let (mut acc, mut comp) = (Vec::new(), Vec::new());
    for _ in 0..reps.max(1) {
        let (mut a, mut c) = (0.0, 0.0);
        for k in 0..sheets {
            let t = Instant::now();
            accumulate::<C>(&mut sheet, s, per_sheet(k), &weights);
            black_box(&mut sheet);
            let u = Instant::now();
            composite::<C>(&mut image, &mut sheet, run);
            black_box(&mut image);
            a += (u - t).as_secs_f64();
            c += u.elapsed().as_secs_f64();
        }
        acc.push(a);
        comp.push(c);
    }
    (median(acc), median(comp), s)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    // `cargo bench` passes --bench; anything else that is not a number is refused.
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let nums: Result<Vec<u64>, _> = args.iter().map(|a| a.parse::<u64>()).collect();
    let (scene, reps) = match nums.as_deref() {
        Ok([u, c, v, s, rest @ ..]) if rest.len() <= 1 => {
            let scene = Scene {
                updates: *u,
                composites: *c,
                voxels: *v,
                sheets: *s,
            };
            (scene, rest.first().map_or(9, |&r| r as usize))
        }
        Ok([]) => {
            let scene = Scene {
                updates: 200_000,
                composites: 100_000,
                voxels: 4_000,
                sheets: 10,
            };
            (scene, 1)
        }
        _ => {
            eprintln!("usage: floor UPDATES COMPOSITES VOXELS SHEETS [REPS]");
            std::process::exit(2);
        }
    };
    let report = |name: &str, (a, c, s): (f64, f64, usize)| {
        println!(
            "floor {name}: box {s} px, accumulate {:.3} ms ({:.3} ns/update), composite {:.3} ms \
             ({:.3} ns/pixel), floor {:.3} ms",
            a * 1e3,
            a * 1e9 / scene.updates.max(1) as f64,
            c * 1e3,
            c * 1e9 / scene.composites.max(1) as f64,
            (a + c) * 1e3
        );
    };
    report("rgba", floor::<4>(scene, reps));
    report("la", floor::<2>(scene, reps));
}
