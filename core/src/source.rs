//! Sheet sources: where the voxels come from when the whole volume is never in memory — a file
//! read a sheet at a time, a pipe, a sensor, a network, flash.
//!
//! A source fills one sheet (row-major over the sheet's in-sheet axes, see [`crate::frame`]) on
//! request. [`render_from`] asks for the sheets of a frame in compositing order and keeps only
//! three of them (in a caller-owned [`SheetRing`]), so memory stays bounded by the image and three
//! sheets whatever the volume's size. A source that can only deliver sheets in one order (a pipe:
//! ascending index along its slice axis) says so with [`SheetSource::sequential_axis`], and the
//! driver refuses a frame it cannot serve before reading anything.

use crate::frame::Order;
use crate::render::{Precision, RenderError, SheetRenderer, SheetRing};
use crate::shade::Sample;

/// A source of sheets.
pub trait SheetSource {
    /// The sample type delivered.
    type Sample: Sample;
    /// The source's error; must be able to carry the renderer's.
    type Error: From<RenderError>;

    /// Fills `out` (exactly one sheet) with sheet `index` along grid axis `axis`.
    ///
    /// The layout: the sheet's two other grid axes a < b ([`crate::geometry::in_sheet_axes`]),
    /// row-major with a fastest: `out[v · dims[a] + u]` is the sample at index `index` on `axis`,
    /// `u` on a and `v` on b. For `axis` = 2 (k) that is a z-slice as files store it, x fastest.
    fn read_sheet(
        &mut self,
        axis: usize,
        index: usize,
        out: &mut [Self::Sample],
    ) -> Result<(), Self::Error>;

    /// `Some(axis)` if this source can only deliver sheets along `axis`, in ascending index order,
    /// each once (a pipe or a sensor); `None` if it can read any sheet of any axis (a seekable file).
    fn sequential_axis(&self) -> Option<usize> {
        None
    }
}

/// A source borrowed mutably is a source (so adaptors such as [`crate::lod::Coarsened`] can wrap
/// a `&mut dyn SheetSource` and nest to a depth chosen at run time).
impl<S: SheetSource + ?Sized> SheetSource for &mut S {
    type Sample = S::Sample;
    type Error = S::Error;
    fn read_sheet(
        &mut self,
        axis: usize,
        index: usize,
        out: &mut [Self::Sample],
    ) -> Result<(), Self::Error> {
        (**self).read_sheet(axis, index, out)
    }
    fn sequential_axis(&self) -> Option<usize> {
        (**self).sequential_axis()
    }
}

/// Why a source cannot serve a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OrderMismatch {
    /// The axis the source delivers sheets along.
    pub source_axis: usize,
    /// The frame's sheet axis.
    pub frame_axis: usize,
}

impl core::fmt::Display for OrderMismatch {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let name = |a: usize| ["i (x)", "j (y)", "k (z)"].get(a).copied().unwrap_or("?");
        write!(
            f,
            "the source delivers sheets along axis {} in order, but this view splats sheets along \
             axis {}: read the volume into memory (or from a seekable file), or choose a view whose \
             sheet axis is the source's",
            name(self.source_axis),
            name(self.frame_axis)
        )
    }
}

impl core::error::Error for OrderMismatch {}

/// The compositing order to use with `source` for `renderer`'s frame: `preferred` for a seekable
/// source; for a sequential one, the order its ascending delivery implies, or an
/// [`OrderMismatch`] if its axis is not the frame's sheet axis.
pub fn order_for<S: SheetSource>(
    source: &S,
    frame: &crate::frame::FrameSetup,
    preferred: Order,
) -> Result<Order, OrderMismatch> {
    match source.sequential_axis() {
        None => Ok(preferred),
        Some(axis) if axis == frame.sheet_axis => Ok(frame.order_for_ascending()),
        Some(axis) => Err(OrderMismatch {
            source_axis: axis,
            frame_axis: frame.sheet_axis,
        }),
    }
}

/// Renders every sheet of `renderer`'s frame from `source`, in the renderer's compositing order,
/// through `ring` (three sheets of caller storage). Call [`SheetRenderer::finish`] afterwards.
/// For a sequential source, pick the renderer's order with [`order_for`] first.
pub fn render_from<P, Src>(
    renderer: &mut SheetRenderer<'_, P>,
    ring: &mut SheetRing<'_, Src::Sample>,
    source: &mut Src,
) -> Result<(), Src::Error>
where
    P: Precision,
    Src: SheetSource,
{
    render_all_from(core::slice::from_mut(renderer), ring, source)
}

