//! Section stencils: a view's slab sections sampled once, so that splatting a voxel into its
//! slabs is a few runs of stencil rows, as for the paper's sheets ([`crate::stencil`]).
//!
//! **Why they exist.** Under an orthographic view every voxel has the same kernel footprint, so
//! the share of a voxel's kernel that a pixel's ray meets inside a slab depends only on the
//! pixel's offset from the voxel (its sub-pixel phase and box pixel), the voxel's depth within
//! its own slab, and which slab (its offset from the voxel's own). With depth phases
//! ([`SlabSetup::with_depth_phases`]) the depth within the slab takes `D` values, so the sections
//! are a finite family: for depth phase e = 0 … D − 1 and slab offset m (from the first a kernel
//! of that phase can reach to the last), one set of phase stencils ([`crate::stencil`]'s layout:
//! (P + 1)² stencils of B² weights, bilinear in the sub-pixel phase, with each phase cell's
//! non-zero runs per row). A voxel in slab j at depth phase e puts set (e, m) into slab j + m.
//!
//! **Weights.** Set (e, m), box pixel at offset q = (dx, dy) from the voxel, holds
//! `scale` · [G(ρ², t_b) − G(ρ², t_a)] ([`super`]' derivation), t_a = κ·T·(m − δ_e) −
//! κ·(z*₀·dx + z*₁·dy) and t_b = t_a + κ·T, δ_e = (e + ½)/D: the same section the per-pixel
//! renderer computes, read from the same [`SectionTable`]. Over m they telescope to the whole
//! chord, so a voxel deposits the same total as without slabs; blending four phase corners keeps
//! that (each corner's sets sum to its footprint).
//!
//! **Error.** Against the per-pixel sections of the same depth-phased setup, only the bilinear
//! phase blend: at most (2.5/(P·r))²/8 of a section's peak for a footprint of shorter semi-axis
//! r px (the sheet stencils' bound). The depth phases themselves move each kernel by at most
//! T/(2D) along the view ([`SlabSetup::with_depth_phases`]); docs/section-stencils.md measures
//! both against the continuous model.
//!
//! **Memory.** D · K sets of (P + 1)² · B² + P² · B floats, K the slab offsets
//! ([`SectionStencils::len_for`]), plus one flag per set (whether it holds any weight).
//!
//! **Which footprints.** Those whose sheet stencils would be blended ([`crate::stencil::plan_for`]
//! not edged): a footprint too long and thin to blend is cut per pixel by the renderer.

use super::{SlabError, SlabSetup};
use crate::composite::RowSpan;
use crate::geometry::{Footprint, Sampler};
use crate::math;
use crate::splat::floor_i64;
use crate::stencil::walk::{corner_rows, SpanWalk};
use crate::stencil::{cell_read, phase_cell, plan_for, PhaseLookup, Plan, Stencils};
use crate::table::SectionTable;

/// A view's section stencils in caller storage (see the module docs).
#[derive(Clone, Copy, Debug)]
pub struct SectionStencils<'a> {
    setup: SlabSetup,
    plan: Plan,
    /// D · K sets of `set_len` floats, then per set and phase cell (P² each) the box rows
    /// holding a non-zero run, `first | last << 16` as the bits of an f32 (first > last: none).
    data: &'a [f32],
    set_len: usize,
    /// The first slab offset m and the number K of offsets.
    first_offset: i64,
    offsets: usize,
    lookup: PhaseLookup,
}

/// The footprint of a setup's kernel, as the stencil layout sees it: the ellipse ρ² ≤ 1 of
/// [`super`], ρ² = qᵀ·Q·q, with A = the Cholesky factor of Q (|A q|² = ρ²).
fn section_footprint(s: &SlabSetup) -> Option<Footprint> {
    let [qxx, qxy, qyy] = s.q;
    let det = qxx * qyy - qxy * qxy;
    if !(qxx > 0.0 && det > 0.0) {
        return None;
    }
    let a = math::sqrt(qxx);
    let b = qxy / a;
    let c = math::sqrt(det / qxx);
    Some(Footprint {
        to_unit: [[a, b], [0.0, c]],
        half_extent: s.half,
        scale: 1.0,
        row_coefficients: [-qxy / qxx, 1.0 / qxx, -det / (qxx * qxx)],
        ..Footprint::EMPTY
    })
}

