//! The view-transformed footprint table: the generic table resampled over one view's footprint,
//! built once per view and reused for every voxel.
//!
//! # Where the nodes lie: [`ViewLayout`]
//! The paper lays the view table over the footprint's screen-aligned bounding box, so a pixel row
//! is a row of the table. That wastes the table on a thin ellipse that lies oblique to the screen
//! axes: a 30:1 ellipse at 45° fills 5 % of its box, and the 129 nodes across the box leave about
//! 4 across the ellipse's short axis (measured: 7.6 % of peak error against the exact footprint,
//! 43 % at 100:1). Such footprints get the nodes laid over the footprint's own unit coordinates
//! instead (the [`Footprint::to_unit`] map, where the support is the unit disc or square), so all
//! M nodes span the short axis too; the row walk then steps both table coordinates per pixel.
//! [`ViewLayout::for_footprint`] picks the box while the support fills at least
//! [`MIN_BOX_FILL`] of it (every axis-aligned ellipse fills π/4) and the unit layout below.

use super::{sample_nodes, GenericTable, Lookup};
use crate::geometry::{mul2, Footprint, Mat2};
use crate::kernel::Shape;

/// Smallest share of its screen box a footprint's support may fill for the view table to be laid
/// over the box ([`ViewLayout::ScreenBox`]); thinner oblique footprints use [`ViewLayout::Unit`].
/// An ellipse at 45° fills 1/2 of its box at axis ratio 1 : 3.4 (about 1 : 1.2 in voxel spacing
/// terms of a 45° view), where the box layout's error at 129 nodes is still below 0.1 % of peak.
pub const MIN_BOX_FILL: f32 = 0.5;

/// Where a view table's M×M nodes lie. The paper lays them over the footprint's screen box; a thin
/// ellipse oblique to the screen axes fills a sliver of that box (a 30:1 ellipse at 45°: 5 %) and
/// leaves a few nodes across its short axis (7.6 % of peak error at 129 nodes, 43 % at 100:1), so
/// such footprints get the unit layout. [`ViewLayout::for_footprint`] decides by [`box_fill`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewLayout {
    /// Over the screen box [−eₓ, eₓ] × [−e_y, e_y] px: node (row, col) at offset
    /// (−eₓ + 2eₓ·col/(M−1), −e_y + 2e_y·row/(M−1)). Rows of the table are rows of pixels.
    ScreenBox,
    /// Over the unit square of the footprint's own coordinates u = A q ([`Footprint::to_unit`]):
    /// node (row, col) at u = (−1 + 2·col/(M−1), −1 + 2·row/(M−1)), the generic table's own
    /// nodes when M = N.
    Unit,
}

impl ViewLayout {
    /// The layout for `footprint`: [`ViewLayout::ScreenBox`] while its support fills at least
    /// [`MIN_BOX_FILL`] of its box, [`ViewLayout::Unit`] otherwise.
    pub fn for_footprint(footprint: &Footprint) -> Self {
        if box_fill(footprint) >= MIN_BOX_FILL {
            Self::ScreenBox
        } else {
            Self::Unit
        }
    }
}

/// The share of its screen bounding box that `footprint`'s support covers: the support's area in
/// unit coordinates (π for the disc, 4 for the square) over |det A|, divided by 4eₓe_y. 1 for an
/// empty or non-finite footprint (nothing to gain from another layout).
pub fn box_fill(footprint: &Footprint) -> f32 {
    let [ex, ey] = footprint.half_extent;
    let unit_area = match footprint.shape {
        Shape::Radial => core::f32::consts::PI,
        Shape::Separable => 4.0,
    };
    let fill = unit_area / (footprint.scale * 4.0 * ex * ey);
    if fill.is_finite() {
        fill
    } else {
        1.0
    }
}

/// M×M samples of one view's footprint weight (px⁻², see [`Footprint`]) at the nodes of its
/// [`ViewLayout`]. M ≥ 2.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewTable<const M: usize> {
    pub(crate) data: [[f32; M]; M],
    pub(crate) footprint: Footprint,
    pub(crate) layout: ViewLayout,
    /// Screen box: nodes per pixel along x and y, (M−1)/(2e).
    pub(crate) nodes_per_px: [f32; 2],
    /// Unit layout: the map from a screen offset (px) to node coordinates less (M−1)/2, that is
    /// (M−1)/2 · A.
    pub(crate) unit_map: Mat2,
    pub(crate) lookup: Lookup,
}

