//! The continuous field's voxels in blocks of [`SIDE`]³ (x fastest inside a block), allocated
//! only where a voxel is stored: an absent block reads as transparent (all zeros).
//!
//! A dense `[f32; 4]` per voxel costs 16 bytes a voxel whatever the data: 268 MB for a 256³
//! volume, most of it transparent in a typical scan. The pre-classified models store only voxels
//! that can be seen, so only the blocks holding one are allocated (on the 256³ blobs of
//! `../shared/data`, 15.5 % of its 8³ blocks), and the pages of the rest are never touched.
//! Post-classification stores every voxel (a value below the transfer function's first opacity
//! still weighs in a sample's interpolation), so every block is allocated there, as dense as
//! before.

/// Voxels per block side (a block is 512 voxels, 8 KiB).
pub(super) const SIDE: usize = 8;
const VOXELS: usize = SIDE * SIDE * SIDE;
const ABSENT: u32 = u32::MAX;

/// Voxels `[f32; 4]` of a `dims` grid, each zero until stored.
pub(super) struct SparseGrid {
    dims: [usize; 3],
    /// SparseGrid per axis.
    count: [usize; 3],
    /// Per block (x fastest): its first voxel in `data` ÷ [`VOXELS`], or [`ABSENT`].
    slot: Vec<u32>,
    data: Vec<[f32; 4]>,
}

impl SparseGrid {
    /// An empty grid of `dims` voxels (no block allocated), or `None` if its block map cannot be
    /// allocated. With `dense` the storage of every block is reserved at once (for a field that
    /// stores every voxel: no reallocation, no doubling on the way), or `None` if it cannot be.
    pub(super) fn new(dims: [usize; 3], dense: bool) -> Option<Self> {
        let count = dims.map(|d| d.div_ceil(SIDE));
        let n = count.iter().try_fold(1usize, |a, &c| a.checked_mul(c))?;
        let mut slot = Vec::new();
        slot.try_reserve_exact(n).ok()?;
        slot.resize(n, ABSENT);
        let mut data = Vec::new();
        if dense {
            data.try_reserve_exact(n.checked_mul(VOXELS)?).ok()?;
        }
        Some(SparseGrid {
            dims,
            count,
            slot,
            data,
        })
    }

    /// SparseGrid per axis.
    pub(super) fn count(&self) -> [usize; 3] {
        self.count
    }

    /// Stores `v` at voxel `idx` (inside the grid), allocating its block (zeroed) on first use.
    /// Errs if the block cannot be allocated.
    pub(super) fn set(&mut self, idx: [usize; 3], v: [f32; 4]) -> Result<(), ()> {
        let b = self.block_of(idx);
        if self.slot[b] == ABSENT {
            let next = self.data.len() / VOXELS;
            let next = u32::try_from(next)
                .ok()
                .filter(|&s| s != ABSENT)
                .ok_or(())?;
            self.data.try_reserve(VOXELS).map_err(|_| ())?;
            self.data.resize(self.data.len() + VOXELS, [0.0; 4]);
            self.slot[b] = next;
        }
        let at = self.slot[b] as usize * VOXELS + local(idx);
        self.data[at] = v;
        Ok(())
    }

    /// The voxel at `(x, y, z)` (inside the grid); `None` where its block holds nothing (every
    /// voxel there is zero).
    #[inline]
    pub(super) fn get(&self, x: usize, y: usize, z: usize) -> Option<&[f32; 4]> {
        let s = self.slot[self.block_of([x, y, z])];
        (s != ABSENT).then(|| &self.data[s as usize * VOXELS + local([x, y, z])])
    }

    /// The grid's size in voxels.
    #[cfg(test)]
    fn dims(&self) -> [usize; 3] {
        self.dims
    }

    #[inline]
    fn block_of(&self, idx: [usize; 3]) -> usize {
        debug_assert!(idx.iter().zip(self.dims).all(|(&c, d)| c < d));
        let b = idx.map(|c| c / SIDE);
        (b[2] * self.count[1] + b[1]) * self.count[0] + b[0]
    }
}

/// A voxel's place inside its block.
#[inline]
fn local(idx: [usize; 3]) -> usize {
    ((idx[2] % SIDE) * SIDE + idx[1] % SIDE) * SIDE + idx[0] % SIDE
}

#[cfg(test)]
mod tests {
    use super::SparseGrid;

    #[test]
    fn every_stored_voxel_reads_back_and_every_other_reads_as_zero() {
        // A grid whose sides are not multiples of a block, a scatter of voxels stored (some
        // twice), every voxel read back against a dense copy.
        let dims = [19usize, 9, 13];
        let mut grid = SparseGrid::new(dims, false).unwrap();
        let mut dense = vec![[0.0f32; 4]; dims.iter().product()];
        let mut seed = 7u64;
        for i in 0..300 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let idx = [0, 1, 2].map(|a| (seed >> (16 + 12 * a)) as usize % dims[a]);
            let v = [i as f32, 1.0, 2.0, 3.0];
            grid.set(idx, v).unwrap();
            dense[(idx[2] * dims[1] + idx[1]) * dims[0] + idx[0]] = v;
        }
        assert_eq!(grid.dims(), dims);
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let want = dense[(z * dims[1] + y) * dims[0] + x];
                    let got = grid.get(x, y, z).copied().unwrap_or([0.0; 4]);
                    assert_eq!(got, want, "({x},{y},{z})");
                }
            }
        }
    }

    #[test]
    fn only_blocks_holding_a_stored_voxel_are_allocated() {
        let mut grid = SparseGrid::new([64, 64, 64], false).unwrap();
        assert_eq!(grid.count(), [8, 8, 8]);
        grid.set([0, 0, 0], [1.0; 4]).unwrap();
        grid.set([7, 7, 7], [1.0; 4]).unwrap();
        grid.set([63, 8, 0], [1.0; 4]).unwrap();
        assert_eq!(grid.data.len(), 2 * 512);
        assert!(grid.get(8, 0, 0).is_none());
        assert!(grid.get(62, 15, 7).is_some());
    }
}
