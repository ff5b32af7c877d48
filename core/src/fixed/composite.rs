//! Integer Porter–Duff compositing of Q24 premultiplied RGBA (see [`crate::fixed`] for the
//! formats and the rounding). No floating point here (denied below and audited in CI).
#![deny(clippy::float_arithmetic, clippy::disallowed_types)]

use super::{is_grey, FRAC, ONE};
use crate::frame::Order;

/// An accumulated sheet pixel (Q(24 + `frac`) per channel) rounded to Q24, alpha clamped to
/// [0, [`ONE`]] and each colour channel to [0, alpha]: the fixed-point twin of
/// [`crate::composite::clamp_unit`].
#[inline]
pub fn resolve(acc: [i64; 4], frac: u32) -> [u32; 4] {
    let round = |a: i64| {
        if frac == 0 {
            a
        } else {
            a.saturating_add(1 << (frac - 1)) >> frac
        }
    };
    let alpha = round(acc[3]).clamp(0, i64::from(ONE));
    [
        round(acc[0]).clamp(0, alpha) as u32,
        round(acc[1]).clamp(0, alpha) as u32,
        round(acc[2]).clamp(0, alpha) as u32,
        alpha as u32,
    ]
}

/// `front` over `back`: front + (1 − α_front) · back, each product rounded to nearest (ties up),
/// channels saturating at `u32::MAX`. With α_front = 0 the back is kept exactly.
#[inline]
pub fn over(front: [u32; 4], back: [u32; 4]) -> [u32; 4] {
    let k = u64::from(ONE.saturating_sub(front[3]));
    let mut out = [0u32; 4];
    for ((o, &f), &b) in out.iter_mut().zip(&front).zip(&back) {
        let scaled = (k * u64::from(b) + (1 << (FRAC - 1))) >> FRAC;
        *o = f.saturating_add(u32::try_from(scaled).unwrap_or(u32::MAX));
    }
    out
}

/// Composites one row of an accumulated sheet into the working image and clears the accumulator:
/// *over* the image back to front, *under* it front to back.
///
/// Written without branches per pixel (the order and the fraction bits are settled per row, the
/// rounding and saturation are arithmetic; see `resolve_fast` and `over_fast`), so the loop
/// vectorises: the same bits as [`resolve`] and [`over`] (a unit test checks them against each
/// other).
#[inline(never)]
pub fn composite_row(acc: &mut [[i64; 4]], image: &mut [[u32; 4]], frac: u32, order: Order) {
    if frac == 0 || frac > FAST_FRAC_MAX {
        for (a, px) in acc.iter_mut().zip(image.iter_mut()) {
            let s = resolve(*a, frac);
            *a = [0; 4];
            *px = match order {
                Order::BackToFront => over(s, *px),
                Order::FrontToBack => over(*px, s),
            };
        }
        return;
    }
    // Groups of pixels whose accumulators are all zero are skipped: a zero sheet pixel resolves
    // to zero, and compositing zero over or under a pixel leaves it exactly as it is (see
    // `over`), so the bits are the same; sparse sheets have long runs of them.
    let mut a_groups = acc.chunks_mut(GROUP);
    let mut i_groups = image.chunks_mut(GROUP);
    while let (Some(a), Some(img)) = (a_groups.next(), i_groups.next()) {
        if a.iter().all(|p| (p[0] | p[1] | p[2] | p[3]) == 0) {
            continue;
        }
        // A group whose sheet and image pixels are all grey (R = G = B, as everywhere under a
        // grey transfer function over a grey background) is composited with each colour
        // computed once: the same bits.
        if a.iter().all(is_grey) && img.iter().all(is_grey) {
            composite_group::<true>(a, img, frac, order);
        } else {
            composite_group::<false>(a, img, frac, order);
        }
    }
}

/// [`composite_row`]'s work on one group of pixels, 1 ≤ `frac` ≤ [`FAST_FRAC_MAX`]. With `GREY`
/// (every pixel of both grey) each pixel is composited from its red and alpha channels.
#[inline(always)]
fn composite_group<const GREY: bool>(
    acc: &mut [[i64; 4]],
    image: &mut [[u32; 4]],
    frac: u32,
    order: Order,
) {
    // Grey: the colour channels read from red, so each colour is computed once.
    let sheet = |p: [i64; 4]| if GREY { [p[0], p[0], p[0], p[3]] } else { p };
    let under = |p: [u32; 4]| if GREY { [p[0], p[0], p[0], p[3]] } else { p };
    match order {
        Order::BackToFront => {
            for (a, px) in acc.iter_mut().zip(image.iter_mut()) {
                *px = over_fast(resolve_fast(sheet(*a), frac), under(*px));
                *a = [0; 4];
            }
        }
        Order::FrontToBack => {
            for (a, px) in acc.iter_mut().zip(image.iter_mut()) {
                *px = over_fast(under(*px), resolve_fast(sheet(*a), frac));
                *a = [0; 4];
            }
        }
    }
}

