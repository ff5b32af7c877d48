//! The pilot's sample of the image ([`super::pilot`]): which pixels it measures (one per cell,
//! stratified, stage by stage), its estimate of a candidate's error there, and the
//! verdict that estimate gives against a target. No rendering and no reference here: a leaf
//! beside [`super::sampling`], tested on its own.

use super::sampling::{mix, Estimate};

/// Rays the pilot aims at: the image is sampled once per cell of about W·H / `PILOT_RAYS`
/// pixels.
pub const PILOT_RAYS: usize = 4096;
/// The fewest pixels an early stage measures on ([`super::pilot`], "Stages"); a smaller one is
/// not a stage.
pub const MIN_FIRST_STAGE: usize = 256;
/// Standard errors added to the sampled MSE before it is compared with the target.
pub const Z: f64 = 3.0;
/// How far past the target a candidate's bound must lie for an early stage alone to take it,
/// dB: on the sixteenth, then on the quarter ([`super::pilot`], "Stages" and "Why margins").
/// A part of the sample can miss the few pixels that carry most of the squared error, and
/// understate its spread with them; the smaller the part, the more it can miss.
pub const STAGE_MARGINS_DB: [f64; 2] = [5.0, 1.0];

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

/// Where a stage ends in the reordered sample, and the margin it takes a candidate at, dB
/// (`None` for the whole sample).
pub type StageEnd = (usize, Option<f64>);

/// `pixels` (one per `stride`-sided cell, row by row) reordered stage by stage, and where each
/// stage ends with the margin it takes a candidate at ([`STAGE_MARGINS_DB`]), as [`decide`]
/// reads it. First the pixels of the cells whose column and row are both multiples of 4 (a
/// stratified sample of its own at four times the cell side, about a sixteenth), then those of
/// the other cells whose column and row are both even (with the first, the same at twice the
/// side, about a quarter), then the rest (margin `None`: the last stage is the whole sample).
/// An early stage under [`MIN_FIRST_STAGE`] pixels, or one that is already the whole sample, is
/// not a stage.
pub fn stages(pixels: Vec<[usize; 2]>, stride: usize) -> (Vec<[usize; 2]>, Vec<StageEnd>) {
    let level = |&[x, y]: &[usize; 2]| {
        let (cx, cy) = (x / stride, y / stride);
        if cx.is_multiple_of(4) && cy.is_multiple_of(4) {
            0
        } else if cx.is_multiple_of(2) && cy.is_multiple_of(2) {
            1
        } else {
            2
        }
    };
    let mut ordered = Vec::with_capacity(pixels.len());
    let mut ends = Vec::new();
    for (l, margin) in STAGE_MARGINS_DB.into_iter().enumerate() {
        ordered.extend(pixels.iter().filter(|p| level(p) == l));
        if ordered.len() >= MIN_FIRST_STAGE && ordered.len() < pixels.len() {
            ends.push((ordered.len(), Some(margin)));
        }
    }
    ordered.extend(pixels.iter().filter(|p| level(p) == STAGE_MARGINS_DB.len()));
    ends.push((ordered.len(), None));
    (ordered, ends)
}

/// What one estimate says of a candidate against `target_db` (dB).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Its bound reaches the target (on an early stage, that stage's margin past it).
    Taken,
    /// Even its lower bound falls short (or its error is NaN): more pixels would not help.
    Rejected,
    /// Neither: on an early stage, to be measured on the next.
    Undecided,
}

