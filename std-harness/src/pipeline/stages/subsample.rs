//! Image-space level of detail for magnified volumes (`--subsample`): render the frame at 1/s of
//! the output size and resample it to that size.
//!
//! **Why it is close.** Compositing is per pixel, so a frame rendered with the view scaled by 1/s
//! holds, at each of its pixel centres, exactly the value the full-size render has at that point
//! of the screen (up to the tables' sampling): it samples the full-size image on a grid s pixels
//! apart. What is lost is only what that grid cannot carry. Each sheet's image is a sum of
//! footprints, smooth on the scale of their width, so when footprints stay a few pixels wide at
//! the lower resolution a cubic interpolation recovers the full-size image closely; the products
//! of compositing sharpen it somewhat. Splatting costs per covered pixel, so a footprint r pixels
//! across at the output costs about (r/s)² at the lower resolution.
//!
//! **Auto.** `--subsample auto` takes the largest s ≤ [`MAX_FACTOR`] that keeps the footprint's
//! shorter semi-axis (before any widening) at least [`AUTO_MIN_RADIUS_PX`] pixels (and at least
//! `--min-radius`, so nothing is widened) at the lower resolution; only for Gaussian kernels and
//! orthographic views, where that rule was measured (docs/modes.md, "Subsampling"); elsewhere 1.
//!
//! **Geometry.** The output is W × H with pixel x's centre at x + ½ and the volume's centre at
//! (W/2, H/2) (the core's `frame` placement). The low frame is w × h = (⌈W/s⌉ + 2m) × (⌈H/s⌉ + 2m)
//! with m = [`MARGIN`] (so every cubic tap of an output pixel lies inside it), the view scaled by
//! 1/s and the volume's centre at (w/2, h/2). Output pixel x therefore sits at low-frame index
//! t = (x + ½ − W/2)/s + w/2 − ½ (low pixel i at t = i), and likewise in y.
//!
//! **Resampling.** Separable Catmull-Rom (cubic convolution, a = −½: interpolating, exact for
//! quadratics), rows first, then columns; every output pixel is computed the same way on any
//! number of threads, so the image does not depend on `--threads`. The cubic overshoots at sharp
//! edges: channels are clamped at 0 and opacity at 1. A background image is composited under the
//! resampled frame at the output size (C + (1 − A)·background, what the core's sheet loop does).

use crate::plan::{End, Plan, Supersample};
use crate::CliError;
use footprint::frame::FrameSetup;
use footprint::geometry::FootprintOptions;
use footprint::refine::catmull_rom;
use footprint::Kernel;

/// The low frame's margin, pixels on each side: Catmull-Rom reads two pixels either side.
pub const MARGIN: usize = 2;

/// Largest factor (`--subsample` takes 1 … 8).
pub const MAX_FACTOR: usize = 8;

/// `auto`'s floor on the footprint's shorter semi-axis at the lower resolution, pixels. Measured
/// (Gaussian 1.6 / 2.5, 512², view 30,20,0, against the full-size render): semi-axes of 2.1 px
/// (the walnut at s = 2) and 1.9 px (the CT head at s = 4) resample to 59.7 and 56.6 dB.
pub const AUTO_MIN_RADIUS_PX: f32 = 2.0;

