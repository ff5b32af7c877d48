//! A per-frame memo of emission shading: a voxel's shaded value depends only on its sample when
//! the shading is [`Shading::Emission`] and the samples carry no colours, so a volume of few
//! distinct values (8- and 16-bit data, classified once into visible lists) shades each value
//! once per frame instead of once per voxel.
//!
//! The memo is direct-mapped on the sample's bits in caller storage ([`SHADE_CACHE_LEN`]
//! entries); a hit returns the very value the shader computed for those bits, so the image is the
//! same, bit for bit, with or without it. Float data with many distinct values mostly misses,
//! at the cost of a hash and a compare per voxel.

use crate::shade::{Shader, Shading};

/// Entries a shade cache buffer should hold (a power of two; 4096 × 24 bytes = 96 KiB).
pub const SHADE_CACHE_LEN: usize = 4096;

/// One memo entry: the sample's bits (valid when `tag` is set) and the shaded premultiplied RGBA.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShadeCacheEntry {
    key: u32,
    tag: bool,
    rgba: [f32; 4],
}

/// The memo over a caller's buffer (whose length is rounded down to a power of two).
pub struct ShadeCache<'a> {
    entries: &'a mut [ShadeCacheEntry],
    mask: usize,
}

impl<'a> ShadeCache<'a> {
    /// A memo for `shader` over `buffer`, emptied; `None` when the shading is not emission (the
    /// shaded value then depends on more than the sample) or the buffer is empty.
    pub fn new(shader: &Shader<'_>, buffer: &'a mut [ShadeCacheEntry]) -> Option<Self> {
        if !matches!(shader.shading, Shading::Emission) || buffer.is_empty() {
            return None;
        }
        let len = 1usize << (usize::BITS - 1 - buffer.len().leading_zeros());
        let entries = &mut buffer[..len];
        entries.fill(ShadeCacheEntry::default());
        Some(ShadeCache {
            entries,
            mask: len - 1,
        })
    }

    /// The shaded RGBA of a voxel of `value`: remembered when it has no colour of its own (its
    /// shade then depends on the value alone), else, or on a miss, `shade()` (which must be the
    /// shader's result for this voxel).
    #[inline]
    pub fn shade(
        cache: Option<&mut Self>,
        value: f32,
        coloured: bool,
        shade: impl FnOnce() -> [f32; 4],
    ) -> [f32; 4] {
        let Some(cache) = cache.filter(|_| !coloured) else {
            return shade();
        };
        let key = value.to_bits();
        // Fibonacci hashing: the top bits of key × ⌊2³²/φ⌋.
        let slot = (key.wrapping_mul(0x9E37_79B9) >> 20) as usize & cache.mask;
        let e = &mut cache.entries[slot];
        if e.tag && e.key == key {
            return e.rgba;
        }
        let rgba = shade();
        *e = ShadeCacheEntry {
            key,
            tag: true,
            rgba,
        };
        rgba
    }
}
