//! Phase stencils: a view's footprint sampled once per sub-pixel phase, so that splatting a
//! footprint is a run of multiply-adds with no table walk per pixel.
//!
//! A voxel projected to screen position c = (i + φx, j + φy) (i, j whole pixels, φ ∈ [0, 1)²)
//! covers pixel centres whose offsets from its pixel (i, j) lie in a fixed box of B × B pixels,
//! B = 2·⌈e + ½⌉ + 1 for half-extent e. For each phase on a (P + 1) × (P + 1) grid
//! (φ = (a/P, b/P), a, b = 0 … P) the stencil holds the footprint weight (px⁻²) at each pixel of the
//! box, read from a [`Sampler`] (the view table), zero outside the footprint's support, and, for a
//! footprint small enough to be renormalised ([`Footprint::renormalise`]), divided by its sum so a
//! voxel deposits exactly one unit. A voxel's weights are the bilinear blend of the four stencils
//! around its phase; since every stencil sums to one, so does the blend.
//!
//! **Narrow, blended and edged footprints.** A *narrow* footprint (box side B ≤ [`NARROW_SIDE`],
//! 16 px) is blended at P = P_max phases (the caller's, 32 in the harness) over every pixel where a
//! corner stencil is non-zero. A wider one varies more slowly per pixel, so it needs fewer phases
//! for the same blending error: it is blended the same way at P = min(P_max, ⌈[`BLEND_REACH`] /
//! r⌉), r the shorter semi-axis ([`minor_semi_axis`]), so P·r ≥ 224 px, when those stencils fit in
//! [`MAX_STENCIL_FLOATS`]; otherwise (a long thin footprint) it is *edged*: P = min(P_max,
//! ⌈[`PHASE_REACH`] / r⌉) (P·r ≥ 128), it visits exactly the pixel centres inside its support (as
//! the table walk does), blends where all four corner stencils are non-zero and reads the sampler
//! at the few edge pixels where one is not ([`plan_for`] decides). The footprint is not smooth at
//! its support's edge (the truncated Gaussian drops there from 4 % of its peak to nothing), and a
//! blend across it is off by a share of the edge weight on a sliver 1/P px wide, a fraction of the
//! pixels that falls as 1/(P·r): blended at P·r = 64, `verify` lost up to 1.5 dB against the table
//! walk, which is why wide footprints were once always edged. Blended at P·r ≥ 224 they lose
//! nothing: against edging at P·r ≥ 128, `verify` (f64 reference, view 30,20,0) went from 102.22
//! to 102.76 dB on headsq at 512² (half-extent 8 px), 102.31 to 102.76 dB at 2048² (32 px), 98.40
//! to 98.75 dB on the walnut at 1024² (8.4 px), 99.49 to 100.66 dB on the built-in scene at
//! 1024² (15 px), and frames got 1.4–1.9× faster (no sampler reads, no per-row support solve:
//! `footprint bench`, the two builds alternated, 1 thread). Stencils that would exceed
//! [`MAX_STENCIL_FLOATS`] either way are not built: the table walk serves those.
//!
//! **Accuracy.** Blending between phases adds the error of linear interpolation over a phase step
//! of 1/P px: at most (1/P)²/8 · |∂²w/∂φ²|. For a Gaussian of standard deviation σ ≈ r/2.5
//! (the default kernel) |∂²w/∂φ²| ≤ peak/σ², so the error is at most (2.5/(P·r))²/8 of the peak:
//! 3.4·10⁻⁴ for the smallest footprint (r = 1.5 px at P = 32), 1.6·10⁻⁵ for a blended wide one
//! (P·r ≥ 224), 4.8·10⁻⁵ for an edged one. The
//! harness's `verify` measures it with the rest; `tests/stencils.rs` checks it against the table
//! walk and checks every pixel against brute force.
//!
//! **Only the support is visited.** For each phase cell (a, b) the stencils store, per box row, the
//! first and last pixel where any of the cell's four corner stencils is non-zero (blended) or where
//! all four are (edged); a blended splat visits only the former (about π/4 of the box for an
//! ellipse, less for a thin one). Every pixel skipped would have received a weight of exactly
//! zero, so this changes no pixel.
//!
//! **Memory.** (P + 1)² · B² + P² · B floats, built once per view in caller storage:
//! [`len_for`]. For P_max = 32 and round footprints: 126 KiB at e = 1.5 px (B = 5), 236 KiB at
//! e = 2 px (B = 7), 559 KiB at e = 4.2 px (B = 11), 1.2 MiB at e = 8 px (B = 19, P = 28),
//! 1.1 MiB at e = 16 px (B = 35, P = 14) and at e = 32 px (B = 67, P = 7), 1.6 MiB at the
//! largest, e = 63 px (B = 129, P = 4).

