//! Fixed-point accumulation: the splat, the sheet accumulator, the working image and compositing
//! in integers only, so a render is bit-exact on every target and runs on cores without an FPU.
//!
//! # Formats
//! | quantity | type | format | range |
//! |---|---|---|---|
//! | voxel value (premultiplied RGBA channel) | `u32` | Q24: v / 2²⁴ | 0 … 255 (clamped) |
//! | table entry = footprint weight × cell area | `i32` | Q*f*: e / 2^f, f ≤ 28 chosen per view | \|e\| ≤ 2²⁸ |
//! | sheet accumulator channel | `i64` | Q(24 + f) | saturates at ±2⁶³ |
//! | working-image channel | `u32` | Q24, [`ONE`] = 2²⁴ is opacity 1 | saturates at 2³² − 1 |
//! | screen positions, table coordinates | `i64` | Q24 pixels / nodes | ±2³⁰ px (checked at set-up) |
//!
//! A table entry is the share of a voxel's value one pixel receives: the footprint weight (px⁻²)
//! times the sheet's cell area (px²), so that a flat sheet accumulates to its own value. Its
//! fraction bits f are chosen per view ([`FixedTable`]) so the largest entry uses 28 bits: a
//! 1000-pixel footprint, whose entries are about 10⁻⁶, keeps 8 to 9 significant bits per entry
//! (and the rounding errors of the ~10⁶ entries it spreads over average out) instead of rounding
//! to zero.
//!
//! Values and the image carry 24 fraction bits, not 16: a thousand sheets of opacity 0.003 each
//! round once per sheet, and at 16 bits those roundings add up to 10⁻³ (measured against the
//! float path); at 24 bits to 10⁻⁵.
//!
//! # Why this headroom is enough
//! - A voxel value is at most [`ONE`] after shading (255 · [`ONE`] < 2³² if a caller pushes
//!   brighter values) and an entry at most 2²⁸, so one product is below 2⁵² (2⁶⁰ at worst).
//!   Renormalised small footprints scale values by at most 2⁸ more, capped so a product stays
//!   below 2⁶². The accumulator holds 2⁶³.
//! - A sheet's contributions at a pixel sum to its flat-field value: Σ entries ≈ 2^f · (1 +
//!   ripple), with ripple ≤ 0.1 for the shipped kernels (`tests/flat_field.rs`). Opacity-1 voxels
//!   therefore accumulate to about 2²⁴⁺²⁸ = 2⁵², leaving 2¹¹ = 2048-fold headroom, however large
//!   the footprints (a 1000-px footprint spreads the same total over more pixels) and however
//!   many voxels overlap. Past that, adds saturate, and `tests/fixed_point.rs` drives an
//!   accumulator into saturation to show it stops instead of wrapping. A saturating `i64` add
//!   costs a compare and select per channel, so where the caller bounds the voxel values
//!   ([`crate::render::FixedPath::with_value_bound`]) and the bound, the stencils' largest
//!   weight and the number of voxels whose box can hold one pixel prove that no pixel's sum can
//!   pass 2⁶² ([`stencil::FixedStencils::exact_below`]), the stencils add with plain (wrapping)
//!   adds: the same bits, since none can wrap; a voxel above the bound is refused.
//! - Accumulated sheets are rounded to Q24 and clamped to [0, [`ONE`]] before compositing, so the
//!   working image's alpha never exceeds [`ONE`], and for valid premultiplied input (colour ≤
//!   alpha) neither does any colour. Invalid input grows a colour by at most [`ONE`] per sheet
//!   and saturates at 2³² − 1 (256 opaque sheets).

//! # Rounding, and why nothing drifts
//! Every product is rounded to nearest, ties up, by adding half an LSB before an arithmetic
//! shift: `(x + 2^(s−1)) >> s`. Opacity 1 is exactly 2²⁴, a power of two, so compositing a
//! transparent sheet multiplies by (2²⁴ − 0) / 2²⁴ = 1 **exactly**: a thousand empty sheets leave
//! the image bit-identical. (The classic bug scales by 255/256 or truncates, and the image drifts
//! dark by one LSB per sheet.) Conversions to and from 8 bits divide by 255, not 256, with
//! rounding: [`to_u8`] and [`from_u8`] are exact inverses on 0…255.
//!
//! # What is float and what is not
//! Per-view set-up ([`FixedTable`] and [`Placement`]) uses `f32`: the ellipse, the table and the
//! voxel placement are computed once and quantised. The per-voxel and per-pixel work
//! ([`splat`], [`stencil`], [`composite`]) is integer only: those modules deny
//! `clippy::float_arithmetic`
//! and the `f32`/`f64` types, and CI disassembles them on `thumbv7m-none-eabi` (no FPU) to check
//! they call no soft-float routine. Shading through [`crate::shade::Shader`] is float per voxel;
//! callers who want no float per voxel shade through an integer lookup table and pass values with
//! [`crate::render::SheetRenderer::render_value_sheet`], or voxel by voxel with
//! [`crate::render::SheetRenderer::render_sheet_with`] (the firmware in `embedded/` does).
//!
//! # Determinism
//! Integer arithmetic is exact, and the float set-up uses only IEEE-754 basic operations (no
//! fused multiply-add: Rust never contracts) and the software `libm`, so the same inputs give
//! the same bytes on x86-64, Cortex-M4F and Cortex-M3, in debug and release.

