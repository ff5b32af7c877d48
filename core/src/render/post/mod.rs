//! Post-classification (Mueller, Möller and Crawfis 1999, "Splatting without the blur"): the
//! voxels' *values* and gradients are splatted into image-aligned slabs, and each slab is
//! classified and shaded per pixel, so transfer-function edges stay as sharp as the
//! reconstructed field makes them instead of being blurred by the kernel.
//!
//! # What a slab holds
//! The slabs are [`super::SlabSetup`]'s (screen depths z₀ + jT to z₀ + (j+1)T, slab 0 nearest). Each
//! voxel adds, at every pixel and for every slab whose **mid-plane** its kernel reaches, its
//! kernel weight w at that point of the mid-plane: the point sample of the reconstruction
//! Σᵥ w(x − v)·fᵥ at the slab's centre along the pixel's ray. A slab accumulates
//! [Σw, Σw·f, Σw·∇f] (∇f the voxel's world gradient: the renderer's central differences), and
//! the sample is the normalised f̄ = Σw·f / Σw, ∇̄f = Σw·∇f / Σw. The normalisation by the weights
//! actually present keeps a constant field constant everywhere, including near the volume's faces,
//! where the kernel's lattice sum drops below one, and past missing (NaN) samples, which the caller
//! leaves out: a sample is a convex combination of its neighbours' values. A sample with no
//! weight is empty (transparent).
//!
//! The weight is the continuous reference's: the Gaussian w(q) ∝ exp(−s²|q|²/(2R²)) for
//! |q| < R (grid steps; s = the kernel's `sigmas`), read from a [`WeightTable`] over
//! r² = |q|²/R² = ρ² + t² (ρ the offset across the ray, t along it, both in kernel radii: see
//! [`super::slabs`]). Its normalisation cancels in f̄. A [`PostSetup::trilinear`] frame weighs
//! by each voxel's tent instead, Π(1 − |q_a|)₊ (its trilinear basis function), so the sample is
//! the trilinear interpolant, as VTK's ray casters reconstruct ([`PostReconstruction`];
//! `tent.rs` finds each row's support in closed form).
//!
//! # Classification and compositing
//! Per pixel and slab, the caller's [`Classify`] turns (f̄, ∇̄f) into a premultiplied layer of
//! the slab's chord: [`ShadedLayers`] shades the sample with the transfer function for one world
//! unit (opacity α per world unit, Phong from ∇̄f) and holds it over the chord L:
//! α_L = 1 − (1 − α)^L, colour the shaded straight colour × α_L. This is the midpoint rule of
//! the post-classified emission–absorption integral with step L (what ray casters compute),
//! second order in L. Samples exist only inside the voxel box (grid coordinates in
//! [0, dims − 1] on every axis, as the continuous reference; [−½, ½] along an axis one voxel
//! thick, [`sample_box`]): a slab that the ray leaves or enters inside it is held over the
//! part of its chord inside the box.
//!
//! Front to back, a pixel whose opacity has reached exactly one is not classified again (exact,
//! not a threshold). A sample whose value is at or below the classifier's transparent bound is not
//! classified either (exact too).
//!
//! # Values at a coarser resolution
//! The reconstructed values vary on the scale of the kernel, which may be many pixels wide on
//! screen; the transfer function's edges are what need every pixel. [`PostSetup::with_value_scale`]
//! splats the values at 1/s of the image size (s² fewer pixel updates) and interpolates the slab's
//! sums bilinearly at each pixel before dividing and classifying, so edges stay per pixel. Value
//! pixel X's centre sits at image coordinate (X + ½)·s. Interpolating the sums, not the
//! normalised values, keeps the bounds exact: where all four surrounding value pixels are at or
//! below the transparent value, so is every pixel between them (a mediant), and the whole cell is
//! skipped. At s = 1 every pixel reads its own value pixel, bit for bit.
//!
//! # Memory, streaming and precision
//! The caller owns everything ([`PostBuffers`]: a ring of [`PostSetup::ring`] accumulators of five
//! floats per value pixel over [`PostSetup::value_rows`], the image and row spans). As for pre-classified slabs, an oblique slab
//! crosses every sheet, so a sheet-at-a-time source cannot feed it from a bounded window. There
//! is no fixed-point variant (classification divides and shades per pixel and slab).

