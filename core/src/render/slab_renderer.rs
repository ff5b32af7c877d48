//! The slab renderer ([`SlabRenderer`]): each voxel's kernel cut by the image-aligned slabs it
//! overlaps ([`super::slabs`] derives the sections), a ring of slab accumulators in caller-owned
//! [`SlabBuffers`], slabs composited in order, optionally culling occluded voxels.

use super::absorption::{Absorption, OpacityLayers};
use super::band::{check_band, start_image, SlabQueue};
use super::clip::{ClipPlanes, ClipSide};
use super::occlusion::Occlusion;
use super::precision::{float_opacity_pixel, float_over_row, float_reaches};
use super::slabs::{centres_within, SectionStencils, SlabError, SlabSetup, SlabVoxel, MAX_RING};
use super::{RenderError, RenderStats};
use crate::composite::{over, RowSpan};
use crate::frame::Order;
use crate::math;
use crate::table::{SectionRay, SectionTable};

/// The caller-owned buffers of a slab render over a band of `rows` image rows of width `w`, for a
/// setup whose kernels span at most `ring` = [`SlabSetup::ring`] slabs.
#[derive(Debug)]
pub struct SlabBuffers<'a> {
    /// The ring of slab accumulators, slab-major (one plane of the band's pixels per ring slot,
    /// rows contiguous): `accumulators[(slot·rows + y)·w + x]`, at least `ring × w × rows` long,
    /// all zero at the start (left all zero).
    pub accumulators: &'a mut [[f32; 4]],
    /// Working image, premultiplied RGBA, row-major, `w × rows`: the result.
    pub image: &'a mut [[f32; 4]],
    /// Per slot and row, the extent touched: `rows[slot·rows + y]`, at least `ring × rows` long.
    pub rows: &'a mut [RowSpan],
}

/// Renders slabs into caller-owned buffers, float only.
///
/// **Order of work.** Each voxel is splatted once ([`SlabRenderer::splat_voxel`]): its kernel's
/// section in every slab it overlaps goes to that slab's accumulator, one of a ring of
/// [`SlabSetup::ring`]. [`SlabRenderer::composite_next`] composites the next slab in compositing
/// order (front to back: slab 0 first; back to front: the last first) and frees its slot. So the
/// caller feeds voxels sorted by the slab they reach first in that order (their first slab front
/// to back, their last back to front) and composites slab j once every voxel reaching it has
/// been splatted; a voxel reaching a slab already composited is refused
/// ([`RenderError::SlabOrder`]).
///
/// **Bands.** Like [`SheetRenderer`](super::SheetRenderer) it may own a band of image rows only;
/// each pixel receives the same additions in the same order whatever the band, so bands put
/// together are bit-identical to one whole-image render.
pub struct SlabRenderer<'a, const R: usize, const T: usize> {
    setup: &'a SlabSetup,
    table: &'a SectionTable<R, T>,
    order: Order,
    band: (usize, usize),
    ring: usize,
    buffers: SlabBuffers<'a>,
    background: Option<&'a [[f32; 4]]>,
    queue: SlabQueue,
    occlusion: Option<Occlusion<'a, [f32; 4]>>,
    clip: Option<&'a ClipPlanes>,
    stencils: Option<&'a SectionStencils<'a>>,
    layers: Option<&'a OpacityLayers>,
    stats: RenderStats,
}