/// A footprint-only sampler: the layout's plan is found from its footprint; a blended splat
/// never reads its weights.
struct Layout(Footprint);

impl Sampler for Layout {
    fn footprint(&self) -> &Footprint {
        &self.0
    }
    fn weight(&self, _: [f32; 2]) -> f32 {
        0.0
    }
}

/// The range of slab offsets m (from the voxel's own slab) a kernel at any depth phase of `s`
/// can reach: ⌊½/D − R⌋ … ⌊(D − ½)/D + R⌋, R the kernel's depth reach in slabs.
fn offsets_of(s: &SlabSetup) -> (i64, usize) {
    let d = s.depth_phases.max(1) as f32;
    let reach = s.z_reach / s.thickness;
    let lo = math::floor(0.5 / d - reach);
    let hi = math::floor((d - 0.5) / d + reach);
    (lo as i64, (hi - lo) as usize + 1)
}

impl<'a> SectionStencils<'a> {
    /// Floats [`SectionStencils::build`] needs for `setup` with at most `max_phases` sub-pixel
    /// phases; `None` when the setup has no depth phases, the footprint is too wide to blend, or
    /// the size overflows.
    pub fn len_for(setup: &SlabSetup, max_phases: usize) -> Option<usize> {
        Self::len(setup, Self::plan(setup, max_phases)?)
    }

    /// Floats the sets and their row ranges take for `setup` laid out by `plan`.
    fn len(setup: &SlabSetup, plan: Plan) -> Option<usize> {
        let sets = setup.depth_phases.checked_mul(offsets_of(setup).1)?;
        let cells = plan.phases.checked_mul(plan.phases)?;
        sets.checked_mul(plan.floats())?
            .checked_add(sets.checked_mul(cells)?)
    }

    fn plan(setup: &SlabSetup, max_phases: usize) -> Option<Plan> {
        if setup.depth_phases == 0 {
            return None;
        }
        let plan = plan_for(&section_footprint(setup)?, max_phases)?;
        (!plan.edged).then_some(plan)
    }

    /// Samples every section of `setup`'s kernel (a setup with depth phases) from `table` into
    /// `buffer` (at least [`SectionStencils::len_for`] floats), with at most `max_phases`
    /// sub-pixel phases.
    pub fn build<const R: usize, const T: usize>(
        setup: &SlabSetup,
        table: &SectionTable<R, T>,
        max_phases: usize,
        buffer: &'a mut [f32],
    ) -> Result<Self, SlabError> {
        let plan = Self::plan(setup, max_phases).ok_or(SlabError::NoStencils)?;
        let len = Self::len(setup, plan).ok_or(SlabError::NoStencils)?;
        if buffer.len() < len {
            return Err(SlabError::StencilBuffer {
                needed: len,
                got: buffer.len(),
            });
        }
        let (first_offset, offsets) = offsets_of(setup);
        let (d, set_len) = (setup.depth_phases, plan.floats());
        let sets = d * offsets;
        let (weights, row_ranges) = buffer[..len].split_at_mut(sets * set_len);
        weights.fill(0.0);
        fill_sections(setup, table, plan, (first_offset, offsets), weights);
        let layout = Layout(section_footprint(setup).ok_or(SlabError::NoStencils)?);
        let (side, cells) = (plan.side, plan.phases * plan.phases);
        let runs_at = (plan.phases + 1) * (plan.phases + 1) * side * side;
        for (set, ranges) in weights
            .chunks_exact_mut(set_len)
            .zip(row_ranges.chunks_exact_mut(cells))
        {
            // The weights are written: only the runs are found here.
            Stencils::build_split(&layout, max_phases, set, |_, _| {})
                .map_err(|_| SlabError::NoStencils)?;
            for (cell, range) in set[runs_at..].chunks_exact(side).zip(ranges.iter_mut()) {
                let full = |r: &f32| {
                    let packed = r.to_bits();
                    packed & 0xffff <= packed >> 16
                };
                let first = cell.iter().position(full).unwrap_or(side);
                let last = cell.iter().rposition(full).unwrap_or(0);
                // B ≤ 129: both fit 16 bits; the pattern is never a NaN (exponent field 0).
                *range = f32::from_bits(first as u32 | (last as u32) << 16);
            }
        }
        Ok(SectionStencils {
            setup: *setup,
            plan,
            data: &buffer[..len],
            set_len,
            first_offset,
            offsets,
            lookup: PhaseLookup::Blend,
        })
    }