/// The verdict on `e` against `target_db`: on an early stage (`margin`, dB, from
/// [`STAGE_MARGINS_DB`]) or on the whole sample (`None`), where it is never undecided
/// ([`super::pilot`], "Stages" and "Why margins").
pub fn decide(e: &Estimate, target_db: f64, margin: Option<f64>) -> Verdict {
    if e.bound_db >= target_db + margin.unwrap_or(0.0) {
        Verdict::Taken
    } else if margin.is_some() && e.hope_db >= target_db {
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
    fn each_stage_is_a_coarser_stratified_sample_and_nothing_is_lost() {
        for (w, h) in [(512, 512), (800, 600), (1024, 300), (256, 256)] {
            let (px, s) = sample_pixels(w, h, PILOT_RAYS);
            let (ordered, ends) = stages(px.clone(), s);
            let mut a = px.clone();
            let mut b = ordered.clone();
            a.sort_unstable();
            b.sort_unstable();
            assert_eq!(a, b, "{w}x{h}: the same pixels");
            // A sixteenth, a quarter and the whole, at the margins in that order.
            let margins: Vec<Option<f64>> = ends.iter().map(|e| e.1).collect();
            assert_eq!(margins, [Some(5.0), Some(1.0), None], "{w}x{h}");
            assert_eq!(ends[2].0, px.len());
            // Stage k (its pixels and all before) is one pixel per cell of side 4S, then 2S,
            // every such cell represented.
            for (k, side) in [(0, 4 * s), (1, 2 * s)] {
                let end = ends[k].0;
                assert_eq!(
                    end,
                    w.div_ceil(side) * h.div_ceil(side),
                    "{w}x{h} stage {k}"
                );
                let mut seen = std::collections::HashSet::new();
                for &[x, y] in &ordered[..end] {
                    assert!(seen.insert((x / side, y / side)), "two in one cell");
                    assert!((x / s) % (side / s) == 0 && (y / s) % (side / s) == 0);
                }
            }
            assert!(ordered[ends[1].0..]
                .iter()
                .all(|&[x, y]| (x / s) % 2 == 1 || (y / s) % 2 == 1));
        }
        // A sixteenth under MIN_FIRST_STAGE is not a stage; the quarter is: 32x32 cells, and
        // 640x480 (72x54 cells of 9 pixels: a sixteenth of 18x14 = 252, a quarter of 36x27).
        let (px, s) = sample_pixels(32, 32, PILOT_RAYS);
        let n = px.len();
        assert_eq!(stages(px, s).1, [(256, Some(1.0)), (n, None)]);
        let (px, s) = sample_pixels(640, 480, PILOT_RAYS);
        let n = px.len();
        assert_eq!(stages(px, s).1, [(36 * 27, Some(1.0)), (n, None)]);
        // Too few for any early stage: one.
        let (px, s) = sample_pixels(20, 20, PILOT_RAYS);
        let n = px.len();
        assert_eq!(stages(px, s).1, [(n, None)]);
        // A one-pixel sample: one stage, not an early stage that is already the whole.
        assert_eq!(stages(vec![[0, 0]], 1).1, [(1, None)]);
    }

    #[test]
    fn an_early_stage_takes_a_candidate_only_its_margin_past_the_target() {
        let e = |bound_db, hope_db| Estimate {
            estimate_db: 0.5 * (bound_db + hope_db),
            bound_db,
            hope_db,
        };
        let [sixteenth, quarter] = STAGE_MARGINS_DB;
        assert!(sixteenth > quarter && quarter > 0.0, "{STAGE_MARGINS_DB:?}");
        // Between the quarter's margin and the sixteenth's: the sixteenth waits, the quarter
        // and the whole sample take it.
        let between = e(44.0 + 0.5 * (sixteenth + quarter), 60.0);
        assert_eq!(decide(&between, 44.0, Some(sixteenth)), Verdict::Undecided);
        assert_eq!(decide(&between, 44.0, Some(quarter)), Verdict::Taken);
        assert_eq!(decide(&between, 44.0, None), Verdict::Taken);
        let near = e(44.0 + 0.5 * quarter, 50.0);
        assert_eq!(decide(&near, 44.0, Some(quarter)), Verdict::Undecided);
        assert_eq!(decide(&near, 44.0, None), Verdict::Taken);
        let far = e(44.0 + sixteenth, 60.0);
        assert_eq!(decide(&far, 44.0, Some(sixteenth)), Verdict::Taken);
        // Rejection needs no margin: a lower bound short of the target.
        let short = e(40.0, 43.9);
        assert_eq!(decide(&short, 44.0, Some(sixteenth)), Verdict::Rejected);
        let unsure = e(40.0, 44.0);
        assert_eq!(decide(&unsure, 44.0, Some(sixteenth)), Verdict::Undecided);
        assert_eq!(decide(&unsure, 44.0, None), Verdict::Rejected);
        let nan = e(f64::NAN, f64::NAN);
        assert_eq!(decide(&nan, 44.0, Some(sixteenth)), Verdict::Rejected);
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
