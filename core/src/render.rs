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
//! [`Sampler`]) or [`FixedPath`] (integer table, `i64` accumulator, Q24 image; see
//! [`crate::fixed`]). One build holds both, so they can be compared on the same frame.

use crate::composite::{clamp_unit, over, RowSpan};
use crate::fixed::{self, FixedError, FixedTable, Placement};
use crate::frame::{FrameSetup, Order};
use crate::shade::{Lighting, Sample, Shader};
use crate::splat::{splat_rows, BufferError, ImageMut, Sampler, SplatStats};
use core::fmt;
use glam::Vec3;

/// Why a render step was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum RenderError {
    /// A caller buffer has the wrong size.
    Buffer(BufferError),
    /// A sheet holds the wrong number of samples.
    SheetLength {
        /// Samples expected (dims[a] × dims[b]).
        expected: usize,
        /// Samples given.
        got: usize,
    },
    /// A sheet index beyond the volume.
    SheetIndex {
        /// Index given.
        index: usize,
        /// Number of sheets.
        count: usize,
    },
    /// More sheets pushed into a [`SheetRing`] than the volume has.
    TooManySheets,
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Buffer(e) => e.fmt(f),
            Self::SheetLength { expected, got } => {
                write!(f, "sheet has {got} samples, expected {expected}")
            }
            Self::SheetIndex { index, count } => write!(f, "sheet {index} is outside 0..{count}"),
            Self::TooManySheets => f.write_str("more sheets than the volume has"),
        }
    }
}

impl core::error::Error for RenderError {}

impl From<BufferError> for RenderError {
    fn from(e: BufferError) -> Self {
        RenderError::Buffer(e)
    }
}

/// One sheet and its neighbours along the sheet axis (index − 1 and index + 1), each
/// `dims[a] × dims[b]` samples, row-major over the in-sheet axes. Missing neighbours (at the volume's
/// faces) are `None`; gradients there are one-sided.
#[derive(Clone, Copy, Debug)]
pub struct SheetWindow<'s, T> {
    /// Sheet index − 1.
    pub lower: Option<&'s [T]>,
    /// The sheet to render.
    pub current: &'s [T],
    /// Sheet index + 1.
    pub upper: Option<&'s [T]>,
}

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

/// What a [`SheetRenderer`] splats with and accumulates into.
pub trait Precision {
    /// A voxel's value as the splat takes it (premultiplied RGBA).
    type Value: Copy;
    /// A sheet-accumulator pixel.
    type Acc: Copy;
    /// A working-image pixel (premultiplied RGBA).
    type Pixel: Copy;
    /// The cleared accumulator pixel (what a caller fills a fresh accumulator with).
    const ACC_ZERO: Self::Acc;
    /// Transparent black.
    const CLEAR: Self::Pixel;
    /// The value of a voxel shaded to premultiplied RGBA (float, from the shader).
    fn value(&self, rgba: [f32; 4]) -> Self::Value;
    /// Whether a value is fully transparent (such voxels are skipped).
    fn is_transparent(value: &Self::Value) -> bool;
    /// Splats voxel (u, v) of sheet `sheet` of `frame` into `acc`, reporting touched rows.
    fn splat(
        &self,
        frame: &FrameSetup,
        sheet: usize,
        uv: (usize, usize),
        value: &Self::Value,
        acc: &mut ImageMut<'_, Self::Acc>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError>;
    /// Composites one row of the accumulated sheet into the image (over back to front, under
    /// front to back) and clears the accumulator row.
    fn composite_row(&self, acc: &mut [Self::Acc], image: &mut [Self::Pixel], order: Order);
    /// `front = front over back`, pixel by pixel.
    fn over_row(&self, front: &mut [Self::Pixel], back: &[Self::Pixel]);
}

/// Float accumulation through any [`Sampler`] (view table or direct).
#[derive(Debug)]
pub struct FloatPath<'a, S: ?Sized> {
    /// The footprint sampler.
    pub sampler: &'a S,
}