impl<'a, const R: usize, const T: usize> SlabRenderer<'a, R, T> {
    /// Starts a frame over image rows `rows` (`0..height` for the whole image): `buffers` (and
    /// `background`) hold `rows.len()` rows (see [`SlabBuffers`]). `background` as for sheets
    /// (the starting image back to front, composited under the result front to back).
    pub fn with_band(
        setup: &'a SlabSetup,
        table: &'a SectionTable<R, T>,
        order: Order,
        buffers: SlabBuffers<'a>,
        background: Option<&'a [[f32; 4]]>,
        rows: core::ops::Range<usize>,
    ) -> Result<Self, RenderError> {
        let ring = setup.ring();
        let n = setup.size[0] * rows.len();
        check_band(
            &rows,
            setup.size[1],
            &[
                (buffers.accumulators.len(), ring * n),
                (buffers.image.len(), n),
                (background.map_or(n, <[_]>::len), n),
                (buffers.rows.len(), ring * rows.len()),
            ],
        )?;
        let r = SlabRenderer {
            setup,
            table,
            order,
            band: (rows.start, rows.len()),
            ring,
            buffers,
            background,
            queue: SlabQueue::new(setup.count, order),
            occlusion: None,
            clip: None,
            stencils: None,
            layers: None,
            stats: RenderStats::default(),
        };
        start_image(&mut r.buffers.image[..n], background, order, [0.0; 4]);
        r.buffers.rows[..ring * rows.len()].fill(RowSpan::EMPTY);
        Ok(r)
    }

    /// Culls occluded voxels as [`SheetRenderer::with_occlusion`](super::SheetRenderer::with_occlusion)
    /// does: once every pixel of an [`OCCLUSION_TILE`](super::OCCLUSION_TILE)-pixel tile has
    /// reached opacity 1 − `eps`, no slab composites into it, and voxels whose footprint lies on
    /// such tiles only are skipped. Each pixel of a closed tile stays within `eps` per channel of
    /// the image without culling; the same refusals.
    pub fn with_occlusion(mut self, buffer: &'a mut [u8], eps: f32) -> Result<Self, RenderError> {
        let size = [self.setup.size[0], self.band.1];
        Occlusion::<[f32; 4]>::check(eps, self.order, self.band.0, size, buffer.len())?;
        self.occlusion = Some(Occlusion::with_test(
            buffer,
            size,
            self.setup.half,
            float_opacity_pixel(1.0 - eps),
            float_reaches,
        ));
        Ok(self)
    }

    /// Clips the frame by `planes` ([`super::clip`]): a voxel whose kernel lies outside one is
    /// skipped, one that straddles one has each pixel's section cut to the depths the planes keep
    /// on that pixel's ray, and the rest are splatted as without planes, bit for bit. `planes`
    /// must be made for this renderer's frame.
    pub fn with_clip(mut self, planes: &'a ClipPlanes) -> Self {
        self.clip = (!planes.is_empty()).then_some(planes);
        self
    }

    /// Splats through `stencils` ([`SectionStencils`], built for this renderer's setup, which
    /// has depth phases): each voxel's section in each slab is a few runs of stencil rows instead
    /// of a table walk per pixel and slab. Kernels a clipping plane crosses are still cut per
    /// pixel. Refused ([`SlabError::NoStencils`]) for stencils of another setup.
    pub fn with_stencils(mut self, stencils: &'a SectionStencils<'a>) -> Result<Self, SlabError> {
        if stencils.setup() != self.setup {
            return Err(SlabError::NoStencils);
        }
        self.stencils = Some(stencils);
        Ok(self)
    }

    /// Composites opacity-model slabs through `layers` (the tabulated [`OpacityLayers`], within
    /// 10⁻⁵ of the exact layer) instead of a logarithm and an exponential per pixel. Ignored
    /// for the extinction model or a table of another chord.
    pub fn with_layers(mut self, layers: &'a OpacityLayers) -> Self {
        let fits =
            self.setup.absorption == Absorption::Opacity && layers.chord() == self.setup.chord;
        self.layers = fits.then_some(layers);
        self
    }

    /// Counts so far (`sheets` counts slabs composited).
    pub fn stats(&self) -> RenderStats {
        self.stats
    }

    /// The next slab [`SlabRenderer::composite_next`] composites (`None` when all are done).
    pub fn next_slab(&self) -> Option<usize> {
        self.queue.next()
    }