use super::band::{check_band, start_image, SlabQueue};
use super::precision::float_over_row;
use super::slabs::centres_within;
use super::{RenderError, RenderStats};
use crate::composite::{over, RowSpan};
use crate::frame::Order;
use crate::math;
use glam::Vec3;

mod blend;
mod setup;
mod tent;

pub use blend::{vertex, Blend};
use setup::{cell_of, pixels_of_cell};
pub use setup::{
    sample_box, sample_box_of, tent_bound, Classify, PostReconstruction, PostSetup, ShadedLayers,
    WeightTable, MAX_VALUE_SCALE, WEIGHT_NODES,
};

/// One voxel to splat: where it lands, its value and its world gradient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PostVoxel {
    /// Screen position, image pixels (x right, y down, z depth growing away from the viewer):
    /// [`crate::frame::FrameSetup::affine_position`] of the voxel's grid index.
    pub position: [f32; 3],
    /// The sample (finite: leave missing samples out).
    pub value: f32,
    /// World gradient, value units per world unit ([`super::gradient`]); ignored where the
    /// classifier needs none.
    pub gradient: [f32; 3],
}

/// One slab's accumulation at a value pixel: [Σw, Σw·f, Σw·∂f/∂x, Σw·∂f/∂y, Σw·∂f/∂z].
pub type PostSample = [f32; 5];

/// The caller-owned buffers of a post-classified render over a band of image rows `rows`, image
/// width `w`, value width `vw` and value rows `vr` = [`PostSetup::value_rows`]`(rows)`.
#[derive(Debug)]
pub struct PostBuffers<'a> {
    /// The ring of slab accumulators, value-pixel-major: `accumulators[(y·vw + x)·ring + slot]`
    /// (y counted from `vr.start`), at least `ring × vw × vr.len()` long, all zero at the start
    /// (left all zero).
    pub accumulators: &'a mut [PostSample],
    /// Working image, premultiplied RGBA, row-major, `w × rows.len()`: the result.
    pub image: &'a mut [[f32; 4]],
    /// Per slot and value row, the extent touched: `rows[slot·vr.len() + y]`, at least
    /// `ring × vr.len()` long.
    pub rows: &'a mut [RowSpan],
}

/// One voxel's work in a band: its centre at the values' scale, its slabs and value rows.
struct Run {
    centre: [f32; 3],
    first: usize,
    slabs: usize,
    rows: core::ops::Range<usize>,
}

/// Renders post-classified slabs into caller-owned buffers (float). The order of work, the
/// refusal of a voxel reaching a slab already composited, and bands are as for
/// [`super::SlabRenderer`]: every value pixel and every image pixel receives the same additions
/// in the same order whatever the band, so bands put together are bit-identical to one
/// whole-image render.
pub struct PostRenderer<'a, C: Classify, const N: usize> {
    setup: &'a PostSetup,
    weights: &'a WeightTable<N>,
    classify: &'a C,
    gradients: bool,
    order: Order,
    /// Image rows (first, count) and value rows (first, count).
    band: (usize, usize),
    values: (usize, usize),
    ring: usize,
    buffers: PostBuffers<'a>,
    background: Option<&'a [[f32; 4]]>,
    queue: SlabQueue,
    blend: Blend,
    stats: RenderStats,
}

impl<'a, C: Classify, const N: usize> PostRenderer<'a, C, N> {
    /// Starts a frame over image rows `rows` (`0..height` for the whole image); `buffers` and
    /// `background` as [`PostBuffers`] says; `background` as for sheets.
    pub fn with_band(
        setup: &'a PostSetup,
        weights: &'a WeightTable<N>,
        classify: &'a C,
        order: Order,
        buffers: PostBuffers<'a>,
        background: Option<&'a [[f32; 4]]>,
        rows: core::ops::Range<usize>,
    ) -> Result<Self, RenderError> {
        let ring = setup.ring();
        let n = setup.full.size[0] * rows.len();
        let vr = setup.value_rows(rows.clone());
        let vn = setup.low.size[0] * vr.len();
        check_band(
            &rows,
            setup.full.size[1],
            &[
                (buffers.accumulators.len(), ring * vn),
                (buffers.image.len(), n),
                (background.map_or(n, <[_]>::len), n),
                (buffers.rows.len(), ring * vr.len()),
            ],
        )?;
        let r = PostRenderer {
            setup,
            weights,
            classify,
            gradients: classify.needs_gradient(),
            order,
            band: (rows.start, rows.len()),
            values: (vr.start, vr.len()),
            ring,
            buffers,
            background,
            queue: SlabQueue::new(setup.full.count, order),
            blend: Blend::Composite,
            stats: RenderStats::default(),
        };
        start_image(&mut r.buffers.image[..n], background, order, [0.0; 4]);
        r.buffers.rows[..ring * vr.len()].fill(RowSpan::EMPTY);
        Ok(r)
    }