impl<S: Sampler + ?Sized> Precision for FloatPath<'_, S> {
    type Value = [f32; 4];
    type Acc = [f32; 4];
    type Pixel = [f32; 4];
    const ACC_ZERO: [f32; 4] = [0.0; 4];
    const CLEAR: [f32; 4] = [0.0; 4];

    #[inline]
    fn value(&self, rgba: [f32; 4]) -> [f32; 4] {
        rgba
    }

    #[inline]
    fn is_transparent(value: &[f32; 4]) -> bool {
        !(value[3] > 0.0)
    }

    #[inline]
    fn splat(
        &self,
        f: &FrameSetup,
        sheet: usize,
        (u, v): (usize, usize),
        value: &[f32; 4],
        acc: &mut ImageMut<'_, [f32; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError> {
        let cols = f.grid_to_screen;
        let (a, b) = f.in_sheet;
        let p = f.origin
            + cols.col(f.sheet_axis) * sheet as f32
            + cols.col(a) * u as f32
            + cols.col(b) * v as f32;
        let value = value.map(|c| c * f.cell_area);
        splat_rows(self.sampler, [p.x, p.y], &value, acc, touched)
    }

    fn composite_row(&self, acc: &mut [[f32; 4]], image: &mut [[f32; 4]], order: Order) {
        for (a, i) in acc.iter_mut().zip(image.iter_mut()) {
            let s = clamp_unit(*a);
            *a = [0.0; 4];
            *i = match order {
                Order::BackToFront => over(s, *i),
                Order::FrontToBack => over(*i, s),
            };
        }
    }

    fn over_row(&self, front: &mut [[f32; 4]], back: &[[f32; 4]]) {
        for (i, b) in front.iter_mut().zip(back) {
            *i = over(*i, *b);
        }
    }
}

/// Fixed-point accumulation (see [`crate::fixed`]): an integer M×M table, Q24 voxel placement,
/// `i64` accumulator and Q24 image. Splat and compositing use no floating point.
#[derive(Clone, Copy, Debug)]
pub struct FixedPath<'a, const M: usize> {
    table: &'a FixedTable<M>,
    place: Placement,
}

impl<'a, const M: usize> FixedPath<'a, M> {
    /// The fixed path for `frame` through `table` (built for this frame). Refused when the
    /// volume lands outside the fixed-point screen range.
    pub fn new(frame: &FrameSetup, table: &'a FixedTable<M>) -> Result<Self, FixedError> {
        Ok(FixedPath {
            table,
            place: Placement::new(frame)?,
        })
    }
}

impl<const M: usize> Precision for FixedPath<'_, M> {
    type Value = [u32; 4];
    type Acc = [i64; 4];
    type Pixel = [u32; 4];
    const ACC_ZERO: [i64; 4] = [0; 4];
    const CLEAR: [u32; 4] = [0; 4];

    #[inline]
    fn value(&self, rgba: [f32; 4]) -> [u32; 4] {
        fixed::quantise(rgba)
    }

    #[inline]
    fn is_transparent(value: &[u32; 4]) -> bool {
        value[3] == 0
    }

    #[inline]
    fn splat(
        &self,
        _: &FrameSetup,
        sheet: usize,
        (u, v): (usize, usize),
        value: &[u32; 4],
        acc: &mut ImageMut<'_, [i64; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError> {
        let center = self.place.at(sheet, u, v);
        Ok(fixed::splat::splat(self.table, center, value, acc, touched))
    }

    fn composite_row(&self, acc: &mut [[i64; 4]], image: &mut [[u32; 4]], order: Order) {
        fixed::composite::composite_row(acc, image, self.table.frac_bits(), order);
    }

    fn over_row(&self, front: &mut [[u32; 4]], back: &[[u32; 4]]) {
        fixed::composite::over_row(front, back);
    }
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
}

/// Renders sheets into caller-owned buffers, with float or fixed-point accumulation
/// ([`Precision`]).
pub struct SheetRenderer<'a, P: Precision> {
    frame: &'a FrameSetup,
    path: P,
    shader: Shader<'a>,
    lighting: Lighting,
    order: Order,
    buffers: RenderBuffers<'a, P::Acc, P::Pixel>,
    background: Option<&'a [P::Pixel]>,
    stats: RenderStats,
}