impl<const M: usize> ViewTable<M> {
    const VALID: () = assert!(M >= 2, "a table needs at least 2×2 nodes");

    /// An empty table (zero weights over a zero box), for `static` storage before the first build.
    pub const fn zeroed(footprint: Footprint) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::VALID;
        ViewTable {
            data: [[0.0; M]; M],
            footprint,
            layout: ViewLayout::ScreenBox,
            nodes_per_px: [0.0; 2],
            unit_map: [[0.0; 2]; 2],
            lookup: Lookup::Nearest,
        }
    }

    /// Builds the view table for `footprint` from `generic` in the layout
    /// [`ViewLayout::for_footprint`] picks: each node q is mapped to u = A q and read from the
    /// generic table with `build` lookup. Pixels are later read from this table with `sample`
    /// lookup.
    pub fn build<const N: usize>(
        footprint: &Footprint,
        generic: &GenericTable<N>,
        build: Lookup,
        sample: Lookup,
    ) -> Self {
        let mut t = Self::zeroed(*footprint);
        t.build_into(footprint, generic, build, sample);
        t
    }

    /// [`ViewTable::build`] in place (no M×M temporary).
    pub fn build_into<const N: usize>(
        &mut self,
        footprint: &Footprint,
        generic: &GenericTable<N>,
        build: Lookup,
        sample: Lookup,
    ) {
        let layout = ViewLayout::for_footprint(footprint);
        self.build_laid_out(footprint, generic, build, sample, layout);
    }

    /// [`ViewTable::build_into`] in a layout of the caller's choice (benchmarks and tests compare
    /// the two).
    pub fn build_laid_out<const N: usize>(
        &mut self,
        footprint: &Footprint,
        generic: &GenericTable<N>,
        build: Lookup,
        sample: Lookup,
        layout: ViewLayout,
    ) {
        let [ex, ey] = footprint.half_extent;
        let steps = (M - 1) as f32;
        for_each_view_node(
            footprint,
            generic,
            build,
            layout,
            &mut self.data,
            |value, t| *value = footprint.scale * t,
        );
        self.footprint = *footprint;
        self.layout = layout;
        self.nodes_per_px = [steps / (2.0 * ex), steps / (2.0 * ey)];
        let half = 0.5 * steps;
        self.unit_map = footprint.to_unit.map(|row| row.map(|a| a * half));
        self.lookup = sample;
    }

    /// Samples `sampler`'s weights at the nodes of its footprint's screen box (layout
    /// [`ViewLayout::ScreenBox`]), to be read with `sample` lookup: a table of any footprint a
    /// [`Sampler`](crate::geometry::Sampler) gives, such as a refined sample's scaled one
    /// ([`crate::render::ScaledFootprint`]), so that it splats through the row walk.
    pub fn resample_into<S: crate::geometry::Sampler + ?Sized>(
        &mut self,
        sampler: &S,
        sample: Lookup,
    ) {
        let footprint = *sampler.footprint();
        let [ex, ey] = footprint.half_extent;
        let steps = (M - 1) as f32;
        for (row, line) in self.data.iter_mut().enumerate() {
            let y = -ey + 2.0 * ey * row as f32 / steps;
            for (col, value) in line.iter_mut().enumerate() {
                let x = -ex + 2.0 * ex * col as f32 / steps;
                *value = sampler.weight([x, y]);
            }
        }
        self.footprint = footprint;
        self.layout = ViewLayout::ScreenBox;
        self.nodes_per_px = [steps / (2.0 * ex), steps / (2.0 * ey)];
        let half = 0.5 * steps;
        self.unit_map = footprint.to_unit.map(|row| row.map(|a| a * half));
        self.lookup = sample;
    }

    /// Where this table's nodes lie.
    pub fn layout(&self) -> ViewLayout {
        self.layout
    }

    /// The footprint this table was built for.
    pub fn footprint(&self) -> &Footprint {
        &self.footprint
    }

    /// The samples, row-major.
    pub fn as_slice(&self) -> &[f32] {
        self.data.as_flattened()
    }

    /// Weight (px⁻²) at screen offset `q` pixels from the voxel's projected centre.
    #[inline]
    pub fn weight(&self, q: [f32; 2]) -> f32 {
        let t = match self.layout {
            ViewLayout::ScreenBox => {
                let [ex, ey] = self.footprint.half_extent;
                [
                    (q[0] + ex) * self.nodes_per_px[0],
                    (q[1] + ey) * self.nodes_per_px[1],
                ]
            }
            ViewLayout::Unit => {
                let half = 0.5 * (M - 1) as f32;
                let t = mul2(&self.unit_map, q);
                [t[0] + half, t[1] + half]
            }
        };
        sample_nodes(self.as_slice(), M, t, self.lookup)
    }

    /// Weights of consecutive pixels along one row, `out[k]` at offset `(qx0 + k, qy)`: what
    /// [`ViewTable::weight`] gives there, with the row's table line and fraction found once and
    /// the column stepped per pixel in 16.16 fixed point (integer adds and shifts instead of a
    /// float-to-integer conversion per pixel; the column's position is rounded to 2⁻¹⁶ of a node).
    /// Bilinear weights are blended across the two table rows first, then along the row.
    ///
    /// In the unit layout both table coordinates step per pixel (by the first column of
    /// (M−1)/2 · A), each in 16.16 fixed point.
    #[inline]
    pub fn row_weights(&self, qx0: f32, qy: f32, out: &mut [f32]) {
        if self.layout == ViewLayout::Unit {
            return self.unit_row_weights(qx0, qy, out);
        }
        const ONE: f32 = 65536.0;
        let [ex, ey] = self.footprint.half_extent;
        let last = (M - 1) as f32;
        let ty = (qy + ey) * self.nodes_per_px[1];
        let tx0 = (qx0 + ex) * self.nodes_per_px[0];
        let tx_end = tx0 + out.len() as f32 * self.nodes_per_px[0];
        // The row must be on the table, and the fixed-point walk must stay within ±2³¹ nodes.
        if !(ty >= 0.0 && ty <= last && tx0 > -4096.0 && tx_end < 4096.0 + last) {
            out.fill(0.0);
            return;
        }
        let last_fx = ((M - 1) as i64) << 16;
        let step = (self.nodes_per_px[0] * ONE + 0.5) as i64;
        let mut t = (tx0 * ONE + 0.5 * tx0.signum()) as i64;
        match self.lookup {
            Lookup::Nearest => {
                let row = &self.data[((ty + 0.5) as usize).min(M - 1)];
                for w in out.iter_mut() {
                    *w = if (0..=last_fx).contains(&t) {
                        row[(((t + 0x8000) >> 16) as usize).min(M - 1)]
                    } else {
                        0.0
                    };
                    t += step;
                }
            }
            Lookup::Bilinear => {
                let r = (ty as usize).min(M - 2);
                let fy = ty - r as f32;
                let (a, b) = (&self.data[r], &self.data[r + 1]);
                for w in out.iter_mut() {
                    *w = if (0..=last_fx).contains(&t) {
                        let c = ((t >> 16) as usize).min(M - 2);
                        let fx = (t - ((c as i64) << 16)) as f32 * (1.0 / ONE);
                        let left = a[c] + fy * (b[c] - a[c]);
                        let right = a[c + 1] + fy * (b[c + 1] - a[c + 1]);
                        left + fx * (right - left)
                    } else {
                        0.0
                    };
                    t += step;
                }
            }
        }
    }
}

