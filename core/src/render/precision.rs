//! The two precisions a [`SheetRenderer`](super::SheetRenderer) runs in: [`FloatPath`] (f32
//! accumulator and image, any [`Sampler`]) and [`FixedPath`] (integer table, `i64` accumulator, Q24
//! image; see [`crate::fixed`]).

use super::absorption::{extinction_layer, Absorption};
use super::RenderError;
use crate::composite::{clamp_unit, over};
use crate::fixed::compact::{self, CompactPlacement, CompactStencils};
use crate::fixed::stencil::FixedStencils;
use crate::fixed::{self, FixedError, FixedTable, Placement};
use crate::frame::{FrameSetup, Order};
use crate::splat::{ImageMut, SplatStats, Splatter};

/// What a [`SheetRenderer`](super::SheetRenderer) splats with and accumulates into.
pub trait Precision {
    /// A voxel's value as the splat takes it (premultiplied RGBA).
    type Value: Copy;
    /// A sheet-accumulator pixel.
    type Acc: Copy;
    /// A working-image pixel (premultiplied RGBA).
    type Pixel: Copy;
    /// Whether this precision can render a perspective frame (per-voxel footprints); a renderer
    /// refuses a perspective frame with [`RenderError::Projection`] otherwise.
    const PERSPECTIVE: bool = false;
    /// The cleared accumulator pixel (what a caller fills a fresh accumulator with).
    const ACC_ZERO: Self::Acc;
    /// Transparent black.
    const CLEAR: Self::Pixel;
    /// The value of a voxel shaded to premultiplied RGBA (float, from the shader).
    fn value(&self, rgba: [f32; 4]) -> Self::Value;
    /// Whether a value is fully transparent (such voxels are skipped).
    fn is_transparent(value: &Self::Value) -> bool;
    /// Splats voxel (u, v) of sheet `sheet` of `frame` into `acc`, whose first row is image row
    /// `row0` (a band; 0 for the whole image), reporting touched rows (relative to `acc`).
    #[allow(clippy::too_many_arguments)]
    fn splat(
        &self,
        frame: &FrameSetup,
        sheet: usize,
        uv: (usize, usize),
        row0: usize,
        value: &Self::Value,
        acc: &mut ImageMut<'_, Self::Acc>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, RenderError>;
    /// Composites one row of the accumulated sheet into the image (over back to front, under
    /// front to back) and clears the accumulator row.
    fn composite_row(&self, acc: &mut [Self::Acc], image: &mut [Self::Pixel], order: Order);
    /// `front = front over back`, pixel by pixel.
    fn over_row(&self, front: &mut [Self::Pixel], back: &[Self::Pixel]);
    /// A working-image pixel of opacity `alpha` (0 to 1) in this precision's format, rounded up,
    /// colour zero: the threshold [`Precision::reaches`] compares with (occlusion culling,
    /// [`super::SheetRenderer::with_occlusion`]).
    fn opacity_pixel(alpha: f32) -> Self::Pixel;
    /// Whether `pixel`'s opacity is at least `at`'s.
    fn reaches(pixel: &Self::Pixel, at: &Self::Pixel) -> bool;
}

/// How the float path places one voxel of a sheet in the accumulator: any [`Splatter`] (a
/// footprint sampler or phase stencils shared by the whole orthographic view, the voxel at its
/// screen position with the frame's cell area), or one footprint per voxel for a perspective
/// frame ([`super::PerVoxel`]). The float path is one, whatever places its voxels.
pub trait VoxelSplat {
    /// Whether it places the voxels of a perspective frame (a renderer refuses a perspective
    /// frame with [`RenderError::Projection`] otherwise).
    const PERSPECTIVE: bool = false;
    /// Splats voxel (u, v) of sheet `sheet` of `frame`, valued `value` in `absorption`'s model
    /// ([`FloatPath`]'s accumulation), into `acc`, whose first row is image row `row0`;
    /// reports touched rows (relative to `acc`).
    #[allow(clippy::too_many_arguments)]
    fn splat_voxel_of(
        &self,
        frame: &FrameSetup,
        sheet: usize,
        uv: (usize, usize),
        row0: usize,
        value: &[f32; 4],
        absorption: Absorption,
        acc: &mut ImageMut<'_, [f32; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, RenderError>;
}

impl<S: Splatter + ?Sized> VoxelSplat for S {
    #[inline]
    fn splat_voxel_of(
        &self,
        f: &FrameSetup,
        sheet: usize,
        (u, v): (usize, usize),
        row0: usize,
        value: &[f32; 4],
        _: Absorption,
        acc: &mut ImageMut<'_, [f32; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, RenderError> {
        let p = float_position(f, sheet, u, v);
        let value = value.map(|c| c * f.cell_area);
        // Subtracting a whole number of rows is exact here (|p.y| < 2²⁴), so every pixel of a
        // band sees the offsets, and so the weights, of a whole-image render.
        Ok(self.splat_voxel([p[0], p[1] - row0 as f32], &value, acc, touched)?)
    }
}

/// Float accumulation: f32 accumulator and image, each voxel placed by a [`VoxelSplat`] (a
/// footprint [`Sampler`](crate::Sampler) (view table or direct) or a view's phase stencils
/// ([`crate::stencil::Stencils`]) in an orthographic frame; [`super::PerVoxel`] in perspective).
///
/// A sheet composites the [`Absorption`] model it is given: opacity (the paper's sheets: the
/// premultiplied values summed, clamped to [0, 1]) or extinction (each voxel's sheet opacity α
/// splatted as its optical depth −ln(1 − α) and emission, the sheet a layer of opacity
/// 1 − e^(−τ): [`super::absorption::extinction_layer`]).
#[derive(Debug)]
pub struct FloatPath<'a, S: ?Sized> {
    /// The footprint sampler.
    pub sampler: &'a S,
    /// The model each sheet composites.
    pub absorption: Absorption,
}

impl<'a, S: ?Sized> FloatPath<'a, S> {
    /// Sheets through `sampler`, compositing the default model (opacity, the paper's).
    pub fn new(sampler: &'a S) -> Self {
        FloatPath {
            sampler,
            absorption: Absorption::Opacity,
        }
    }

