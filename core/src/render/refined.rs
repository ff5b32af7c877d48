//! Rendering a refined grid ([`crate::refine`]) with the paper's sheets: every refined sample
//! along the sheet axis is a sheet, composited in order; every refined sample in it is splatted
//! with a footprint for its local spacing ([`super::scaled`] derives them). A rectilinear grid
//! (samples at given positions, [`crate::refine`]'s "Rectilinear grids") renders the same way.
//!
//! # Which footprint
//! A sample's spacings (previous and next along each in-sheet axis, its sheet's width along the
//! sheet axis), each rounded to 1, ½ or ¼, make its [`spacing_key`]. The caller builds, once per
//! view, whatever footprints it wants per key ([`RefineTables::splatters`]): for a spacing equal on
//! both sides, the footprint of the kernel scaled by it (exact); for the paper's asymmetric border
//! case, a [`ScaledFootprint`](super::ScaledFootprint). A key without one is splatted from the table of its *rate*
//! ρ = width / in-sheet spacing ∈ {¼, ½, 1, 2, 4} (the kernel scaled by ρ along the sheet axis),
//! read at per-side scaled coordinates ([`splat_scaled`]).
//!
//! # Values
//! Samples between coarse ones are Catmull–Rom interpolated ([`crate::refine::catmull_rom`]) from
//! the coarse grid extended linearly past its faces, and shaded with the interpolant's gradient:
//! at a coarse sample both are what the sheet renderer computes (its value, its central or, at a
//! face, one-sided difference).
//!
//! # Opacity
//! A sheet standing for w coarse sheet spacings (the mean of its two neighbours' distances) gets
//! opacity 1 − (1 − α)^w, α the frame's corrected opacity, and its colour scaled alike.

use super::precision::FloatPath;
use super::scaled::{sheet_map, splat_scaled};
use super::{RenderError, SheetRenderer};
use crate::frame::FrameSetup;
use crate::math;
use crate::refine::{catmull_rom, RefinedAxis, RefinedSample};
use crate::splat::{ImageMut, Sampler, Splatter};
use glam::{Mat2, Vec3};

/// A refined grid: one [`RefinedAxis`] per grid axis (i, j, k).
#[derive(Clone, Copy, Debug)]
pub struct RefinedGrid<'a> {
    /// The axes.
    pub axes: [RefinedAxis<'a>; 3],
}

impl RefinedGrid<'_> {
    /// Refined samples in all.
    pub fn len(&self) -> usize {
        self.axes.iter().map(RefinedAxis::len).product()
    }

    /// Whether the grid has no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Spacing keys: (σₐ₋, σₐ₊) × (σ_b₋, σ_b₊) × sheet width, each of 1, ½, ¼ ([`spacing_key`]).
pub const SPACING_KEYS: usize = 243;

/// How many of the log-scale midpoints between ¼, ½, 1, 2, 4 (2^(k − 1.5), k = 0..4) lie below
/// `x`: the index of the power of two in ¼…4 nearest `x` (0 for NaN or x ≤ 2^−1.5).
#[inline]
fn octave(x: f32) -> usize {
    use core::f32::consts::{FRAC_1_SQRT_2, SQRT_2};
    [0.5 * FRAC_1_SQRT_2, FRAC_1_SQRT_2, SQRT_2, 2.0 * SQRT_2]
        .iter()
        .filter(|&&m| x > m)
        .count()
}

/// 0, 1, 2 for a spacing nearest (in log scale) to 1, ½, ¼.
#[inline]
fn level(s: f32) -> usize {
    2 - octave(s).min(2)
}

/// The key of a sample's spacings: `a` and `b` its (previous, next) spacings along the in-sheet
/// axes a, b and `width` its sheet's width (mean spacing along the sheet axis), each rounded to
/// the nearest of 1, ½, ¼ in log scale: (3·ℓ(a₋) + ℓ(a₊)) + 9·(3·ℓ(b₋) + ℓ(b₊)) + 81·ℓ(width).
#[inline]
pub fn spacing_key(a: [f32; 2], b: [f32; 2], width: f32) -> usize {
    (3 * level(a[0]) + level(a[1])) + 9 * (3 * level(b[0]) + level(b[1])) + 81 * level(width)
}

/// The spacings of `key` (the inverse of [`spacing_key`]): (a, b, width).
pub fn key_spacings(key: usize) -> ([f32; 2], [f32; 2], f32) {
    let s = |l: usize| 1.0 / f32::from(1u8 << (l % 3));
    let pa = key % 9;
    let pb = (key / 9) % 9;
    ([s(pa / 3), s(pa % 3)], [s(pb / 3), s(pb % 3)], s(key / 81))
}