use crate::geometry::Footprint;
use crate::math;
use crate::splat::{floor_i64, BufferError, ImageMut, Pixel, Sampler, SplatStats, Splatter};

mod edged;
mod fill;
mod row;
mod small;
pub(crate) mod walk;

pub use fill::StencilFill;
use walk::{corner_rows, SpanWalk};

/// Largest number of phases per pixel the harness uses ([`phases_for`] lowers it for
/// footprints wider than [`NARROW_SIDE`]).
pub const DEFAULT_PHASES: usize = 32;

/// How a blended footprint's weights are read at a voxel's sub-pixel phase φ ∈ [0, 1)² (phase
/// cell (a, b), fraction f = φ·P − (a, b) ∈ [0, 1)²).
///
/// - [`PhaseLookup::Blend`]: the bilinear blend of the cell's four corner stencils (the module
///   docs): a phase placed exactly, up to the blend's error of (2.5/(P·r))²/8 of the peak.
/// - [`PhaseLookup::Nearest`]: the one corner stencil nearest the phase, (a + [f_x ≥ ½],
///   b + [f_y ≥ ½]): the footprint placed up to 1/(2P) px off in each axis, one stencil row read
///   per pixel instead of four and no multiply. Each voxel still deposits exactly one unit (every
///   stencil of a renormalised footprint sums to one). The footprint moves at most √2/(2P) px,
///   so a weight moves at most √2/(2P) · peak/(σ·√e) ≈ 0.43/(P·σ) of the peak for a Gaussian of
///   standard deviation σ ≈ r/2.5: 2.2 % at r = 1.5 px and P = 32. Measured (the harness's
///   `verify`, 512², view 30,20,0): 80.8–86.8 dB against the f64 sheet reference on the shared
///   volumes instead of blending's 98.1–104.8, while the error against the continuous integral
///   (the opacity model) moved by −0.44 to −0.01 dB (`--phase-lookup`, docs/modes.md). Edged
///   footprints ([`Plan::edged`]) are always blended: their phases are too few for it. The
///   fixed path's integer stencils read it the same way
///   ([`crate::fixed::stencil::FixedStencils::with_phase_lookup`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PhaseLookup {
    /// The bilinear blend of the four corner stencils (the default).
    #[default]
    Blend,
    /// The nearest corner stencil.
    Nearest,
}

/// For an edged footprint ([`Plan::edged`]), phases × shorter semi-axis (px) kept at least this
/// large: P = ⌈`PHASE_REACH` / r⌉, capped by the caller's maximum (see the module docs for the error
/// it bounds).
pub const PHASE_REACH: f32 = 128.0;

/// Largest stencil storage, floats (8 MiB): beyond it a footprint is splatted by the table walk.
///
/// A wide footprint is blended when its stencils at P·r ≥ [`BLEND_REACH`] fit, else edged, and an
/// edged splat costs about twice a blended one (a support solve per row and sampler reads at
/// the edge). At 2 MiB the long footprints of anisotropic grids were edged: the CT head
/// (64×64×93, spacing 3.2 × 3.2 × 1.5) at 1024² seen from the side. Raised to 8 MiB (`footprint
/// bench --frames 3 --orbit 2 --threads 1`, builds alternated; `verify` against the f64
/// reference): views 80,20,0 / 90,0,0 / 60,70,0 went 291 → 161, 279 → 171 and 265 → 149 ms per
/// frame and 98.10 → 98.26, 92.47 → 92.67 and 98.66 → 98.74 dB; fixed at 80,20,0 428 → 320 ms,
/// 98.08 → 98.25 dB. Building those stencils takes 9 ms instead of 4 (one thread).
pub const MAX_STENCIL_FLOATS: usize = 1 << 21;