    /// Projects the samples instead of compositing them ([`Blend`]): each image pixel then holds
    /// its projection so far while the frame renders, and [`PostRenderer::finish`] classifies
    /// the projected value ([`Classify::projection`]) and puts it over the background, whichever
    /// the order. Every sample is folded (no value is transparent to a projection, no pixel
    /// opaque), so give the renderer every finite voxel. Call before the first splat.
    pub fn with_blend(mut self, blend: Blend) -> Self {
        self.blend = blend;
        if blend.projects() {
            let n = self.setup.full.size[0] * self.band.1;
            self.buffers.image[..n].fill(blend.start());
        }
        self
    }

    /// Counts so far (`sheets` counts slabs composited; `pixel_updates` the (value pixel, slab)
    /// additions; `pixels_composited` the image pixels whose slab sums were read).
    pub fn stats(&self) -> RenderStats {
        self.stats
    }

    /// The next slab [`PostRenderer::composite_next`] composites (`None` when all are done).
    pub fn next_slab(&self) -> Option<usize> {
        self.queue.next()
    }

    /// Adds `voxel`'s weighted value (and gradient) at the mid-plane of every slab its kernel
    /// reaches, at every value pixel of the band it covers. Refused if it reaches a slab already
    /// composited.
    pub fn splat_voxel(&mut self, voxel: &PostVoxel) -> Result<(), RenderError> {
        let s = &self.setup.low;
        // The slabs a voxel reaches at the image's scale: what a caller sorts by, whatever
        // rounding the value scale brings.
        let (first, last) = self.setup.full.slabs_of(voxel.position[2]);
        let inv = 1.0 / self.setup.scale as f32;
        let [cx, cy, cz] = voxel.position.map(|c| c * inv);
        self.queue.admit(first, last)?;
        let rows = s.rows_of(cy);
        let (v0, vn) = self.values;
        let (y0, y1) = (rows.start.max(v0), rows.end.min(v0 + vn));
        if y0 >= y1 {
            return Ok(());
        }
        self.stats.voxels += 1;
        let g = voxel.gradient;
        let add: [f32; 5] = [1.0, voxel.value, g[0], g[1], g[2]];
        let run = Run {
            centre: [cx, cy, cz],
            first,
            slabs: last - first + 1,
            rows: y0..y1,
        };
        let updates = match (self.setup.reconstruction, self.gradients) {
            (PostReconstruction::Kernel, true) => self.accumulate::<5>(&run, &add),
            (PostReconstruction::Kernel, false) => self.accumulate::<2>(&run, &[add[0], add[1]]),
            (PostReconstruction::Trilinear, true) => self.accumulate_tent::<5>(&run, &add),
            (PostReconstruction::Trilinear, false) => {
                self.accumulate_tent::<2>(&run, &[add[0], add[1]])
            }
        };
        self.stats.pixel_updates += updates;
        self.stats.voxels_splatted += u64::from(updates > 0);
        Ok(())
    }