/// The rate ρ = width / √(w_a·w_b) of a sample (w the mean spacing per in-sheet axis): which
/// [`RefineTables::rates`] entry its scaled footprint reads, the index of the power of two
/// nearest ρ in ¼…4.
#[inline]
pub fn rate_index(a: [f32; 2], b: [f32; 2], width: f32) -> usize {
    let inner = math::sqrt(0.25 * (a[0] + a[1]) * (b[0] + b[1]));
    let rho = width / inner;
    if !(rho > 0.0) {
        return 2;
    }
    octave(rho)
}

/// The footprints a refined render splats with (see the module docs).
///
/// - `rates`: one sampler per rate ρ = ¼, ½, 1, 2, 4 ([`rate_index`]: the kernel scaled by ρ
///   along the sheet axis; `rates[2]` is the view's own footprint). A sample with no splatter of
///   its own is splatted from its rate's table read at scaled coordinates ([`splat_scaled`]).
/// - `splatters`: per [`spacing_key`], optionally a splatter of exactly that sample's footprint,
///   built once per view: for spacings equal on both sides, the footprint of the kernel scaled by
///   them; otherwise [`ScaledFootprint`](super::ScaledFootprint) over the rate's table (its phase stencils, say). `None`
///   takes the `rates` path: the same weights, read per pixel.
#[derive(Clone, Copy, Debug)]
pub struct RefineTables<'a, T: ?Sized, S> {
    /// Samplers for ρ = 2^(k − 2), k = 0..5.
    pub rates: [&'a T; 5],
    /// Splatters by [`spacing_key`] ([`SPACING_KEYS`] long, or shorter: missing keys are `None`).
    pub splatters: &'a [Option<S>],
}

impl<T: ?Sized, S> RefineTables<'_, T, S> {
    /// The rates, in `rates` order.
    pub const RATES: [f32; 5] = [0.25, 0.5, 1.0, 2.0, 4.0];
}