/// The shorter semi-axis of `footprint`'s support ellipse |A q| ≤ 1, px: 1 / σ_max(A), A =
/// [`Footprint::to_unit`] (for a separable kernel's parallelogram, the half-width of its
/// inscribed ellipse, a lower bound). 0 for a degenerate footprint.
pub fn minor_semi_axis(footprint: &Footprint) -> f32 {
    let [[a, b], [c, d]] = footprint.to_unit;
    let t = a * a + b * b + c * c + d * d;
    let det = a * d - b * c;
    let s2 = 0.5 * (t + math::sqrt((t * t - 4.0 * det * det).max(0.0)));
    if s2 > 0.0 && s2.is_finite() {
        1.0 / math::sqrt(s2)
    } else {
        0.0
    }
}

/// Footprints whose box side is at most this many pixels are *narrow*: blended at every phase the
/// caller allows, up to the support's edge. Wider ones get fewer phases, and are blended up to
/// the edge or edged ([`plan_for`], the module docs).
pub const NARROW_SIDE: usize = 16;

/// For a footprint wider than [`NARROW_SIDE`] blended everywhere: phases × shorter semi-axis (px)
/// kept at least this large, P = ⌈`BLEND_REACH` / r⌉ capped by the caller's maximum (see the
/// module docs for what it bounds).
pub const BLEND_REACH: f32 = 224.0;

/// How a footprint's stencils are laid out and splatted: box side B, phases P, and whether the
/// splat reads the edge from the sampler (*edged*) instead of blending up to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Box side B, pixels.
    pub side: usize,
    /// Phases per pixel P.
    pub phases: usize,
    /// Blended only where all four corner stencils are non-zero, the rest read exactly.
    pub edged: bool,
}

impl Plan {
    /// Floats the stencils take: (P + 1)² · B² + P² · B; `usize::MAX` where that overflows
    /// (P comes from the caller: such a plan never fits [`MAX_STENCIL_FLOATS`]).
    pub fn floats(&self) -> usize {
        stencil_len(self.phases, self.side).unwrap_or(usize::MAX)
    }
}

/// (P + 1)² · B² + P² · B entries for P phases and box side B, or `None` where that overflows
/// `usize` (both come from the caller: no size computed from them may wrap).
pub fn stencil_len(phases: usize, side: usize) -> Option<usize> {
    let p1 = phases.checked_add(1)?;
    let corners = p1.checked_mul(p1)?.checked_mul(side)?.checked_mul(side)?;
    let cells = phases.checked_mul(phases)?.checked_mul(side)?;
    corners.checked_add(cells)
}

/// The stencils for `footprint` with at most `max_phases` (≥ 1) phases per pixel, if any fit in
/// [`MAX_STENCIL_FLOATS`]: a narrow footprint (B ≤ [`NARROW_SIDE`]) blended at `max_phases`;
/// a wider one blended at P = ⌈[`BLEND_REACH`] / r⌉ when that fits, else edged at
/// P = ⌈[`PHASE_REACH`] / r⌉ (r the shorter semi-axis, [`minor_semi_axis`]; both capped by
/// `max_phases`).
pub fn plan_for(footprint: &Footprint, max_phases: usize) -> Option<Plan> {
    let side = side_for(footprint)?;
    let max_phases = max_phases.max(1);
    let fits = |p: Plan| (p.floats() <= MAX_STENCIL_FLOATS).then_some(p);
    let r = minor_semi_axis(footprint);
    if side <= NARROW_SIDE || !(r > 0.0) {
        return fits(Plan {
            side,
            phases: max_phases,
            edged: side > NARROW_SIDE,
        });
    }
    let at = |reach| phases_at(reach, r, max_phases);
    fits(Plan {
        side,
        phases: at(BLEND_REACH),
        edged: false,
    })
    .or_else(|| {
        fits(Plan {
            side,
            phases: at(PHASE_REACH),
            edged: true,
        })
    })
}