    /// These stencils read at each voxel's sub-pixel phase by `lookup`: the blend of the phase
    /// cell's four corner stencils (the default), or the nearest corner (the footprint placed up
    /// to 1/(2P) px off in each axis, one weight read per pixel instead of four; each voxel
    /// still deposits all of itself: see [`PhaseLookup::Nearest`]).
    pub fn with_phase_lookup(mut self, lookup: PhaseLookup) -> Self {
        self.lookup = lookup;
        self
    }

    /// The setup these stencils were built for.
    pub fn setup(&self) -> &SlabSetup {
        &self.setup
    }

    /// Adds a voxel's sections to the slabs `first..=last` it reaches: the voxel of `value` at
    /// screen `center` (pixels; y relative to the band's first row), placed in slab `own` at
    /// depth phase `phase` ([`SlabSetup::place`]), into the ring `acc` of `ring` slab planes of
    /// `w × bn` pixels (slab j in plane j mod `ring`), widening each plane's touched row spans
    /// (`spans`, `bn` per plane). The four phase-cell corners are found once; per slab only its
    /// set's non-zero runs are visited. Returns the (pixel, slab) updates.
    #[inline]
    pub(in crate::render) fn splat(
        &self,
        (own, phase): (i64, usize),
        (first, last): (usize, usize),
        center: [f32; 2],
        value: &[f32; 4],
        (acc, spans, [w, bn, ring]): (&mut [[f32; 4]], &mut [RowSpan], [usize; 3]),
    ) -> u64 {
        let (side, p) = (self.plan.side, self.plan.phases);
        if !(center[0].is_finite() && center[1].is_finite()) || phase >= self.setup.depth_phases {
            return 0;
        }
        let (ix, iy) = (floor_i64(center[0]), floor_i64(center[1]));
        let Some(walk) = SpanWalk::new([ix, iy], side, w, bn) else {
            return 0;
        };
        let ((ka, fx), (kb, fy)) = (phase_cell(center[0], ix, p), phase_cell(center[1], iy, p));
        // A copy the compiler knows no accumulator store can change (kept in registers).
        let value = *value;
        let value = &value;
        let cells = side * side;
        let nearest = self.lookup == PhaseLookup::Nearest;
        let (corners, blend) = cell_read((ka, kb), (fx, fy), p, cells, nearest);
        let ranges = (p + 1) * (p + 1) * cells + (kb * p + ka) * side;
        let ranges_at = self.set_len * self.setup.depth_phases * self.offsets;
        let cell = kb * p + ka;
        // The box rows inside the band.
        let y0 = iy - (side / 2) as i64;
        let (in0, in1) = (
            (-y0).max(0) as usize,
            (bn as i64 - y0).min(side as i64) as usize,
        );
        let n = w * bn;
        let mut updates = 0u64;
        for slab in first..=last {
            let m = slab as i64 - own - self.first_offset;
            if m < 0 || m as usize >= self.offsets {
                continue;
            }
            let set = phase * self.offsets + m as usize;
            let packed = self.data[ranges_at + set * p * p + cell].to_bits();
            let (r0, r1) = ((packed & 0xffff) as usize, (packed >> 16) as usize + 1);
            let (r0, r1) = (r0.max(in0), r1.min(in1));
            if r0 >= r1 {
                continue;
            }
            let data = &self.data[set * self.set_len..][..self.set_len];
            let runs = &data[ranges..][..side];
            let slot = slab % ring;
            let plane = &mut acc[slot * n..][..n];
            let touched = &mut spans[slot * bn..][..bn];
            for (my, run) in runs.iter().enumerate().take(r1).skip(r0) {
                let run = run.to_bits();
                let (first, last) = (i64::from(run & 0xffff), i64::from(run >> 16));
                let Some(c) = walk.clip(my, walk.x0 + first, walk.x0 + last) else {
                    continue;
                };
                let y = (y0 + my as i64) as usize;
                let rows = corner_rows(data, corners, c.entry, c.n);
                let px = &mut plane[y * w + c.lo..][..c.n];
                if nearest {
                    section_row::<true>(blend, rows, value, px);
                } else {
                    section_row::<false>(blend, rows, value, px);
                }
                updates += c.n as u64;
                touched[y].include(c.lo, c.hi);
            }
        }
        updates
    }
}