impl<'a, S: Splatter + ?Sized> SheetRenderer<'a, FloatPath<'a, S>> {
    /// Renders the whole refined `grid` of the coarse volume `volume(index)` (grid index i, j, k,
    /// each below the frame's dims; NaN is missing data): every refined sheet in compositing
    /// order, each sample's value interpolated ([`catmull_rom`]), shaded with the interpolant's
    /// gradient, splatted through the table of its rate ([`splat_scaled`]) and each sheet
    /// composited. `scratch` holds two coarse sheets (2 × `dims[a]` × `dims[b]`). The renderer's
    /// own splatter is not used. Orthographic frames only.
    pub fn render_refined<T: Sampler + ?Sized, Q: Splatter>(
        &mut self,
        grid: &RefinedGrid<'_>,
        tables: &RefineTables<'_, T, Q>,
        volume: impl Fn([usize; 3]) -> f32,
        scratch: &mut [f32],
    ) -> Result<(), RenderError> {
        let f = self.frame;
        if f.camera().is_some() {
            return Err(RenderError::Projection);
        }
        for (axis, ra) in grid.axes.iter().enumerate() {
            if ra.coarse_len() != f.dims[axis] {
                return Err(RenderError::SheetIndex {
                    index: ra.coarse_len(),
                    count: f.dims[axis],
                });
            }
        }
        let (len, na, nb) = f.sheet_shape();
        if scratch.len() < 2 * len {
            return Err(crate::splat::BufferError::TooSmall {
                needed: 2 * len,
                got: scratch.len(),
            }
            .into());
        }
        let (values, slopes) = scratch.split_at_mut(len);
        let k = f.sheet_axis;
        let ascending = f.ascending_for(self.order);
        let map = sheet_map(f);
        grid.axes[k].for_each(ascending, |zs| {
            fill_sheet(f, &volume, zs, values, &mut slopes[..len]);
            self.splat_refined_sheet(grid, tables, zs, map, values, &slopes[..len], [na, nb])?;
            self.stats.sheets += 1;
            self.composite_sheet();
            Ok::<(), RenderError>(())
        })
    }

    /// Splats one refined sheet `zs` from its interpolated coarse-grid values and sheet-axis
    /// slopes (`dims` = [na, nb]).
    #[allow(clippy::too_many_arguments)]
    fn splat_refined_sheet<T: Sampler + ?Sized, Q: Splatter>(
        &mut self,
        grid: &RefinedGrid<'_>,
        tables: &RefineTables<'_, T, Q>,
        zs: RefinedSample,
        map: Mat2,
        values: &[f32],
        slopes: &[f32],
        [na, nb]: [usize; 2],
    ) -> Result<(), RenderError> {
        let f = self.frame;
        let (k, (a, b)) = (f.sheet_axis, f.in_sheet);
        let (shader, lighting, opacity) = (self.shader, self.lighting, self.opacity);
        let needs_gradient = shader.shading.needs_gradient();
        let thickness = zs.width();
        let (w, band_rows, row0) = (f.size[0], self.band.1, self.band.0);
        let mut image = ImageMut::new(&mut *self.buffers.accumulator, w, band_rows, w)?;
        let rows = &mut *self.buffers.rows;
        let stats = &mut self.stats;
        grid.axes[b].for_each(true, |vb| {
            grid.axes[a].for_each(true, |ua| {
                let [v, ga, gb, gz] =
                    interpolate_sheet(values, slopes, [na, nb], ua, vb, needs_gradient);
                let mut idx = [0usize; 3];
                idx[k] = zs.coarse;
                idx[a] = ua.coarse;
                idx[b] = vb.coarse;
                let gradient = || {
                    // Per coarse step, then per grid step (`RefinedSample::rate`).
                    let mut g = [0.0f32; 3];
                    g[a] = ga * ua.rate;
                    g[b] = gb * vb.rate;
                    g[k] = gz * zs.rate;
                    f.grid_inverse_transpose * Vec3::from_array(g)
                };
                let mut rgba =
                    shader.shade_with(&lighting, opacity.as_ref(), v, gradient, idx, f.dims);
                stats.voxels += 1;
                if !(rgba[3] > 0.0) {
                    return Ok(());
                }
                if thickness != 1.0 && rgba[3] < 1.0 {
                    let alpha = 1.0 - math::powf(1.0 - rgba[3], thickness);
                    let s = alpha / rgba[3];
                    rgba = [rgba[0] * s, rgba[1] * s, rgba[2] * s, alpha];
                }
                let mut pos = [0.0f32; 3];
                pos[k] = zs.position();
                pos[a] = ua.position();
                pos[b] = vb.position();
                let p = f.affine_position(pos);
                let key = spacing_key(ua.spacing, vb.spacing, thickness);
                // A key's splatter is the footprint of exactly its in-sheet spacings (its sheet
                // width rounded, as the rates are): a sample whose spacings are otherwise (on a
                // rectilinear grid) reads its rate's table at its own.
                let (ka, kb, _) = key_spacings(key);
                let own = tables
                    .splatters
                    .get(key)
                    .and_then(Option::as_ref)
                    .filter(|_| ka == ua.spacing && kb == vb.spacing);
                let s = if let Some(splatter) = own {
                    // Its own footprint: the area it stands for is in the weights (a symmetric
                    // spacing's footprint integrates to one over its own, smaller, cell; a
                    // scaled one to the share its sides give it), so the value carries the
                    // coarse cell's area only where the weights are the coarse table's.
                    let area = if ua.spacing[0] == ua.spacing[1] && vb.spacing[0] == vb.spacing[1] {
                        f.cell_area * ua.spacing[0] * vb.spacing[0]
                    } else {
                        f.cell_area
                    };
                    let value = rgba.map(|c| c * area);
                    // As in the sheet path: a whole number of rows off, exactly.
                    splatter.splat_voxel(
                        [p.x, p.y - row0 as f32],
                        &value,
                        &mut image,
                        |y, x0, x1| rows[y].include(x0, x1),
                    )?
                } else {
                    let table = tables.rates[rate_index(ua.spacing, vb.spacing, thickness)];
                    splat_scaled(
                        table,
                        map,
                        [p.x, p.y],
                        [ua.spacing, vb.spacing],
                        f.cell_area,
                        &rgba,
                        row0,
                        &mut image,
                        |y, x0, x1| rows[y].include(x0, x1),
                    )
                };
                stats.voxels_splatted += u64::from(s.pixels_updated > 0);
                stats.pixel_updates += u64::from(s.pixels_updated);
                Ok::<(), RenderError>(())
            })
        })
    }
}

/// The coarse sheet at sheet-axis position `zs`, interpolated along the sheet axis
/// ([`catmull_rom`] over [`taps`]), into `values`, and its slope along the sheet axis (per coarse
/// step) into `slopes`.
fn fill_sheet(
    f: &FrameSetup,
    volume: &impl Fn([usize; 3]) -> f32,
    zs: RefinedSample,
    values: &mut [f32],
    slopes: &mut [f32],
) {
    let (_, na, nb) = f.sheet_shape();
    let n = f.dims[f.sheet_axis];
    let (w, d) = catmull_rom(zs.frac);
    for v in 0..nb {
        for u in 0..na {
            let t = taps(zs.coarse, n, |s| [volume(f.grid_index(s, u, v))]).map(|x| x[0]);
            let (val, slope) = (dot(&w, &t), dot(&d, &t));
            values[v * na + u] = val;
            slopes[v * na + u] = slope;
        }
    }
}