pub mod compact;
pub mod composite;
pub mod splat;
pub mod stencil;
mod table;

pub use table::{FixedError, FixedTable, Placement};

/// Fraction bits of voxel values and of the working image.
pub const FRAC: u32 = 24;

/// Opacity 1 (and colour 1): 2²⁴.
pub const ONE: u32 = 1 << FRAC;

/// Most fraction bits a table entry gets (fewer when a view's weights exceed 1).
pub const MAX_ENTRY_FRAC: u32 = 28;

/// Fraction bits of screen positions and table coordinates.
pub const POS_FRAC: u32 = 24;

/// The 8-bit value nearest to `q` (Q24, clamped to [0, [`ONE`]]): round(q · 255 / 2²⁴).
#[inline]
pub const fn to_u8(q: u32) -> u8 {
    let q = if q > ONE { ONE } else { q };
    ((q as u64 * 255 + (1 << (FRAC - 1))) >> FRAC) as u8
}

/// The Q24 value nearest to `v / 255`: round(v · 2²⁴ / 255). [`to_u8`] inverts it exactly.
#[inline]
pub const fn from_u8(v: u8) -> u32 {
    ((v as u64 * ONE as u64 + 127) / 255) as u32
}

/// A premultiplied RGBA colour in Q24 from `f32` (clamped to [0, 255], NaN to 0), rounded to
/// nearest. Set-up and shading use it; the integer paths never do.
#[inline]
pub fn quantise(c: [f32; 4]) -> [u32; 4] {
    c.map(|x| {
        if !(x > 0.0) {
            0
        } else {
            // y = x·2²⁴ + ½ lies in (½, 255·2²⁴ + ½], inside u32 and positive, where truncation
            // is the floor: `as u32` rounds to nearest without a call to `floor` per channel.
            (x.min(255.0) * ONE as f32 + 0.5) as u32
        }
    })
}

/// A Q24 colour as `f32` (exact up to opacity 1; above, rounded to f32).
#[inline]
pub fn to_f32(c: [u32; 4]) -> [f32; 4] {
    c.map(|x| x as f32 / ONE as f32)
}

/// Whether an RGBA value is grey (R = G = B, as everywhere under a grey transfer function): the
/// fixed path then computes each colour once for the three channels.
#[inline]
pub(crate) fn is_grey<T: PartialEq>(p: &[T; 4]) -> bool {
    p[0] == p[1] && p[1] == p[2]
}

/// CRC-32 of an image's channels, each as 4 little-endian bytes, row by row: the checksum the
/// firmware and the host print for the same scene.
pub fn checksum(image: &[[u32; 4]]) -> u32 {
    channel_crc(image, |c, crc| crc.update(&c.to_le_bytes()))
}

/// CRC-32 of an image's channels in order, each written by `bytes` (both fixed formats' checksum).
pub(crate) fn channel_crc<C: Copy>(
    image: &[[C; 4]],
    bytes: impl Fn(C, &mut crate::table::Crc32),
) -> u32 {
    let mut crc = crate::table::Crc32::new();
    for px in image {
        for &c in px {
            bytes(c, &mut crc);
        }
    }
    crc.finish()
}

#[cfg(test)]
mod tests {
    use super::{quantise, ONE};

    /// `quantise`'s truncation is the floor, over the whole range and its edges. (Above 2²³ the
    /// f32 y = x·2²⁴ + ½ is a whole number, its own floor; below, the backend's `floor` is the
    /// reference. micromath's `floor` goes through `i32`, so it cannot serve above 2³¹: there the
    /// former `floor`-based `quantise` gave 2³¹ for every x ≥ 128 under that backend.)
    #[test]
    fn quantise_rounds_as_the_floor_did() {
        let floor = |x: f32| -> u32 {
            if !(x > 0.0) {
                return 0;
            }
            let y = x.min(255.0) * ONE as f32 + 0.5;
            if y < 8_388_608.0 {
                crate::math::floor(y) as u32
            } else {
                y as u64 as u32
            }
        };
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut edges = vec![
            0.0f32,
            -0.0,
            f32::MIN_POSITIVE,
            1e-30,
            0.5 / ONE as f32,
            1.0,
            254.999_98,
            255.0,
            256.0,
            f32::MAX,
            f32::INFINITY,
            f32::NAN,
            -1.0,
        ];
        for _ in 0..200_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            // Values in (0, 256): a random mantissa and a random exponent from 2^-30 up.
            let bits = (seed as u32 & 0x007f_ffff) | (((seed >> 32) as u32 % 38 + 97) << 23);
            edges.push(f32::from_bits(bits));
        }
        for x in edges {
            assert_eq!(quantise([x; 4]), [floor(x); 4], "{x:e}");
        }
    }
}
