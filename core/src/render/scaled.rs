//! A footprint for a local spacing: the view's footprint read at per-side scaled sheet
//! coordinates (the paper's adaptive re-sampling; used by [`super::refined`]).
//!
//! # Derivation (checked against separately built footprints and a flat field in the tests)
//! Write the sheet plane's coordinates (s, t) in coarse grid steps along the in-sheet axes a, b,
//! and P for the 2×2 map from them to screen pixels (the screen x, y of those grid axes,
//! [`sheet_map`]). A coarse sample's footprint, read in sheet coordinates, is F(P·(s, t)), F the
//! view's footprint (px⁻², integrating to one), and the sample's value is scaled by the cell area
//! |det P|. A kernel scaled by σ along every grid axis has the footprint F(P·(s, t)/σ)/σ² and
//! stands for σ² of a cell, so its contribution is value·|det P|·F(P·(s, t)/σ): the coarse
//! footprint read at scaled coordinates. The paper's asymmetric case takes the scale per side:
//! s/σₐ₋ where s < 0 and s/σₐ₊ where s ≥ 0 (likewise for t); the footprint stays continuous
//! across s = 0. Exact for a view along the sheet axis and for a sample scaled alike along all
//! three axes and on both sides; otherwise the footprint's stretch by the view's obliqueness
//! along the sheet axis is that of the table's own sheet-axis scale, not the sample's.

use crate::frame::FrameSetup;
use crate::geometry::Footprint;
use crate::kernel::Shape;
use crate::math;
use crate::splat::{pixel_range, ImageMut, Sampler, SplatStats};
use glam::{Mat2, Vec2};

/// A footprint read at per-side scaled sheet coordinates (see the module docs), as a
/// [`Sampler`]: what [`splat_scaled`] splats, in a form phase stencils can be built from. Its
/// [`Footprint`] is the base's with the support replaced by a box around the scaled support.
#[derive(Clone, Copy, Debug)]
pub struct ScaledFootprint<'a, T: ?Sized> {
    base: &'a T,
    map: Mat2,
    inv: Mat2,
    inv_scale: [[f32; 2]; 2],
    /// The box around the scaled support, offsets from the centre, pixels.
    lo: Vec2,
    hi: Vec2,
    footprint: Footprint,
}

impl<'a, T: Sampler + ?Sized> ScaledFootprint<'a, T> {
    /// `base` read at P·D·P⁻¹·q, P = `sheet_map`, D = 1/`scales` per side (see [`splat_scaled`]).
    /// `None` for a singular P or a non-positive scale.
    pub fn new(base: &'a T, sheet_map: Mat2, scales: [[f32; 2]; 2]) -> Option<Self> {
        let (lo, hi) = scaled_box(base.footprint(), sheet_map, scales)?;
        let half = [lo.x.abs().max(hi.x.abs()), lo.y.abs().max(hi.y.abs())];
        if !(half[0] > 0.0 && half[1] > 0.0 && half[0].is_finite() && half[1].is_finite()) {
            return None;
        }
        let footprint = Footprint {
            to_unit: [[1.0 / half[0], 0.0], [0.0, 1.0 / half[1]]],
            half_extent: half,
            renormalise: false,
            shape: Shape::Separable,
            ..*base.footprint()
        };
        Some(ScaledFootprint {
            base,
            map: sheet_map,
            inv: sheet_map.inverse(),
            inv_scale: scales.map(|s| [1.0 / s[0], 1.0 / s[1]]),
            lo,
            hi,
            footprint,
        })
    }
}

impl<T: Sampler + ?Sized> Sampler for ScaledFootprint<'_, T> {
    fn footprint(&self) -> &Footprint {
        &self.footprint
    }

    #[inline]
    fn weight(&self, q: [f32; 2]) -> f32 {
        let s = self.inv * Vec2::from_array(q);
        let d = Vec2::new(
            self.inv_scale[0][usize::from(s.x >= 0.0)],
            self.inv_scale[1][usize::from(s.y >= 0.0)],
        );
        let q = self.map * (s * d);
        self.base.weight([q.x, q.y])
    }
}