/// min(`max_phases`, ⌈`reach` / r⌉), at least 1.
fn phases_at(reach: f32, r: f32, max_phases: usize) -> usize {
    let p = -math::floor(-(reach / r)); // ⌈reach / r⌉
    if p >= max_phases as f32 {
        max_phases
    } else {
        (p as usize).max(1)
    }
}

/// Phases for stencils that always read a wide footprint's edge (the fixed path's,
/// [`crate::fixed::stencil`]): `max_phases` for a box side up to [`NARROW_SIDE`], else
/// min(`max_phases`, ⌈[`PHASE_REACH`] / r⌉).
pub fn edged_phases_for(footprint: &Footprint, max_phases: usize) -> usize {
    let max_phases = max_phases.max(1);
    let r = minor_semi_axis(footprint);
    match side_for(footprint) {
        Some(side) if side > NARROW_SIDE && r > 0.0 => phases_at(PHASE_REACH, r, max_phases),
        _ => max_phases,
    }
}

/// Largest box side (pixels) stencils are built for (half-extent up to 63.5 px); wider
/// footprints use the table walk, whose per-row cost they amortise.
pub const MAX_STENCIL_SIDE: usize = 129;

/// Box side B for `footprint`, if stencils apply (B ≤ [`MAX_STENCIL_SIDE`]).
pub fn side_for(footprint: &Footprint) -> Option<usize> {
    let e = footprint.half_extent[0].max(footprint.half_extent[1]);
    if !(e.is_finite() && e >= 0.0) {
        return None;
    }
    let reach = -math::floor(-(e + 0.5)); // ⌈e + ½⌉
    let side = 2.0 * reach + 1.0;
    (side <= MAX_STENCIL_SIDE as f32).then_some(side as usize)
}

/// Phases per pixel P of [`plan_for`]'s stencils for `footprint` when the caller allows at most
/// `max_phases` (≥ 1): `max_phases` for a narrow footprint, fewer for a wider one (the weight
/// varies fastest across the shorter semi-axis, [`minor_semi_axis`]); `max_phases` also when no
/// stencils fit.
pub fn phases_for(footprint: &Footprint, max_phases: usize) -> usize {
    plan_for(footprint, max_phases).map_or(max_phases.max(1), |p| p.phases)
}

/// Floats needed for `footprint`'s stencils with at most `max_phases` phases per pixel, if
/// stencils apply: (P + 1)² · B² + P² · B.
/// `None` also when that would exceed [`MAX_STENCIL_FLOATS`] (a long thin footprint that
/// needs many phases: the table walk serves it).
pub fn len_for(footprint: &Footprint, max_phases: usize) -> Option<usize> {
    plan_for(footprint, max_phases).map(|p| p.floats())
}

/// The four stencils at the corners of phase cell `c` = a + b·P (indices into the (P + 1)² grid of
/// stencils, row b first): (a, b), (a + 1, b), (a, b + 1), (a + 1, b + 1).
pub(crate) fn cell_corners(c: usize, phases: usize) -> [usize; 4] {
    let (a, b) = (c % phases, c / phases);
    [
        b * (phases + 1) + a,
        b * (phases + 1) + a + 1,
        (b + 1) * (phases + 1) + a,
        (b + 1) * (phases + 1) + a + 1,
    ]
}

/// Where the four stencils around phase cell (`ka`, `kb`) start in the stencil data (stencils of
/// `cells` weights on a (P + 1)² grid): (ka, kb), (ka + 1, kb), (ka, kb + 1), (ka + 1, kb + 1).
/// (Written out rather than through [`cell_corners`]: that divides, and this runs per voxel.)
#[inline]
pub(crate) fn corner_offsets(ka: usize, kb: usize, phases: usize, cells: usize) -> [usize; 4] {
    let s00 = (kb * (phases + 1) + ka) * cells;
    let s01 = s00 + (phases + 1) * cells;
    [s00, s00 + cells, s01, s01 + cells]
}