/// The factor `plan` asks for with a render prepared at the output size (its `frame`, `kernel`,
/// footprint `options`, `supersample` factor and level of detail `level`, as
/// `Prepared::subsample_factor` passes them): 1 (off) unless `--subsample` gives s ≥ 2 or `auto`
/// finds one. An explicit s ≥ 2 that cannot be honoured here is refused: with a perspective view,
/// a supersampled or coarser-level frame, or when the footprints would be narrower than
/// `--min-radius` at 1/s of the size (they would be widened: a blurred image). (`--quality` and
/// `--refine` with a factor are refused by the plan, `crate::plan::plan`.)
pub fn factor(
    frame: &FrameSetup,
    kernel: &Kernel,
    options: FootprintOptions,
    supersample: usize,
    level: u32,
    plan: &Plan,
) -> Result<usize, CliError> {
    let explicit = match plan.subsample {
        Supersample::Fixed(1) => return Ok(1),
        Supersample::Fixed(s) => Some(s),
        Supersample::Auto => None,
    };
    let refuse = |why: &str| {
        CliError::input(format!(
            "--subsample {}: {why}",
            explicit.map_or("auto".to_string(), |s| s.to_string())
        ))
    };
    let refined = matches!(plan.end, End::Refined { .. });
    let blocked = if frame.camera().is_some() {
        Some(crate::plan::SUBSAMPLE_NOT_PERSPECTIVE)
    } else if refined {
        Some("--refine adds samples for magnified volumes; subsampling removes pixels: drop one")
    } else if supersample > 1 {
        Some(
            "the frame is supersampled (--supersample, or voxels projecting closer than \
             --min-radius)",
        )
    } else if level > 0 {
        Some(crate::plan::SUBSAMPLE_NOT_AT_A_LEVEL)
    } else {
        None
    };
    let min_radius = options.min_radius_px;
    let natural = frame.footprint.natural_minor_px;
    match (explicit, blocked) {
        (Some(_), Some(why)) => Err(refuse(why)),
        (None, Some(_)) => Ok(1),
        (Some(s), None) => {
            if natural / s as f32 >= min_radius {
                Ok(s)
            } else {
                Err(refuse(&format!(
                    "the footprints' shorter semi-axis is {natural:.2} px, {:.2} px at 1/{s} of \
                     the size, below --min-radius {min_radius} px (they would be widened and the \
                     image blurred); the largest factor here is {}",
                    natural / s as f32,
                    ((natural / min_radius).floor() as usize).max(1)
                )))
            }
        }
        (None, None) => {
            if !matches!(kernel, Kernel::Gaussian { .. }) {
                return Ok(1);
            }
            let floor = AUTO_MIN_RADIUS_PX.max(min_radius);
            let s = (natural / floor).floor();
            Ok(if s.is_finite() && s >= 2.0 {
                (s as usize).min(MAX_FACTOR)
            } else {
                1
            })
        }
    }
}

/// The low frame's size for an output `size` and factor `s`: ⌈n/s⌉ + 2·[`MARGIN`] per side.
pub fn low_size(size: (usize, usize), s: usize) -> (usize, usize) {
    (
        size.0.div_ceil(s) + 2 * MARGIN,
        size.1.div_ceil(s) + 2 * MARGIN,
    )
}

/// A background (`background`, the output's size) composited under the resampled `image`:
/// C + (1 − A)·background per channel, what the core's sheet loop does with a background.
pub fn under_background(image: &mut [[f32; 4]], background: &[[f32; 4]]) {
    for (c, b) in image.iter_mut().zip(background) {
        *c = footprint::composite::over(*c, *b);
    }
}

/// For each of `out` output pixels along an axis, the first of its four low-frame taps and their
/// weights (`low` low pixels along it, factor `s`; see the module docs for t).
pub fn taps(out: usize, low: usize, s: usize) -> Vec<(usize, [f32; 4])> {
    let (out_f, low_f, s_f) = (out as f64, low as f64, s as f64);
    (0..out)
        .map(|x| {
            let t = (x as f64 + 0.5 - out_f / 2.0) / s_f + low_f / 2.0 - 0.5;
            let i = t.floor();
            let frac = (t - i) as f32;
            let first = (i as isize - 1).clamp(0, low.saturating_sub(4) as isize) as usize;
            let shift = (i as isize - 1) - first as isize;
            // Weights of taps i − 1 … i + 2 (shifted onto the clamped window at the edges, which
            // the margin keeps from happening for frames made by `low_size`).
            let mut w = [0.0f32; 4];
            for (k, wk) in catmull_rom(frac).0.into_iter().enumerate() {
                let at = (k as isize + shift).clamp(0, 3) as usize;
                w[at] += wk;
            }
            (first, w)
        })
        .collect()
}

/// Output pixels worth a thread of their own in [`magnify`]. Measured on the 16-core device
/// machine (2026-12-04, `footprint bench --frames 8 --orbit 2 --threads 16`, default plan, two
/// rounds, walnut and CT head): at 512² the resampling took 0.99-1.26 ms on 16 threads and
/// 0.72-0.94 on 8; at 1024² 1.40-1.94 ms on 16 and 1.93-2.57 on 8, so 16 threads pay at 64 Ki
/// pixels each and not at 16 Ki.
pub const RESAMPLE_PIXELS: usize = 32 << 10;

/// The threads [`magnify`] is worth to an `out`-sized image given `threads`: one per
/// [`RESAMPLE_PIXELS`] output pixels at most (more start up slower than they work).
pub fn resample_threads(threads: usize, out: (usize, usize)) -> usize {
    threads
        .min(out.0.saturating_mul(out.1) / RESAMPLE_PIXELS)
        .max(1)
}

