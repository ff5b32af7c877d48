//! The view-transformed footprint table: the generic table resampled over one view's screen
//! extent, built once per view and reused for every voxel.

use super::{sample_nodes, GenericTable, Lookup};
use crate::geometry::{mul2, Footprint};

/// M×M samples of one view's footprint weight (px⁻², see [`Footprint`]) at the nodes of the
/// screen box [−eₓ, eₓ] × [−e_y, e_y] (e = the footprint's half-extent in pixels). M ≥ 2.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewTable<const M: usize> {
    pub(crate) data: [[f32; M]; M],
    pub(crate) footprint: Footprint,
    /// Nodes per pixel along x and y: (M−1)/(2e).
    pub(crate) nodes_per_px: [f32; 2],
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
            nodes_per_px: [0.0; 2],
            lookup: Lookup::Nearest,
        }
    }

    /// Builds the view table for `footprint` from `generic`: each node q is mapped to
    /// u = A q and read from the generic table with `build` lookup. Pixels are later read from
    /// this table with `sample` lookup.
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
        let [ex, ey] = footprint.half_extent;
        let steps = (M - 1) as f32;
        for_each_view_node(footprint, generic, build, &mut self.data, |value, t| {
            *value = footprint.scale * t
        });
        self.footprint = *footprint;
        self.nodes_per_px = [steps / (2.0 * ex), steps / (2.0 * ey)];
        self.lookup = sample;
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
        let [ex, ey] = self.footprint.half_extent;
        let t = [
            (q[0] + ex) * self.nodes_per_px[0],
            (q[1] + ey) * self.nodes_per_px[1],
        ];
        sample_nodes(self.as_slice(), M, t, self.lookup)
    }

    /// Weights of consecutive pixels along one row, `out[k]` at offset `(qx0 + k, qy)`: what
    /// [`ViewTable::weight`] gives there, with the row's table line and fraction found once and
    /// the column stepped per pixel in 16.16 fixed point (integer adds and shifts instead of a
    /// float-to-integer conversion per pixel; the column's position is rounded to 2⁻¹⁶ of a node).
    /// Bilinear weights are blended across the two table rows first, then along the row.
    #[inline]
    pub fn row_weights(&self, qx0: f32, qy: f32, out: &mut [f32]) {
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

/// Calls `set(node, T)` for every node of an M×M table over `footprint`'s screen box (node
/// (row, col) at screen offset (−eₓ + 2eₓ·col/(M−1), −e_y + 2e_y·row/(M−1)) px), with T the
/// generic table read at that node's unit coordinates with `build` lookup. The float view table
/// and the fixed-point one both sample through this, so they share their nodes bit for bit.
pub(crate) fn for_each_view_node<T, const N: usize, const M: usize>(
    footprint: &Footprint,
    generic: &GenericTable<N>,
    build: Lookup,
    data: &mut [[T; M]; M],
    mut set: impl FnMut(&mut T, f32),
) {
    let [ex, ey] = footprint.half_extent;
    let steps = (M - 1) as f32;
    for (row, line) in data.iter_mut().enumerate() {
        let y = -ey + 2.0 * ey * row as f32 / steps;
        for (col, value) in line.iter_mut().enumerate() {
            let x = -ex + 2.0 * ex * col as f32 / steps;
            set(
                value,
                generic.sample(mul2(&footprint.to_unit, [x, y]), build),
            );
        }
    }
}
