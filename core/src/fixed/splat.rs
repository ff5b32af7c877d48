//! The integer splat: one voxel's Q24 value spread into an `i64` sheet accumulator through a
//! [`FixedTable`]. No floating point here (denied below and audited in CI on a no-FPU target).
//!
//! The pixels visited are those whose centres lie in the footprint's box and inside its support
//! (|A q| ≤ 1, tested in integers per pixel); table and unit coordinates step by a constant per
//! pixel along a row, so a pixel costs a few adds, one or four table reads and four multiplies.
#![deny(clippy::float_arithmetic, clippy::disallowed_types)]

use super::{FixedTable, Placement, POS_FRAC};
use crate::splat::{ImageMut, SplatStats};
use crate::table::Lookup;

const ONE_POS: i64 = 1 << POS_FRAC;
const HALF_POS: i64 = 1 << (POS_FRAC - 1);
/// Largest value (Q24) a renormalised splat may carry, so that its products with entries
/// (≤ 2²⁸) stay below 2⁶².
const MAX_RENORM_VALUE: i128 = (1 << 34) - 1;

impl Placement {
    /// Screen position of voxel (u, v) of sheet `sheet`, Q24 px (exact integer sums).
    #[inline]
    pub fn at(&self, sheet: usize, u: usize, v: usize) -> [i64; 2] {
        let (s, u, v) = (sheet as i64, u as i64, v as i64);
        [0, 1]
            .map(|i| self.origin[i] + s * self.sheet[i] + u * self.along_a[i] + v * self.along_b[i])
    }
}

/// ⌈x / 2²⁴⌉ and ⌊x / 2²⁴⌋ for Q24 x.
#[inline]
fn ceil_pos(x: i64) -> i64 {
    -((-x) >> POS_FRAC)
}
#[inline]
fn floor_pos(x: i64) -> i64 {
    x >> POS_FRAC
}

/// (a · b) / 2²⁴ rounded, saturating (row starts only; per-pixel steps are exact adds).
#[inline]
fn mul_pos(a: i64, b: i64) -> i64 {
    a.saturating_mul(b).saturating_add(HALF_POS) >> POS_FRAC
}

/// Walks table coordinates t and unit coordinates u along image rows.
#[derive(Clone, Copy)]
pub(super) struct Cursor {
    t: [i64; 2],
    u: [i64; 2],
}

impl<const M: usize> FixedTable<M> {
    /// The cursor at screen offset q (Q24 px).
    #[inline]
    pub(super) fn cursor(&self, q: [i64; 2]) -> Cursor {
        let m = |a: &[[i64; 2]; 2], r: usize| {
            mul_pos(a[r][0], q[0]).saturating_add(mul_pos(a[r][1], q[1]))
        };
        Cursor {
            t: [
                self.t0[0] + m(&self.t_map, 0),
                self.t0[1] + m(&self.t_map, 1),
            ],
            u: [m(&self.u_map, 0), m(&self.u_map, 1)],
        }
    }

    /// Moves the cursor one pixel right.
    #[inline]
    fn step(&self, c: &mut Cursor) {
        c.t[0] += self.t_map[0][0];
        c.t[1] += self.t_map[1][0];
        c.u[0] += self.u_map[0][0];
        c.u[1] += self.u_map[1][0];
    }

    /// The entry-scaled weight (Q f) at the cursor: zero outside the support or the table.
    #[inline]
    pub(super) fn weight(&self, c: &Cursor) -> i64 {
        let [u0, u1] = c.u;
        if u0.abs() > ONE_POS || u1.abs() > ONE_POS {
            return 0;
        }
        if !self.separable {
            // |u|² ≤ 1 in Q32: (u >> 8) ≤ 2¹⁶, so the squares fit easily.
            let (a, b) = (u0 >> 8, u1 >> 8);
            if a * a + b * b > 1 << 32 {
                return 0;
            }
        }
        let last = ((M - 1) as i64) << POS_FRAC;
        let [tx, ty] = c.t;
        if tx < 0 || ty < 0 || tx > last || ty > last {
            return 0;
        }
        match self.lookup {
            Lookup::Nearest => {
                let col = ((tx + HALF_POS) >> POS_FRAC) as usize;
                let row = ((ty + HALF_POS) >> POS_FRAC) as usize;
                i64::from(self.data[row.min(M - 1)][col.min(M - 1)])
            }
            Lookup::Bilinear => {
                let col = ((tx >> POS_FRAC) as usize).min(M - 2);
                let row = ((ty >> POS_FRAC) as usize).min(M - 2);
                // Fractions in Q16 (0 … 2¹⁶ inclusive at the last node).
                let fx = (tx - ((col as i64) << POS_FRAC)) >> (POS_FRAC - 16);
                let fy = (ty - ((row as i64) << POS_FRAC)) >> (POS_FRAC - 16);
                let lerp = |a: i64, b: i64, f: i64| a + (((b - a) * f + (1 << 15)) >> 16);
                let (r0, r1) = (&self.data[row], &self.data[row + 1]);
                let top = lerp(i64::from(r0[col]), i64::from(r0[col + 1]), fx);
                let bottom = lerp(i64::from(r1[col]), i64::from(r1[col + 1]), fx);
                lerp(top, bottom, fy)
            }
        }
    }