impl<const M: usize> ViewTable<M> {
    /// [`ViewTable::row_weights`] in the unit layout.
    #[inline]
    fn unit_row_weights(&self, qx0: f32, qy: f32, out: &mut [f32]) {
        self.line_weights([qx0, qy], [1.0, 0.0], out);
    }

    /// Weights along a line of pixels: `out[k]` at screen offset `q0 + k·step` (pixels) — what
    /// [`ViewTable::weight`] gives there, with both table coordinates stepped per pixel in 16.16
    /// fixed point (positions rounded to 2⁻¹⁶ of a node). [`ViewTable::row_weights`] is the
    /// case `step` = (1, 0); a refined sample's footprint read at scaled coordinates
    /// ([`crate::render::splat_scaled`]) walks other directions.
    #[inline]
    pub fn line_weights(&self, q0: [f32; 2], step: [f32; 2], out: &mut [f32]) {
        const ONE: f32 = 65536.0;
        let (t0, dt) = match self.layout {
            ViewLayout::Unit => {
                let half = 0.5 * (M - 1) as f32;
                let m = &self.unit_map;
                (
                    [
                        m[0][0] * q0[0] + m[0][1] * q0[1] + half,
                        m[1][0] * q0[0] + m[1][1] * q0[1] + half,
                    ],
                    [
                        m[0][0] * step[0] + m[0][1] * step[1],
                        m[1][0] * step[0] + m[1][1] * step[1],
                    ],
                )
            }
            ViewLayout::ScreenBox => {
                let [ex, ey] = self.footprint.half_extent;
                let n = self.nodes_per_px;
                (
                    [(q0[0] + ex) * n[0], (q0[1] + ey) * n[1]],
                    [step[0] * n[0], step[1] * n[1]],
                )
            }
        };
        let n = out.len() as f32;
        let t1 = [t0[0] + n * dt[0], t0[1] + n * dt[1]];
        // The fixed-point walk must stay within ±2³¹ nodes; anything else (huge offsets, NaN)
        // takes the per-pixel path, which reads zero off the table.
        let bound = 16384.0;
        if !(t0[0].abs() < bound
            && t0[1].abs() < bound
            && t1[0].abs() < bound
            && t1[1].abs() < bound)
        {
            for (k, w) in out.iter_mut().enumerate() {
                let k = k as f32;
                *w = self.weight([q0[0] + k * step[0], q0[1] + k * step[1]]);
            }
            return;
        }
        let fx = |x: f32| (x * ONE + 0.5 * x.signum()) as i64;
        let last_fx = ((M - 1) as i64) << 16;
        let (mut tx, mut ty) = (fx(t0[0]), fx(t0[1]));
        let (sx, sy) = (fx(dt[0]), fx(dt[1]));
        for w in out.iter_mut() {
            let inside = (0..=last_fx).contains(&tx) && (0..=last_fx).contains(&ty);
            *w = if !inside {
                0.0
            } else {
                match self.lookup {
                    Lookup::Nearest => {
                        let c = (((tx + 0x8000) >> 16) as usize).min(M - 1);
                        let r = (((ty + 0x8000) >> 16) as usize).min(M - 1);
                        self.data[r][c]
                    }
                    Lookup::Bilinear => {
                        let c = ((tx >> 16) as usize).min(M - 2);
                        let r = ((ty >> 16) as usize).min(M - 2);
                        let f = (tx - ((c as i64) << 16)) as f32 * (1.0 / ONE);
                        let g = (ty - ((r as i64) << 16)) as f32 * (1.0 / ONE);
                        let (a, b) = (&self.data[r], &self.data[r + 1]);
                        let top = a[c] + f * (a[c + 1] - a[c]);
                        let bottom = b[c] + f * (b[c + 1] - b[c]);
                        top + g * (bottom - top)
                    }
                }
            };
            tx += sx;
            ty += sy;
        }
    }
}

