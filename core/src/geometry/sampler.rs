//! [`Sampler`]: what a splat reads a footprint through (a view table, phase stencils, the
//! direct method, a per-voxel footprint). It lives beside [`Footprint`] so that the tables, which
//! implement it, stand below the splat that uses them.

use super::Footprint;

/// Something that gives a view's footprint weight at a screen offset.
pub trait Sampler {
    /// The footprint (extent, renormalisation) this sampler evaluates.
    fn footprint(&self) -> &Footprint;
    /// Weight, px⁻², at offset `q` pixels from the voxel's projected centre (x right, y down).
    fn weight(&self, q: [f32; 2]) -> f32;
    /// Weights of `out.len()` consecutive pixels of one row: `out[k]` at offset
    /// `(qx0 + k, qy)`. The splat's inner loop; samplers override it to step through their table.
    #[inline]
    fn row_weights(&self, qx0: f32, qy: f32, out: &mut [f32]) {
        for (k, w) in out.iter_mut().enumerate() {
            *w = self.weight([qx0 + k as f32, qy]);
        }
    }
    /// Weights along any line of pixels: `out[k]` at offset `q0 + k·step`. Samplers that can
    /// step through their table override it.
    #[inline]
    fn line_weights(&self, q0: [f32; 2], step: [f32; 2], out: &mut [f32]) {
        for (k, w) in out.iter_mut().enumerate() {
            let k = k as f32;
            *w = self.weight([q0[0] + k * step[0], q0[1] + k * step[1]]);
        }
    }
}
