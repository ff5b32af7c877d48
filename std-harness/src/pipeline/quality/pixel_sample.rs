//! The pilot's sample of the image ([`super::pilot`]): which pixels it measures (one per cell,
//! stratified, the first stage's first), its estimate of a candidate's error there, and the
//! verdict that estimate gives against a target. No rendering and no reference here: a leaf
//! beside [`super::sampling`], tested on its own.

use super::sampling::{mix, Estimate};

/// Rays the pilot aims at: the image is sampled once per cell of about W·H / `PILOT_RAYS`
/// pixels.
pub const PILOT_RAYS: usize = 4096;
/// The fewest pixels a first stage measures on ([`super::pilot`], "Two stages"); below, one stage.
pub const MIN_FIRST_STAGE: usize = 256;
/// Standard errors added to the sampled MSE before it is compared with the target.
pub const Z: f64 = 3.0;
/// How far past the target a candidate's bound must lie for the first stage alone to take it,
/// dB ([`super::pilot`], "Two stages"): a quarter of the sample can miss the few pixels that
/// carry most of the squared error, and understate its spread with them.
pub const FIRST_STAGE_MARGIN_DB: f64 = 1.0;

/// The stratified sample of a `w`×`h` image for about `rays` pixels: one pixel per S×S cell
/// (S = ⌈√(w·h / rays)⌉, at least 1), at a position inside the cell fixed by a hash of the
/// cell, row by row; and S.
pub fn sample_pixels(w: usize, h: usize, rays: usize) -> (Vec<[usize; 2]>, usize) {
    let area = (w * h) as f64 / rays.max(1) as f64;
    let stride = (area.sqrt().ceil() as usize).max(1);
    let mut out = Vec::new();
    for cy in 0..h.div_ceil(stride) {
        for cx in 0..w.div_ceil(stride) {
            let (x0, y0) = (cx * stride, cy * stride);
            let (cw, ch) = (stride.min(w - x0), stride.min(h - y0));
            let r = mix(((cy as u64) << 32) | cx as u64);
            out.push([
                x0 + (r % cw as u64) as usize,
                y0 + ((r >> 32) % ch as u64) as usize,
            ]);
        }
    }
    (out, stride)
}

/// `image` (`w` wide, premultiplied RGBA) against `reference` at `pixels` (the reference's
/// values in that order), for an image of `total` pixels.
pub fn estimate(
    image: &[[f32; 4]],
    w: usize,
    pixels: &[[usize; 2]],
    reference: &[[f64; 4]],
    total: usize,
) -> Estimate {
    let errors: Vec<f64> = pixels
        .iter()
        .zip(reference)
        .map(|(&[x, y], r)| {
            let c = image[y * w + x];
            (0..3)
                .map(|ch| (f64::from(c[ch]) - r[ch]).powi(2))
                .sum::<f64>()
                / 3.0
        })
        .collect();
    Estimate::of(&errors, total, Z)
}

/// `pixels` (one per `stride`-sided cell, row by row) reordered so that the first stage comes
/// first: the pixels of the cells whose column and row are both even, a stratified sample of
/// its own at twice the cell side (about a quarter); and how many those are. A sample too
/// small to split (a first stage under [`MIN_FIRST_STAGE`]) is one stage.
pub fn first_stage(pixels: Vec<[usize; 2]>, stride: usize) -> (Vec<[usize; 2]>, usize) {
    let even =
        |&[x, y]: &[usize; 2]| (x / stride).is_multiple_of(2) && (y / stride).is_multiple_of(2);
    let (mut first, rest): (Vec<_>, Vec<_>) = pixels.into_iter().partition(even);
    let n = first.len();
    first.extend(rest);
    let stage = if n < MIN_FIRST_STAGE { first.len() } else { n };
    (first, stage)
}

/// What one estimate says of a candidate against `target_db` (dB).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Its bound reaches the target (on the first stage, [`FIRST_STAGE_MARGIN_DB`] past it).
    Taken,
    /// Even its lower bound falls short (or its error is NaN): more pixels would not help.
    Rejected,
    /// Neither: on the first stage, to be measured on every sampled pixel.
    Undecided,
}