/// Calls `set(node, T)` for every node of an M×M table in `layout` over `footprint` (see
/// [`ViewLayout`] for where node (row, col) lies), with T the generic table read at that node's
/// unit coordinates with `build` lookup. The float view table and the fixed-point one both sample
/// through this, so they share their nodes bit for bit.
pub(crate) fn for_each_view_node<T, const N: usize, const M: usize>(
    footprint: &Footprint,
    generic: &GenericTable<N>,
    build: Lookup,
    layout: ViewLayout,
    data: &mut [[T; M]; M],
    mut set: impl FnMut(&mut T, f32),
) {
    let [ex, ey] = footprint.half_extent;
    let steps = (M - 1) as f32;
    for (row, line) in data.iter_mut().enumerate() {
        let y = -ey + 2.0 * ey * row as f32 / steps;
        let v = -1.0 + 2.0 * row as f32 / steps;
        for (col, value) in line.iter_mut().enumerate() {
            let u = match layout {
                ViewLayout::ScreenBox => {
                    let x = -ex + 2.0 * ex * col as f32 / steps;
                    mul2(&footprint.to_unit, [x, y])
                }
                ViewLayout::Unit => [-1.0 + 2.0 * col as f32 / steps, v],
            };
            set(value, generic.sample(u, build));
        }
    }
}
