//! Sampling one phase stencil from a view's footprint ([`super::Stencils::build_split`] hands
//! these out, so a caller with threads can fill stencils in parallel).

use crate::splat::Sampler;

/// Samples single stencils of a view's phase stencils for [`super::Stencils::build_split`].
#[derive(Debug)]
pub struct StencilFill<'a, S: ?Sized> {
    pub(super) sampler: &'a S,
    pub(super) side: usize,
    pub(super) phases: usize,
    pub(super) reach: i64,
}

impl<S: Sampler + ?Sized> StencilFill<'_, S> {
    /// Weights per stencil, B².
    pub fn cells(&self) -> usize {
        self.side * self.side
    }

    /// Fills stencil `k` (phase (k mod (P + 1), k div (P + 1)) on the (P + 1)² grid; `stencil`
    /// holds [`StencilFill::cells`] weights): the sampler's weight (px⁻²) at each box pixel inside
    /// the support, zero outside, divided by the sum for a renormalised footprint.
    pub fn fill(&self, k: usize, stencil: &mut [f32]) {
        let (sampler, side, phases, reach) = (self.sampler, self.side, self.phases, self.reach);
        let fp = sampler.footprint();
        let (pa, pb) = (k % (phases + 1), k / (phases + 1));
        let phase = [pa as f32 / phases as f32, pb as f32 / phases as f32];
        let mut sum = 0.0f32;
        for (my, row) in stencil.chunks_exact_mut(side).enumerate() {
            let qy = (my as i64 - reach) as f32 + 0.5 - phase[1];
            for (mx, w) in row.iter_mut().enumerate() {
                let q = [(mx as i64 - reach) as f32 + 0.5 - phase[0], qy];
                *w = if fp.contains(q) {
                    sampler.weight(q)
                } else {
                    0.0
                };
                sum += *w;
            }
        }
        if fp.renormalise {
            if sum > 0.0 {
                let inv = 1.0 / sum;
                stencil.iter_mut().for_each(|w| *w *= inv);
            } else {
                // No pixel centre saw the footprint: the whole voxel goes to its own pixel.
                stencil.fill(0.0);
                stencil[reach as usize * side + reach as usize] = 1.0;
            }
        }
    }
}
