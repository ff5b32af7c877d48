//! The sheets a renderer reads: one sheet and its two neighbours ([`SheetWindow`]), the ring of
//! three caller-owned sheet buffers a non-seeking source fills in sequence ([`SheetRing`]), and the
//! gradient across them.

use super::RenderError;
use crate::frame::{FrameSetup, Order};
use crate::shade::Sample;
use crate::splat::BufferError;
use glam::Vec3;

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
    order: Order,
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
            order,
        })
    }

    /// A ring over `storage` for `renderer`'s frame and compositing order (the order given once,
    /// to the renderer).
    pub fn for_renderer<P: super::Precision>(
        storage: &'a mut [T],
        renderer: &super::SheetRenderer<'_, P>,
    ) -> Result<Self, RenderError> {
        Self::new(storage, renderer.frame(), renderer.order())
    }

    /// The compositing order the ring delivers sheets for.
    pub fn order(&self) -> Order {
        self.order
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

    /// Ends the delivery: renders the last sheet (which no later push completes) through
    /// `renderer`, and refuses a frame whose sheets were not all pushed
    /// ([`RenderError::MissingSheets`]) rather than leave it silently short. Call it after the
    /// last [`SheetRing::push`] (each push's completed sheet rendered), then
    /// [`super::SheetRenderer::finish`].
    pub fn finish<P: super::Precision>(
        &self,
        renderer: &mut super::SheetRenderer<'_, P>,
    ) -> Result<(), RenderError>
    where
        T: Sample,
    {
        match self.last() {
            Some(last) => renderer.render_sheet(self.sheet_index(last), self.window(last)),
            None => Err(RenderError::MissingSheets {
                delivered: self.pushed,
                expected: self.total,
            }),
        }
    }

    /// Sheets pushed so far.
    pub fn delivered(&self) -> usize {
        self.pushed
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
