//! The generic footprint table: the paper's preprocessor output, built once per kernel.

use super::{sample_nodes, Lookup};
use crate::kernel::Kernel;

/// N×N samples of a kernel's normalised footprint T(u) = F(u)/∫∫F over u ∈ [−1, 1]², at the nodes
/// u = −1 + 2t/(N−1) (see [`crate::table`] for the layout and normalisation). N ≥ 2.
///
/// 4·N² bytes; build it in place ([`GenericTable::build_into`]) or in a `static` on small targets.
#[derive(Clone, Debug, PartialEq)]
pub struct GenericTable<const N: usize> {
    pub(crate) kernel: Kernel,
    pub(crate) data: [[f32; N]; N],
}

impl<const N: usize> GenericTable<N> {
    pub(crate) const VALID: () = assert!(N >= 2, "a table needs at least 2×2 nodes");

    /// An all-zero table for `kernel`, to be filled by [`GenericTable::build_into`] or
    /// [`GenericTable::load_into`]. Usable in `static` initialisers.
    pub const fn zeroed(kernel: Kernel) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::VALID;
        GenericTable {
            kernel,
            data: [[0.0; N]; N],
        }
    }

    /// Builds the table for `kernel` (the paper's preprocessor; N² footprint evaluations).
    pub fn build(kernel: Kernel) -> Self {
        let mut t = Self::zeroed(kernel);
        t.build_into(kernel);
        t
    }

    /// Rebuilds this table in place for `kernel`, without a second N×N array on the stack.
    pub fn build_into(&mut self, kernel: Kernel) {
        self.kernel = kernel;
        let inv_integral = 1.0 / kernel.integral();
        let step = 2.0 / (N - 1) as f32;
        for (row, line) in self.data.iter_mut().enumerate() {
            let v = -1.0 + step * row as f32;
            for (col, value) in line.iter_mut().enumerate() {
                let u = -1.0 + step * col as f32;
                *value = kernel.footprint([u, v]) * inv_integral;
            }
        }
    }

    /// The kernel the table was built for.
    pub fn kernel(&self) -> &Kernel {
        &self.kernel
    }

    /// The samples, row-major (row = u₁, column = u₀).
    pub fn as_slice(&self) -> &[f32] {
        self.data.as_flattened()
    }

    /// T at unit coordinates `u` (zero outside [−1, 1]²).
    #[inline]
    pub fn sample(&self, u: [f32; 2], lookup: Lookup) -> f32 {
        let half = 0.5 * (N - 1) as f32;
        sample_nodes(
            self.as_slice(),
            N,
            [(u[0] + 1.0) * half, (u[1] + 1.0) * half],
            lookup,
        )
    }
}