    /// Adds the `K` channels of `add` (the first `K` of a [`PostSample`]), weighted, at the
    /// mid-plane of every slab of `run` that the kernel reaches, at every value pixel of its rows;
    /// returns the (value pixel, slab) additions. At scale 1 (value pixels are image pixels) an
    /// opaque pixel is skipped front to back: nothing it accumulates would be classified.
    ///
    /// Per slab and row the kernel's support is an interval of x: r² = ρ² + t² is a quadratic
    /// Q(dx) = A·dx² + 2B·dx + C + 1 in the pixel's offset (t moves with dx where the grid is
    /// sheared), so the run is found by the quadratic formula and Q is stepped by its differences
    /// along it: a weight costs one table read.
    #[inline]
    fn accumulate<const K: usize>(&mut self, run: &Run, add: &[f32; K]) -> u64 {
        let s = &self.setup.low;
        let (w, ring, v0, vn) = (s.size[0], self.ring, self.values.0, self.values.1);
        let [cx, cy, cz] = run.centre;
        let [qxx, qxy, qyy] = s.q;
        // Chord coordinate of the first slab's mid-plane at the voxel's own pixel offset (0, 0),
        // and per slab.
        let dt = s.kappa * s.thickness;
        let t0 = s.kappa * (s.front(run.first) + 0.5 * s.thickness - cz);
        let (ka, kb) = (s.kappa * s.shear[0], s.kappa * s.shear[1]);
        let a2 = qxx + ka * ka;
        let opaque_skip =
            self.setup.scale == 1 && self.order == Order::FrontToBack && !self.blend.projects();
        let mut updates = 0u64;
        for k in 0..run.slabs.min(ring) {
            let slot = (run.first + k) % ring;
            let tk = t0 + k as f32 * dt;
            for y in run.rows.clone() {
                let dy = y as f32 + 0.5 - cy;
                // t = tr − ka·dx; Q − 1 = a2·dx² + 2·bh·dx + c.
                let tr = tk - kb * dy;
                let bh = qxy * dy - ka * tr;
                let c = qyy * dy * dy + tr * tr - 1.0;
                let disc = bh * bh - a2 * c;
                if !(disc > 0.0) {
                    continue;
                }
                let root = math::sqrt(disc);
                let cols = centres_within(cx + (-bh - root) / a2, cx + (-bh + root) / a2, w);
                let (x0, x1) = (cols.start, cols.end);
                if x0 >= x1 {
                    continue;
                }
                let yl = y - v0;
                let dx0 = x0 as f32 + 0.5 - cx;
                let mut q = (a2 * dx0 + 2.0 * bh) * dx0 + c + 1.0;
                let mut dq = a2 * (2.0 * dx0 + 1.0) + 2.0 * bh;
                let dq2 = 2.0 * a2;
                let base = yl * w;
                let acc = &mut self.buffers.accumulators[(base + x0) * ring..(base + x1) * ring];
                let img = &self.buffers.image;
                for (x, px) in acc.chunks_exact_mut(ring).enumerate() {
                    if !(opaque_skip && img[base + x0 + x][3] >= 1.0) {
                        let wgt = self.weights.at(q);
                        for (c, a) in px[slot].iter_mut().zip(add) {
                            *c += wgt * a;
                        }
                    }
                    q += dq;
                    dq += dq2;
                }
                updates += (x1 - x0) as u64;
                self.buffers.rows[slot * vn + yl].include(x0, x1 - 1);
            }
        }
        updates
    }

