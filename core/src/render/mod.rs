//! The sheet renderer: classify and shade each voxel of a sheet, splat it into the sheet
//! accumulator, then composite the sheet into the working image (the paper's pipeline), in
//! buffers the caller owns.
//!
//! # Order of work
//! The caller pushes sheets one at a time in the sequence [`FrameSetup::sheet_at`] gives for the
//! chosen [`Order`] (ascending or descending index), each with its two neighbours along the sheet
//! axis when the shading needs gradients ([`SheetWindow`]). A source that cannot seek can use
//! [`SheetRing`]: three sheet buffers, filled in sequence, so no more than three sheets are ever held.
//!
//! # Normalisation
//! Each voxel's premultiplied RGBA is splatted with weight × [`FrameSetup::cell_area`]; since a
//! footprint integrates to one per px², a flat sheet accumulates to its own value at every pixel
//! (up to the kernel's ripple). The accumulated sheet is clamped to [0, 1] per channel and
//! composited: *over* the working image back to front, *under* it front to back. Both give the same
//! image up to rounding (associativity of Porter–Duff over).
//!
//! # Precision
//! The renderer is generic over a [`Precision`]: [`FloatPath`] (f32 accumulator and image, any
//! [`Splatter`]: a footprint sampler or phase stencils) or [`FixedPath`] (integer table, `i64` accumulator, Q24 image; see
//! [`crate::fixed`]). One build holds both, so they can be compared on the same frame.

pub mod absorption;
mod band;
pub mod clip;
mod error;
mod occlusion;
mod perspective;
pub mod post;
mod precision;
mod refined;
mod scaled;
mod shade_cache;
mod sheets;
mod slab_renderer;
pub mod slabs;
mod visible;

pub use absorption::Absorption;
pub use error::RenderError;
pub use occlusion::{occlusion_len, OcclusionError, OCCLUSION_TILE};
pub use perspective::PerVoxel;
pub use post::{
    Blend, Classify, PostBuffers, PostRenderer, PostSample, PostSetup, PostVoxel, ShadedLayers,
    WeightTable,
};
pub use precision::{CompactPath, FixedPath, FloatPath, Precision, VoxelSplat};
pub use refined::{key_spacings, rate_index, spacing_key, RefineTables, RefinedGrid, SPACING_KEYS};
pub use scaled::{sheet_map, splat_scaled, ScaledFootprint};
pub use shade_cache::{ShadeCache, ShadeCacheEntry, SHADE_CACHE_LEN};
pub use sheets::{gradient, SheetRing, SheetWindow};
pub use slab_renderer::{SlabBuffers, SlabRenderer};
pub use slabs::{SectionStencils, SlabError, SlabSetup, SlabVoxel};
pub use visible::{classify_sheet, VisibleSheet, VisibleVoxel};

use crate::composite::RowSpan;
use crate::frame::{FrameSetup, Order};
use crate::shade::{Lighting, OpacityTable, Sample, Shader};
use crate::splat::{BufferError, ImageMut, Splatter};
use band::{check_band, start_image, BandReach, RowCounts};
use occlusion::Occlusion;

/// The caller-owned buffers of a render, each [`FrameSetup::image_len`] long except `rows`
/// (one per image row). `A` and `P` are the [`Precision`]'s accumulator and image pixels:
/// `[f32; 4]` and `[f32; 4]` for [`FloatPath`], `[i64; 4]` and `[u32; 4]` for [`FixedPath`].
#[derive(Debug)]
pub struct RenderBuffers<'a, A = [f32; 4], P = [f32; 4]> {
    /// Sheet accumulator, premultiplied RGBA; must be all zero at the start (left all zero).
    pub accumulator: &'a mut [A],
    /// Working image, premultiplied RGBA, row-major, top row first: the result.
    pub image: &'a mut [P],
    /// Per-row extent of what the current sheet touched.
    pub rows: &'a mut [RowSpan],
}