/// The `low` image (w × h, premultiplied RGBA) resampled to `out` with factor `s` on `threads`
/// threads (the same values for any number): rows first, then columns; channels clamped at 0,
/// opacity at 1 and each colour at its opacity (a valid premultiplied colour, as the renderer's
/// frames are).
pub fn magnify(
    image: &[[f32; 4]],
    low: (usize, usize),
    out: (usize, usize),
    s: usize,
    threads: usize,
) -> Result<Vec<[f32; 4]>, CliError> {
    let (lw, lh) = low;
    let (w, h) = out;
    assert!(
        lw >= 4 && lh >= 4 && image.len() == lw * lh,
        "a low frame of at least 4x4"
    );
    let xs = taps(w, lw, s);
    let ys = taps(h, lh, s);
    let threads = threads.max(1);
    // Where a low row is zero (transparent, most of a frame around a volume), its resampled row
    // is zero too: every tap reads zeros, a sum of zero products with at least one non-negative
    // weight is +0, and the clamps keep it, the value the output is filled with. So each low
    // row's non-zero columns are found once, and only output columns whose taps reach them are
    // computed, with the same arithmetic: the same bits.
    let spans: Vec<Option<(usize, usize)>> = image
        .chunks_exact(lw)
        .map(|row| {
            let nz = |p: &[f32; 4]| p.iter().any(|c| c.to_bits() != 0);
            let lo = row.iter().position(nz)?;
            let hi = row.iter().rposition(nz)?;
            Some((lo, hi))
        })
        .collect();
    // Output columns whose four taps reach low columns lo..=hi (the taps' first columns never
    // decrease along the row).
    let reach = |(lo, hi): (usize, usize)| {
        let a = xs.partition_point(|(first, _)| first + 3 < lo);
        let b = xs.partition_point(|(first, _)| *first <= hi);
        (a, b)
    };
    // Each thread makes its band of output rows from the low rows they need, each low row
    // resampled to the output width once per thread into a ring of four (output rows need taps
    // first..first + 4, and first never decreases down the image): no frame-sized intermediate.
    // `row` is zero outside columns `held` (what it held before); returns the columns written,
    // zeros elsewhere (none for a zero row).
    let resample_row = |y: usize, row: &mut [[f32; 4]], held: (usize, usize)| -> (usize, usize) {
        row[held.0..held.1].fill([0.0; 4]);
        let Some(span) = spans[y] else {
            return (0, 0);
        };
        let (a, b) = reach(span);
        if a >= b {
            return (0, 0);
        }
        let src = &image[y * lw..][..lw];
        for (o, (first, wt)) in row[a..b].iter_mut().zip(&xs[a..b]) {
            let t = &src[*first..*first + 4];
            for ch in 0..4 {
                o[ch] = wt[0] * t[0][ch] + wt[1] * t[1][ch] + wt[2] * t[2][ch] + wt[3] * t[3][ch];
            }
        }
        (a, b)
    };
    // Every output pixel is written once by the thread of its band (zeros included), so the
    // image is not filled first: a frame-sized serial pass (4 MiB at 512², 16 MiB at 1024², its
    // pages first touched on one core) was most of this stage on 16 threads.
    let mut out_img: Vec<[f32; 4]> =
        crate::io::try_vec(w * h, "the resampled image").map_err(CliError::input)?;
    let per = h.div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        for (c, chunk) in out_img.spare_capacity_mut()[..w * h]
            .chunks_mut(per * w)
            .enumerate()
        {
            let (ys, resample_row) = (&ys, &resample_row);
            crate::threads::spawn(scope, move || {
                // Slot k % 4 holds low row k once `held[k % 4] == Some(k)`, its non-zero
                // output columns in `cols[k % 4]` (zeros outside them).
                let mut ring = vec![[0.0f32; 4]; 4 * w];
                let mut held = [None::<usize>; 4];
                let mut cols = [(0usize, 0usize); 4];
                for (r, row) in chunk.chunks_exact_mut(w).enumerate() {
                    let (first, wt) = ys[c * per + r];
                    for k in first..first + 4 {
                        if held[k % 4] != Some(k) {
                            let slot = &mut ring[(k % 4) * w..][..w];
                            cols[k % 4] = resample_row(k, slot, cols[k % 4]);
                            held[k % 4] = Some(k);
                        }
                    }
                    // The union of the four rows' columns; the output row is zero outside.
                    let (a, b) = cols
                        .iter()
                        .filter(|(a, b)| a < b)
                        .fold((w, 0), |(a, b), &(x, y)| (a.min(x), b.max(y)));
                    let (a, b) = if a < b { (a, b) } else { (0, 0) };
                    let src = |k: usize| &ring[((first + k) % 4) * w..][..w];
                    write_row(row, (a, b), [src(0), src(1), src(2), src(3)], wt);
                }
            });
        }
    });
    // SAFETY: the chunks above tile the first w·h slots of the capacity (`chunks_mut` of the
    // `w * h` slice; h·w is a multiple of w, so each chunk is whole rows), and every row of every
    // chunk had each of its w slots written: [0, a) and [b, w) with zeros, [a, b) with a value.
    // A panic in a thread is carried on by the scope before this line.
    unsafe { out_img.set_len(w * h) };
    Ok(out_img)
}