/// The screen box (offsets from the centre, pixels) that holds `base`'s support read at scaled
/// sheet coordinates: the base box's corners taken to sheet coordinates, scaled per side, and
/// back. `None` for a singular map or a non-positive scale.
fn scaled_box(base: &Footprint, sheet_map: Mat2, scales: [[f32; 2]; 2]) -> Option<(Vec2, Vec2)> {
    let det = sheet_map.determinant();
    if !(det != 0.0 && det.is_finite() && scales.as_flattened().iter().all(|&s| s > 0.0)) {
        return None;
    }
    let inv = sheet_map.inverse();
    let [hx, hy] = base.half_extent;
    let (mut ex, mut ey) = (0.0f32, 0.0f32);
    for c in [Vec2::new(hx, hy), Vec2::new(hx, -hy)] {
        let s = inv * c;
        ex = ex.max(s.x.abs());
        ey = ey.max(s.y.abs());
    }
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for s in [
        Vec2::new(-scales[0][0] * ex, -scales[1][0] * ey),
        Vec2::new(scales[0][1] * ex, -scales[1][0] * ey),
        Vec2::new(-scales[0][0] * ex, scales[1][1] * ey),
        Vec2::new(scales[0][1] * ex, scales[1][1] * ey),
    ] {
        let q = sheet_map * s;
        lo = lo.min(q);
        hi = hi.max(q);
    }
    Some((lo, hi))
}

/// Splats `value` of a sample projected to `centre` (absolute pixels) with `sampler`'s footprint
/// scaled per side in sheet coordinates: `scales[0]` = (σₐ₋, σₐ₊), `scales[1]` = (σ_b₋, σ_b₊),
/// coarse steps; `sheet_map` = P (columns: the screen x, y of one step along a and along b).
/// `acc`'s first row is image row `row0`; `touched(y, x0, x1)` reports each row's updated span
/// (relative to `acc`). The value is scaled by `area` (the coarse cell's |det P|). Nothing for a
/// singular P or a non-positive scale. [`ScaledFootprint::splat`] of a footprint built here.
#[allow(clippy::too_many_arguments)]
pub fn splat_scaled<T: Sampler + ?Sized>(
    sampler: &T,
    sheet_map: Mat2,
    centre: [f32; 2],
    scales: [[f32; 2]; 2],
    area: f32,
    value: &[f32; 4],
    row0: usize,
    acc: &mut ImageMut<'_, [f32; 4]>,
    touched: impl FnMut(usize, usize, usize),
) -> SplatStats {
    ScaledFootprint::new(sampler, sheet_map, scales).map_or_else(SplatStats::default, |s| {
        s.splat(centre, area, value, row0, acc, touched)
    })
}