    /// The same path compositing `absorption`'s model.
    pub fn with_absorption(self, absorption: Absorption) -> Self {
        FloatPath { absorption, ..self }
    }
}

impl<S: ?Sized> Clone for FloatPath<'_, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S: ?Sized> Copy for FloatPath<'_, S> {}

impl<S: VoxelSplat + ?Sized> Precision for FloatPath<'_, S> {
    type Value = [f32; 4];
    type Acc = [f32; 4];
    type Pixel = [f32; 4];
    const PERSPECTIVE: bool = S::PERSPECTIVE;
    const ACC_ZERO: [f32; 4] = [0.0; 4];
    const CLEAR: [f32; 4] = [0.0; 4];

    #[inline]
    fn value(&self, rgba: [f32; 4]) -> [f32; 4] {
        match self.absorption {
            Absorption::Opacity => rgba,
            Absorption::Extinction => Absorption::Extinction.voxel_value(rgba).unwrap_or([0.0; 4]),
        }
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
        uv: (usize, usize),
        row0: usize,
        value: &[f32; 4],
        acc: &mut ImageMut<'_, [f32; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, RenderError> {
        self.sampler
            .splat_voxel_of(f, sheet, uv, row0, value, self.absorption, acc, touched)
    }

    fn composite_row(&self, acc: &mut [[f32; 4]], image: &mut [[f32; 4]], order: Order) {
        match self.absorption {
            Absorption::Opacity => float_composite_row(acc, image, order),
            Absorption::Extinction => extinction_composite_row(acc, image, order),
        }
    }

    fn over_row(&self, front: &mut [[f32; 4]], back: &[[f32; 4]]) {
        float_over_row(front, back);
    }

    fn opacity_pixel(alpha: f32) -> [f32; 4] {
        float_opacity_pixel(alpha)
    }

    #[inline]
    fn reaches(pixel: &[f32; 4], at: &[f32; 4]) -> bool {
        float_reaches(pixel, at)
    }
}

/// A float image pixel of opacity `alpha`, colour zero: the float path's and the slab renderer's
/// culling threshold ([`Precision::opacity_pixel`]).
pub(super) fn float_opacity_pixel(alpha: f32) -> [f32; 4] {
    [0.0, 0.0, 0.0, alpha]
}

/// Whether a float pixel's opacity is at least `at`'s ([`Precision::reaches`]).
#[inline]
pub(super) fn float_reaches(pixel: &[f32; 4], at: &[f32; 4]) -> bool {
    pixel[3] >= at[3]
}

