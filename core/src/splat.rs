//! Splatting: spreading one voxel's value over the pixels its footprint covers, in a buffer the
//! caller owns.
//!
//! Pixel (x, y) has its centre at (x + 0.5, y + 0.5) in screen pixels; a voxel projected to screen
//! position c adds `value × w(centre − c)` to every pixel whose centre lies within the footprint's
//! bounding box, clipped to the image, w the footprint weight of a [`Sampler`]. Weights are px⁻²
//! densities that integrate to one over the screen plane, so summed over all pixels (area one
//! each) a splat deposits ≈ one `value`; small footprints (see [`Footprint::renormalise`]) deposit
//! exactly one, computed over the unclipped footprint so weight that falls off-screen stays lost.

use crate::geometry::{mul2, Footprint};
use crate::math;
use crate::table::{GenericTable, Lookup, ViewTable};
use core::fmt;

/// Something that gives a view's footprint weight at a screen offset.
pub trait Sampler {
    /// The footprint (extent, renormalisation) this sampler evaluates.
    fn footprint(&self) -> &Footprint;
    /// Weight, px⁻², at offset `q` pixels from the voxel's projected centre (x right, y down).
    fn weight(&self, q: [f32; 2]) -> f32;
}

impl<const M: usize> Sampler for ViewTable<M> {
    fn footprint(&self) -> &Footprint {
        &self.footprint
    }
    #[inline]
    fn weight(&self, q: [f32; 2]) -> f32 {
        ViewTable::weight(self, q)
    }
}

/// The *direct* method: every pixel is mapped straight into the generic table through the
/// footprint's 2×2 map, with no view table in between.
#[derive(Clone, Copy, Debug)]
pub struct Direct<'a, const N: usize> {
    /// The view's footprint.
    pub footprint: Footprint,
    /// The kernel's generic table.
    pub table: &'a GenericTable<N>,
    /// Lookup used to read the generic table.
    pub lookup: Lookup,
}

impl<const N: usize> Sampler for Direct<'_, N> {
    fn footprint(&self) -> &Footprint {
        &self.footprint
    }
    #[inline]
    fn weight(&self, q: [f32; 2]) -> f32 {
        self.footprint.scale
            * self
                .table
                .sample(mul2(&self.footprint.to_unit, q), self.lookup)
    }
}

/// A pixel type that can accumulate weighted values.
pub trait Pixel: Copy {
    /// `self += value × w`.
    fn add_weighted(&mut self, value: &Self, w: f32);
}

impl Pixel for f32 {
    #[inline]
    fn add_weighted(&mut self, value: &Self, w: f32) {
        *self += value * w;
    }
}

/// Premultiplied RGBA.
impl Pixel for [f32; 4] {
    #[inline]
    fn add_weighted(&mut self, value: &Self, w: f32) {
        for (d, s) in self.iter_mut().zip(value) {
            *d += s * w;
        }
    }
}

/// Why a buffer or a splat was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum BufferError {
    /// The row stride (pixels) is smaller than the width.
    StrideTooSmall {
        /// Stride given, pixels.
        stride: usize,
        /// Width, pixels.
        width: usize,
    },
    /// The buffer holds fewer pixels than width, height and stride need.
    TooSmall {
        /// Pixels needed: stride × (height − 1) + width.
        needed: usize,
        /// Pixels given.
        got: usize,
    },
    /// Width or height above [`MAX_IMAGE_SIDE`], or a size that overflows.
    TooLarge {
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
    },
    /// The voxel's projected centre is NaN or infinite.
    NonFiniteCenter,
}

impl fmt::Display for BufferError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::StrideTooSmall { stride, width } => {
                write!(f, "row stride {stride} is smaller than the width {width}")
            }
            Self::TooSmall { needed, got } => {
                write!(f, "buffer holds {got} pixels, needs {needed}")
            }
            Self::TooLarge { width, height } => {
                write!(
                    f,
                    "image {width}x{height} is too large (max side {MAX_IMAGE_SIDE})"
                )
            }
            Self::NonFiniteCenter => f.write_str("voxel centre is not finite"),
        }
    }
}

impl core::error::Error for BufferError {}

/// Largest image width or height accepted, pixels.
pub const MAX_IMAGE_SIDE: usize = 1 << 20;

/// A caller-owned image: `height` rows of `width` pixels, row r starting at `r × stride`.
#[derive(Debug)]
pub struct ImageMut<'a, P> {
    data: &'a mut [P],
    width: usize,
    height: usize,
    stride: usize,
}

impl<'a, P> ImageMut<'a, P> {
    /// Wraps `data` after checking it is large enough: `stride ≥ width` and
    /// `data.len() ≥ stride × (height − 1) + width`.
    pub fn new(
        data: &'a mut [P],
        width: usize,
        height: usize,
        stride: usize,
    ) -> Result<Self, BufferError> {
        if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
            return Err(BufferError::TooLarge { width, height });
        }
        if stride < width {
            return Err(BufferError::StrideTooSmall { stride, width });
        }
        let needed = if width == 0 || height == 0 {
            0
        } else {
            stride
                .checked_mul(height - 1)
                .and_then(|v| v.checked_add(width))
                .ok_or(BufferError::TooLarge { width, height })?
        };
        if data.len() < needed {
            return Err(BufferError::TooSmall {
                needed,
                got: data.len(),
            });
        }
        Ok(ImageMut {
            data,
            width,
            height,
            stride,
        })
    }

    /// Width, pixels.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Height, pixels.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Row stride, pixels.
    pub fn stride(&self) -> usize {
        self.stride
    }
    /// The underlying buffer.
    pub fn data(&self) -> &[P] {
        self.data
    }
    /// The underlying buffer, mutably.
    pub fn data_mut(&mut self) -> &mut [P] {
        self.data
    }
}

