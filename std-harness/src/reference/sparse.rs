//! The continuous field's voxels in blocks of [`SIDE`]³ (x fastest inside a block), allocated
//! only where a voxel is stored: an absent block reads as transparent (all zeros).
//!
//! A dense `[f32; 4]` per voxel, x fastest, costs 16 bytes a voxel whatever the data: 268 MB for
//! a 256³ volume, and a row of 256 voxels is one 4 KiB page, so one voxel that can be seen in a
//! row faults its page in. The pre-classified models store only voxels that can be seen, so only
//! the blocks holding one are used (on the 256³ blobs of `../shared/data`, 15.5 % of its 8³
//! blocks). Storage for every block is reserved at once, zeroed by the allocator (fresh pages from
//! the system for a large grid, not written here), and blocks are handed out in the order they are
//! first stored to, so the pages touched are those of the blocks used and nothing is ever moved.
//! Post-classification stores every voxel (a value below the transfer function's first opacity
//! still weighs in a sample's interpolation), so every block is used there: the grid's sides
//! rounded up to whole blocks, ∏⌈dᵢ/8⌉·8 / ∏dᵢ of the dense size (1.0 for sides that are
//! multiples of 8, 1.08 for 257³, at most 1.36 for sides of 65 and up).

/// Voxels per block side (a block is 512 voxels, 8 KiB).
pub(super) const SIDE: usize = 8;
const VOXELS: usize = SIDE * SIDE * SIDE;
const ABSENT: u32 = u32::MAX;

/// Voxels `[f32; 4]` of a `dims` grid, each zero until stored.
pub(super) struct SparseGrid {
    dims: [usize; 3],
    /// Blocks per axis.
    count: [usize; 3],
    /// Per block (x fastest): its first voxel in `data` ÷ [`VOXELS`], or [`ABSENT`].
    slot: Vec<u32>,
    /// Blocks used so far.
    used: u32,
    /// Room for every block, zero bits (0.0) until stored to.
    data: Vec<[f32; 4]>,
}

impl SparseGrid {
    /// An empty grid of `dims` voxels, or `None` if its block map or the room for its blocks
    /// cannot be allocated.
    pub(super) fn new(dims: [usize; 3]) -> Option<Self> {
        let count = dims.map(|d| d.div_ceil(SIDE));
        let n = count.iter().try_fold(1usize, |a, &c| a.checked_mul(c))?;
        // Slots are u32 with one value kept for "absent".
        if n >= ABSENT as usize {
            return None;
        }
        let mut slot = Vec::new();
        slot.try_reserve_exact(n).ok()?;
        slot.resize(n, ABSENT);
        Some(SparseGrid {
            dims,
            count,
            slot,
            used: 0,
            data: zeroed(n.checked_mul(VOXELS)?)?,
        })
    }

    /// Blocks per axis.
    pub(super) fn count(&self) -> [usize; 3] {
        self.count
    }

    /// Stores `v` at voxel `idx` (inside the grid), taking the next block for its block on first
    /// use.
    #[inline]
    pub(super) fn set(&mut self, idx: [usize; 3], v: [f32; 4]) {
        let b = self.block_of(idx);
        if self.slot[b] == ABSENT {
            // At most one slot per block, and there are fewer blocks than ABSENT.
            self.slot[b] = self.used;
            self.used += 1;
        }
        let at = self.slot[b] as usize * VOXELS + local(idx);
        self.data[at] = v;
    }

    /// The voxel at `(x, y, z)` (inside the grid); `None` where its block holds nothing (every
    /// voxel there is zero).
    #[inline]
    pub(super) fn get(&self, x: usize, y: usize, z: usize) -> Option<&[f32; 4]> {
        self.row(y, z).get(x)
    }

    /// The row of voxels at `(y, z)` (inside the grid), for reading several of its voxels.
    #[inline]
    pub(super) fn row(&self, y: usize, z: usize) -> Row<'_> {
        debug_assert!(y < self.dims[1] && z < self.dims[2]);
        Row {
            grid: self,
            blocks: ((z / SIDE) * self.count[1] + y / SIDE) * self.count[0],
            local: ((z % SIDE) * SIDE + y % SIDE) * SIDE,
        }
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

/// One row of a [`SparseGrid`]: its blocks' first index in the block map and its place inside
/// them.
pub(super) struct Row<'g> {
    grid: &'g SparseGrid,
    blocks: usize,
    local: usize,
}