impl<T: Sampler + ?Sized> ScaledFootprint<'_, T> {
    /// Splats `value` × `area` of a sample projected to `centre` (absolute pixels) into `acc`
    /// (first row: image row `row0`), reading the base footprint along runs of pixels in one
    /// quadrant of the sheet plane (one line walk each, [`Sampler::line_weights`]) rather than
    /// per pixel; `touched(y, x0, x1)` reports each row's updated span (relative to `acc`).
    pub fn splat(
        &self,
        centre: [f32; 2],
        area: f32,
        value: &[f32; 4],
        row0: usize,
        acc: &mut ImageMut<'_, [f32; 4]>,
        mut touched: impl FnMut(usize, usize, usize),
    ) -> SplatStats {
        let mut stats = SplatStats::default();
        let (lo, hi, inv, inv_scale) = (self.lo, self.hi, self.inv, self.inv_scale);
        let (sampler, sheet_map) = (self.base, self.map);
        let (w, h) = (acc.width(), acc.height());
        let stride = acc.stride();
        let (x0, x1) = pixel_range(centre[0] + lo.x, centre[0] + hi.x);
        let (y0, y1) = pixel_range(centre[1] + lo.y, centre[1] + hi.y);
        let x0 = x0.max(0) as usize;
        let x1 = (x1 + 1).clamp(0, w as i64) as usize;
        let y0 = (y0.max(row0 as i64) as usize).max(row0);
        let y1 = (y1 + 1).clamp(0, (row0 + h) as i64) as usize;
        if x0 >= x1 || y0 >= y1 {
            return stats;
        }
        let value = value.map(|c| c * area);
        let data = acc.data_mut();
        let along = inv.col(0); // ∂s/∂x per pixel
        let mut weights = [0.0f32; 256];
        for y in y0..y1 {
            let qy = y as f32 + 0.5 - centre[1];
            let row = (y - row0) * stride;
            let (mut first, mut last) = (usize::MAX, 0);
            // Runs of pixels in one quadrant of the sheet plane (split where s·x or s·y changes
            // sign; the footprint is continuous there, both scales giving 0): one line walk each.
            let s_row = inv * Vec2::new(x0 as f32 + 0.5 - centre[0], qy);
            let mut cuts = [x1; 2];
            for (c, (s0, ds)) in cuts
                .iter_mut()
                .zip([(s_row.x, along.x), (s_row.y, along.y)])
            {
                if ds != 0.0 {
                    let t = -s0 / ds;
                    if t > 0.0 && t < (x1 - x0) as f32 {
                        *c = x0 + (math::floor(t) as usize + 1).min(x1 - x0);
                    }
                }
            }
            if cuts[0] > cuts[1] {
                cuts.swap(0, 1);
            }
            let mut x = x0;
            for end in [cuts[0], cuts[1], x1] {
                while x < end {
                    let stop = end.min(x + weights.len());
                    let s0 = s_row + along * (x - x0) as f32;
                    let mid = s0 + along * (0.5 * (stop - x - 1) as f32);
                    let d = Vec2::new(
                        inv_scale[0][usize::from(mid.x >= 0.0)],
                        inv_scale[1][usize::from(mid.y >= 0.0)],
                    );
                    let q0 = sheet_map * (s0 * d);
                    let step = sheet_map * (along * d);
                    let out = &mut weights[..stop - x];
                    sampler.line_weights([q0.x, q0.y], [step.x, step.y], out);
                    for (k, &wgt) in out.iter().enumerate() {
                        if wgt != 0.0 {
                            let p = &mut data[row + x + k];
                            for (c, v) in p.iter_mut().zip(&value) {
                                *c += v * wgt;
                            }
                            stats.pixels_updated += 1;
                            first = first.min(x + k);
                            last = x + k;
                        }
                    }
                    stats.pixels_visited += (stop - x) as u32;
                    x = stop;
                }
            }
            if first <= last {
                touched(y - row0, first, last);
            }
        }
        stats
    }
}