/// What one splat did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SplatStats {
    /// Pixels inside both the footprint's box and the image.
    pub pixels_visited: u32,
    /// Pixels that received a non-zero weight.
    pub pixels_updated: u32,
}

/// Inclusive pixel index range whose centres lie within [c − e, c + e], unclipped, clamped to
/// ±2³¹ so later clipping stays exact.
fn pixel_span(c: f32, e: f32) -> (i64, i64) {
    pixel_range(c - e, c + e)
}

/// Spreads `value` (e.g. premultiplied RGBA) of a voxel projected to screen position `center`
/// (pixels, absolute) into `image`, using `sampler`'s footprint. Only pixels whose centres lie
/// inside the footprint's support ([`Footprint::row_span`]) are visited. See the module docs.
pub fn splat<S: Sampler + ?Sized, P: Pixel>(
    sampler: &S,
    center: [f32; 2],
    value: &P,
    image: &mut ImageMut<'_, P>,
) -> Result<SplatStats, BufferError> {
    splat_rows(sampler, center, value, image, |_, _, _| {})
}

/// [`splat`], also calling `touched(y, x0, x1)` for every image row it visits with the inclusive
/// pixel range it visited there (so a caller can composite only what a sheet covered).
pub fn splat_rows<S: Sampler + ?Sized, P: Pixel>(
    sampler: &S,
    center: [f32; 2],
    value: &P,
    image: &mut ImageMut<'_, P>,
    mut touched: impl FnMut(usize, usize, usize),
) -> Result<SplatStats, BufferError> {
    if !(center[0].is_finite() && center[1].is_finite()) {
        return Err(BufferError::NonFiniteCenter);
    }
    let fp = sampler.footprint();
    let (y0, y1) = pixel_span(center[1], fp.half_extent[1]);
    let mut factor = 1.0;
    if fp.renormalise {
        // Small footprint (at most 9×9 pixels): sum its sampled weights over the unclipped
        // support so the voxel deposits exactly one unit, less what falls off-screen.
        let mut sum = 0.0f32;
        for_each_in_support(fp, center, y0, y1, i64::MIN, i64::MAX, |_, _, q| {
            sum += sampler.weight(q)
        });
        if sum > 0.0 {
            factor = 1.0 / sum;
        } else {
            // No pixel centre saw the footprint (a table too coarse to resolve it): put the whole
            // voxel in the pixel that contains its centre rather than lose it.
            return Ok(deposit_whole(center, value, image, touched));
        }
    }
    let mut stats = SplatStats::default();
    let (w, h) = (image.width as i64, image.height as i64);
    let stride = image.stride;
    let data = &mut *image.data;
    let mut row = (-1i64, 0i64, 0i64);
    for_each_in_support(fp, center, y0.max(0), y1.min(h - 1), 0, w - 1, |x, y, q| {
        stats.pixels_visited += 1;
        if y != row.0 {
            if row.0 >= 0 {
                touched(row.0 as usize, row.1 as usize, row.2 as usize);
            }
            row = (y, x, x);
        }
        row.2 = x;
        let weight = sampler.weight(q);
        if weight != 0.0 {
            // x, y are within the clipped image, so the index is in the buffer ImageMut checked.
            data[y as usize * stride + x as usize].add_weighted(value, weight * factor);
            stats.pixels_updated += 1;
        }
    });
    if row.0 >= 0 {
        touched(row.0 as usize, row.1 as usize, row.2 as usize);
    }
    Ok(stats)
}

/// Calls `f(x, y, q)` for every pixel (x, y) with y in `y0..=y1`, x in `xmin..=xmax`, whose centre
/// lies inside the footprint's support; q is the centre's offset from `center`, pixels.
#[inline]
fn for_each_in_support(
    fp: &Footprint,
    center: [f32; 2],
    y0: i64,
    y1: i64,
    xmin: i64,
    xmax: i64,
    mut f: impl FnMut(i64, i64, [f32; 2]),
) {
    for y in y0..=y1 {
        let qy = y as f32 + 0.5 - center[1];
        let Some((lo, hi)) = fp.row_span(qy) else {
            continue;
        };
        let (x0, x1) = pixel_range(center[0] + lo, center[0] + hi);
        for x in x0.max(xmin)..=x1.min(xmax) {
            f(x, y, [x as f32 + 0.5 - center[0], qy]);
        }
    }
}

/// Inclusive range of pixel indices whose centres lie in [lo, hi] (screen pixels).
fn pixel_range(lo: f32, hi: f32) -> (i64, i64) {
    let first = -math::floor(-(lo - 0.5)); // ceil
    let last = math::floor(hi - 0.5);
    let clamp = |v: f32| v.clamp(-2_147_483_648.0, 2_147_483_647.0) as i64;
    (clamp(first), clamp(last))
}

fn deposit_whole<P: Pixel>(
    center: [f32; 2],
    value: &P,
    image: &mut ImageMut<'_, P>,
    mut touched: impl FnMut(usize, usize, usize),
) -> SplatStats {
    let (x, y) = (math::floor(center[0]), math::floor(center[1]));
    if x >= 0.0 && y >= 0.0 && (x as usize) < image.width && (y as usize) < image.height {
        image.data[y as usize * image.stride + x as usize].add_weighted(value, 1.0);
        touched(y as usize, x as usize, x as usize);
        SplatStats {
            pixels_visited: 1,
            pixels_updated: 1,
        }
    } else {
        SplatStats::default()
    }
}