    /// Calls `f(x, y, w)` for every pixel (x, y), y in `ys`, x in `xs` (inclusive) whose centre
    /// is in the support, w its weight (Q f, may be zero).
    #[inline]
    fn for_each(
        &self,
        center: [i64; 2],
        ys: (i64, i64),
        xs: (i64, i64),
        mut f: impl FnMut(i64, i64, i64),
    ) {
        for y in ys.0..=ys.1 {
            let q = [
                (xs.0 << POS_FRAC) + HALF_POS - center[0],
                (y << POS_FRAC) + HALF_POS - center[1],
            ];
            let mut c = self.cursor(q);
            for x in xs.0..=xs.1 {
                f(x, y, self.weight(&c));
                self.step(&mut c);
            }
        }
    }
}

/// Spreads `value` (premultiplied RGBA, Q24) of a voxel projected to `center` (Q24 px, absolute)
/// into the sheet accumulator `acc` (Q(24 + f) per channel, saturating adds), calling
/// `touched(y, x0, x1)` for each row it updated. Small footprints are renormalised so the voxel
/// deposits exactly `value × cell area` (less what falls off-screen), as the float path does.
#[inline(never)]
pub fn splat<const M: usize>(
    table: &FixedTable<M>,
    center: [i64; 2],
    value: &[u32; 4],
    acc: &mut ImageMut<'_, [i64; 4]>,
    mut touched: impl FnMut(usize, usize, usize),
) -> SplatStats {
    let [ex, ey] = table.half_extent;
    // Pixel centres (p + ½) within [c − e, c + e].
    let ys = (
        ceil_pos(center[1] - ey - HALF_POS),
        floor_pos(center[1] + ey - HALF_POS),
    );
    let xs = (
        ceil_pos(center[0] - ex - HALF_POS),
        floor_pos(center[0] + ex - HALF_POS),
    );
    let mut v = value.map(i64::from);
    // CI builds once with `--cfg footprint_audit_plant` to show that clippy and the object-code
    // audit (embedded/elf_check.py) both catch this float multiply. Never set otherwise.
    #[cfg(footprint_audit_plant)]
    {
        v[0] = (v[0] as f32 * 1.0001) as i64;
    }
    if table.renorm != 0 {
        let mut sum = 0i64;
        table.for_each(center, ys, xs, |_, _, w| sum += w);
        if sum <= 0 {
            return deposit_whole(table, center, &v, acc, touched);
        }
        v = v.map(|x| renormalise(x, table.renorm, sum));
    }
    let (w, h) = (acc.width() as i64, acc.height() as i64);
    let stride = acc.stride();
    let ys = (ys.0.max(0), ys.1.min(h - 1));
    let xs = (xs.0.max(0), xs.1.min(w - 1));
    let mut stats = SplatStats::default();
    if ys.0 > ys.1 || xs.0 > xs.1 {
        return stats;
    }
    let data = acc.data_mut();
    let mut row = (-1i64, 0i64, 0i64);
    table.for_each(center, ys, xs, |x, y, weight| {
        stats.pixels_visited += 1;
        if weight == 0 {
            return;
        }
        if y != row.0 {
            if row.0 >= 0 {
                touched(row.0 as usize, row.1 as usize, row.2 as usize);
            }
            row = (y, x, x);
        }
        row.2 = x;
        // Clipped to the image above, so the index is inside the buffer ImageMut checked.
        let px = &mut data[y as usize * stride + x as usize];
        for (a, c) in px.iter_mut().zip(&v) {
            *a = a.saturating_add(c * weight);
        }
        stats.pixels_updated += 1;
    });
    if row.0 >= 0 {
        touched(row.0 as usize, row.1 as usize, row.2 as usize);
    }
    stats
}

/// `x · c / s` rounded (s > 0), capped at [`MAX_RENORM_VALUE`]: a Q24 value scaled by the cell
/// area C = round(area · 2^f) over the footprint's sum S. In 64 bits when x·c + s/2 fits (always
/// for values up to 2²⁴ and C up to 2³⁸), else in 128 bits; both give the same quotient (integer
/// division truncates either way). The 64-bit divide is the fast path on 32-bit cores, where a
/// 128-bit one is a long library routine (Cortex-M3: 277 → 181 M instructions per demo frame;
/// embedded/check.sh, in bands of 8 rows).
fn renormalise(x: i64, c: i64, s: i64) -> i64 {
    match x.checked_mul(c).and_then(|p| p.checked_add(s / 2)) {
        Some(n) => (n / s).min(MAX_RENORM_VALUE as i64),
        None => {
            let (x, c, s) = (i128::from(x), i128::from(c), i128::from(s));
            ((x * c + s / 2) / s).min(MAX_RENORM_VALUE) as i64
        }
    }
}

/// A renormalised footprint no pixel centre saw: the whole voxel goes to the pixel containing its
/// centre, as in the float path.
fn deposit_whole<const M: usize>(
    table: &FixedTable<M>,
    center: [i64; 2],
    v: &[i64; 4],
    acc: &mut ImageMut<'_, [i64; 4]>,
    mut touched: impl FnMut(usize, usize, usize),
) -> SplatStats {
    let (x, y) = (floor_pos(center[0]), floor_pos(center[1]));
    if x < 0 || y < 0 || x >= acc.width() as i64 || y >= acc.height() as i64 {
        return SplatStats::default();
    }
    let i = y as usize * acc.stride() + x as usize;
    for (a, &c) in acc.data_mut()[i].iter_mut().zip(v) {
        *a = a.saturating_add(c.saturating_mul(table.renorm));
    }
    touched(y as usize, x as usize, x as usize);
    SplatStats {
        pixels_visited: 1,
        pixels_updated: 1,
    }
}
