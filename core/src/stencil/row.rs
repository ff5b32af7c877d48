//! One row of a blended splat outside the small-box path ([`super::Stencils::splat`]'s general
//! loop): the weights of eight pixels at a time with a fixed trip count, then the rest.
//!
//! Measured against a loop over single pixels (`footprint bench --frames 8 --orbit 2 --threads
//! 1`, headsq at view 30,20,0, builds alternated, 3 rounds, re-render medians): 580² (runs of
//! about 18 px) 56.2 → 48.5 ms, 640² 68.7 → 57.3 ms, 1024² 154.5 → 119.0 ms; the same bits.

use crate::splat::Pixel;

/// Pixels blended together.
const BLOCK: usize = 8;

/// Adds `value` × w to each pixel of `px`, w = Σ blend[i] · rows[i][k] (the blend of the four
/// corner stencils' row entries, in that order, as [`super::Stencils::splat`] sums them); every
/// row holds at least `px.len()` entries. Returns how many weights were non-zero. `NEAREST`: w =
/// rows[0][k] itself (the nearest phase's stencil, [`super::PhaseLookup::Nearest`]; the other
/// rows and weights are not read).
#[inline(always)]
pub(super) fn blend_row<const NEAREST: bool, P: Pixel>(
    [w00, w10, w01, w11]: [f32; 4],
    (r00, r10, r01, r11): (&[f32], &[f32], &[f32], &[f32]),
    value: &P,
    px: &mut [P],
) -> u32 {
    let n = px.len();
    let (r00, r10, r01, r11) = (&r00[..n], &r10[..n], &r01[..n], &r11[..n]);
    let mut updated = 0;
    let (blocks, rest) = px.as_chunks_mut::<BLOCK>();
    let block = |r: &[f32], k: usize| -> [f32; BLOCK] {
        r[k..k + BLOCK].try_into().unwrap_or([0.0; BLOCK])
    };
    for (j, ds) in blocks.iter_mut().enumerate() {
        let k = j * BLOCK;
        let (a, b, c, e) = (block(r00, k), block(r10, k), block(r01, k), block(r11, k));
        let mut wt = [0.0f32; BLOCK];
        for (i, o) in wt.iter_mut().enumerate() {
            *o = if NEAREST {
                a[i]
            } else {
                w00 * a[i] + w10 * b[i] + w01 * c[i] + w11 * e[i]
            };
        }
        for (d, &w) in ds.iter_mut().zip(&wt) {
            d.add_weighted(value, w);
            updated += u32::from(w != 0.0);
        }
    }
    let k0 = n - rest.len();
    for (k, d) in (k0..).zip(rest.iter_mut()) {
        let wt = if NEAREST {
            r00[k]
        } else {
            w00 * r00[k] + w10 * r10[k] + w01 * r01[k] + w11 * r11[k]
        };
        d.add_weighted(value, wt);
        updated += u32::from(wt != 0.0);
    }
    updated
}