/// Counts of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Sheets rendered.
    pub sheets: u32,
    /// Voxels classified.
    pub voxels: u64,
    /// Voxels with non-zero opacity, splatted.
    pub voxels_splatted: u64,
    /// Pixel updates in sheet accumulators.
    pub pixel_updates: u64,
    /// Pixel composites into the working image.
    pub pixels_composited: u64,
    /// Voxels skipped because their footprint lay on opaque tiles only
    /// ([`SheetRenderer::with_occlusion`]); with bands, once per band that skipped it.
    pub culled_voxels: u64,
}

/// Renders sheets into caller-owned buffers, with float or fixed accumulation ([`Precision`]).
///
/// **Bands.** A renderer may own only a band of image rows ([`SheetRenderer::with_band`]): its
/// buffers then hold just those rows, voxels are splatted only where they reach them, and every
/// pixel receives exactly the additions, in exactly the order, that a whole-image render gives it.
/// Renderers of disjoint bands can therefore run on separate cores (each fed the same sheets) and
/// their bands put together are bit-identical to one whole-image render, whatever the number of
/// bands.
pub struct SheetRenderer<'a, P: Precision> {
    frame: &'a FrameSetup,
    path: P,
    shader: Shader<'a>,
    lighting: Lighting,
    opacity: Option<OpacityTable<'a>>,
    cache: Option<ShadeCache<'a>>,
    order: Order,
    /// First image row of the band and its number of rows.
    band: (usize, usize),
    buffers: RenderBuffers<'a, P::Acc, P::Pixel>,
    background: Option<&'a [P::Pixel]>,
    occlusion: Option<Occlusion<'a, P::Pixel>>,
    stats: RenderStats,
}

impl<'a, S: Splatter + ?Sized> SheetRenderer<'a, FloatPath<'a, S>> {
    /// Starts a float frame through `sampler` (a view table, the direct method or phase stencils); see
    /// [`SheetRenderer::with_path`].
    pub fn new(
        frame: &'a FrameSetup,
        sampler: &'a S,
        shader: Shader<'a>,
        order: Order,
        buffers: RenderBuffers<'a>,
        background: Option<&'a [[f32; 4]]>,
    ) -> Result<Self, RenderError> {
        Self::with_path(
            frame,
            FloatPath::new(sampler),
            shader,
            order,
            buffers,
            background,
        )
    }
}

impl<'a, P: Precision> SheetRenderer<'a, P> {
    /// Starts a frame. `background` is the starting working image (back to front) or what is
    /// composited under the result at [`SheetRenderer::finish`] (front to back); `None` means
    /// transparent black. Checks every buffer's size.
    pub fn with_path(
        frame: &'a FrameSetup,
        path: P,
        shader: Shader<'a>,
        order: Order,
        buffers: RenderBuffers<'a, P::Acc, P::Pixel>,
        background: Option<&'a [P::Pixel]>,
    ) -> Result<Self, RenderError> {
        Self::with_band(
            frame,
            path,
            shader,
            order,
            buffers,
            background,
            0..frame.size[1],
        )
    }

    /// [`SheetRenderer::with_path`] for the image rows `rows` only: `buffers` (and `background`)
    /// hold `rows.len()` rows of `frame.size[0]` pixels, row `rows.start` first (`rows` one entry
    /// per band row). See the type's docs for what bands guarantee.
    pub fn with_band(
        frame: &'a FrameSetup,
        path: P,
        shader: Shader<'a>,
        order: Order,
        buffers: RenderBuffers<'a, P::Acc, P::Pixel>,
        background: Option<&'a [P::Pixel]>,
        rows: core::ops::Range<usize>,
    ) -> Result<Self, RenderError> {
        let band_rows = rows.len();
        let n = frame.size[0] * band_rows;
        check_band(
            &rows,
            frame.size[1],
            &[
                (buffers.accumulator.len(), n),
                (buffers.image.len(), n),
                (background.map_or(n, <[_]>::len), n),
                (buffers.rows.len(), band_rows),
            ],
        )?;
        shader.check()?;
        if frame.camera().is_some() && !P::PERSPECTIVE {
            return Err(RenderError::Projection);
        }
        let r = SheetRenderer {
            frame,
            path,
            shader,
            lighting: Lighting::new(frame),
            opacity: None,
            cache: None,
            order,
            band: (rows.start, band_rows),
            buffers,
            background,
            occlusion: None,
            stats: RenderStats::default(),
        };
        start_image(&mut r.buffers.image[..n], background, order, P::CLEAR);
        r.buffers.rows[..band_rows].fill(RowSpan::EMPTY);
        Ok(r)
    }