/// The phase cell k (0 … P − 1) and the fraction f ∈ [0, 1] within it of a centre coordinate `c`
/// (pixels) whose pixel is `i`, at `p` phases: (c − i)·P split into its floor and remainder.
#[inline(always)]
pub(crate) fn phase_cell(c: f32, i: i64, p: usize) -> (usize, f32) {
    let t = (c - i as f32) * p as f32;
    let k = (t.max(0.0) as usize).min(p - 1);
    (k, (t - k as f32).clamp(0.0, 1.0))
}

/// Where and how a splat reads phase cell (`ka`, `kb`) at fraction (`fx`, `fy`), for stencils of
/// `cells` weights at `phases` phases: the four corner stencils' offsets ([`corner_offsets`]) and
/// their bilinear weights; `nearest`: the corner (a + [fx ≥ ½], b + [fy ≥ ½]) alone, first and
/// weighed 1 (the others are read by no loop: their weight is never formed).
#[inline(always)]
pub(crate) fn cell_read(
    (ka, kb): (usize, usize),
    (fx, fy): (f32, f32),
    phases: usize,
    cells: usize,
    nearest: bool,
) -> ([usize; 4], [f32; 4]) {
    let corners = corner_offsets(ka, kb, phases, cells);
    if nearest {
        let c = corners[usize::from(fx >= 0.5) + 2 * usize::from(fy >= 0.5)];
        return ([c; 4], [1.0, 0.0, 0.0, 0.0]);
    }
    let blend = [
        (1.0 - fx) * (1.0 - fy),
        fx * (1.0 - fy),
        (1.0 - fx) * fy,
        fx * fy,
    ];
    (corners, blend)
}

/// The first and last index of a non-zero weight in `row`, if any.
pub(crate) fn nonzero_run<W: PartialEq + Default>(row: &[W]) -> Option<(usize, usize)> {
    let zero = W::default();
    let first = row.iter().position(|w| *w != zero)?;
    let last = row.iter().rposition(|w| *w != zero)?;
    Some((first, last))
}

/// One view's phase stencils (see the module docs), in caller storage, with the sampler they were
/// built from (an edged footprint reads it at the support's edge).
#[derive(Debug)]
pub struct Stencils<'a, S: ?Sized> {
    sampler: &'a S,
    /// Whether the footprint is edged ([`Plan::edged`]).
    wide: bool,
    /// (P + 1)² stencils of B² weights, then P² cells of B row ranges (first | last << 16, kept
    /// as the bits of an f32: a tiny positive number, never NaN).
    data: &'a [f32],
    /// Offset of the per-cell row ranges in `data`.
    ranges: usize,
    side: usize,
    phases: usize,
    /// The longest stored row run, pixels (0 when every run is empty).
    run_width: usize,
    /// log₂ P when P is a power of two (see [`Stencils::splat`]'s scaled centre).
    phase_shift: Option<u32>,
    /// How a blended footprint reads its phase ([`Stencils::with_phase_lookup`]).
    lookup: PhaseLookup,
}

impl<S: ?Sized> Clone for Stencils<'_, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S: ?Sized> Copy for Stencils<'_, S> {}

impl<'a, S: Sampler + ?Sized> Stencils<'a, S> {
    /// Samples `sampler`'s footprint at every phase into `buffer` (at least
    /// [`len_for`] floats), with at most `max_phases` (≥ 1) phases per pixel.
    pub fn build(
        sampler: &'a S,
        max_phases: usize,
        buffer: &'a mut [f32],
    ) -> Result<Self, BufferError> {
        Self::build_split(sampler, max_phases, buffer, |weights, fill| {
            for (k, stencil) in weights.chunks_exact_mut(fill.cells()).enumerate() {
                fill.fill(k, stencil);
            }
        })
    }