impl<'g> Row<'g> {
    /// Voxel `x` of the row (inside the grid), as [`SparseGrid::get`].
    #[inline]
    pub(super) fn get(&self, x: usize) -> Option<&'g [f32; 4]> {
        let s = self.grid.slot[self.blocks + x / SIDE];
        (s != ABSENT).then(|| &self.grid.data[s as usize * VOXELS + self.local + x % SIDE])
    }
}

/// `n` voxels of zero bits, or `None` if they cannot be allocated. The memory comes zeroed from
/// the allocator (fresh pages from the system for a large grid), not written here, so a page no
/// voxel is stored to is never touched.
fn zeroed(n: usize) -> Option<Vec<[f32; 4]>> {
    let layout = std::alloc::Layout::array::<[f32; 4]>(n).ok()?;
    if layout.size() == 0 {
        return Some(Vec::new());
    }
    // SAFETY: the layout has a non-zero size, as `alloc_zeroed` requires. A non-null result
    // is valid for `n` `[f32; 4]`s of zero bits, which are valid values (0.0), allocated by the
    // global allocator with exactly the layout of a `Vec` of capacity `n`, so `from_raw_parts`
    // (length and capacity `n`) takes ownership of it as a `Vec` would have allocated it.
    unsafe {
        let ptr = std::alloc::alloc_zeroed(layout).cast::<[f32; 4]>();
        (!ptr.is_null()).then(|| Vec::from_raw_parts(ptr, n, n))
    }
}

/// A voxel's place inside its block.
#[inline]
fn local(idx: [usize; 3]) -> usize {
    ((idx[2] % SIDE) * SIDE + idx[1] % SIDE) * SIDE + idx[0] % SIDE
}

/// The blocks of a `blocks`-sized map (x fastest) within `r` blocks along every axis of one set
/// in `holds`.
pub(super) fn dilate(holds: &[bool], blocks: [usize; 3], r: usize) -> Vec<bool> {
    let mut out = vec![false; holds.len()];
    let span = |c: usize, a: usize| c.saturating_sub(r)..=(c + r).min(blocks[a] - 1);
    for z in 0..blocks[2] {
        for y in 0..blocks[1] {
            for x in 0..blocks[0] {
                if !holds[(z * blocks[1] + y) * blocks[0] + x] {
                    continue;
                }
                for bz in span(z, 2) {
                    for by in span(y, 1) {
                        for bx in span(x, 0) {
                            out[(bz * blocks[1] + by) * blocks[0] + bx] = true;
                        }
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::SparseGrid;

    #[test]
    fn every_stored_voxel_reads_back_and_every_other_reads_as_zero() {
        // A grid whose sides are not multiples of a block, a scatter of voxels stored (some
        // twice), every voxel read back against a dense copy.
        let dims = [19usize, 9, 13];
        let mut grid = SparseGrid::new(dims).unwrap();
        let mut dense = vec![[0.0f32; 4]; dims.iter().product()];
        let mut seed = 7u64;
        for i in 0..300 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let idx = [0, 1, 2].map(|a| (seed >> (16 + 12 * a)) as usize % dims[a]);
            let v = [i as f32, 1.0, 2.0, 3.0];
            grid.set(idx, v);
            dense[(idx[2] * dims[1] + idx[1]) * dims[0] + idx[0]] = v;
        }
        assert_eq!(grid.dims(), dims);
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let want = dense[(z * dims[1] + y) * dims[0] + x];
                    let got = grid.get(x, y, z).copied().unwrap_or([0.0; 4]);
                    assert_eq!(got, want, "({x},{y},{z})");
                    let by_row = grid.row(y, z).get(x).copied().unwrap_or([0.0; 4]);
                    assert_eq!(by_row, want, "row ({x},{y},{z})");
                }
            }
        }
    }

    #[test]
    fn only_blocks_holding_a_stored_voxel_are_allocated() {
        let mut grid = SparseGrid::new([64, 64, 64]).unwrap();
        assert_eq!(grid.count(), [8, 8, 8]);
        grid.set([0, 0, 0], [1.0; 4]);
        grid.set([7, 7, 7], [1.0; 4]);
        grid.set([63, 8, 0], [1.0; 4]);
        assert_eq!(grid.used, 2);
        assert!(grid.get(8, 0, 0).is_none());
        assert!(grid.get(62, 15, 7).is_some());
    }
}