/// Adds `value` × w to each pixel of `px`, w the blend of the four corner stencils' entries
/// (`rows`, each at least `px.len()` long) by `blend`: a section's runs are short (a few pixels),
/// so one pixel at a time, its four channels together. `NEAREST`: w = the first row's entry
/// (the nearest phase's stencil; the other rows are not read).
#[inline(always)]
fn section_row<const NEAREST: bool>(
    [b00, b10, b01, b11]: [f32; 4],
    (r00, r10, r01, r11): (&[f32], &[f32], &[f32], &[f32]),
    v: &[f32; 4],
    px: &mut [[f32; 4]],
) {
    let rows = r00.iter().zip(r10).zip(r01.iter().zip(r11));
    for (d, ((a, b), (c, e))) in px.iter_mut().zip(rows) {
        let w = if NEAREST {
            *a
        } else {
            b00 * a + b10 * b + b01 * c + b11 * e
        };
        *d = [
            d[0] + v[0] * w,
            d[1] + v[1] * w,
            d[2] + v[2] * w,
            d[3] + v[3] * w,
        ];
    }
}

/// Writes every set's (P + 1)² stencils of B² section weights into `weights` (zeroed, D · K sets
/// of `plan.floats()`): one table ray per box pixel and phase, read at every depth phase's
/// K + 1 slab boundaries.
fn fill_sections<const R: usize, const T: usize>(
    s: &SlabSetup,
    table: &SectionTable<R, T>,
    plan: Plan,
    (first_offset, offsets): (i64, usize),
    weights: &mut [f32],
) {
    let (side, p) = (plan.side, plan.phases);
    let (set_len, cells) = (plan.floats(), side * side);
    let reach = (side / 2) as f32;
    let [qxx, qxy, qyy] = s.q;
    let (ka, kb) = (s.kappa * s.shear[0], s.kappa * s.shear[1]);
    let dt = s.kappa * s.thickness;
    let d = s.depth_phases;
    for k in 0..(p + 1) * (p + 1) {
        let phase = [
            (k % (p + 1)) as f32 / p as f32,
            (k / (p + 1)) as f32 / p as f32,
        ];
        for my in 0..side {
            let dy = my as f32 - reach + 0.5 - phase[1];
            for mx in 0..side {
                let dx = mx as f32 - reach + 0.5 - phase[0];
                let rho2 = (qxx * dx + 2.0 * qxy * dy) * dx + qyy * dy * dy;
                let Some(ray) = table.ray(rho2) else {
                    continue;
                };
                let shift = ka * dx + kb * dy;
                let at = k * cells + my * side + mx;
                for e in 0..d {
                    let delta = (e as f32 + 0.5) / d as f32;
                    let front = |m: usize| dt * ((first_offset + m as i64) as f32 - delta) - shift;
                    let mut before = ray.at(front(0));
                    for m in 0..offsets {
                        let after = ray.at(front(m + 1));
                        weights[(e * offsets + m) * set_len + at] = s.scale * (after - before);
                        before = after;
                    }
                }
            }
        }
    }
}