/// Writes every pixel of output `row`: zeros outside columns a..b, and inside them the four
/// resampled low rows `src` weighted by `wt`, clamped to a valid premultiplied colour (channels
/// at 0, opacity at 1, each colour at its opacity).
fn write_row(
    row: &mut [std::mem::MaybeUninit<[f32; 4]>],
    (a, b): (usize, usize),
    src: [&[[f32; 4]]; 4],
    wt: [f32; 4],
) {
    let (head, rest) = row.split_at_mut(a);
    for o in head.iter_mut().chain(rest[b - a..].iter_mut()) {
        o.write([0.0; 4]);
    }
    let [r0, r1, r2, r3] = src;
    for (x, o) in row.iter_mut().enumerate().take(b).skip(a) {
        let mut px = [0.0f32; 4];
        for ch in 0..4 {
            let v = wt[0] * r0[x][ch] + wt[1] * r1[x][ch] + wt[2] * r2[x][ch] + wt[3] * r3[x][ch];
            px[ch] = if v > 0.0 { v } else { 0.0 };
        }
        if px[3] > 1.0 {
            px[3] = 1.0;
        }
        // Premultiplied: the cubic's overshoot at an edge must not leave a colour above its
        // opacity (the renderer's sheets never do).
        for ch in 0..3 {
            if px[ch] > px[3] {
                px[ch] = px[3];
            }
        }
        o.write(px);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cubic reproduces a quadratic exactly, so resampling samples of q at the low frame's
    /// pixel centres gives q at every output pixel centre (brute force over sizes and factors).
    #[test]
    fn magnify_reproduces_quadratics() {
        for (out, s) in [((37, 23), 2), ((64, 64), 3), ((101, 7), 4), ((5, 9), 8)] {
            let low = low_size(out, s);
            // Screen position (output pixels) of low pixel (i, j)'s centre.
            let screen = |i: usize, n_low: usize, n_out: usize| {
                (i as f64 + 0.5 - n_low as f64 / 2.0) * s as f64 + n_out as f64 / 2.0
            };
            let q = |x: f64, y: f64| 0.2 + 0.003 * x - 0.002 * y + 1e-4 * x * y + 5e-5 * x * x;
            let image: Vec<[f32; 4]> = (0..low.0 * low.1)
                .map(|n| {
                    let (x, y) = (
                        screen(n % low.0, low.0, out.0),
                        screen(n / low.0, low.1, out.1),
                    );
                    // Colours below their opacity (q stays under 1.2 here), so the clamps to
                    // it do not act.
                    let v = q(x, y) as f32;
                    [0.5 * v, 0.25 * v, 0.125 * v, 1.0]
                })
                .collect();
            for threads in [1, 3] {
                let up = magnify(&image, low, out, s, threads).unwrap();
                for (n, p) in up.iter().enumerate() {
                    let (x, y) = ((n % out.0) as f64 + 0.5, (n / out.0) as f64 + 0.5);
                    let want = 0.5 * q(x, y);
                    assert!(
                        (f64::from(p[0]) - want).abs() < 2e-5 * want.abs().max(1.0),
                        "out {out:?} s {s} pixel ({x}, {y}): {} against {want}",
                        p[0]
                    );
                    assert!((p[1] - 0.5 * p[0]).abs() < 1e-6, "channels resampled alike");
                }
            }
        }
    }

    /// Skipping the transparent parts changes no bit: on frames of zero rows, zero runs at
    /// either end of a row, isolated non-zero pixels (one of them −0) and rows full of colour,
    /// `magnify` gives exactly what every output pixel's taps give when all are computed (the
    /// same sums in the same order), for 1, 2 and 5 threads.
    #[test]
    fn skipping_zero_runs_changes_no_bit() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for (out, s) in [((64, 48), 2), ((97, 61), 3), ((40, 40), 5)] {
            let (lw, lh) = low_size(out, s);
            let mut image = vec![[0.0f32; 4]; lw * lh];
            for y in 0..lh {
                let kind = next() % 5;
                let row = &mut image[y * lw..][..lw];
                let (lo, hi) = ((next() as usize) % lw, (next() as usize) % lw);
                let (lo, hi) = (lo.min(hi), lo.max(hi));
                for (x, p) in row.iter_mut().enumerate() {
                    let a = (next() % 1000) as f32 / 1000.0;
                    let on = match kind {
                        0 => false,
                        1 => (lo..=hi).contains(&x),
                        2 => x == lo,
                        _ => true,
                    };
                    if on {
                        *p = [0.3 * a, 0.6 * a, 0.9 * a, a];
                    }
                }
                if kind == 2 && y % 2 == 0 {
                    row[hi] = [-0.0, 0.0, 0.0, 0.0];
                }
            }
            let (w, h) = out;
            let (xs, ys) = (taps(w, lw, s), taps(h, lh, s));
            let rows: Vec<Vec<[f32; 4]>> = (0..lh)
                .map(|y| {
                    let src = &image[y * lw..][..lw];
                    xs.iter()
                        .map(|(first, wt)| {
                            let t = &src[*first..*first + 4];
                            core::array::from_fn(|ch| {
                                wt[0] * t[0][ch]
                                    + wt[1] * t[1][ch]
                                    + wt[2] * t[2][ch]
                                    + wt[3] * t[3][ch]
                            })
                        })
                        .collect()
                })
                .collect();
            let mut want = vec![[0.0f32; 4]; w * h];
            for (y, (first, wt)) in ys.iter().enumerate() {
                for x in 0..w {
                    let o = &mut want[y * w + x];
                    for ch in 0..4 {
                        let v = wt[0] * rows[*first][x][ch]
                            + wt[1] * rows[first + 1][x][ch]
                            + wt[2] * rows[first + 2][x][ch]
                            + wt[3] * rows[first + 3][x][ch];
                        o[ch] = if v > 0.0 { v } else { 0.0 };
                    }
                    o[3] = o[3].min(1.0);
                    for ch in 0..3 {
                        o[ch] = o[ch].min(o[3]);
                    }
                }
            }
            let bits = |im: &[[f32; 4]]| -> Vec<[u32; 4]> {
                im.iter().map(|p| p.map(f32::to_bits)).collect()
            };
            for threads in [1, 2, 5] {
                let got = magnify(&image, (lw, lh), out, s, threads).unwrap();
                assert!(
                    bits(&got) == bits(&want),
                    "out {out:?} s {s} threads {threads}"
                );
            }
            // Not vacuous: some output rows are all zero and some are not.
            assert!(want.chunks(w).any(|r| r.iter().all(|p| *p == [0.0; 4])));
            assert!(want.iter().any(|p| p[3] > 0.0));
        }
    }

    /// At a sharp colour edge under even opacity the cubic overshoots (above the brighter side's
    /// colour, which equals the opacity); the result stays a valid premultiplied colour.
    #[test]
    fn overshoot_leaves_colour_at_most_opacity() {
        let (out, s) = ((40, 8), 4);
        let low = low_size(out, s);
        let image: Vec<[f32; 4]> = (0..low.0 * low.1)
            .map(|n| {
                let c = if n % low.0 < low.0 / 2 { 0.0 } else { 0.5 };
                [c, c, c, 0.5]
            })
            .collect();
        // Not vacuous: the cubic along a row, before any clamp, rises above 0.5 somewhere.
        let row: Vec<f32> = taps(out.0, low.0, s)
            .iter()
            .map(|(first, w)| (0..4).map(|k| w[k] * image[first + k][0]).sum())
            .collect();
        assert!(row.iter().any(|&c| c > 0.5 + 1e-3), "{row:?}");
        for p in magnify(&image, low, out, s, 1).unwrap() {
            assert!((p[3] - 0.5).abs() < 1e-6, "even opacity stays even: {p:?}");
            assert!(p[..3].iter().all(|&c| (0.0..=p[3]).contains(&c)), "{p:?}");
        }
    }

    /// Weights sum to one and the taps stay inside frames made by `low_size`.
    #[test]
    fn taps_are_inside_and_sum_to_one() {
        for n in 1..200usize {
            for s in 2..=MAX_FACTOR {
                let low = n.div_ceil(s) + 2 * MARGIN;
                for (x, (first, w)) in taps(n, low, s).into_iter().enumerate() {
                    assert!(first + 4 <= low, "n {n} s {s} x {x}");
                    let t = (x as f64 + 0.5 - n as f64 / 2.0) / s as f64 + low as f64 / 2.0 - 0.5;
                    assert_eq!(
                        first as f64,
                        t.floor() - 1.0,
                        "n {n} s {s} x {x}: no clamping"
                    );
                    let sum: f32 = w.iter().sum();
                    assert!((sum - 1.0).abs() < 1e-6, "n {n} s {s} x {x}: {sum}");
                }
            }
        }
    }
}