/// An extinction sheet's compositing: each pixel's [E, τ] as a layer
/// ([`super::absorption::extinction_layer`]), over or under the image; clears the accumulator.
fn extinction_composite_row(acc: &mut [[f32; 4]], image: &mut [[f32; 4]], order: Order) {
    for (a, i) in acc.iter_mut().zip(image.iter_mut()) {
        let layer = extinction_layer(*a);
        *i = match order {
            Order::BackToFront => over(layer, *i),
            Order::FrontToBack => over(*i, layer),
        };
        *a = [0.0; 4];
    }
}

/// The float paths' compositing: clamp the accumulated sheet to [0, 1], over or under the image,
/// clear the accumulator.
fn float_composite_row(acc: &mut [[f32; 4]], image: &mut [[f32; 4]], order: Order) {
    // The order settled per row, so each loop is straight-line per pixel.
    match order {
        Order::BackToFront => {
            for (a, i) in acc.iter_mut().zip(image.iter_mut()) {
                *i = over(clamp_unit(*a), *i);
                *a = [0.0; 4];
            }
        }
        Order::FrontToBack => {
            for (a, i) in acc.iter_mut().zip(image.iter_mut()) {
                *i = over(*i, clamp_unit(*a));
                *a = [0.0; 4];
            }
        }
    }
}

pub(super) fn float_over_row(front: &mut [[f32; 4]], back: &[[f32; 4]]) {
    for (i, b) in front.iter_mut().zip(back) {
        *i = over(*i, *b);
    }
}

/// Screen position (pixels) of voxel (u, v) of sheet `sheet`.
#[inline(always)]
pub(super) fn float_position(f: &FrameSetup, sheet: usize, u: usize, v: usize) -> [f32; 2] {
    let cols = f.grid_to_screen;
    let (a, b) = f.in_sheet;
    let p = f.origin
        + cols.col(f.sheet_axis) * sheet as f32
        + cols.col(a) * u as f32
        + cols.col(b) * v as f32;
    [p.x, p.y]
}

/// Fixed-point accumulation (see [`crate::fixed`]): an integer M×M table, Q24 voxel placement,
/// `i64` accumulator and Q24 image. Splat and compositing use no floating point.
#[derive(Clone, Copy, Debug)]
pub struct FixedPath<'a, const M: usize> {
    table: &'a FixedTable<M>,
    stencils: Option<FixedStencils<'a, M>>,
    place: Placement,
    /// The caller's bound on voxel channel values ([`FixedPath::with_value_bound`]).
    value_bound: Option<u32>,
    /// That bound, when it lets the stencils add without saturating (it keeps every sum in
    /// range); `None` otherwise.
    unsaturated_below: Option<u32>,
}

impl<'a, const M: usize> FixedPath<'a, M> {
    /// The fixed path for `frame` through `table` (built for this frame), splatting by the table
    /// walk. Refused when the volume lands outside the fixed-point screen range, and for a
    /// perspective frame ([`FixedError::Perspective`]: the fixed path places voxels with one
    /// integer affine map and one table per view).
    pub fn new(frame: &FrameSetup, table: &'a FixedTable<M>) -> Result<Self, FixedError> {
        if frame.camera().is_some() {
            return Err(FixedError::Perspective);
        }
        Ok(FixedPath {
            table,
            stencils: None,
            place: Placement::new(frame)?,
            value_bound: None,
            unsaturated_below: None,
        })
    }

    /// Promises that no voxel this path splats has a channel above `bound` (Q24; a shaded voxel
    /// is at most [`fixed::ONE`]). Where that keeps every pixel's sum within the `i64`
    /// accumulator ([`FixedStencils::exact_below`]), the stencils add without saturating, which
    /// gives the same bits faster; a voxel above the bound is then refused
    /// ([`RenderError::ValueAboveBound`]) rather than risk a wrapped sum.
    pub fn with_value_bound(mut self, bound: u32) -> Self {
        self.value_bound = Some(bound);
        self.settle();
        self
    }

    /// Whether the stencils add without saturating (see [`FixedPath::with_value_bound`]).
    pub fn unsaturated(&self) -> bool {
        self.unsaturated_below.is_some()
    }

    fn settle(&mut self) {
        let (a, b) = (self.place.along_a, self.place.along_b);
        self.unsaturated_below = self.value_bound.filter(|&bound| {
            self.stencils
                .and_then(|s| s.exact_below(a, b))
                .is_some_and(|m| u64::from(bound) <= m)
        });
    }