/// Pixels per group in [`composite_row`]'s test for all-zero accumulators.
const GROUP: usize = 8;

/// Widest fraction [`resolve_fast`] serves: `i64::MAX` >> 32 = 2³¹ − 1 is still above [`ONE`]
/// (the tables use at most [`super::MAX_ENTRY_FRAC`] = 28 bits).
const FAST_FRAC_MAX: u32 = 32;

/// [`resolve`] for 1 ≤ `frac` ≤ [`FAST_FRAC_MAX`] without a saturating add: ⌊(a + 2^(frac−1)) / 2^frac⌋ is
/// ⌊a / 2^frac⌋ plus bit frac − 1 of a, which cannot overflow. Where `resolve`'s add would
/// saturate (a within 2^(frac−1) of `i64::MAX`) the two differ by one before the clamp, and both
/// clamp to the same value (both are above [`ONE`]).
#[inline(always)]
fn resolve_fast(acc: [i64; 4], frac: u32) -> [u32; 4] {
    let round = |a: i64| (a >> frac) + ((a >> (frac - 1)) & 1);
    let alpha = round(acc[3]).clamp(0, i64::from(ONE));
    [
        round(acc[0]).clamp(0, alpha) as u32,
        round(acc[1]).clamp(0, alpha) as u32,
        round(acc[2]).clamp(0, alpha) as u32,
        alpha as u32,
    ]
}

/// [`over`] with the saturation done in 64 bits (front + scaled back ≤ 2³² − 1 + 2³², then the
/// smaller of it and `u32::MAX`): the same values.
#[inline(always)]
fn over_fast(front: [u32; 4], back: [u32; 4]) -> [u32; 4] {
    let k = u64::from(ONE.saturating_sub(front[3]));
    let mut out = [0u32; 4];
    for ((o, &f), &b) in out.iter_mut().zip(&front).zip(&back) {
        let scaled = (k * u64::from(b) + (1 << (FRAC - 1))) >> FRAC;
        *o = (u64::from(f) + scaled).min(u64::from(u32::MAX)) as u32;
    }
    out
}

/// `front[i] = front[i] over back[i]` for every pixel (the background under a front-to-back
/// render).
#[inline(never)]
pub fn over_row(front: &mut [[u32; 4]], back: &[[u32; 4]]) {
    for (f, b) in front.iter_mut().zip(back) {
        *f = over(*f, *b);
    }
}

#[cfg(test)]
mod tests {
    use super::{composite_row, over, over_fast, resolve, resolve_fast, FAST_FRAC_MAX, GROUP};
    use crate::frame::Order;