    /// Adds `voxel`'s kernel, cut by every slab it overlaps, to those slabs' accumulators
    /// (nothing where it misses the band). Refused if it overlaps a slab already composited.
    pub fn splat_voxel(&mut self, voxel: &SlabVoxel) -> Result<(), RenderError> {
        let s = self.setup;
        let [cx, cy, _] = voxel.position;
        let (first, last) = s.slabs_of(voxel.position[2]);
        self.queue.admit(first, last)?;
        let Some(cut) = straddled(self.clip, voxel.position) else {
            return Ok(());
        };
        let rows = s.rows_of(cy);
        let (b0, bn) = self.band;
        if rows.start.max(b0) >= rows.end.min(b0 + bn) {
            return Ok(());
        }
        if let Some(o) = &self.occlusion {
            if o.hides_at(cx, cy - b0 as f32) {
                self.stats.culled_voxels += 1;
                return Ok(());
            }
        }
        self.stats.voxels += 1;
        let updates = match (self.stencils, cut) {
            (Some(st), None) => self.splat_stencils(st, voxel, (first, last)),
            _ => self.splat_pixels(voxel, (first, last), cut),
        };
        self.stats.pixel_updates += updates;
        self.stats.voxels_splatted += u64::from(updates > 0);
        Ok(())
    }

    /// [`SlabRenderer::splat_voxel`] through section stencils: each slab's section as runs of
    /// stencil rows into that slab's plane. Returns the (pixel, slab) updates.
    fn splat_stencils(
        &mut self,
        st: &SectionStencils<'_>,
        voxel: &SlabVoxel,
        slabs: (usize, usize),
    ) -> u64 {
        let (w, bn, b0) = (self.setup.size[0], self.band.1, self.band.0);
        let (own, phase, _) = self.setup.place(voxel.position[2]);
        // Subtracting a whole number of rows is exact here (|y| < 2²⁴), so every pixel of a band
        // sees the offsets, and so the weights, of a whole-image render.
        let center = [voxel.position[0], voxel.position[1] - b0 as f32];
        let buffers = (
            &mut *self.buffers.accumulators,
            &mut *self.buffers.rows,
            [w, bn, self.ring],
        );
        st.splat((own, phase), slabs, center, &voxel.value, buffers)
    }