    /// Classifies the next slab in compositing order at every image pixel of the band (its
    /// sums interpolated from the value pixels around it, normalised, through the [`Classify`]),
    /// composites it into the image and clears its slot. Nothing once every slab is done.
    pub fn composite_next(&mut self) {
        let Some(slab) = self.next_slab() else {
            return;
        };
        let scale = self.setup.scale;
        let (w, vw) = (self.setup.full.size[0], self.setup.low.size[0]);
        let (ring, (b0, bn), (v0, vn)) = (self.ring, self.band, self.values);
        let slot = slab % ring;
        let (order, blend) = (self.order, self.blend);
        let clear = blend.transparent_bound(self.classify.transparent_at_or_below());
        let channels = if self.gradients { 5 } else { 2 };
        let spans = &self.buffers.rows[slot * vn..(slot + 1) * vn];
        let acc = &*self.buffers.accumulators;
        let img = &mut *self.buffers.image;
        let zero = [0.0f32; 5];
        // A value row of the band's buffer, if it holds anything in this slot.
        let row = |r: i64| -> Option<(usize, RowSpan)> {
            let r = usize::try_from(r).ok()?.checked_sub(v0)?;
            (r < vn && !spans[r].is_empty()).then(|| (r, spans[r]))
        };
        let at = |r: Option<(usize, RowSpan)>, x: i64| -> &PostSample {
            match (r, usize::try_from(x)) {
                (Some((r, span)), Ok(x)) if x >= span.lo as usize && x <= span.hi as usize => {
                    &acc[(r * vw + x) * ring + slot]
                }
                _ => &zero,
            }
        };
        let transparent = |c: &PostSample| !(c[0] > 0.0) || c[1] <= clear * c[0];
        let (setup, classify) = (self.setup, self.classify);
        // One pixel's sums `a` classified and composited, or folded into its projection (nothing
        // where it is transparent or outside the voxel box).
        let shade = |pixel: &mut [f32; 4], a: &PostSample, x: usize, y: usize| {
            if transparent(a) {
                return;
            }
            if order == Order::FrontToBack && pixel[3] >= 1.0 && !blend.projects() {
                return;
            }
            let (fraction, index) = setup.inside(x, y, slab);
            if !(fraction > 0.0) {
                return;
            }
            let inv = 1.0 / a[0];
            if blend.projects() {
                blend.fold(pixel, a[1] * inv, fraction);
                return;
            }
            let gradient = Vec3::new(a[2] * inv, a[3] * inv, a[4] * inv);
            let layer = classify.layer(a[1] * inv, gradient, index, fraction);
            if layer[3] > 0.0 {
                *pixel = match order {
                    Order::BackToFront => over(layer, *pixel),
                    Order::FrontToBack => over(*pixel, layer),
                };
            }
        };
        let mut composited = 0u64;
        if scale == 1 {
            // Value pixels are image pixels, value rows the band's rows.
            for (y, span) in spans.iter().enumerate().filter(|(_, s)| !s.is_empty()) {
                let (lo, hi) = (span.lo as usize, span.hi as usize);
                for x in lo..=hi {
                    shade(
                        &mut img[y * w + x],
                        &acc[(y * vw + x) * ring + slot],
                        x,
                        b0 + y,
                    );
                }
                composited += (hi - lo + 1) as u64;
            }
        } else {
            for y in 0..bn {
                let (ry, fy) = cell_of(b0 + y, scale);
                let (ra, rb) = (row(ry), row(ry + 1));
                let (lo, hi) = match (ra, rb) {
                    (None, None) => continue,
                    (Some((_, s)), None) | (None, Some((_, s))) => (s.lo, s.hi),
                    (Some((_, s)), Some((_, t))) => (s.lo.min(t.lo), s.hi.max(t.hi)),
                };
                let line = &mut img[y * w..(y + 1) * w];
                for cx in i64::from(lo) - 1..=i64::from(hi) {
                    let c = [at(ra, cx), at(ra, cx + 1), at(rb, cx), at(rb, cx + 1)];
                    if c.iter().all(|c| transparent(c)) {
                        continue;
                    }
                    for x in pixels_of_cell(cx, scale, w) {
                        let fx = cell_of(x, scale).1;
                        let mut a = [0.0f32; 5];
                        for (ch, v) in a.iter_mut().enumerate().take(channels) {
                            let top = c[0][ch] + fx * (c[1][ch] - c[0][ch]);
                            let bottom = c[2][ch] + fx * (c[3][ch] - c[2][ch]);
                            *v = top + fy * (bottom - top);
                        }
                        composited += 1;
                        shade(&mut line[x], &a, x, b0 + y);
                    }
                }
            }
        }
        // The slot's value rows, cleared for the slab that takes it next.
        let acc = &mut *self.buffers.accumulators;
        for (r, span) in self.buffers.rows[slot * vn..(slot + 1) * vn]
            .iter_mut()
            .enumerate()
        {
            if span.is_empty() {
                continue;
            }
            for x in span.lo as usize..=span.hi as usize {
                acc[(r * vw + x) * ring + slot] = [0.0; 5];
            }
            *span = RowSpan::EMPTY;
        }
        self.stats.pixels_composited += composited;
        self.queue.advance();
        self.stats.sheets += 1;
    }

    /// Ends the frame: composites the slabs not yet composited, then (front to back) the
    /// background under the result; returns the counts. A projection ([`Self::with_blend`])
    /// classifies each pixel's projected value and puts it over the background, either order.
    pub fn finish(mut self) -> RenderStats {
        while self.next_slab().is_some() {
            self.composite_next();
        }
        let n = self.setup.full.size[0] * self.band.1;
        let image = &mut self.buffers.image[..n];
        if self.blend.projects() {
            for p in image.iter_mut() {
                *p = match self.blend.projected(*p) {
                    Some(v) => self.classify.projection(v),
                    None => [0.0; 4],
                };
            }
            if let Some(bg) = self.background {
                float_over_row(image, &bg[..n]);
            }
        } else if let (Order::FrontToBack, Some(bg)) = (self.order, self.background) {
            float_over_row(image, &bg[..n]);
        }
        self.stats
    }
}

#[cfg(test)]
mod tests;
