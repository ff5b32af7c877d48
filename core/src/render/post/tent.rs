//! Trilinear reconstruction as splatting ([`PostReconstruction::Trilinear`]).
//!
//! A voxel at grid index v contributes to a sample at grid point g the weight
//! τ(g − v) = Π_a (1 − |g_a − v_a|)₊, its trilinear basis function (the tent): summed over the
//! lattice, Σᵥ τ(g − v)·fᵥ is the trilinear interpolant of the values at g, and Σᵥ τ(g − v) = 1
//! wherever all eight corners exist. A post-classified slab is a point sample of the
//! reconstruction at its mid-plane (see the module docs of [`super`]), so a voxel's "section"
//! through a slab is its tent at one point per pixel: no integral along the ray is involved.
//!
//! **Where the tent is non-zero on a row.** Screen offsets d = (dx, dy, dz) from the voxel
//! (value pixels, and the mid-plane's depth) map to grid offsets q = M·d, M the screen → grid
//! matrix at the values' scale. On a row (dy fixed) of a slab's mid-plane (dz fixed) each
//! q_a = m_a·dx + b_a is linear in dx, so the support |q_a| < 1 on every axis is the
//! intersection of three intervals of dx (the cube's section by the row: a segment), found in
//! closed form; an axis with m_a = 0 keeps the whole row or none of it.

use super::setup::PostReconstruction;
use super::{Classify, PostRenderer, Run};
use crate::composite::RowSpan;
use crate::frame::Order;
use crate::render::slabs::centres_within;
use glam::Mat3;

/// A tent on one row of one slab's mid-plane: q_a = m_a·dx + b_a, dx the pixel centre's offset
/// from the voxel (value pixels).
#[derive(Clone, Copy, Debug)]
pub(super) struct TentRow {
    m: [f32; 3],
    b: [f32; 3],
    /// 1/m_a (infinite where m_a = 0).
    inv: [f32; 3],
}

impl TentRow {
    /// The row at screen offset `dy` (rows) and `dz` (depth) from the voxel, for `to_grid`
    /// (screen at the values' scale → grid steps), with `inv` = 1/m_a, m_a its first column (the
    /// same for every row of a frame: the divisions are done once, not per row).
    #[inline]
    pub(super) fn with_inverse(to_grid: &Mat3, inv: [f32; 3], dy: f32, dz: f32) -> Self {
        let b = to_grid.col(1) * dy + to_grid.col(2) * dz;
        TentRow {
            m: to_grid.col(0).to_array(),
            b: b.to_array(),
            inv,
        }
    }

    /// The open interval of dx where every |q_a| < 1 (`None` if empty), to the rounding of
    /// 1/m_a: a pixel at its very ends weighs (1 − |q_a|)₊ = 0 either way.
    #[inline]
    pub(super) fn support(&self) -> Option<(f32, f32)> {
        let (mut lo, mut hi) = (f32::NEG_INFINITY, f32::INFINITY);
        for ((&m, &b), &inv) in self.m.iter().zip(&self.b).zip(&self.inv) {
            if m == 0.0 {
                if !(b.abs() < 1.0) {
                    return None;
                }
                continue;
            }
            let (u, v) = ((-1.0 - b) * inv, (1.0 - b) * inv);
            lo = lo.max(u.min(v));
            hi = hi.min(u.max(v));
        }
        (lo < hi).then_some((lo, hi))
    }

    /// The tent at offset `dx`: Π (1 − |q_a|)₊.
    #[inline]
    pub(super) fn weight(&self, dx: f32) -> f32 {
        let f = |a: usize| (1.0 - (self.m[a] * dx + self.b[a]).abs()).max(0.0);
        f(0) * f(1) * f(2)
    }
}

impl<C: Classify, const N: usize> PostRenderer<'_, C, N> {
    /// [`PostRenderer::accumulate`] for a trilinear setup: the same slabs, rows, order of
    /// additions and opaque-pixel skip, each weight the voxel's tent at the pixel's point of the
    /// slab's mid-plane.
    #[inline]
    pub(super) fn accumulate_tent<const K: usize>(&mut self, run: &Run, add: &[f32; K]) -> u64 {
        debug_assert_eq!(self.setup.reconstruction, PostReconstruction::Trilinear);
        let s = &self.setup.low;
        let (w, ring, v0, vn) = (s.size[0], self.ring, self.values.0, self.values.1);
        let [cx, cy, cz] = run.centre;
        // Value pixels are `scale` image pixels (and depth units) each.
        let to_grid = self.setup.to_grid * self.setup.scale as f32;
        let inv = to_grid.col(0).to_array().map(|m| 1.0 / m);
        let opaque_skip =
            self.setup.scale == 1 && self.order == Order::FrontToBack && !self.blend.projects();
        let mut updates = 0u64;
        for k in 0..run.slabs.min(ring) {
            let slot = (run.first + k) % ring;
            let dz = s.front(run.first + k) + 0.5 * s.thickness - cz;
            for y in run.rows.clone() {
                let dy = y as f32 + 0.5 - cy;
                let row = TentRow::with_inverse(&to_grid, inv, dy, dz);
                let Some((lo, hi)) = row.support() else {
                    continue;
                };
                let cols = centres_within(cx + lo, cx + hi, w);
                let (x0, x1) = (cols.start, cols.end);
                if x0 >= x1 {
                    continue;
                }
                let yl = y - v0;
                let base = yl * w;
                let acc = &mut self.buffers.accumulators[(base + x0) * ring..(base + x1) * ring];
                let img = &self.buffers.image;
                for (x, px) in acc.chunks_exact_mut(ring).enumerate() {
                    if opaque_skip && img[base + x0 + x][3] >= 1.0 {
                        continue;
                    }
                    let wgt = row.weight((x0 + x) as f32 + 0.5 - cx);
                    for (c, a) in px[slot].iter_mut().zip(add) {
                        *c += wgt * a;
                    }
                }
                updates += (x1 - x0) as u64;
                let span: &mut RowSpan = &mut self.buffers.rows[slot * vn + yl];
                span.include(x0, x1 - 1);
            }
        }
        updates
    }
}