    /// [`SlabRenderer::splat_voxel`] pixel by pixel: each pixel's chord read from the section
    /// table at every slab boundary it crosses (cut where a clipping plane crosses the kernel).
    /// Returns the pixels updated.
    fn splat_pixels(
        &mut self,
        voxel: &SlabVoxel,
        (first, last): (usize, usize),
        cut: Option<&ClipPlanes>,
    ) -> u64 {
        let s = self.setup;
        let [cx, cy, _] = voxel.position;
        // The depth the voxel is placed at: snapped to its depth phase if the setup has them,
        // else its own (bit for bit).
        let cz = match s.place(voxel.position[2]) {
            (own, _, delta) if s.depth_phases > 0 => s.z0 + (own as f32 + delta) * s.thickness,
            _ => voxel.position[2],
        };
        let rows = s.rows_of(cy);
        let (b0, bn) = self.band;
        let (y0, y1) = (rows.start.max(b0), rows.end.min(b0 + bn));
        let (w, ring) = (s.size[0], self.ring);
        let n = w * bn;
        let value = voxel.value.map(|c| c * s.scale);
        let [qxx, qxy, qyy] = s.q;
        // Chord coordinate of the first slab's front at the voxel's own pixel offset (0, 0), and
        // per slab boundary.
        let t0 = s.kappa * (s.front(first) - cz);
        let dt = s.kappa * s.thickness;
        let (ka, kb) = (s.kappa * s.shear[0], s.kappa * s.shear[1]);
        let slabs = last - first + 1;
        // Each slab's slot and plane in the ring, so the pixel loop does no modular arithmetic.
        let slots = ring_slots(first, slabs, ring);
        let planes = slots.map(|slot| slot * n);
        let (slots, planes) = (&slots[..slabs], &planes[..slabs]);
        // Without shear every pixel's chord meets slab boundary k at the same chord position
        // t0 + k·dt: the depth integral there is read once per voxel, not per pixel.
        let mut ends = [0.0f32; MAX_RING + 1];
        let boundaries = s.shear_free().then(|| {
            for (k, e) in ends.iter_mut().enumerate().take(slabs + 1) {
                *e = self.table.depth(t0 + k as f32 * dt);
            }
            &ends[..slabs + 1]
        });
        let acc = &mut *self.buffers.accumulators;
        // A section g of the voxel into one slab's plane at pixel index `at`.
        let mut add = |at: usize, g: f32, hit: &mut bool| {
            for (p, v) in acc[at].iter_mut().zip(&value) {
                *p += v * g;
            }
            *hit |= g != 0.0;
        };
        let mut updates = 0u64;
        for y in y0..y1 {
            let dy = y as f32 + 0.5 - cy;
            let disc = qxx - (qxx * qyy - qxy * qxy) * dy * dy;
            if !(disc > 0.0) {
                continue;
            }
            let root = math::sqrt(disc);
            let cols = centres_within(
                cx + (-qxy * dy - root) / qxx,
                cx + (-qxy * dy + root) / qxx,
                w,
            );
            let (x0, x1) = (cols.start, cols.end);
            if x0 >= x1 {
                continue;
            }
            let yl = y - b0;
            let t_row = t0 - kb * dy;
            let mut touched = [false; MAX_RING];
            for x in x0..x1 {
                let px = yl * w + x;
                let dx = x as f32 + 0.5 - cx;
                let rho2 = (qxx * dx + 2.0 * qxy * dy) * dx + qyy * dy * dy;
                if let Some(c) = cut {
                    let at = (x as f32 + 0.5, y as f32 + 0.5, t_row - ka * dx);
                    let chord = (dt, s.kappa, s.front(first), planes.len());
                    let add = |k: usize, g: f32| add(planes[k] + px, g, &mut touched[k]);
                    updates += cut_sections(c, self.table.ray(rho2), at, chord, add);
                    continue;
                }
                // Every slab the kernel spans, with no branch per slab (outside the chord
                // [−c, c] a section is exactly zero and adds nothing).
                if let Some(ends) = &boundaries {
                    // No shear: the boundaries' depth integrals are the voxel's, clamped to
                    // this ray's chord [C(−c), C(c)] = [−C(c), C(c)] (C is increasing and odd:
                    // see `SectionTable::chord`).
                    let Some([radial, hi]) = self.table.chord(rho2) else {
                        continue;
                    };
                    let clamp = |e: f32| math::select_clamp(e, -hi, hi);
                    let mut before = clamp(ends[0]);
                    for ((&plane, hit), &end) in planes.iter().zip(&mut touched).zip(&ends[1..]) {
                        let after = clamp(end);
                        add(plane + px, radial * (after - before), hit);
                        before = after;
                    }
                } else {
                    let Some(ray) = self.table.ray(rho2) else {
                        continue;
                    };
                    let t_front = t_row - ka * dx;
                    let mut before = ray.at(t_front);
                    for (k, (&plane, hit)) in planes.iter().zip(&mut touched).enumerate() {
                        let after = ray.at(t_front + (k + 1) as f32 * dt);
                        add(plane + px, after - before, hit);
                        before = after;
                    }
                }
                updates += 1;
            }
            for (&slot, _) in slots.iter().zip(&touched).filter(|(_, &t)| t) {
                self.buffers.rows[slot * bn + yl].include(x0, x1 - 1);
            }
        }
        updates
    }

    /// Composites the next slab in compositing order (as one layer of the setup's model,
    /// [`Absorption::layer`](super::Absorption::layer)) into the image over the rows it touched, and clears its slot.
    /// Nothing once every slab is done.
    pub fn composite_next(&mut self) {
        let Some(slab) = self.next_slab() else {
            return;
        };
        let (w, ring, bn) = (self.setup.size[0], self.ring, self.band.1);
        let (slot, plane) = (slab % ring, w * bn);
        let (order, model, chord) = (self.order, self.setup.absorption, self.setup.chord);
        let layers = self.layers;
        let (acc, img) = (&mut *self.buffers.accumulators, &mut *self.buffers.image);
        for (y, span) in self.buffers.rows[slot * bn..(slot + 1) * bn]
            .iter_mut()
            .enumerate()
        {
            if span.is_empty() {
                continue;
            }
            let mut layer_row =
                |px: core::ops::Range<usize>, closed: bool, img: &mut [[f32; 4]]| {
                    for p in px {
                        let a = &mut acc[slot * plane + p];
                        if !closed {
                            let layer = match layers {
                                Some(t) => t.layer(*a),
                                None => model.layer(*a, chord),
                            };
                            let i = &mut img[p];
                            *i = match order {
                                Order::BackToFront => over(layer, *i),
                                Order::FrontToBack => over(*i, layer),
                            };
                        }
                        *a = [0.0; 4];
                    }
                };
            let (lo, hi) = (span.lo as usize, span.hi as usize);
            self.stats.pixels_composited += match &mut self.occlusion {
                Some(o) => o.composite_row(y, (lo, hi), img, layer_row),
                None => {
                    layer_row(y * w + lo..y * w + hi + 1, false, img);
                    (hi - lo + 1) as u64
                }
            };
            *span = RowSpan::EMPTY;
        }
        self.queue.advance();
        self.stats.sheets += 1;
    }