/// Value, ∂/∂a and ∂/∂b (per coarse step) and the sheet-axis slope at (`ua`, `vb`) of a coarse
/// sheet already interpolated along the sheet axis (`values`, its `slopes`; `na` × `nb`, a
/// fastest): [`catmull_rom`] along a, then along b, over [`taps`]. Without `gradient` only the
/// value is computed.
fn interpolate_sheet(
    values: &[f32],
    slopes: &[f32],
    [na, nb]: [usize; 2],
    ua: RefinedSample,
    vb: RefinedSample,
    gradient: bool,
) -> [f32; 4] {
    let (wa, da) = catmull_rom(ua.frac);
    let (wb, db) = catmull_rom(vb.frac);
    // Row r's value, ∂/∂a and slope at ua.
    let row = |r: usize| {
        let line = |src: &[f32]| taps(ua.coarse, na, |i| [src[r * na + i]]).map(|x| x[0]);
        let t = line(values);
        if gradient {
            [dot(&wa, &t), dot(&da, &t), dot(&wa, &line(slopes))]
        } else {
            [dot(&wa, &t), 0.0, 0.0]
        }
    };
    let rows = taps(vb.coarse, nb, row);
    let col = |c: usize, w: &[f32; 4]| dot(w, &rows.map(|r| r[c]));
    if gradient {
        [col(0, &wb), col(1, &wb), col(0, &db), col(2, &wb)]
    } else {
        [col(0, &wb), 0.0, 0.0, 0.0]
    }
}

/// The samples at c − 1 … c + 2 of a line of `n` ≥ 1 samples `get(i)`, extended linearly past
/// its ends (the end's one-sided slope; none when n = 1), so that the Catmull–Rom slope at an
/// end sample is the one-sided difference the sheet renderer's gradient takes there.
#[inline]
fn taps<const L: usize>(c: usize, n: usize, get: impl Fn(usize) -> [f32; L]) -> [[f32; L]; 4] {
    let last = n - 1;
    let at = |i: isize| -> [f32; L] {
        if i < 0 || i as usize > last {
            let (end, next) = if i < 0 {
                (0, 1.min(last))
            } else {
                (last, last.saturating_sub(1))
            };
            let (e, x) = (get(end), get(next));
            let k = if i < 0 { -i } else { i - last as isize } as f32;
            core::array::from_fn(|l| e[l] + k * (e[l] - x[l]))
        } else {
            get(i as usize)
        }
    };
    core::array::from_fn(|t| at(c as isize + t as isize - 1))
}

