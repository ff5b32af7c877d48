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
        if !self.separable && !inside_disc(u0, u1) {
            return 0;
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
                let (r0, r1) = (&self.data[row], &self.data[row + 1]);
                let (fx, fy) = (fx as u32, fy as u32);
                let top = lerp(r0[col], r0[col + 1], fx);
                let bottom = lerp(r1[col], r1[col + 1], fx);
                i64::from(lerp(top, bottom, fy))
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

/// Whether unit coordinates (u0, u1) (Q24, each within ±1) lie in the unit disc: (u0 >> 8)² +
/// (u1 >> 8)² ≤ 2³² (Q32). On a 64-bit core in 64-bit multiplies, on others in 32-bit ones
/// ([`inside_disc_narrow`]): the same answer (see [`lerp`] on why both).
#[inline]
fn inside_disc(u0: i64, u1: i64) -> bool {
    if cfg!(target_pointer_width = "64") {
        let (a, b) = (u0 >> 8, u1 >> 8);
        a * a + b * b <= 1 << 32
    } else {
        inside_disc_narrow(u0, u1)
    }
}

/// [`inside_disc`] in 32-bit multiplies, exactly: each |u >> 8| ≤ 2¹⁶, whose square is below 2³²
/// except at 2¹⁶ itself (the square 2³², handled without multiplying), and the sum of two squares
/// is taken in `u64` (an add, not a multiply on a 32-bit core).
#[inline]
fn inside_disc_narrow(u0: i64, u1: i64) -> bool {
    let square = |u: i64| {
        let m = (u >> 8).unsigned_abs();
        if m >= 1 << 16 {
            1 << 32 // m = 2¹⁶ exactly: |u| ≤ 2²⁴ was checked.
        } else {
            u64::from((m as u32) * (m as u32))
        }
    };
    square(u0) + square(u1) <= 1 << 32
}

/// a + round((b − a) · f / 2¹⁶) for entries |a|, |b| ≤ 2²⁸ ([`super::MAX_ENTRY_FRAC`]: every
/// table entry, and every lerp of entries, obeys it) and f in Q16 (0 … 2¹⁶), as
/// `a + (((b − a) · f + 2¹⁵) >> 16)` in `i64` ([`lerp_wide`]) on a 64-bit core, and bit for bit
/// the same in 32-bit arithmetic ([`lerp_narrow`]) on others. With d = b − a =
/// d_hi · 2¹⁶ + d_lo (d_lo = d mod 2¹⁶ ≥ 0), d · f + 2¹⁵ = d_hi · f · 2¹⁶ + (d_lo · f + 2¹⁵), and
/// the floor of that over 2¹⁶ is d_hi · f + ⌊(d_lo · f + 2¹⁵) / 2¹⁶⌋ because the second part is
/// not negative; |d_hi · f| ≤ 2¹³ · 2¹⁶ and d_lo · f + 2¹⁵ < 2³² fit 32 bits. A core without a
/// 64-bit multiply (Cortex-M0: `__aeabi_lmul`, a library call) pays three 32-bit ones instead.
#[inline]
fn lerp(a: i32, b: i32, f: u32) -> i32 {
    // A 64-bit core multiplies in 64 bits at no extra cost, and the narrow form's extra steps
    // measured slower there (host table walk, headsq 512², one thread: 300 → 350 ms).
    if cfg!(target_pointer_width = "64") {
        lerp_wide(a, b, f)
    } else {
        lerp_narrow(a, b, f)
    }
}

/// [`lerp`] in `i64`, as written.
#[inline]
fn lerp_wide(a: i32, b: i32, f: u32) -> i32 {
    let (a, b, f) = (i64::from(a), i64::from(b), i64::from(f));
    (a + (((b - a) * f + (1 << 15)) >> 16)) as i32
}

/// [`lerp`] in 32-bit arithmetic (see there).
#[inline]
fn lerp_narrow(a: i32, b: i32, f: u32) -> i32 {
    debug_assert!(a.unsigned_abs() <= 1 << 28 && b.unsigned_abs() <= 1 << 28 && f <= 1 << 16);
    let d = b.wrapping_sub(a);
    let (hi, lo) = (d >> 16, (d & 0xffff) as u32);
    a.wrapping_add(hi.wrapping_mul(f as i32))
        .wrapping_add(((lo * f + (1 << 15)) >> 16) as i32)
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
    // A renormalised footprint's weights, kept from the summing pass for the deposit when its
    // box fits (entries are i32, so every weight is).
    let mut kept = [0i32; KEPT_WEIGHTS];
    let whole = (ys, xs);
    let box_width = xs.1 - xs.0 + 1;
    let keep = table.renorm != 0 && box_width * (ys.1 - ys.0 + 1) <= KEPT_WEIGHTS as i64;
    if table.renorm != 0 {
        let mut sum = 0i64;
        let mut k = 0;
        table.for_each(center, ys, xs, |_, _, w| {
            sum += w;
            if keep {
                kept[k] = w as i32;
                k += 1;
            }
        });
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
    let mut deposit = |x: i64, y: i64, weight: i64| {
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
    };
    if keep {
        // The same pixels, in the same order, with the weights the summing pass computed.
        let ((y0, _), (x0, _)) = whole;
        for y in ys.0..=ys.1 {
            let at = ((y - y0) * box_width) as usize;
            for x in xs.0..=xs.1 {
                deposit(x, y, i64::from(kept[at + (x - x0) as usize]));
            }
        }
    } else {
        table.for_each(center, ys, xs, deposit);
    }
    if row.0 >= 0 {
        touched(row.0 as usize, row.1 as usize, row.2 as usize);
    }
    stats
}

/// Most weights a renormalised splat keeps from its summing pass: 9 × 9, the largest box of a
/// renormalised footprint (both half-extents at most [`crate::geometry::RENORMALISE_BELOW_PX`] =
/// 4 px, so at most 9 pixel centres per row and column), 324 bytes of stack.
const KEPT_WEIGHTS: usize = 81;
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

#[cfg(test)]
mod tests {
    use super::{inside_disc_narrow as inside_disc, lerp_narrow as lerp};

    /// The 32-bit disc test is the 64-bit one at every point of a lattice over ±1 and along the
    /// circle's edge.
    #[test]
    fn the_32_bit_disc_test_is_the_64_bit_one() {
        let wide = |u0: i64, u1: i64| {
            let (a, b) = (u0 >> 8, u1 >> 8);
            a * a + b * b <= 1 << 32
        };
        let one = 1i64 << 24;
        let mut pts = std::vec::Vec::new();
        for i in -64..=64 {
            for j in -64..=64 {
                pts.push((i * one / 64, j * one / 64));
            }
        }
        for k in 0..=4096i64 {
            // Along the edge: u1 = ⌊√(1 − u0²)⌋ and its neighbours (Q24).
            let u0 = k * one / 4096;
            let r = (one * one - u0 * u0).isqrt();
            for d in -300..=300 {
                pts.push((u0, r + d));
                pts.push((-u0, -(r + d)));
            }
        }
        pts.extend([
            (one, 0),
            (0, one),
            (-one, -one),
            (one, 255),
            (one, 256),
            (one, -256),
        ]);
        for (u0, u1) in pts {
            if u0.abs() <= one && u1.abs() <= one {
                assert_eq!(inside_disc(u0, u1), wide(u0, u1), "{u0} {u1}");
            }
        }
    }

    /// The 32-bit lerp is the 64-bit one, bit for bit, over the entries' whole range: every
    /// fraction against edge and random pairs.
    #[test]
    fn the_32_bit_lerp_is_the_64_bit_one() {
        let wide = |a: i32, b: i32, f: u32| {
            let (a, b, f) = (i64::from(a), i64::from(b), i64::from(f));
            a + (((b - a) * f + (1 << 15)) >> 16)
        };
        let m = 1i32 << 28;
        let mut pairs = std::vec![(m, -m), (-m, m), (0, m), (m, 0), (-m, 0), (0, 0), (1, -1)];
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..2000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let r = |s: u64| (s % (2 * m as u64 + 1)) as i64 - i64::from(m);
            pairs.push((r(seed) as i32, r(seed >> 20) as i32));
        }
        for (a, b) in pairs {
            for f in (0..=1u32 << 16)
                .step_by(7)
                .chain([1 << 16, 1, 32767, 32768, 32769])
            {
                assert_eq!(i64::from(lerp(a, b, f)), wide(a, b, f), "{a} {b} {f}");
            }
        }
    }
}