    /// Splats through `stencils` (built from this path's table: [`FixedStencils::build`])
    /// instead of the table walk. Still integer only and bit-exact everywhere, but not the same
    /// bits as the walk (the blend between phases differs from the walk's lookup).
    pub fn with_stencils(mut self, stencils: FixedStencils<'a, M>) -> Self {
        self.stencils = Some(stencils);
        self.settle();
        self
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
        row0: usize,
        value: &[u32; 4],
        acc: &mut ImageMut<'_, [i64; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, RenderError> {
        let mut center = self.place.at(sheet, u, v);
        center[1] -= (row0 as i64) << fixed::POS_FRAC;
        Ok(match (&self.stencils, self.unsaturated_below) {
            (Some(s), Some(bound)) => {
                if let Some(&c) = value.iter().find(|&&c| c > bound) {
                    return Err(RenderError::ValueAboveBound { value: c, bound });
                }
                s.splat_unsaturated(center, value, acc, touched)
            }
            (Some(s), None) => s.splat(center, value, acc, touched),
            (None, _) => fixed::splat::splat(self.table, center, value, acc, touched),
        })
    }

    fn composite_row(&self, acc: &mut [[i64; 4]], image: &mut [[u32; 4]], order: Order) {
        fixed::composite::composite_row(acc, image, self.table.frac_bits(), order);
    }

    fn over_row(&self, front: &mut [[u32; 4]], back: &[[u32; 4]]) {
        fixed::composite::over_row(front, back);
    }

    fn opacity_pixel(alpha: f32) -> [u32; 4] {
        // Set-up only (once per renderer): the one float operation of the fixed path's culling.
        let q = -crate::math::floor(-alpha.clamp(0.0, 1.0) * fixed::ONE as f32) as u32;
        [0, 0, 0, q.min(fixed::ONE)]
    }

    #[inline]
    fn reaches(pixel: &[u32; 4], at: &[u32; 4]) -> bool {
        pixel[3] >= at[3]
    }
}

/// Compact fixed-point accumulation for small cores ([`crate::fixed::compact`]): Q15 values and
/// image, `i32` accumulator, Q16 placement and one phase stencil per voxel; every per-voxel and
/// per-pixel operation a 32-bit integer one.
#[derive(Clone, Copy, Debug)]
pub struct CompactPath<'a> {
    stencils: CompactStencils<'a>,
    place: CompactPlacement,
}

impl<'a> CompactPath<'a> {
    /// The compact path for `frame` through `stencils` (built for this frame). Refused for a
    /// perspective frame and when the volume lands outside the Q16 screen range.
    pub fn new(
        frame: &FrameSetup,
        stencils: CompactStencils<'a>,
    ) -> Result<Self, compact::CompactError> {
        Ok(CompactPath {
            stencils,
            place: CompactPlacement::new(frame)?,
        })
    }
}

impl Precision for CompactPath<'_> {
    type Value = [u16; 4];
    type Acc = [i32; 4];
    type Pixel = [u16; 4];
    const ACC_ZERO: [i32; 4] = [0; 4];
    const CLEAR: [u16; 4] = [0; 4];

    #[inline]
    fn value(&self, rgba: [f32; 4]) -> [u16; 4] {
        compact::quantise_value(rgba)
    }

    #[inline]
    fn is_transparent(value: &[u16; 4]) -> bool {
        value[3] == 0
    }

    #[inline]
    fn splat(
        &self,
        _: &FrameSetup,
        sheet: usize,
        (u, v): (usize, usize),
        row0: usize,
        value: &[u16; 4],
        acc: &mut ImageMut<'_, [i32; 4]>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, RenderError> {
        let mut center = self.place.at(sheet, u, v);
        // row0 < 2¹⁴ (the image size was checked at set-up).
        center[1] -= (row0 as i32) << compact::POS_FRAC;
        Ok(self.stencils.splat(center, value, acc, touched))
    }

    fn composite_row(&self, acc: &mut [[i32; 4]], image: &mut [[u16; 4]], order: Order) {
        compact::composite_row(acc, image, self.stencils.frac_bits(), order);
    }

    fn over_row(&self, front: &mut [[u16; 4]], back: &[[u16; 4]]) {
        compact::over_row(front, back);
    }

    fn opacity_pixel(alpha: f32) -> [u16; 4] {
        let q = -crate::math::floor(-alpha.clamp(0.0, 1.0) * f32::from(compact::ONE)) as u16;
        [0, 0, 0, q.min(compact::ONE)]
    }

    #[inline]
    fn reaches(pixel: &[u16; 4], at: &[u16; 4]) -> bool {
        pixel[3] >= at[3]
    }
}
