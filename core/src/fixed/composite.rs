//! Integer Porter–Duff compositing of Q24 premultiplied RGBA (see [`crate::fixed`] for the
//! formats and the rounding). No floating point here (denied below and audited in CI).
#![deny(clippy::float_arithmetic, clippy::disallowed_types)]

use super::{FRAC, ONE};
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
#[inline(never)]
pub fn composite_row(acc: &mut [[i64; 4]], image: &mut [[u32; 4]], frac: u32, order: Order) {
    for (a, px) in acc.iter_mut().zip(image.iter_mut()) {
        let s = resolve(*a, frac);
        *a = [0; 4];
        *px = match order {
            Order::BackToFront => over(s, *px),
            Order::FrontToBack => over(*px, s),
        };
    }
}

/// `front[i] = front[i] over back[i]` for every pixel (the background under a front-to-back
/// render).
#[inline(never)]
pub fn over_row(front: &mut [[u32; 4]], back: &[[u32; 4]]) {
    for (f, b) in front.iter_mut().zip(back) {
        *f = over(*f, *b);
    }
}