impl<'a, S: Sampler + ?Sized> SheetRenderer<'a, FloatPath<'a, S>> {
    /// Starts a float frame through `sampler` (a view table or the direct method); see
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
            FloatPath { sampler },
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
        let n = frame.image_len();
        for len in [
            buffers.accumulator.len(),
            buffers.image.len(),
            background.map_or(n, <[_]>::len),
        ] {
            if len < n {
                return Err(BufferError::TooSmall {
                    needed: n,
                    got: len,
                }
                .into());
            }
        }
        if buffers.rows.len() < frame.size[1] {
            return Err(BufferError::TooSmall {
                needed: frame.size[1],
                got: buffers.rows.len(),
            }
            .into());
        }
        if shader.tf.lut.len() < 2 || !(shader.tf.hi > shader.tf.lo) {
            return Err(BufferError::TooSmall {
                needed: 2,
                got: shader.tf.lut.len(),
            }
            .into());
        }
        let r = SheetRenderer {
            frame,
            path,
            shader,
            lighting: Lighting::new(frame),
            order,
            buffers,
            background,
            stats: RenderStats::default(),
        };
        match (order, background) {
            (Order::BackToFront, Some(bg)) => r.buffers.image[..n].copy_from_slice(&bg[..n]),
            _ => r.buffers.image[..n].fill(P::CLEAR),
        }
        r.buffers.rows[..frame.size[1]].fill(RowSpan::EMPTY);
        Ok(r)
    }

    /// The frame being rendered.
    pub fn frame(&self) -> &'a FrameSetup {
        self.frame
    }

    /// The compositing order.
    pub fn order(&self) -> Order {
        self.order
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
        let path = &self.path;
        let shade = |u: usize, v: usize| {
            let value = window.current[v * na + u].to_f32();
            path.value(shader.shade(
                &lighting,
                value,
                || gradient(f, &window, u, v),
                f.grid_index(index, u, v),
                f.dims,
            ))
        };
        Self::splat_sheet(
            f,
            &self.path,
            &mut self.buffers,
            &mut self.stats,
            index,
            lengths,
            shade,
        )?;
        self.composite_sheet();
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
        let path = &self.path;
        Self::splat_sheet(
            self.frame,
            path,
            &mut self.buffers,
            &mut self.stats,
            index,
            [Some(rgba.len()), None, None],
            |u, v| path.value(rgba[v * na + u]),
        )?;
        self.composite_sheet();
        Ok(())
    }

    /// [`SheetRenderer::render_shaded_sheet`] with values already in the precision's own format
    /// (for [`FixedPath`], Q24 premultiplied RGBA): no float work per voxel at all.
    pub fn render_value_sheet(
        &mut self,
        index: usize,
        values: &[P::Value],
    ) -> Result<(), RenderError> {
        let na = self.frame.sheet_shape().1;
        Self::splat_sheet(
            self.frame,
            &self.path,
            &mut self.buffers,
            &mut self.stats,
            index,
            [Some(values.len()), None, None],
            |u, v| values[v * na + u],
        )?;
        self.composite_sheet();
        Ok(())
    }

    /// Checks sheet `index` and the given sheet `lengths`, then splats the value that
    /// `shade(u, v)` gives for every voxel (skipping transparent ones).
    fn splat_sheet(
        f: &FrameSetup,
        path: &P,
        buffers: &mut RenderBuffers<'a, P::Acc, P::Pixel>,
        stats: &mut RenderStats,
        index: usize,
        lengths: [Option<usize>; 3],
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
        let mut image = ImageMut::new(&mut *buffers.accumulator, f.size[0], f.size[1], f.size[0])?;
        let rows = &mut *buffers.rows;
        for v in 0..nb {
            for u in 0..na {
                stats.voxels += 1;
                let value = shade(u, v);
                if P::is_transparent(&value) {
                    continue;
                }
                let s = path.splat(f, index, (u, v), &value, &mut image, |y, x0, x1| {
                    rows[y].include(x0, x1)
                })?;
                stats.voxels_splatted += 1;
                stats.pixel_updates += u64::from(s.pixels_updated);
            }
        }
        stats.sheets += 1;
        Ok(())
    }

    /// Composites the accumulated sheet into the working image over the rows it touched, and
    /// clears what it used.
    fn composite_sheet(&mut self) {
        let w = self.frame.size[0];
        let (acc, img) = (&mut *self.buffers.accumulator, &mut *self.buffers.image);
        for (y, span) in self.buffers.rows[..self.frame.size[1]]
            .iter_mut()
            .enumerate()
        {
            if span.is_empty() {
                continue;
            }
            let (lo, hi) = (y * w + span.lo as usize, y * w + span.hi as usize + 1);
            self.path
                .composite_row(&mut acc[lo..hi], &mut img[lo..hi], self.order);
            self.stats.pixels_composited += u64::from(span.hi - span.lo + 1);
            *span = RowSpan::EMPTY;
        }
    }

    /// Ends the frame: front to back, composites the background under the result. Returns the
    /// counts.
    pub fn finish(self) -> RenderStats {
        if let (Order::FrontToBack, Some(bg)) = (self.order, self.background) {
            let n = self.frame.image_len();
            self.path.over_row(&mut self.buffers.image[..n], &bg[..n]);
        }
        self.stats
    }
}