/// [`render_from`] for several renderers of one frame and compositing order (the bands of an
/// image, say, or a few bands sampled from it), every sheet read once and rendered by each in
/// turn. The first renderer's frame sets the sheets; no renderer, nothing read. A ring made for
/// another compositing order than a renderer's is refused ([`RenderError::RingOrder`]); make it
/// with [`SheetRing::for_renderer`].
pub fn render_all_from<P, Src>(
    renderers: &mut [SheetRenderer<'_, P>],
    ring: &mut SheetRing<'_, Src::Sample>,
    source: &mut Src,
) -> Result<(), Src::Error>
where
    P: Precision,
    Src: SheetSource,
{
    let Some(first) = renderers.first() else {
        return Ok(());
    };
    // The order is the renderers' (given once, to them); a ring built for another one would feed
    // the sheets back to front to a front-to-back renderer: refused, not a silently wrong image.
    if let Some(r) = renderers.iter().find(|r| r.order() != ring.order()) {
        return Err(RenderError::RingOrder {
            ring: ring.order(),
            renderer: r.order(),
        }
        .into());
    }
    let (axis, count) = (first.frame().sheet_axis, first.frame().sheet_count());
    for step in 0..count {
        let s = ring.sheet_index(step);
        if let Some(done) = ring.push_with(|slot| source.read_sheet(axis, s, slot))? {
            for r in renderers.iter_mut() {
                r.render_sheet(ring.sheet_index(done), ring.window(done))?;
            }
        }
    }
    for r in renderers.iter_mut() {
        ring.finish(r)?;
    }
    Ok(())
}

/// A sample that can be missing: the value the renderer treats as absent data (classified
/// transparent, weight zero in the continuous model, no slope toward it in a neighbour's gradient).
/// NaN for the float types.
pub trait MaybeMissing: Sample {
    /// The missing sample.
    const MISSING: Self;
}

impl MaybeMissing for f32 {
    const MISSING: f32 = f32::NAN;
}

impl MaybeMissing for f64 {
    const MISSING: f64 = f64::NAN;
}

/// A box of voxel indices along i, j, k, inclusive at both ends: `lo[c] ..= hi[c]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CropBox {
    /// The first index kept along each axis.
    pub lo: [usize; 3],
    /// The last index kept along each axis.
    pub hi: [usize; 3],
}

impl CropBox {
    /// Whether voxel `g` (i, j, k) lies in the box.
    pub fn contains(&self, g: [usize; 3]) -> bool {
        (0..3).all(|c| self.lo[c] <= g[c] && g[c] <= self.hi[c])
    }
}

/// `source` cropped to `crop`: every sample outside the box is [`MaybeMissing::MISSING`], so the
/// renderer splats only the box's voxels, in their places, and a voxel next to the cut takes its
/// gradient from its kept neighbours. Every sheet is still read from the source (a sequential
/// source must deliver them all; a sheet wholly outside the box is read and discarded), so the
/// memory stays the driver's three sheets. `dims` are the source's grid (the whole volume's).
pub struct Cropped<S> {
    /// The source cropped.
    pub source: S,
    /// The voxels kept.
    pub crop: CropBox,
    /// The source's grid, voxels along i, j, k.
    pub dims: [usize; 3],
}

impl<S: SheetSource> SheetSource for Cropped<S>
where
    S::Sample: MaybeMissing,
{
    type Sample = S::Sample;
    type Error = S::Error;

    fn read_sheet(
        &mut self,
        axis: usize,
        index: usize,
        out: &mut [Self::Sample],
    ) -> Result<(), Self::Error> {
        self.source.read_sheet(axis, index, out)?;
        let missing = <S::Sample as MaybeMissing>::MISSING;
        let (lo, hi) = (self.crop.lo, self.crop.hi);
        if index < lo[axis] || index > hi[axis] {
            out.fill(missing);
            return Ok(());
        }
        let (a, b) = crate::geometry::in_sheet_axes(axis);
        let na = self.dims[a].max(1);
        for (v, row) in out.chunks_mut(na).enumerate() {
            if v < lo[b] || v > hi[b] {
                row.fill(missing);
            } else {
                let (start, end) = (lo[a].min(row.len()), (hi[a] + 1).min(row.len()));
                row[..start].fill(missing);
                row[end..].fill(missing);
            }
        }
        Ok(())
    }

    fn sequential_axis(&self) -> Option<usize> {
        self.source.sequential_axis()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A source whose sample at (i, j, k) is its linear index, with no error of its own.
    struct Counting([usize; 3]);

    impl SheetSource for Counting {
        type Sample = f32;
        type Error = RenderError;
        fn read_sheet(
            &mut self,
            axis: usize,
            s: usize,
            out: &mut [f32],
        ) -> Result<(), RenderError> {
            let (a, b) = crate::geometry::in_sheet_axes(axis);
            let d = self.0;
            for (n, x) in out.iter_mut().enumerate() {
                let mut g = [0; 3];
                (g[axis], g[a], g[b]) = (s, n % d[a], n / d[a]);
                *x = (g[0] + d[0] * (g[1] + d[1] * g[2])) as f32;
            }
            Ok(())
        }
    }

    /// Every sheet of every axis, sample by sample against the box: kept inside, NaN outside.
    #[test]
    fn a_cropped_source_is_the_source_inside_the_box_and_missing_outside() {
        let dims = [5, 4, 3];
        let crop = CropBox {
            lo: [1, 0, 1],
            hi: [3, 2, 2],
        };
        let mut c = Cropped {
            source: Counting(dims),
            crop,
            dims,
        };
        for axis in 0..3 {
            let (a, b) = crate::geometry::in_sheet_axes(axis);
            let mut out = [0.0f32; 20];
            let len = dims[a] * dims[b];
            for s in 0..dims[axis] {
                c.read_sheet(axis, s, &mut out[..len]).unwrap();
                for (n, x) in out[..len].iter().enumerate() {
                    let mut g = [0; 3];
                    (g[axis], g[a], g[b]) = (s, n % dims[a], n / dims[a]);
                    let want = (g[0] + dims[0] * (g[1] + dims[1] * g[2])) as f32;
                    if crop.contains(g) {
                        assert_eq!(*x, want, "{g:?} along {axis}");
                    } else {
                        assert!(x.is_nan(), "{g:?} along {axis}: {x}");
                    }
                }
            }
        }
    }
}