    /// Ends the frame: composites the slabs not yet composited, then (front to back) the
    /// background under the result; returns the counts.
    pub fn finish(mut self) -> RenderStats {
        while self.next_slab().is_some() {
            self.composite_next();
        }
        if let (Order::FrontToBack, Some(bg)) = (self.order, self.background) {
            let n = self.setup.size[0] * self.band.1;
            float_over_row(&mut self.buffers.image[..n], &bg[..n]);
        }
        self.stats
    }
}

/// Each of the `slabs` slabs from `first` on, its slot in a ring of `ring` (so the pixel loop
/// does no modular arithmetic); the entries past `slabs` are 0.
#[inline]
fn ring_slots(first: usize, slabs: usize, ring: usize) -> [usize; MAX_RING] {
    let mut slots = [0usize; MAX_RING];
    for (k, slot) in slots.iter_mut().enumerate().take(slabs) {
        *slot = (first + k) % ring;
    }
    slots
}

/// How the clipping planes take the kernel centred at screen point `c`: `None` when it lies
/// outside one (nothing of it is kept), `Some(None)` when it lies inside every one (or there is
/// none), `Some(Some(planes))` when one crosses it.
#[inline]
fn straddled(clip: Option<&ClipPlanes>, c: [f32; 3]) -> Option<Option<&ClipPlanes>> {
    match clip.map(|p| (p, p.side(c))) {
        Some((_, ClipSide::Outside)) => None,
        Some((p, ClipSide::Straddles)) => Some(Some(p)),
        _ => Some(None),
    }
}

/// The sections of a kernel a clipping plane crosses, on the ray `ray` (`None`: the ray misses
/// the kernel) through pixel centre (x, y): each slab's share read at its ends clamped to the
/// depths the planes keep on that ray, [z_lo, z_hi] as chord positions. `at` is (x, y, t_front),
/// t_front the chord position of the first slab's front on this ray; `chord` is (dt, κ,
/// front_z, slabs): a slab's chord length, chord units per pixel of depth, the first slab's
/// front (screen depth) and the slabs the kernel spans. `add(k, section)` takes slab k's
/// (counted from the first). Returns 1 when the ray met the kernel, else 0 (a pixel update).
#[inline]
fn cut_sections<const T: usize>(
    clip: &ClipPlanes,
    ray: Option<SectionRay<'_, T>>,
    (x, y, t_front): (f32, f32, f32),
    (dt, kappa, front_z, slabs): (f32, f32, f32, usize),
    mut add: impl FnMut(usize, f32),
) -> u64 {
    let Some(ray) = ray else {
        return 0;
    };
    let (z_lo, z_hi) = clip.depths(x, y);
    if !(z_lo < z_hi) {
        return 1;
    }
    let base = t_front - kappa * front_z;
    let (t_lo, t_hi) = (base + kappa * z_lo, base + kappa * z_hi);
    let at = |t: f32| ray.at(t.max(t_lo).min(t_hi));
    let mut before = at(t_front);
    for k in 0..slabs {
        let after = at(t_front + (k + 1) as f32 * dt);
        add(k, after - before);
        before = after;
    }
    1
}