/// The screen x, y of one grid step along each in-sheet axis: P of [`splat_scaled`].
pub fn sheet_map(frame: &FrameSetup) -> Mat2 {
    let m = frame.grid_to_screen;
    let (a, b) = frame.in_sheet;
    Mat2::from_cols(m.col(a).truncate(), m.col(b).truncate())
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::geometry::{FootprintOptions, Grid, View};
    use crate::kernel::Kernel;
    use crate::splat::Splatter;
    use crate::stencil::Stencils;
    use crate::table::{GenericTable, Lookup, ViewTable};

    pub(in crate::render) const K: Kernel = Kernel::PAPER_GAUSSIAN;

    pub(in crate::render) fn frame(
        angles: [f32; 3],
        dims: [usize; 3],
        size: [usize; 2],
    ) -> FrameSetup {
        let grid = Grid::from_spacing([1.0; 3]).unwrap();
        let view = View::from_angles(angles, 1.0, dims, &grid, size).unwrap();
        FrameSetup::new(dims, &grid, &view, &K, FootprintOptions::default(), size).unwrap()
    }

    pub(in crate::render) fn table(
        f: &FrameSetup,
        m: glam::Mat3,
        generic: &GenericTable<65>,
    ) -> ViewTable<65> {
        let fp =
            Footprint::with_sheet_axis(&K, &m, FootprintOptions::default(), f.sheet_axis).unwrap();
        ViewTable::build(&fp, generic, Lookup::Bilinear, Lookup::Bilinear)
    }

    fn splat_into(
        size: [usize; 2],
        mut go: impl FnMut(&mut ImageMut<'_, [f32; 4]>),
    ) -> std::vec::Vec<f32> {
        let mut px = std::vec![[0.0f32; 4]; size[0] * size[1]];
        let mut img = ImageMut::new(&mut px, size[0], size[1], size[0]).unwrap();
        go(&mut img);
        px.iter().map(|p| p[3]).collect()
    }

    fn max_diff(a: &[f32], b: &[f32]) -> (f32, f32) {
        let peak = b.iter().copied().fold(0.0f32, f32::max);
        let d = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max);
        (d / peak, peak)
    }

    /// A sample scaled alike along all three axes: its footprint read at scaled coordinates is
    /// the footprint of the scaled kernel (built on its own), at an oblique view.
    #[test]
    fn uniform_scale_is_the_scaled_kernel() {
        let size = [96, 96];
        let f = frame([35.0, 25.0, 10.0], [8; 3], size);
        let generic = GenericTable::<65>::build(K);
        let base = table(&f, f.grid_to_screen, &generic);
        for s in [0.5f32, 0.25] {
            let own = table(&f, f.grid_to_screen * s, &generic);
            let c = [47.3, 50.6];
            let v = [0.0, 0.0, 0.0, 1.0];
            let scaled = splat_into(size, |img| {
                splat_scaled(
                    &base,
                    sheet_map(&f),
                    c,
                    [[s; 2]; 2],
                    1.0,
                    &v,
                    0,
                    img,
                    |_, _, _| {},
                );
            });
            let exact = splat_into(size, |img| {
                own.splat_voxel(c, &v.map(|x| x * s * s), img, |_, _, _| {})
                    .unwrap();
            });
            let (d, peak) = max_diff(&scaled, &exact);
            assert!(peak > 0.0 && d < 0.02, "σ = {s}: max diff {d} of peak");
        }
    }

    /// The paper's asymmetric case along the sheet's a axis, view along the sheet axis (where it
    /// is exact): samples 1 apart for a < 0 and ½ apart for a ≥ 0 sum to a field whose ripple at
    /// the border is a few times the uniform grid's own; symmetric footprints of the mean spacing
    /// there leave a bump and a dip four times larger.
    #[test]
    fn asymmetric_border_keeps_the_field_flat() {
        let size = [160, 64];
        let f = frame([0.0, 0.0, 0.0], [8; 3], size);
        let generic = GenericTable::<65>::build(K);
        let base = table(&f, f.grid_to_screen, &generic);
        let map = sheet_map(&f);
        let step = map.col(0).x; // pixels per grid step along a (screen x), b along y
        assert!(map.col(0).y.abs() < 1e-4 && map.col(1).x.abs() < 1e-4);
        let hb = map.col(1).y.abs();
        // Positions along a: −12..0 step 1, then 0.5..12 step ½.
        let mut xs = std::vec::Vec::new();
        for i in -12..0 {
            xs.push((i as f32, [1.0f32, 1.0]));
        }
        xs.push((0.0, [1.0, 0.5]));
        for i in 1..=24 {
            xs.push((i as f32 * 0.5, [0.5, 0.5]));
        }
        let field = |asymmetric: bool| {
            splat_into(size, |img| {
                for &(x, sp) in &xs {
                    for j in -8..=8 {
                        let c = [80.0 + x * step, 32.0 + j as f32 * hb];
                        let sa = if asymmetric {
                            sp
                        } else {
                            [0.5 * (sp[0] + sp[1]); 2]
                        };
                        let v = [0.0, 0.0, 0.0, 1.0];
                        splat_scaled(
                            &base,
                            map,
                            c,
                            [sa, [1.0; 2]],
                            f.cell_area,
                            &v,
                            0,
                            img,
                            |_, _, _| {},
                        );
                    }
                }
            })
        };
        let spread = |row: &[f32], centre: f32| {
            // Pixels within ±4 grid steps of `centre`, on the middle row: the largest relative
            // departure from their mean.
            let (lo, hi) = (
                (centre - 4.0 * step) as usize,
                (centre + 4.0 * step) as usize,
            );
            let r = &row[32 * size[0] + lo..32 * size[0] + hi];
            let mean = r.iter().sum::<f32>() / r.len() as f32;
            r.iter()
                .map(|v| (v - mean).abs() / mean)
                .fold(0.0f32, f32::max)
        };
        let (fw, fo) = (field(true), field(false));
        // The uniform coarse grid's own ripple (the kernel is not an exact partition of unity),
        // measured away from the border; then the border with each choice. Measured: 0.012,
        // 0.051 (one-sided scales) and 0.20 (mean spacing).
        let uniform = spread(&fw, 80.0 - 7.0 * step);
        let (with, without) = (spread(&fw, 80.0), spread(&fo, 80.0));
        assert!(uniform < 0.02, "uniform grid ripple {uniform}");
        assert!(
            with < 0.06,
            "asymmetric border ripple {with} (uniform {uniform})"
        );
        assert!(
            without > 3.0 * with,
            "mean-spacing border ripple {without} vs {with}"
        );
    }

    /// Stencils over a [`ScaledFootprint`], and a table resampled from it, give the weights
    /// [`splat_scaled`] reads.
    #[test]
    fn scaled_footprint_stencils_match_the_walk() {
        let size = [96, 96];
        let f = frame([30.0, 20.0, 0.0], [8; 3], size);
        let generic = GenericTable::<65>::build(K);
        let base = table(&f, f.grid_to_screen, &generic);
        let scales = [[1.0, 0.5], [0.25, 1.0]];
        let fp = ScaledFootprint::new(&base, sheet_map(&f), scales).unwrap();
        let mut buffer = std::vec![0.0f32; crate::stencil::len_for(fp.footprint(), 8).unwrap()];
        let st = Stencils::build(&fp, 8, &mut buffer).unwrap();
        let (c, v) = ([45.6, 49.2], [0.0, 0.0, 0.0, 1.0]);
        let walk = splat_into(size, |img| {
            splat_scaled(
                &base,
                sheet_map(&f),
                c,
                scales,
                1.0,
                &v,
                0,
                img,
                |_, _, _| {},
            );
        });
        let stencils = splat_into(size, |img| {
            st.splat_voxel(c, &v, img, |_, _, _| {}).unwrap();
        });
        let (d, peak) = max_diff(&stencils, &walk);
        assert!(peak > 0.0 && d < 0.02, "max diff {d} of peak");
        let (total_w, total_s): (f32, f32) = (walk.iter().sum(), stencils.iter().sum());
        assert!((total_w - total_s).abs() < 0.01 * total_w);
        // Resampled into a table of its own, splatted by the row walk.
        let mut own = ViewTable::<65>::zeroed(*fp.footprint());
        own.resample_into(&fp, Lookup::Bilinear);
        let resampled = splat_into(size, |img| {
            own.splat_voxel(c, &v, img, |_, _, _| {}).unwrap();
        });
        let (d, _) = max_diff(&resampled, &walk);
        assert!(d < 0.02, "resampled: max diff {d} of peak");
        let total_r: f32 = resampled.iter().sum();
        assert!((total_w - total_r).abs() < 0.01 * total_w);
    }
}