    /// Reads the frame's opacity correction from a table built in `buffer` (see
    /// [`OpacityTable`]: [`OPACITY_TABLE_LEN`](crate::shade::OPACITY_TABLE_LEN) entries keep it
    /// within 3·10⁻⁶ of the exact power) instead of computing a power per voxel.
    pub fn with_opacity_table(mut self, buffer: &'a mut [f32]) -> Result<Self, RenderError> {
        self.opacity = Some(OpacityTable::build(&self.lighting, buffer)?);
        Ok(self)
    }

    /// Remembers emission shading per sample value in `buffer` (see [`SHADE_CACHE_LEN`] and the
    /// `shade_cache` module): the same image, shaded once per distinct value instead of once per
    /// voxel. Ignored for other shadings. Call it after [`SheetRenderer::with_opacity_table`]
    /// (the memo holds values shaded with the frame's opacity correction).
    pub fn with_shade_cache(mut self, buffer: &'a mut [ShadeCacheEntry]) -> Self {
        self.cache = ShadeCache::new(&self.shader, buffer);
        self
    }

    /// Culls occluded voxels (Mueller et al. 1999): once every pixel of an [`OCCLUSION_TILE`]²
    /// tile has opacity ≥ 1 − `eps`, nothing more is composited into it, and voxels whose
    /// footprint lies on such tiles only are skipped before they are shaded; each such pixel stays
    /// within `eps` per premultiplied channel of the image without culling. `buffer` holds
    /// [`occlusion_len`]`(width, band rows)` bytes. Refused ([`OcclusionError`]) back to front,
    /// for a perspective frame, for `eps` outside (0, 1), and for a band that does not start on a
    /// multiple of [`OCCLUSION_TILE`] rows (which keeps the image the same for any bands).
    pub fn with_occlusion(mut self, buffer: &'a mut [u8], eps: f32) -> Result<Self, RenderError> {
        if self.frame.camera().is_some() {
            return Err(RenderError::Occlusion(OcclusionError::Perspective));
        }
        let size = [self.frame.size[0], self.band.1];
        Occlusion::<P::Pixel>::check(eps, self.order, self.band.0, size, buffer.len())?;
        let half = self.frame.footprint.half_extent;
        self.occlusion = Some(Occlusion::new::<P>(buffer, size, half, eps));
        Ok(self)
    }