    /// [`Stencils::build`], with the sampling of the stencils (nearly all of the work) handed
    /// to `run(weights, fill)`, which must call `fill.fill(k, stencil)` for every stencil k of
    /// `weights.chunks_exact_mut(fill.cells())`, in any order and on any threads (each stencil
    /// depends on nothing else): a caller with threads splits them, and the stencils are the
    /// same bits however it does. A stencil `run` skips keeps whatever `buffer` held.
    pub fn build_split(
        sampler: &'a S,
        max_phases: usize,
        buffer: &'a mut [f32],
        run: impl FnOnce(&mut [f32], &StencilFill<'_, S>),
    ) -> Result<Self, BufferError> {
        let fp = sampler.footprint();
        let Some(plan) = plan_for(fp, max_phases) else {
            let e = fp.half_extent[0].max(fp.half_extent[1]);
            let side = (2.0 * e + 2.0).min(1e9) as usize;
            return Err(BufferError::TooLarge {
                width: side,
                height: side,
            });
        };
        let (side, phases, len) = (plan.side, plan.phases, plan.floats());
        if buffer.len() < len {
            return Err(BufferError::TooSmall {
                needed: len,
                got: buffer.len(),
            });
        }
        let reach = (side / 2) as i64;
        let cells = side * side;
        let ranges = (phases + 1) * (phases + 1) * cells;
        let (weights, spans) = buffer[..len].split_at_mut(ranges);
        run(
            weights,
            &StencilFill {
                sampler,
                side,
                phases,
                reach,
            },
        );
        // Per phase cell and box row: the first and last pixel where one of the cell's four
        // corner stencils is non-zero (blended footprints: the pixels a splat visits), or where
        // all four are (edged ones: the pixels it blends); first > last when there are none.
        let wide = plan.edged;
        let weights = &*weights;
        let nonzero = |stencil: usize, my: usize| {
            nonzero_run(&weights[stencil * cells + my * side..][..side])
        };
        let run = |corners: [usize; 4], my: usize| {
            if !wide {
                return corners
                    .iter()
                    .filter_map(|&s| nonzero(s, my))
                    .fold((side, 0), |(f, l), (a, b)| (f.min(a), l.max(b)));
            }
            // Non-zero in all four: inside each corner's run, and no zero within (a support row
            // is one interval, but a table can hold a zero inside it).
            let (mut lo, mut hi) = (0, side - 1);
            for &c in &corners {
                match nonzero(c, my) {
                    Some((f, l)) => (lo, hi) = (lo.max(f), hi.min(l)),
                    None => return (side, 0),
                }
            }
            let row = |c: usize| &weights[c * cells + my * side..][lo..=hi];
            if lo <= hi && corners.iter().all(|&c| row(c).iter().all(|&w| w != 0.0)) {
                (lo, hi)
            } else {
                (side, 0)
            }
        };
        // Kept as the bits of an f32: the pattern (exponent field ≤ 1) is never a NaN, so it
        // survives being stored and read as an f32 unchanged.
        let run_width = walk::pack_runs(spans, side, phases, run, f32::from_bits);
        Ok(Stencils {
            sampler,
            wide,
            data: &buffer[..len],
            ranges,
            side,
            phases,
            run_width,
            phase_shift: phases.is_power_of_two().then(|| phases.trailing_zeros()),
            lookup: PhaseLookup::Blend,
        })
    }

    /// These stencils read at each voxel's phase by `lookup` ([`PhaseLookup`]; built blended).
    /// An edged footprint is blended whatever `lookup` says.
    pub fn with_phase_lookup(mut self, lookup: PhaseLookup) -> Self {
        self.lookup = lookup;
        self
    }

    /// How a voxel's phase is read: [`PhaseLookup::Blend`] for an edged footprint.
    pub fn phase_lookup(&self) -> PhaseLookup {
        self.lookup.unless_edged(self.wide)
    }

    /// Box side B, pixels.
    pub fn side(&self) -> usize {
        self.side
    }

    /// Phases per pixel P.
    pub fn phases(&self) -> usize {
        self.phases
    }

    /// Spreads `value` of a voxel projected to `center` (pixels, absolute) into `image`, calling
    /// `touched(y, x0, x1)` for each row it visited: the blend of the four stencils around the
    /// centre's sub-pixel phase. A blended footprint visits the pixels where one of them is
    /// non-zero; an edged one ([`Plan::edged`]) visits the pixel centres inside its support, as the table walk
    /// ([`crate::splat::splat_rows`]) does, blending where all four are non-zero and reading the
    /// sampler at the few edge pixels where one is not (the footprint is not smooth at its
    /// support's edge, so a blend across it is off by a share of the edge weight).
    pub fn splat<P: Pixel>(
        &self,
        center: [f32; 2],
        value: &P,
        image: &mut ImageMut<'_, P>,
        mut touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError> {
        if !(center[0].is_finite() && center[1].is_finite()) {
            return Err(BufferError::NonFiniteCenter);
        }
        let p = self.phases;
        // With P = 2^s phases the centre scaled by P, T = c·P, is exact, and one floor j = ⌊T⌋
        // gives both the pixel (j >> s) and the phase cell (j mod P), and the fraction T − j is
        // exact too (|T| < 2²⁴). For a box inside the image (c ≥ 1, so c − ⌊c⌋ is exact) that is
        // bit for bit the general formula below, (c − ⌊c⌋)·P split into its floor and fraction,
        // with two float-integer conversions fewer per axis.
        let scaled = self.phase_shift.and_then(|s| {
            let t = center.map(|c| c * p as f32);
            (t[0].abs() < small::SMALL_FLOOR_MAX && t[1].abs() < small::SMALL_FLOOR_MAX)
                .then(|| (s, t, t.map(small::small_floor)))
        });
        let (ix, iy) = match scaled {
            Some((s, _, j)) => (j[0] >> s, j[1] >> s),
            None => (floor_i64(center[0]), floor_i64(center[1])),
        };
        let mut stats = SplatStats::default();
        let Some(walk) = SpanWalk::new([ix, iy], self.side, image.width(), image.height()) else {
            return Ok(stats);
        };
        let ((ka, fx), (kb, fy)) = match scaled {
            Some((_, t, j)) if walk.inside => {
                let cell =
                    |t: f32, j: i64| ((j as usize) & (p - 1), (t - j as f32).clamp(0.0, 1.0));
                (cell(t[0], j[0]), cell(t[1], j[1]))
            }
            _ => (phase_cell(center[0], ix, p), phase_cell(center[1], iy, p)),
        };
        let side = self.side;
        let nearest = !self.wide && self.lookup == PhaseLookup::Nearest;
        let (corners, blend) = cell_read((ka, kb), (fx, fy), p, side * side, nearest);
        let spans = &self.data[self.ranges + (kb * p + ka) * side..][..side];
        let stride = image.stride();
        let w = image.width() as i64;
        let data = image.data_mut();
        if !self.wide {
            // A box wholly inside the image whose runs are at most 15 px: windows of a fixed
            // width, no clipping.
            if walk.inside {
                let small = (corners, blend, spans, (walk.x0 as usize, walk.y0 as usize));
                let stats = if nearest {
                    self.splat_small::<true, P>(small, value, data, stride, &mut touched)
                } else {
                    self.splat_small::<false, P>(small, value, data, stride, &mut touched)
                };
                if let Some(stats) = stats {
                    return Ok(stats);
                }
            }
            // Blended: weight and deposit in one pass over the stored runs.
            for row in walk.rows(spans, f32::to_bits) {
                let Some(c) = walk.clip(row.my, row.first, row.last) else {
                    continue;
                };
                let rows = corner_rows(self.data, corners, c.entry, c.n);
                let start = row.y * stride + c.lo;
                // Clipped to the image, so the range is inside the buffer ImageMut checked.
                let px = &mut data[start..start + c.n];
                stats.pixels_updated += if nearest {
                    row::blend_row::<true, P>(blend, rows, value, px)
                } else {
                    row::blend_row::<false, P>(blend, rows, value, px)
                };
                stats.pixels_visited += c.n as u32;
                touched(row.y, c.lo, c.hi);
            }
            return Ok(stats);
        }
        let edged = (corners, blend, spans, center);
        Ok(self.splat_edged(walk, edged, value, data, stride, w, &mut touched))
    }
}

impl<S: Sampler + ?Sized> Splatter for Stencils<'_, S> {
    #[inline]
    fn splat_voxel<P: Pixel>(
        &self,
        center: [f32; 2],
        value: &P,
        image: &mut ImageMut<'_, P>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError> {
        self.splat(center, value, image, touched)
    }
}