    /// A xorshift64 generator of test values from `seed` (non-zero).
    fn xorshift(mut seed: u64) -> impl FnMut() -> u64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        }
    }

    /// Runs `composite_row` on `acc` and `image` and checks that it gave every pixel what
    /// [`resolve`] and [`over`] give it, and cleared the row.
    fn check_row(acc: &mut [[i64; 4]], image: &mut [[u32; 4]], frac: u32, order: Order) {
        let want: std::vec::Vec<[u32; 4]> = acc
            .iter()
            .zip(image.iter())
            .map(|(a, px)| {
                let s = resolve(*a, frac);
                match order {
                    Order::BackToFront => over(s, *px),
                    Order::FrontToBack => over(*px, s),
                }
            })
            .collect();
        composite_row(acc, image, frac, order);
        let len = acc.len();
        assert_eq!(image, &want[..], "len {len} frac {frac} {order:?}");
        assert!(acc.iter().all(|p| *p == [0; 4]), "cleared");
    }

    /// `composite_row`, which skips groups of zero accumulators, gives every pixel what
    /// [`resolve`] and [`over`] give it, and clears the whole row: rows of every length up to a
    /// few groups (a partial last group), zero and non-zero groups mixed, zero pixels inside
    /// non-zero groups, both orders and several fraction widths.
    #[test]
    fn composite_row_matches_per_pixel_compositing() {
        let mut next = xorshift(0x0123_4567_89ab_cdef);
        let mut skipped = 0;
        for len in 0..=3 * GROUP + 3 {
            for frac in [0, 4, 20, 28, 33] {
                for order in [Order::BackToFront, Order::FrontToBack] {
                    let mut acc: std::vec::Vec<[i64; 4]> = (0..len)
                        .map(|i| {
                            let r = next();
                            let a = ((r >> 8) % (1 << 40)) as i64;
                            if (i / GROUP) % 3 == 1 {
                                // Groups of zeros, where one pixel in eight has a single
                                // non-zero channel (a group that must not be skipped).
                                let mut p = [0; 4];
                                if r.is_multiple_of(8) {
                                    p[(r >> 4) as usize % 4] = a | 1;
                                }
                                p
                            } else if r.is_multiple_of(4) {
                                [0; 4]
                            } else {
                                [a / 3, a / 5, a / 2, a]
                            }
                        })
                        .collect();
                    let mut image: std::vec::Vec<[u32; 4]> = (0..len)
                        .map(|_| {
                            let a = (next() % (u64::from(super::ONE) + 1)) as u32;
                            [a / 2, a / 3, a, a]
                        })
                        .collect();
                    skipped += acc
                        .chunks(GROUP)
                        .filter(|g| g.iter().all(|p| *p == [0; 4]))
                        .count();
                    check_row(&mut acc, &mut image, frac, order);
                }
            }
        }
        // Not vacuous: many groups were all zero.
        assert!(skipped > 50, "{skipped}");
    }

    /// Groups of grey pixels (R = G = B in the sheet and the image), composited from one colour
    /// channel, give what [`resolve`] and [`over`] give per pixel: colours below zero, inside
    /// and above alpha, alpha above one and negative; grey groups next to groups where one
    /// pixel's red, green or blue differs, in the sheet or in the image (each of which the grey
    /// test must send to the per-channel loop); both orders, several fraction widths.
    #[test]
    fn grey_groups_match_per_pixel_compositing() {
        let mut next = xorshift(0x5851_f42d_4c95_7f2d);
        let mut grey_groups = 0;
        for len in [GROUP, 7 * GROUP, 8 * GROUP + 6] {
            for frac in [4, 20, 28] {
                for order in [Order::BackToFront, Order::FrontToBack] {
                    // Per group: 0 all grey; in one pixel, 1 the sheet's green differs, 2 its
                    // blue, 3 its red, 4 the image's green, 5 its blue, 6 its red.
                    let kind = |i: usize| (i / GROUP) % 7;
                    let odd = |i: usize, k: usize| kind(i) == k && i % GROUP == 5;
                    let mut acc: std::vec::Vec<[i64; 4]> = (0..len)
                        .map(|i| {
                            let r = next();
                            let a = ((r >> 8) % (1 << 34)) as i64 - (1 << 30);
                            let c = match r % 3 {
                                0 => a / 3,
                                1 => a * 2,
                                _ => -a.abs() / 7,
                            };
                            let d = a / 2 + 12345;
                            match i {
                                _ if odd(i, 1) => [c, d, c, a],
                                _ if odd(i, 2) => [c, c, d, a],
                                _ if odd(i, 3) => [d, c, c, a],
                                _ => [c, c, c, a],
                            }
                        })
                        .collect();
                    let mut image: std::vec::Vec<[u32; 4]> = (0..len)
                        .map(|i| {
                            let a = (next() % (u64::from(super::ONE) + 1)) as u32;
                            let (c, d) = (a / 2, a / 3 + 7);
                            match i {
                                _ if odd(i, 4) => [c, d, c, a],
                                _ if odd(i, 5) => [c, c, d, a],
                                _ if odd(i, 6) => [d, c, c, a],
                                _ => [c, c, c, a],
                            }
                        })
                        .collect();
                    grey_groups += (0..len.div_ceil(GROUP))
                        .filter(|&g| kind(g * GROUP) == 0)
                        .count();
                    check_row(&mut acc, &mut image, frac, order);
                }
            }
        }
        assert!(grey_groups >= 12, "{grey_groups}");
    }

    /// The branch-free twins give the same bits, over random values and the edges (zero, one,
    /// the extremes of `i64` and `u32`, every fraction width the tables use and more).
    #[test]
    fn the_fast_forms_match_the_plain_ones() {
        let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
        let edges = [
            0i64,
            1,
            -1,
            i64::MAX,
            i64::MIN,
            i64::MAX - 1,
            1 << 52,
            -(1 << 52),
        ];
        for frac in 1..=FAST_FRAC_MAX {
            for i in 0..4000 {
                let pick = |r: u64| {
                    if r.is_multiple_of(5) {
                        edges[(r / 5) as usize % edges.len()]
                    } else {
                        (r as i64) >> (r % 40)
                    }
                };
                let acc = [pick(next()), pick(next()), pick(next()), pick(next())];
                assert_eq!(
                    resolve(acc, frac),
                    resolve_fast(acc, frac),
                    "{acc:?} >> {frac}"
                );
                let u = |r: u64| match r % 4 {
                    0 => u32::MAX,
                    1 => (r >> 40) as u32 % (super::ONE + 1),
                    _ => (r >> 32) as u32,
                };
                let (f, b) = (
                    [u(next()), u(next()), u(next()), u(next())],
                    [u(next()), u(next()), u(next()), u(next())],
                );
                assert_eq!(over(f, b), over_fast(f, b), "{f:?} over {b:?} ({i})");
            }
        }
    }
}
