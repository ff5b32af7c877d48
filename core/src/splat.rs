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

/// The footprint sampler trait, defined beside [`Footprint`] (the tables implement it without
/// importing the splat).
pub use crate::geometry::Sampler;

impl<const M: usize> Sampler for ViewTable<M> {
    fn footprint(&self) -> &Footprint {
        &self.footprint
    }
    #[inline]
    fn weight(&self, q: [f32; 2]) -> f32 {
        ViewTable::weight(self, q)
    }
    #[inline]
    fn row_weights(&self, qx0: f32, qy: f32, out: &mut [f32]) {
        ViewTable::row_weights(self, qx0, qy, out)
    }
    #[inline]
    fn line_weights(&self, q0: [f32; 2], step: [f32; 2], out: &mut [f32]) {
        ViewTable::line_weights(self, q0, step, out)
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
    #[inline(always)]
    fn add_weighted(&mut self, value: &Self, w: f32) {
        *self += value * w;
    }
}

/// Premultiplied RGBA.
impl Pixel for [f32; 4] {
    // Always inlined: it is the innermost statement of every splat loop, and with a hint alone
    // LLVM called it out of line once the stencils' loops doubled for the phase lookups (a call
    // per pixel update: a quarter of a re-render, object slicing 35-45 % slower on the walnut).
    #[inline(always)]
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

/// What a float render spreads a voxel with: any footprint [`Sampler`] (row by row, through
/// [`splat_rows`]) or a view's phase stencils ([`crate::stencil::Stencils`]).
pub trait Splatter {
    /// Spreads `value` of a voxel projected to `center` (pixels, absolute) into `image`, calling
    /// `touched(y, x0, x1)` for each row it visited.
    fn splat_voxel<P: Pixel>(
        &self,
        center: [f32; 2],
        value: &P,
        image: &mut ImageMut<'_, P>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError>;
}

impl<S: Sampler + ?Sized> Splatter for S {
    #[inline]
    fn splat_voxel<P: Pixel>(
        &self,
        center: [f32; 2],
        value: &P,
        image: &mut ImageMut<'_, P>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError> {
        splat_rows(self, center, value, image, touched)
    }
}

/// Pixels per batch of row weights (a stack buffer; longer rows are done in several batches).
const BATCH: usize = 64;

/// Largest number of pixel centres a renormalised footprint spans along x or y: half-extents
/// ≤ [`crate::geometry::RENORMALISE_BELOW_PX`] (4 px) cover at most 9 centres; one spare.
const SMALL: usize = 10;

/// [`splat`], also calling `touched(y, x0, x1)` for every image row it visits with the inclusive
/// pixel range it visited there (so a caller can composite only what a sheet covered).
///
/// Cost: per image row one square root ([`Footprint::row_span`]) and two floors; per pixel one
/// [`Sampler::row_weights`] entry and one multiply-add per channel. A renormalised (small)
/// footprint keeps its weights in a 10×10 stack buffer between the sum and the deposit, so the
/// table is read once.
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
    let (y0, y1) = pixel_range(center[1] - fp.half_extent[1], center[1] + fp.half_extent[1]);
    let (w, h) = (image.width as i64, image.height as i64);
    if y1 < 0 || y0 >= h {
        // Entirely above or below the image (or the band it is): nothing to do. (A renormalised
        // footprint's fallback pixel, the one holding its centre, lies inside its box too.)
        return Ok(SplatStats::default());
    }
    let stride = image.stride;
    let data = &mut *image.data;
    let mut stats = SplatStats::default();
    if fp.renormalise {
        let (x0, x1) = pixel_range(center[0] - fp.half_extent[0], center[0] + fp.half_extent[0]);
        if y1 - y0 < SMALL as i64 && x1 - x0 < SMALL as i64 {
            return Ok(splat_small(
                sampler,
                center,
                value,
                (x0, y0),
                ((x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize),
                image,
                touched,
            ));
        }
    }
    let mut batch = [0.0f32; BATCH];
    for y in y0.max(0)..=y1.min(h - 1) {
        let qy = y as f32 + 0.5 - center[1];
        let Some((x0, x1)) = row_pixels(fp, center[0], qy) else {
            continue;
        };
        let (lo, hi) = (x0.max(0), x1.min(w - 1));
        if lo > hi {
            continue;
        }
        let row_start = y as usize * stride;
        let mut x = lo;
        while x <= hi {
            let n = ((hi - x + 1) as usize).min(BATCH);
            let ws = &mut batch[..n];
            sampler.row_weights(x as f32 + 0.5 - center[0], qy, ws);
            let start = row_start + x as usize;
            let px = &mut data[start..start + n];
            for (d, &wt) in px.iter_mut().zip(ws.iter()) {
                d.add_weighted(value, wt);
                stats.pixels_updated += u32::from(wt != 0.0);
            }
            x += n as i64;
        }
        stats.pixels_visited += (hi - lo + 1) as u32;
        touched(y as usize, lo as usize, hi as usize);
    }
    Ok(stats)
}

/// A small (renormalised) footprint whose box `origin`, `size` (≤ 10×10 pixels, unclipped) is
/// known: its weights over the whole box are sampled once into a stack buffer, pixels outside the
/// support are zeroed (|A q|² > 1, the same test as [`Footprint::row_span`]), the sum is taken so
/// the voxel deposits exactly one unit (less what falls off-screen), then the on-screen part is
/// added.
#[inline]
fn splat_small<S: Sampler + ?Sized, P: Pixel>(
    sampler: &S,
    center: [f32; 2],
    value: &P,
    (x0, y0): (i64, i64),
    (nx, ny): (usize, usize),
    image: &mut ImageMut<'_, P>,
    mut touched: impl FnMut(usize, usize, usize),
) -> SplatStats {
    let fp = sampler.footprint();
    let mut weights = [[0.0f32; SMALL]; SMALL];
    let qx0 = x0 as f32 + 0.5 - center[0];
    let mut sum = 0.0f32;
    for (k, row) in weights.iter_mut().enumerate().take(ny) {
        let qy = (y0 + k as i64) as f32 + 0.5 - center[1];
        let row = &mut row[..nx];
        sampler.row_weights(qx0, qy, row);
        for (i, w) in row.iter_mut().enumerate() {
            if !fp.contains([qx0 + i as f32, qy]) {
                *w = 0.0;
            }
            sum += *w;
        }
    }
    if !(sum > 0.0) {
        // No pixel centre saw the footprint (a table too coarse to resolve it): put the whole
        // voxel in the pixel that contains its centre rather than lose it.
        return deposit_whole(center, value, image, touched);
    }
    let factor = 1.0 / sum;
    let (w, h) = (image.width as i64, image.height as i64);
    let stride = image.stride;
    let mut stats = SplatStats::default();
    let (lo, hi) = (x0.max(0), (x0 + nx as i64 - 1).min(w - 1));
    if lo > hi {
        return stats;
    }
    for (k, row) in weights.iter().enumerate().take(ny) {
        let y = y0 + k as i64;
        if y < 0 || y >= h {
            continue;
        }
        let ws = &row[(lo - x0) as usize..=(hi - x0) as usize];
        let start = y as usize * stride + lo as usize;
        // Clipped to the image, so the range is inside the buffer ImageMut checked.
        let px = &mut image.data[start..start + ws.len()];
        let mut span: Option<(usize, usize)> = None;
        for (i, (d, &wt)) in px.iter_mut().zip(ws).enumerate() {
            if wt != 0.0 {
                d.add_weighted(value, wt * factor);
                stats.pixels_updated += 1;
                span = Some(span.map_or((i, i), |(s, _)| (s, i)));
            }
        }
        if let Some((s, e)) = span {
            stats.pixels_visited += (e - s + 1) as u32;
            touched(y as usize, lo as usize + s, lo as usize + e);
        }
    }
    stats
}

/// The inclusive pixel range of image row offset `qy` (pixels from the centre) whose centres lie
/// inside the footprint's support, unclipped; `None` if the row misses it.
#[inline]
pub(crate) fn row_pixels(fp: &Footprint, cx: f32, qy: f32) -> Option<(i64, i64)> {
    let (lo, hi) = fp.row_span(qy)?;
    let (x0, x1) = pixel_range(cx + lo, cx + hi);
    (x0 <= x1).then_some((x0, x1))
}

/// Inclusive range of pixel indices whose centres lie in [lo, hi] (screen pixels), clamped to
/// ±2³¹ so later clipping stays exact.
#[inline]
pub(crate) fn pixel_range(lo: f32, hi: f32) -> (i64, i64) {
    (-floor_i64(-(lo - 0.5)), floor_i64(hi - 0.5))
}

/// ⌊x⌋ for finite x, clamped to ±2³¹ (NaN gives 0); inline, without a libm call. `as i64`
/// truncates toward zero, so a negative non-integer is one too high.
#[inline]
pub(crate) fn floor_i64(x: f32) -> i64 {
    let x = x.clamp(-2_147_483_648.0, 2_147_483_647.0);
    let t = x as i64;
    t - i64::from((t as f32) > x)
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