    /// The frame being rendered.
    pub fn frame(&self) -> &'a FrameSetup {
        self.frame
    }

    /// The compositing order.
    pub fn order(&self) -> Order {
        self.order
    }

    /// The image rows this renderer owns.
    pub fn band(&self) -> core::ops::Range<usize> {
        self.band.0..self.band.0 + self.band.1
    }

    /// Counts so far.
    pub fn stats(&self) -> RenderStats {
        self.stats
    }

    /// Classifies, shades, splats and composites sheet `index`.
    pub fn render_sheet<T: Sample>(
        &mut self,
        index: usize,
        window: SheetWindow<'_, T>,
    ) -> Result<(), RenderError> {
        let (f, shader, lighting) = (self.frame, self.shader, self.lighting);
        let na = f.sheet_shape().1;
        let lengths = [
            Some(window.current.len()),
            window.lower.map(<[T]>::len),
            window.upper.map(<[T]>::len),
        ];
        let (path, opacity, cache) = (&self.path, self.opacity, &mut self.cache);
        let occlusion = self.occlusion.as_ref();
        // Values the transfer function surely makes transparent skip shading (the same image).
        let clear = shader.transparent_at_or_below();
        let shade = |u: usize, v: usize| {
            let sample = window.current[v * na + u];
            let (value, colour) = (sample.to_f32(), sample.colour());
            if value <= clear {
                return path.value([0.0; 4]);
            }
            path.value(ShadeCache::shade(
                cache.as_mut(),
                value,
                colour.is_some(),
                || {
                    shader.shade_coloured(
                        &lighting,
                        opacity.as_ref(),
                        value,
                        colour,
                        || gradient(f, &window, u, v),
                        f.grid_index(index, u, v),
                        f.dims,
                    )
                },
            ))
        };
        Self::splat_sheet(
            f,
            &self.path,
            self.band,
            &mut self.buffers,
            &mut self.stats,
            occlusion,
            index,
            lengths,
            |_| 0..usize::MAX,
            shade,
        )?;
        self.composite_sheet();
        Ok(())
    }

    /// [`SheetRenderer::render_sheet`] from the sheet's visible voxels (see [`classify_sheet`]):
    /// the same image, bit for bit, without visiting transparent voxels.
    pub fn render_visible_sheet(
        &mut self,
        index: usize,
        visible: VisibleSheet<'_>,
    ) -> Result<(), RenderError> {
        self.splat_visible_sheet(index, visible)?;
        self.composite_sheet();
        Ok(())
    }

    /// The splatting half of [`SheetRenderer::render_visible_sheet`]; call
    /// [`SheetRenderer::composite_sheet`] after it (the two are separate so a caller can time
    /// them).
    pub fn splat_visible_sheet(
        &mut self,
        index: usize,
        visible: VisibleSheet<'_>,
    ) -> Result<(), RenderError> {
        let count = self.frame.sheet_count();
        if index >= count {
            return Err(RenderError::SheetIndex { index, count });
        }
        let needs_gradient = self.shader.shading.needs_gradient();
        if needs_gradient && visible.gradients.len() < visible.voxels.len() {
            return Err(BufferError::TooSmall {
                needed: visible.voxels.len(),
                got: visible.gradients.len(),
            }
            .into());
        }
        let (f, shader, lighting, opacity) = (self.frame, self.shader, self.lighting, self.opacity);
        let (w, h) = (f.size[0], self.band.1);
        let mut image = ImageMut::new(&mut *self.buffers.accumulator, w, h, w)?;
        let rows = &mut *self.buffers.rows;
        let (na, nb) = (f.sheet_shape().1, f.sheet_shape().2);
        let reach = BandReach::new(f, self.band, index);
        for (k, vox) in visible.voxels.iter().enumerate() {
            let (u, v) = (usize::from(vox.u), usize::from(vox.v));
            if u >= na || v >= nb {
                return Err(RenderError::SheetLength {
                    expected: na * nb,
                    got: v * na + u + 1,
                });
            }
            if !reach.may_reach(u, v) {
                continue;
            }
            if let Some(o) = &self.occlusion {
                if o.hides(f, index, u, v, self.band.0) {
                    self.stats.culled_voxels += 1;
                    continue;
                }
            }
            let g = || {
                if needs_gradient {
                    glam::Vec3::from_array(visible.gradients[k])
                } else {
                    glam::Vec3::ZERO
                }
            };
            let colour = visible.colours.get(k).copied();
            let cache = self.cache.as_mut();
            let value = self.path.value(ShadeCache::shade(
                cache,
                vox.value,
                colour.is_some(),
                || {
                    shader.shade_coloured(
                        &lighting,
                        opacity.as_ref(),
                        vox.value,
                        colour,
                        g,
                        f.grid_index(index, u, v),
                        f.dims,
                    )
                },
            ));
            self.stats.voxels += 1;
            if P::is_transparent(&value) {
                continue;
            }
            let s = self.path.splat(
                f,
                index,
                (u, v),
                self.band.0,
                &value,
                &mut image,
                |y, x0, x1| rows[y].include(x0, x1),
            )?;
            self.stats.voxels_splatted += u64::from(s.pixels_visited > 0);
            self.stats.pixel_updates += u64::from(s.pixels_updated);
        }
        self.stats.sheets += 1;
        Ok(())
    }

    /// Splats and composites sheet `index` of voxels the caller has already shaded: premultiplied
    /// RGBA per voxel (`dims[a] × dims[b]`, the sheet layout), each the colour and opacity of that
    /// voxel's slab of this sheet (no transfer function, lighting or opacity correction is
    /// applied). Voxels with α = 0 are skipped.
    pub fn render_shaded_sheet(
        &mut self,
        index: usize,
        rgba: &[[f32; 4]],
    ) -> Result<(), RenderError> {
        let na = self.frame.sheet_shape().1;
        self.splat_and_composite(index, Some(rgba.len()), |path, u, v| {
            path.value(rgba[v * na + u])
        })
    }

    /// [`SheetRenderer::render_shaded_sheet`] with values already in the precision's own format
    /// (for [`FixedPath`], Q24 premultiplied RGBA): no float work per voxel at all.
    pub fn render_value_sheet(
        &mut self,
        index: usize,
        values: &[P::Value],
    ) -> Result<(), RenderError> {
        let na = self.frame.sheet_shape().1;
        self.splat_and_composite(index, Some(values.len()), |_, u, v| values[v * na + u])
    }

    /// Splats and composites sheet `index` with each voxel's value computed on the fly by
    /// `shade(u, v)` (`u` < `dims[a]`, `v` < `dims[b]`, the sheet layout; visited row by row,
    /// `u` fastest), so no sheet of values is stored: a caller streaming samples from a sensor or
    /// a file shades each through an integer table as it goes. Transparent values are skipped.
    /// The image is bit-identical to [`SheetRenderer::render_value_sheet`] of the same values.
    pub fn render_sheet_with(
        &mut self,
        index: usize,
        mut shade: impl FnMut(usize, usize) -> P::Value,
    ) -> Result<(), RenderError> {
        self.splat_and_composite(index, None, |_, u, v| shade(u, v))
    }

    /// [`SheetRenderer::render_sheet_with`] where the caller knows which voxels can be
    /// non-transparent: in sheet row `v`, only `u` in `occupied(v)` (a promise: the renderer
    /// neither shades nor visits the others, so a source skips its empty runs in bulk). The image
    /// is bit-identical to `render_sheet_with` when the promise holds.
    pub fn render_sheet_rows_with(
        &mut self,
        index: usize,
        occupied: impl Fn(usize) -> core::ops::Range<usize>,
        shade: impl FnMut(usize, usize) -> P::Value,
    ) -> Result<(), RenderError> {
        Self::splat_sheet(
            self.frame,
            &self.path,
            self.band,
            &mut self.buffers,
            &mut self.stats,
            self.occlusion.as_ref(),
            index,
            [None, None, None],
            occupied,
            shade,
        )?;
        self.composite_sheet();
        Ok(())
    }

    /// [`SheetRenderer::splat_sheet`] of a sheet of `len` values (checked, if given), each
    /// `shade(path, u, v)`, then [`SheetRenderer::composite_sheet`].
    fn splat_and_composite(
        &mut self,
        index: usize,
        len: Option<usize>,
        mut shade: impl FnMut(&P, usize, usize) -> P::Value,
    ) -> Result<(), RenderError> {
        let path = &self.path;
        Self::splat_sheet(
            self.frame,
            path,
            self.band,
            &mut self.buffers,
            &mut self.stats,
            self.occlusion.as_ref(),
            index,
            [len, None, None],
            |_| 0..usize::MAX,
            |u, v| shade(path, u, v),
        )?;
        self.composite_sheet();
        Ok(())
    }

    /// Checks sheet `index` and the given sheet `lengths`, then splats the value that
    /// `shade(u, v)` gives for every voxel of row v in `occupied(v)` (skipping transparent ones,
    /// and in a band the voxels that cannot reach it, without shading them).
    #[allow(clippy::too_many_arguments)]
    fn splat_sheet(
        f: &FrameSetup,
        path: &P,
        band: (usize, usize),
        buffers: &mut RenderBuffers<'a, P::Acc, P::Pixel>,
        stats: &mut RenderStats,
        occlusion: Option<&Occlusion<'a, P::Pixel>>,
        index: usize,
        lengths: [Option<usize>; 3],
        occupied: impl Fn(usize) -> core::ops::Range<usize>,
        mut shade: impl FnMut(usize, usize) -> P::Value,
    ) -> Result<(), RenderError> {
        let count = f.sheet_count();
        if index >= count {
            return Err(RenderError::SheetIndex { index, count });
        }
        let (len, na, nb) = f.sheet_shape();
        if let Some(got) = lengths.into_iter().flatten().find(|&l| l != len) {
            return Err(RenderError::SheetLength { expected: len, got });
        }
        let mut image = ImageMut::new(&mut *buffers.accumulator, f.size[0], band.1, f.size[0])?;
        let rows = &mut *buffers.rows;
        let reach = BandReach::new(f, band, index);
        for v in 0..nb {
            let us = reach.row_within(v, na, occupied(v));
            let mut n = RowCounts::visiting(us.len());
            for u in us {
                if occlusion.is_some_and(|o| o.hides(f, index, u, v, band.0)) {
                    n.culled += 1;
                    continue;
                }
                let value = shade(u, v);
                if P::is_transparent(&value) {
                    continue;
                }
                let s = path.splat(f, index, (u, v), band.0, &value, &mut image, |y, x0, x1| {
                    rows[y].include(x0, x1)
                })?;
                n.splatted += usize::from(s.pixels_visited > 0);
                n.updates += u64::from(s.pixels_updated);
            }
            n.add_to(stats);
        }
        stats.sheets += 1;
        Ok(())
    }

    /// Composites the accumulated sheet into the working image over the rows it touched, and
    /// clears what it used. [`SheetRenderer::render_sheet`] and its siblings call it; a caller of
    /// [`SheetRenderer::splat_visible_sheet`] calls it after each sheet.
    pub fn composite_sheet(&mut self) {
        let w = self.frame.size[0];
        let (acc, img) = (&mut *self.buffers.accumulator, &mut *self.buffers.image);
        let (path, order) = (&self.path, self.order);
        for (y, span) in self.buffers.rows[..self.band.1].iter_mut().enumerate() {
            if span.is_empty() {
                continue;
            }
            if let Some(o) = &mut self.occlusion {
                let cols = (span.lo as usize, span.hi as usize);
                self.stats.pixels_composited += o.composite_row(y, cols, img, |px, closed, img| {
                    if closed {
                        acc[px].fill(P::ACC_ZERO);
                    } else {
                        path.composite_row(&mut acc[px.clone()], &mut img[px], order);
                    }
                });
            } else {
                let (lo, hi) = (y * w + span.lo as usize, y * w + span.hi as usize + 1);
                path.composite_row(&mut acc[lo..hi], &mut img[lo..hi], order);
                self.stats.pixels_composited += u64::from(span.hi - span.lo + 1);
            }
            *span = RowSpan::EMPTY;
        }
    }

    /// Ends the frame: front to back, composites the background under the result. Returns the
    /// counts.
    pub fn finish(self) -> RenderStats {
        if let (Order::FrontToBack, Some(bg)) = (self.order, self.background) {
            let n = self.frame.size[0] * self.band.1;
            self.path.over_row(&mut self.buffers.image[..n], &bg[..n]);
        }
        self.stats
    }
}