/// The verdict on `e` against `target_db`, on the first stage or on the whole sample
/// ([`super::pilot`], "Two stages" and "Why a margin"). On the whole sample a candidate not
/// taken is rejected.
pub fn decide(e: &Estimate, target_db: f64, first_stage: bool) -> Verdict {
    let margin = if first_stage {
        FIRST_STAGE_MARGIN_DB
    } else {
        0.0
    };
    if e.bound_db >= target_db + margin {
        Verdict::Taken
    } else if first_stage && e.hope_db >= target_db {
        Verdict::Undecided
    } else {
        Verdict::Rejected
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sample_has_one_pixel_per_cell_inside_the_image() {
        for (w, h) in [(256, 256), (257, 100), (1, 1), (10, 3), (640, 480)] {
            let (px, s) = sample_pixels(w, h, PILOT_RAYS);
            assert_eq!(px.len(), w.div_ceil(s) * h.div_ceil(s));
            assert!(px.len() <= PILOT_RAYS.max(w * h) + w + h);
            let mut seen = std::collections::HashSet::new();
            for &[x, y] in &px {
                assert!(x < w && y < h);
                assert!(seen.insert((x / s, y / s)), "two pixels in one cell");
            }
        }
        // Small images are sampled whole.
        let (px, s) = sample_pixels(64, 64, PILOT_RAYS);
        assert_eq!((px.len(), s), (4096, 1));
    }

    #[test]
    fn the_first_stage_is_a_coarser_stratified_sample_and_nothing_is_lost() {
        for (w, h) in [(512, 512), (640, 480), (257, 100)] {
            let (px, s) = sample_pixels(w, h, PILOT_RAYS);
            let (ordered, first) = first_stage(px.clone(), s);
            let mut a = px.clone();
            let mut b = ordered.clone();
            a.sort_unstable();
            b.sort_unstable();
            assert_eq!(a, b, "{w}x{h}: the same pixels");
            // One per cell of side 2S, every such cell represented.
            let cells = w.div_ceil(2 * s) * h.div_ceil(2 * s);
            assert_eq!(first, cells, "{w}x{h}");
            let mut seen = std::collections::HashSet::new();
            for &[x, y] in &ordered[..first] {
                assert!(seen.insert((x / (2 * s), y / (2 * s))), "two in one cell");
            }
            assert!(ordered[first..]
                .iter()
                .all(|&[x, y]| (x / s) % 2 == 1 || (y / s) % 2 == 1));
        }
        // Too few for two stages: one.
        let (px, s) = sample_pixels(20, 20, PILOT_RAYS);
        let n = px.len();
        assert_eq!(first_stage(px, s).1, n);
    }

    #[test]
    fn the_first_stage_takes_a_candidate_only_a_margin_past_the_target() {
        let e = |bound_db, hope_db| Estimate {
            estimate_db: 0.5 * (bound_db + hope_db),
            bound_db,
            hope_db,
        };
        let near = e(44.0 + 0.5 * FIRST_STAGE_MARGIN_DB, 50.0);
        assert_eq!(decide(&near, 44.0, true), Verdict::Undecided);
        assert_eq!(decide(&near, 44.0, false), Verdict::Taken);
        let far = e(44.0 + FIRST_STAGE_MARGIN_DB, 50.0);
        assert_eq!(decide(&far, 44.0, true), Verdict::Taken);
        let short = e(40.0, 43.9);
        assert_eq!(decide(&short, 44.0, true), Verdict::Rejected);
        let unsure = e(40.0, 44.0);
        assert_eq!(decide(&unsure, 44.0, true), Verdict::Undecided);
        assert_eq!(decide(&unsure, 44.0, false), Verdict::Rejected);
        let nan = e(f64::NAN, f64::NAN);
        assert_eq!(decide(&nan, 44.0, true), Verdict::Rejected);
    }

    #[test]
    fn the_estimate_is_exact_on_a_whole_image_and_bounded_on_a_sample() {
        // A 4x1 image against a reference: errors 0, 0.1, 0, 0.3 in every RGB channel.
        let image = [
            [0.0f32; 4],
            [0.1, 0.1, 0.1, 0.0],
            [0.0; 4],
            [0.3, 0.3, 0.3, 0.0],
        ];
        let reference = [[0.0f64; 4]; 4];
        let all = [[0, 0], [1, 0], [2, 0], [3, 0]];
        let mse = (0.1f64 * 0.1 + 0.3 * 0.3) / 4.0;
        let e = estimate(&image, 4, &all, &reference, 4);
        let exact = -10.0 * mse.log10();
        assert!((e.estimate_db - exact).abs() < 1e-4, "{e:?}");
        assert_eq!(
            e.estimate_db, e.bound_db,
            "every pixel sampled: no sampling error"
        );
        // Two of them sampled from a larger image: the bound lies below the estimate, the
        // lower bound (the most the image may be) above it.
        let e = estimate(&image, 4, &all[2..], &reference[2..], 400);
        assert!(e.bound_db < e.estimate_db, "{e:?}");
        assert!(e.estimate_db < e.hope_db, "{e:?}");
        // A NaN pixel never reaches a target.
        let bad = [[f32::NAN; 4]];
        let e = estimate(&bad, 1, &all[..1], &reference[..1], 1);
        assert!(!(e.bound_db >= 0.0));
        let e = estimate(&bad, 1, &all[..1], &reference[..1], 10);
        assert!(e.hope_db.is_nan(), "a NaN error hopes for nothing: {e:?}");
    }
}
