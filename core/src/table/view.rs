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
