//! Bricks: boxes of a volume's voxel grid, and where a brick's samples sit in it (for rendering
//! a volume split among processes; see `crate::distributed`). Reading them: [`super::cut`].
//!
//! Indices are the whole grid's, `[lo, hi)` per axis (i, j, k). A brick *owns* the voxels it
//! renders and *stores* those plus the ghost voxels around them that its gradients read (one
//! layer: the core's gradients are central differences of a voxel's six neighbours), clipped to
//! the grid.

/// A box of voxel indices, `[lo, hi)` along each axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct IndexBox {
    pub lo: [usize; 3],
    pub hi: [usize; 3],
}

impl IndexBox {
    /// The whole grid of `dims`.
    pub fn whole(dims: [usize; 3]) -> Self {
        IndexBox {
            lo: [0; 3],
            hi: dims,
        }
    }

    /// Voxels along each axis.
    pub fn dims(&self) -> [usize; 3] {
        [0, 1, 2].map(|c| self.hi[c].saturating_sub(self.lo[c]))
    }

    /// Number of voxels.
    pub fn count(&self) -> usize {
        self.dims().iter().product()
    }

    /// Whether voxel `g` lies inside.
    pub fn contains(&self, g: [usize; 3]) -> bool {
        (0..3).all(|c| self.lo[c] <= g[c] && g[c] < self.hi[c])
    }

    /// This box grown by `by` voxels on every side, clipped to the grid of `dims`.
    pub fn grown(&self, by: usize, dims: [usize; 3]) -> Self {
        IndexBox {
            lo: self.lo.map(|l| l.saturating_sub(by)),
            hi: [0, 1, 2].map(|c| (self.hi[c] + by).min(dims[c])),
        }
    }
}

/// Where a brick's samples sit in the whole volume's grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BrickPlace {
    /// The stored box: the brick and the ghost voxels its gradients read.
    pub stored: IndexBox,
    /// The voxels this brick renders (inside `stored`).
    pub owned: IndexBox,
}

/// Ghost layers a brick stores around the voxels it owns: the core's gradients read a voxel's
/// six neighbours (`footprint::render::sheets`), and nothing else reads past a voxel.
pub const GHOST: usize = 1;

impl BrickPlace {
    /// The brick owning `owned` of a grid of `dims`, with [`GHOST`] layers stored around it.
    pub fn around(owned: IndexBox, dims: [usize; 3]) -> Self {
        BrickPlace {
            stored: owned.grown(GHOST, dims),
            owned,
        }
    }
}