/// Σ wᵢ·xᵢ over the non-zero weights (a missing sample where the weight is zero stays out).
#[inline]
fn dot(w: &[f32; 4], x: &[f32; 4]) -> f32 {
    w.iter()
        .zip(x)
        .filter(|(w, _)| **w != 0.0)
        .map(|(w, x)| w * x)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::composite::RowSpan;
    use crate::frame::Order;
    use crate::render::scaled::tests::{frame, table, K};

    /// A frame rendered into fresh buffers by `go`, back to front.
    fn render_with(
        f: &FrameSetup,
        base: &ViewTable<65>,
        shader: Shader<'_>,
        go: impl for<'a> FnOnce(&mut SheetRenderer<'a, FloatPath<'a, ViewTable<65>>>),
    ) -> std::vec::Vec<[f32; 4]> {
        let n = f.size[0] * f.size[1];
        let (mut acc, mut img) = (std::vec![[0.0f32; 4]; n], std::vec![[0.0f32; 4]; n]);
        let mut rows = std::vec![RowSpan::EMPTY; f.size[1]];
        let buffers = RenderBuffers {
            accumulator: &mut acc,
            image: &mut img,
            rows: &mut rows,
        };
        let mut r = SheetRenderer::new(f, base, shader, Order::BackToFront, buffers, None).unwrap();
        go(&mut r);
        r.finish();
        img
    }
    use crate::render::{RenderBuffers, SheetRing};
    use crate::shade::{Shader, Shading, TransferFunction};
    use crate::table::{GenericTable, ViewTable};

    /// With every factor 1 the refined render is the ordinary render (within table-walk
    /// rounding), whatever the order; with factors it renders, finite.
    #[test]
    fn unrefined_grid_renders_the_sheets() {
        let (dims, size) = ([6usize, 7, 5], [48usize, 40]);
        let data: std::vec::Vec<f32> = (0..6 * 7 * 5).map(|i| ((i * 37) % 11) as f32).collect();
        let at = |[i, j, k]: [usize; 3]| data[i + 6 * (j + 7 * k)];
        let lut = [[0.0; 4], [1.0, 0.7, 0.3, 0.6]];
        for (angles, shading) in [
            ([30.0, 20.0, 0.0], Shading::Emission),
            ([120.0, -35.0, 5.0], Shading::Phong(Default::default())),
        ] {
            let f = frame(angles, dims, size);
            let generic = GenericTable::<65>::build(K);
            let base = table(&f, f.grid_to_screen, &generic);
            let shader = Shader {
                labels: None,
                tf: TransferFunction {
                    lut: &lut,
                    lo: 0.0,
                    hi: 10.0,
                },
                shading,
            };
            let render = |factors: [&[u8]; 3]| {
                render_with(&f, &base, shader, |r| {
                    let grid = RefinedGrid {
                        axes: [0, 1, 2].map(|a| RefinedAxis::new(a, dims[a], factors[a]).unwrap()),
                    };
                    let tables: RefineTables<'_, ViewTable<65>, ViewTable<65>> = RefineTables {
                        rates: [&base; 5],
                        splatters: &[],
                    };
                    let mut scratch = std::vec![0.0f32; 2 * f.sheet_shape().0];
                    r.render_refined(&grid, &tables, at, &mut scratch).unwrap();
                })
            };
            let ones = [&[1u8; 5][..], &[1u8; 6][..], &[1u8; 4][..]];
            let refined = render(ones);
            let img = render_with(&f, &base, shader, |r| {
                let mut sheets = std::vec![0.0f32; 3 * f.sheet_shape().0];
                let mut ring = SheetRing::new(&mut sheets, &f, Order::BackToFront).unwrap();
                let mut vol = crate::volume::MemoryVolume::new(&data, dims).unwrap();
                crate::source::render_from(r, &mut ring, &mut vol).unwrap();
            });
            let d = refined
                .iter()
                .zip(&img)
                .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs()))
                .fold(0.0f32, f32::max);
            assert!(d < 2e-3, "{angles:?}: unrefined grid differs by {d}");
            // A rectilinear grid at 0, 1, 2, ... is the uniform one, bit for bit; positions
            // stretched along i move the picture.
            let rectilinear = |stretch: f32| {
                let pos: [std::vec::Vec<f32>; 3] = core::array::from_fn(|a| {
                    (0..dims[a])
                        .map(|i| {
                            if a == 0 {
                                i as f32 * (1.0 + stretch * i as f32)
                            } else {
                                i as f32
                            }
                        })
                        .collect()
                });
                render_with(&f, &base, shader, |r| {
                    let grid = RefinedGrid {
                        axes: [0, 1, 2]
                            .map(|a| RefinedAxis::rectilinear(a, &pos[a], ones[a]).unwrap()),
                    };
                    let tables: RefineTables<'_, ViewTable<65>, ViewTable<65>> = RefineTables {
                        rates: [&base; 5],
                        splatters: &[],
                    };
                    let mut scratch = std::vec![0.0f32; 2 * f.sheet_shape().0];
                    r.render_refined(&grid, &tables, at, &mut scratch).unwrap();
                })
            };
            assert!(rectilinear(0.0) == refined, "{angles:?}: uniform positions");
            let moved = rectilinear(0.1)
                .iter()
                .zip(&refined)
                .map(|(a, b)| (a[3] - b[3]).abs())
                .fold(0.0f32, f32::max);
            assert!(
                moved > 0.05,
                "{angles:?}: stretched positions moved by {moved}"
            );
            let more = render([&[1, 2, 4, 2, 1][..], &[4u8; 6][..], &[2, 1, 1, 2][..]]);
            assert!(more
                .iter()
                .all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)));
            assert!(more.iter().any(|p| p[3] > 0.05));
        }
    }

    #[test]
    fn keys_round_trip() {
        for key in 0..SPACING_KEYS {
            let (a, b, w) = key_spacings(key);
            assert_eq!(spacing_key(a, b, w), key);
        }
        assert_eq!(spacing_key([1.0, 0.5], [0.25, 0.25], 0.75), 1 + 9 * 8);
        assert_eq!(rate_index([0.5; 2], [0.5; 2], 1.0), 3);
        assert_eq!(rate_index([1.0; 2], [1.0; 2], 1.0), 2);
        assert_eq!(rate_index([0.25; 2], [0.25; 2], 1.0), 4);
    }
}
