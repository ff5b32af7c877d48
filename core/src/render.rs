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

use crate::composite::{clamp_unit, over, RowSpan};
use crate::frame::{FrameSetup, Order};
use crate::shade::{Lighting, Sample, Shader};
use crate::splat::{splat_rows, BufferError, ImageMut, Sampler};
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
/// (one per image row).
#[derive(Debug)]
pub struct RenderBuffers<'a> {
    /// Sheet accumulator, premultiplied RGBA; must be all zero at the start (left all zero).
    pub accumulator: &'a mut [[f32; 4]],
    /// Working image, premultiplied RGBA, row-major, top row first: the result.
    pub image: &'a mut [[f32; 4]],
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
}

/// Renders sheets into caller-owned buffers. Generic over the footprint sampler (a view table or
/// the direct method).
pub struct SheetRenderer<'a, S: ?Sized> {
    frame: &'a FrameSetup,
    sampler: &'a S,
    shader: Shader<'a>,
    lighting: Lighting,
    order: Order,
    buffers: RenderBuffers<'a>,
    background: Option<&'a [[f32; 4]]>,
    stats: RenderStats,
}

impl<'a, S: Sampler + ?Sized> SheetRenderer<'a, S> {
    /// Starts a frame. `background` is the starting working image (back to front) or what is
    /// composited under the result at [`SheetRenderer::finish`] (front to back); `None` means
    /// transparent black. Checks every buffer's size.
    pub fn new(
        frame: &'a FrameSetup,
        sampler: &'a S,
        shader: Shader<'a>,
        order: Order,
        buffers: RenderBuffers<'a>,
        background: Option<&'a [[f32; 4]]>,
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
            sampler,
            shader,
            lighting: Lighting::new(frame),
            order,
            buffers,
            background,
            stats: RenderStats::default(),
        };
        match (order, background) {
            (Order::BackToFront, Some(bg)) => r.buffers.image[..n].copy_from_slice(&bg[..n]),
            _ => r.buffers.image[..n].fill([0.0; 4]),
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
        self.splat_sheet(index, lengths, |u, v| {
            let value = window.current[v * na + u].to_f32();
            shader.shade(
                &lighting,
                value,
                || gradient(f, &window, u, v),
                f.grid_index(index, u, v),
                f.dims,
            )
        })
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
        self.splat_sheet(index, [Some(rgba.len()), None, None], |u, v| {
            rgba[v * na + u]
        })
    }

    /// Checks sheet `index` and the given sheet `lengths`, then splats the premultiplied RGBA that
    /// `shade(u, v)` gives for every voxel (skipping α = 0) and composites the sheet.
    fn splat_sheet(
        &mut self,
        index: usize,
        lengths: [Option<usize>; 3],
        mut shade: impl FnMut(usize, usize) -> [f32; 4],
    ) -> Result<(), RenderError> {
        let f = self.frame;
        let count = f.sheet_count();
        if index >= count {
            return Err(RenderError::SheetIndex { index, count });
        }
        let (len, na, nb) = f.sheet_shape();
        if let Some(got) = lengths.into_iter().flatten().find(|&l| l != len) {
            return Err(RenderError::SheetLength { expected: len, got });
        }
        let (k, (a, b)) = (f.sheet_axis, f.in_sheet);
        let cols = f.grid_to_screen;
        let (ca, cb) = (cols.col(a), cols.col(b));
        let base = f.origin + cols.col(k) * index as f32;
        let mut image = ImageMut::new(
            &mut *self.buffers.accumulator,
            f.size[0],
            f.size[1],
            f.size[0],
        )?;
        let rows = &mut *self.buffers.rows;
        for v in 0..nb {
            for u in 0..na {
                self.stats.voxels += 1;
                let rgba = shade(u, v);
                if !(rgba[3] > 0.0) {
                    continue;
                }
                let p = base + ca * u as f32 + cb * v as f32;
                let value = rgba.map(|c| c * f.cell_area);
                let s = splat_rows(self.sampler, [p.x, p.y], &value, &mut image, |y, x0, x1| {
                    rows[y].include(x0, x1)
                })?;
                self.stats.voxels_splatted += 1;
                self.stats.pixel_updates += u64::from(s.pixels_updated);
            }
        }
        self.composite_sheet();
        self.stats.sheets += 1;
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
            let row = y * w;
            for x in span.lo as usize..=span.hi as usize {
                let s = clamp_unit(acc[row + x]);
                acc[row + x] = [0.0; 4];
                let i = &mut img[row + x];
                *i = match self.order {
                    Order::BackToFront => over(s, *i),
                    Order::FrontToBack => over(*i, s),
                };
            }
            self.stats.pixels_composited += u64::from(span.hi - span.lo + 1);
            *span = RowSpan::EMPTY;
        }
    }

    /// Ends the frame: front to back, composites the background under the result. Returns the
    /// counts.
    pub fn finish(self) -> RenderStats {
        if let (Order::FrontToBack, Some(bg)) = (self.order, self.background) {
            let n = self.frame.image_len();
            for (i, b) in self.buffers.image[..n].iter_mut().zip(&bg[..n]) {
                *i = over(*i, *b);
            }
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