/// World-space gradient (value units per world unit) at voxel (u, v) of `window`'s current
/// sheet: central differences along each grid axis (one-sided at the volume's faces, zero along
/// an axis one voxel thick), turned into world space by G⁻ᵀ so anisotropic and sheared grids
/// are honoured. Non-finite neighbours count as the centre's value.
pub fn gradient<T: Sample>(
    frame: &FrameSetup,
    window: &SheetWindow<'_, T>,
    u: usize,
    v: usize,
) -> Vec3 {
    let (_, na, nb) = frame.sheet_shape();
    let (k, (a, b)) = (frame.sheet_axis, frame.in_sheet);
    let cur = window.current;
    let here = v * na + u;
    let centre = cur[here].to_f32();
    // A non-finite neighbour is missing data: it stands in as the centre's value (no slope toward
    // it), so no NaN reaches a normal.
    let finite = |x: f32| if x.is_finite() { x } else { centre };
    let at = |uu: usize, vv: usize| finite(cur[vv * na + uu].to_f32());
    let mut g = [0.0f32; 3];
    g[a] = central(u, na, |x| at(x, v));
    g[b] = central(v, nb, |y| at(u, y));
    let lower = window.lower.map(|s| finite(s[here].to_f32()));
    let upper = window.upper.map(|s| finite(s[here].to_f32()));
    g[k] = match (lower, upper) {
        (Some(lo), Some(hi)) => 0.5 * (hi - lo),
        (Some(lo), None) => centre - lo,
        (None, Some(hi)) => hi - centre,
        (None, None) => 0.0,
    };
    frame.grid_inverse_transpose * Vec3::from_array(g)
}

/// Central difference of `f` at `i` on 0..n (one-sided at the ends, zero if n = 1), per grid step.
#[inline]
fn central(i: usize, n: usize, f: impl Fn(usize) -> f32) -> f32 {
    if n < 2 {
        return 0.0;
    }
    let (lo, hi) = (i.saturating_sub(1), (i + 1).min(n - 1));
    (f(hi) - f(lo)) / (hi - lo) as f32
}

/// Three sheet buffers in caller-owned storage, filled in sequence order, so a source that cannot
/// seek (a pipe, a sensor) never needs more than three sheets in memory.
///
/// Push sheets in the order [`FrameSetup::sheet_at`] gives; after each push, [`SheetRing::push`]
/// reports the sequence position whose neighbours are now known, and [`SheetRing::window`] lends
/// its [`SheetWindow`]. After the last push, [`SheetRing::last`] gives the final position.
#[derive(Debug)]
pub struct SheetRing<'a, T> {
    storage: &'a mut [T],
    len: usize,
    pushed: usize,
    total: usize,
    ascending: bool,
}

impl<'a, T: Copy> SheetRing<'a, T> {
    /// A ring over `storage` (at least 3 × sheet length) for `frame`'s sheets in `order`.
    pub fn new(
        storage: &'a mut [T],
        frame: &FrameSetup,
        order: Order,
    ) -> Result<Self, RenderError> {
        let len = frame.sheet_shape().0;
        if storage.len() < 3 * len {
            return Err(BufferError::TooSmall {
                needed: 3 * len,
                got: storage.len(),
            }
            .into());
        }
        Ok(SheetRing {
            storage,
            len,
            pushed: 0,
            total: frame.sheet_count(),
            ascending: frame.ascending_for(order),
        })
    }

    /// Fills the next sheet in sequence by calling `fill` with its slot (exactly one sheet long);
    /// returns the sequence position that is now complete (the one before), if any.
    pub fn push_with<E>(
        &mut self,
        fill: impl FnOnce(&mut [T]) -> Result<(), E>,
    ) -> Result<Option<usize>, E>
    where
        E: From<RenderError>,
    {
        if self.pushed >= self.total {
            return Err(RenderError::TooManySheets.into());
        }
        let slot = self.pushed % 3;
        fill(&mut self.storage[slot * self.len..(slot + 1) * self.len])?;
        self.pushed += 1;
        Ok(if self.pushed >= 2 {
            Some(self.pushed - 2)
        } else {
            None
        })
    }

    /// Copies the next sheet in; see [`SheetRing::push_with`].
    pub fn push(&mut self, sheet: &[T]) -> Result<Option<usize>, RenderError> {
        if sheet.len() != self.len {
            return Err(RenderError::SheetLength {
                expected: self.len,
                got: sheet.len(),
            });
        }
        self.push_with(|slot| {
            slot.copy_from_slice(sheet);
            Ok(())
        })
    }

    /// The last sequence position, once every sheet has been pushed.
    pub fn last(&self) -> Option<usize> {
        (self.pushed == self.total && self.total > 0).then(|| self.total - 1)
    }

    /// The sheet index at sequence position `n`.
    pub fn sheet_index(&self, n: usize) -> usize {
        if self.ascending {
            n
        } else {
            self.total - 1 - n
        }
    }

    /// The window of sequence position `n` (which must be one of the last two pushed).
    pub fn window(&self, n: usize) -> SheetWindow<'_, T> {
        let slot = |m: usize| &self.storage[(m % 3) * self.len..(m % 3 + 1) * self.len];
        let before = (n >= 1).then(|| slot(n - 1));
        let after = (n + 1 < self.pushed).then(|| slot(n + 1));
        let (lower, upper) = if self.ascending {
            (before, after)
        } else {
            (after, before)
        };
        SheetWindow {
            lower,
            current: slot(n),
            upper,
        }
    }
}
