//! Image-aligned slicing (Mueller and Crawfis 1998, "Eliminating popping artifacts in sheet
//! buffer-based splatting"): the volume is cut by slabs parallel to the image plane instead of
//! the paper's sheets along a grid axis, each voxel's kernel is cut by the slabs it overlaps, and
//! each slab is composited as a unit.
//!
//! # Geometry (derived in grid steps; checked against brute-force line integrals in tests)
//! Let M = V·G (grid steps → screen pixels, z in pixels along the view, growing away from the
//! viewer) and d = M⁻¹·ẑ, the grid-space step per pixel of screen depth. A pixel at screen offset
//! (dx, dy) from a voxel, at depth offset z, sits at grid offset q = dx·p₀ + dy·p₁ + z·d (p₀, p₁
//! the first two columns of M⁻¹). Along the pixel's ray, |q|² = |d|²(z − z*)² + r⊥², with
//! z* = a·dx + b·dy (a = −p₀·d/|d|², b = −p₁·d/|d|²) and r⊥² a quadratic form in (dx, dy). For a
//! radial kernel of radius R (grid steps), ρ² = r⊥²/R² and the chord coordinate is
//! t = (|d|/R)(z − z*). The kernel w(q) = h(|q|/R)/(R³∫_ball h) (the continuous field's own
//! normalisation: lattice weights sum to one) then puts
//!
//! ```text
//! ∫_slab w dl = |G·d| / (|d|·R²) · [G(ρ², t_b) − G(ρ², t_a)]
//! ```
//!
//! of itself (l world length along the ray) into the slab between depths z_a < z_b, with G the
//! [`SectionTable`](crate::table::SectionTable). For an anisotropic grid z* ≠ 0: the chord's midpoint moves with the pixel.
//!
//! # Values and compositing
//! A voxel's value is what its [`Absorption`] model reconstructs, per world unit
//! ([`SlabSetup::voxel`]): its opacity α₁ over one world unit and premultiplied colour α₁c
//! (opacity, the default), or its extinction σ = −ln(1 − α₁) and σc (extinction). A slab
//! accumulates the integral of that field along each pixel's chord through it and is composited
//! as one layer ([`Absorption::layer`]): opacity 1 − (1 − ᾱ)^L with ᾱ the mean opacity over the
//! chord of L world units, or 1 − e^(−τ); colour the mean straight colour. That is the
//! emission–absorption integral of the continuous field Σᵥ w(x − v)·valueᵥ, with only the
//! ordering inside each slab (and, for opacity, α by its mean over the chord) approximated:
//! thinner slabs converge to it. A slab does not need the per-sheet opacity correction of object
//! slicing, and nothing depends on which grid axis is most parallel to the image (no pop at 45°).
//!
//! # Slabs
//! Slab j covers screen depths [z₀ + jT, z₀ + (j+1)T): slab 0 is the nearest. Boundaries are
//! anchored at the volume's centre (z₀ + kT passes through it for some k), so they move with
//! the volume, not with the view. T = `thickness` × the smallest grid spacing, along the ray.
//!
//! # Memory, streaming and precision
//! The core holds nothing but the [`SlabSetup`] (a few dozen floats) and reads the caller's
//! [`SectionTable`](crate::table::SectionTable); the caller supplies the slab accumulator, image and row spans (as for
//! sheets) and, per slab, the voxels that overlap it ([`SlabSetup::slabs_of`]). A slab of an
//! oblique view crosses every sheet of the volume, so a source that delivers sheets one at a
//! time cannot feed it from a bounded window: the caller buffers the volume's non-transparent
//! voxels (the harness: 32 bytes each) or reads the source once per slab. There is no fixed-point
//! variant (compositing takes an exponential per pixel and slab); perspective frames are refused
//! ([`SlabError::Perspective`]).

use super::absorption::{extinction_layer, Absorption, MAX_UNIT_ALPHA};
use crate::frame::FrameSetup;
use crate::geometry::box_corners;
use crate::kernel::Kernel;
use crate::math;
use crate::splat::pixel_range;
use crate::table::SectionError;
use core::fmt;

mod sections;
pub use sections::SectionStencils;

/// The most slabs a frame may have.
pub const MAX_SLABS: usize = 1 << 16;

/// A chord-midpoint shear (z* over the footprint, in chord units: unit kernel radii) at or below
/// this is taken as none. It moves a slab boundary along a chord by at most this much, which
/// changes a section by at most 10⁻⁶ × max C′ = 1.01·10⁻⁶ of the peak footprint for the default
/// Gaussian (C′(0) / (C(1) − C(−1)), [`SectionTable`](crate::table::SectionTable)'s C), below the
/// section table's own error (2.4·10⁻⁶ of the peak).
pub const SHEAR_SNAP: f32 = 1e-6;

/// The most slabs one kernel may span ([`SlabSetup::ring`], the ring of slab accumulators a
/// renderer keeps): slabs thinner than about a twentieth of the kernel's depth along the ray are
/// refused ([`SlabError::KernelTooDeep`]).
pub const MAX_RING: usize = 40;

/// The most depth phases per slab ([`SlabSetup::with_depth_phases`]).
pub const MAX_DEPTH_PHASES: usize = 256;

/// Why image-aligned slicing could not be set up.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum SlabError {
    /// Slab thickness not a positive finite number of voxel spacings.
    BadThickness {
        /// The thickness given.
        value: f32,
    },
    /// So thin a slab that the volume needs more than [`MAX_SLABS`].
    TooManySlabs {
        /// Slabs the volume would need.
        needed: f32,
    },
    /// So thin a slab that one kernel spans more than [`MAX_RING`] of them (a kernel is deep
    /// along the ray on a grid much coarser along it than its finest spacing).
    KernelTooDeep {
        /// Slabs one kernel would span.
        slabs: f32,
    },
    /// The kernel cannot be cut ([`SectionError`]).
    Kernel(SectionError),
    /// A perspective frame: slabs would have to be cut per ray (not supported).
    Perspective,
    /// The view or grid is singular or not finite.
    Singular,
    /// Value subsampling outside 1..=64 ([`super::post::PostSetup::with_value_scale`]).
    ValueScale {
        /// The factor given.
        scale: usize,
    },
    /// More depth phases than [`MAX_DEPTH_PHASES`] ([`SlabSetup::with_depth_phases`]).
    DepthPhases {
        /// The phases asked for.
        phases: usize,
    },
    /// Section stencils ([`SectionStencils`]) for a setup without depth phases, or for a
    /// footprint they do not serve (one too wide to blend: the renderer cuts it per pixel).
    NoStencils,
    /// A section stencil buffer shorter than [`SectionStencils::len_for`].
    StencilBuffer {
        /// Floats needed.
        needed: usize,
        /// Floats given.
        got: usize,
    },
    /// Post-classified slabs at least as deep as the volume's sample box along the view
    /// ([`super::post::PostSetup::new`]): a slab samples each ray once, at its mid-plane, and
    /// a mid-plane need not meet the volume at all (the frame would be empty).
    ThickerThanVolume {
        /// The thickness given, smallest grid spacings.
        thickness: f32,
        /// The sample box's depth along the view, smallest grid spacings.
        depth: f32,
    },
}

impl fmt::Display for SlabError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadThickness { value } => write!(
                f,
                "slab thickness {value} is not a positive finite number of voxel spacings"
            ),
            Self::TooManySlabs { needed } => write!(
                f,
                "slabs this thin would need {needed:.0} slabs (at most {MAX_SLABS}): thicken them"
            ),
            Self::KernelTooDeep { slabs } => write!(
                f,
                "slabs this thin would cut one kernel into {slabs:.0} (at most {MAX_RING}, the \
                 ring of slab accumulators): thicken them"
            ),
            Self::Kernel(e) => e.fmt(f),
            Self::Perspective => f.write_str(
                "image-aligned slicing supports orthographic frames only (drop --perspective or \
                 use --slicing object)",
            ),
            Self::Singular => f.write_str("the view or grid is singular"),
            Self::ValueScale { scale } => write!(f, "value subsampling {scale} is outside 1..=64"),
            Self::DepthPhases { phases } => write!(
                f,
                "{phases} depth phases per slab is more than {MAX_DEPTH_PHASES}"
            ),
            Self::NoStencils => f.write_str(
                "section stencils need depth phases and a footprint narrow enough to blend",
            ),
            Self::StencilBuffer { needed, got } => write!(
                f,
                "section stencils need {needed} floats of storage, got {got}"
            ),
            Self::ThickerThanVolume { thickness, depth } => write!(
                f,
                "post-classified slabs {thickness} spacings thick are at least as deep as the \
                 volume along this view ({depth:.3} spacings), and a slab samples each ray once, \
                 at its mid-plane, which could miss the volume: give slabs thinner than that"
            ),
        }
    }
}

impl core::error::Error for SlabError {}

impl From<SectionError> for SlabError {
    fn from(e: SectionError) -> Self {
        SlabError::Kernel(e)
    }
}

/// One voxel ready for slab rendering: where it lands and what it emits and absorbs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabVoxel {
    /// Screen position, pixels (x right, y down, z depth growing away from the viewer):
    /// [`FrameSetup::affine_position`] of the voxel's grid index.
    pub position: [f32; 3],
    /// Per world unit, as the setup's [`Absorption`] model reads the voxel: [α₁r, α₁g, α₁b, α₁]
    /// (opacity over one world unit and the premultiplied colour) or [σr, σg, σb, σ] (extinction
    /// and σ times the straight colour).
    pub value: [f32; 4],
}

impl SlabVoxel {
    /// The most opacity per world unit the extinction model takes as is
    /// ([`super::absorption::MAX_UNIT_ALPHA`]).
    pub const MAX_UNIT_ALPHA: f32 = MAX_UNIT_ALPHA;

    /// Extinction and emission per world unit (the [`Absorption::Extinction`] model) from a
    /// voxel's premultiplied RGBA shaded for one world unit of thickness (the shader with
    /// `sheet_distance` = `reference_distance`). `None` for a transparent (or NaN) voxel. A setup's
    /// own model: [`SlabSetup::voxel`].
    pub fn from_unit_rgba(position: [f32; 3], rgba: [f32; 4]) -> Option<SlabVoxel> {
        Absorption::Extinction
            .voxel_value(rgba)
            .map(|value| SlabVoxel { position, value })
    }
}

/// One orthographic frame's slab geometry (see the module docs for the derivation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabSetup {
    pub(super) size: [usize; 2],
    /// ρ² = qxx·dx² + 2·qxy·dx·dy + qyy·dy².
    pub(super) q: [f32; 3],
    /// z* = shear[0]·dx + shear[1]·dy.
    pub(super) shear: [f32; 2],
    /// |d| / R: chord units per pixel of depth.
    pub(super) kappa: f32,
    /// Half extents of the ρ² < 1 ellipse, pixels.
    pub(super) half: [f32; 2],
    /// Depth half-extent of the kernel, pixels.
    pub(super) z_reach: f32,
    /// Front of slab 0 and the slab thickness, pixels of depth.
    pub(super) z0: f32,
    pub(super) thickness: f32,
    pub(super) count: usize,
    /// |G·d| / (|d|·R²): a section's weight per unit of table difference.
    pub(super) scale: f32,
    /// The model the slabs composite, and a slab's chord along the ray, world units.
    pub(super) absorption: Absorption,
    pub(super) chord: f32,
    /// Depth phases per slab (0: voxels at their own depth; see [`SlabSetup::with_depth_phases`]).
    pub(super) depth_phases: usize,
}

impl SlabSetup {
    /// Slabs `thickness` smallest-grid-spacings thick for `frame` (orthographic), cutting
    /// `kernel` (a Gaussian), compositing the default [`Absorption`] model (opacity; see
    /// [`SlabSetup::with_absorption`]).
    pub fn new(frame: &FrameSetup, kernel: &Kernel, thickness: f32) -> Result<Self, SlabError> {
        if frame.camera().is_some() {
            return Err(SlabError::Perspective);
        }
        if !matches!(kernel, Kernel::Gaussian { .. }) {
            return Err(SectionError::NotAVolumeKernel.into());
        }
        if !(thickness > 0.0 && thickness.is_finite()) {
            return Err(SlabError::BadThickness { value: thickness });
        }
        let m = frame.grid_to_screen;
        let det = m.determinant();
        if !(det != 0.0 && det.is_finite()) {
            return Err(SlabError::Singular);
        }
        let inv = m.inverse();
        let (p0, p1, d) = (inv.col(0), inv.col(1), inv.col(2));
        let d2 = d.length_squared();
        let r = kernel.spread();
        let (a, b) = (-p0.dot(d) / d2, -p1.dot(d) / d2);
        let (e0, e1) = (p0 + d * a, p1 + d * b);
        let r2 = r * r;
        let q = [e0.dot(e0) / r2, e0.dot(e1) / r2, e1.dot(e1) / r2];
        let qdet = q[0] * q[2] - q[1] * q[1];
        if !(qdet > 0.0 && qdet.is_finite()) {
            return Err(SlabError::Singular);
        }
        let half = [math::sqrt(q[2] / qdet), math::sqrt(q[0] / qdet)];
        // World length per pixel of depth along the ray: |G·d|.
        let to_world = frame.grid_inverse_transpose.inverse().transpose();
        let world_per_z = (to_world * d).length();
        let min_spacing = frame.spacing.iter().copied().fold(f32::INFINITY, f32::min);
        let t = thickness * min_spacing / world_per_z;
        let z_reach = r * m.row(2).length();
        let dl = math::sqrt(d2);
        // The voxel box's depth range, padded by the kernel.
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for c in box_corners(frame.dims, 0.0) {
            let z = frame.origin.z + m.row(2).dot(c);
            lo = lo.min(z - z_reach);
            hi = hi.max(z + z_reach);
        }
        let center = box_corners(frame.dims, 0.0)[7] * 0.5;
        let zc = frame.origin.z + m.row(2).dot(center);
        let j0 = math::floor((lo - zc) / t);
        let z0 = zc + j0 * t;
        let needed = (hi - z0) / t;
        if !(needed.is_finite() && t.is_finite()) {
            return Err(SlabError::Singular);
        }
        if needed > MAX_SLABS as f32 {
            return Err(SlabError::TooManySlabs { needed });
        }
        // A shear far below f32 resolution of a chord position is rounding on an isotropic grid
        // (measured ≤ 8·10⁻⁸ chord units over the footprint): snap it to zero so the renderer
        // takes its shear-free path ([`SlabSetup::shear_free`]).
        let (a, b) = if (dl / r) * (a.abs() * half[0] + b.abs() * half[1]) <= SHEAR_SNAP {
            (0.0, 0.0)
        } else {
            (a, b)
        };
        let ring = ring_for(z_reach, t);
        if ring > MAX_RING as f32 {
            return Err(SlabError::KernelTooDeep { slabs: ring });
        }
        Ok(SlabSetup {
            size: frame.size,
            q,
            shear: [a, b],
            kappa: dl / r,
            half,
            z_reach,
            z0,
            thickness: t,
            count: (math::floor(needed) as usize + 1).max(1),
            scale: world_per_z / (dl * r2),
            absorption: Absorption::default(),
            chord: thickness * min_spacing,
            depth_phases: 0,
        })
    }

    /// The same slabs compositing `absorption`'s model (voxels made with [`SlabSetup::voxel`]).
    pub fn with_absorption(self, absorption: Absorption) -> Self {
        SlabSetup { absorption, ..self }
    }

    /// The same slabs with every voxel's depth snapped to the middle of its depth phase: a voxel
    /// at depth z lies `u` = (z − z₀)/T slabs behind slab 0's front, in slab j = ⌊u⌋ at phase
    /// δ = u − j, and is placed at j + (e + ½)/`phases` with e = ⌊δ·`phases`⌋: at most T/(2·`phases`)
    /// from where it was, along the view. Then a kernel's share of each slab depends only on
    /// (e, the slab's offset from j, the sub-pixel phase), so it can be precomputed once per view
    /// ([`SectionStencils`]). Moving every kernel by a small depth moves mass between
    /// neighbouring slabs only: each kernel still deposits all of itself. `phases` 0 (the
    /// default) leaves voxels where they are; at most [`MAX_DEPTH_PHASES`].
    pub fn with_depth_phases(self, phases: usize) -> Result<Self, SlabError> {
        if phases > MAX_DEPTH_PHASES {
            return Err(SlabError::DepthPhases { phases });
        }
        Ok(SlabSetup {
            depth_phases: phases,
            ..self
        })
    }

    /// Depth phases per slab (0: voxels at their own depth).
    pub fn depth_phases(&self) -> usize {
        self.depth_phases
    }

    /// Where a voxel at screen depth `z` (pixels) is placed: its slab j (may lie outside the
    /// frame's slabs), its depth phase e (0 without depth phases) and its depth within slab j as
    /// a fraction δ ∈ [0, 1] of the slab (the middle of phase e, or exactly where it is without
    /// phases).
    #[inline]
    pub(super) fn place(&self, z: f32) -> (i64, usize, f32) {
        let u = (z - self.z0) / self.thickness;
        let j = math::floor(u);
        let delta = u - j;
        let d = self.depth_phases;
        if d == 0 {
            return (j as i64, 0, delta);
        }
        let e = ((delta * d as f32) as usize).min(d - 1);
        (j as i64, e, (e as f32 + 0.5) / d as f32)
    }

    /// The model the slabs composite.
    pub fn absorption(&self) -> Absorption {
        self.absorption
    }

    /// A slab's chord along the ray, world units (the thickness given × the smallest spacing).
    pub fn chord(&self) -> f32 {
        self.chord
    }

    /// The voxel at screen `position` shaded to premultiplied `rgba` for one world unit of
    /// thickness, valued as this setup's model reads it; `None` for a transparent (or NaN) voxel.
    #[inline]
    pub fn voxel(&self, position: [f32; 3], rgba: [f32; 4]) -> Option<SlabVoxel> {
        self.absorption
            .voxel_value(rgba)
            .map(|value| SlabVoxel { position, value })
    }

    /// Whether chords through a kernel all have their midpoint at the kernel's own depth (z* = 0:
    /// any orthographic view of an isotropic grid, or one along an axis of an anisotropic grid;
    /// a shear below [`SHEAR_SNAP`] counts as none). Then a slab boundary sits at the same chord
    /// position for every pixel of a footprint, and the renderer reads the depth table once per
    /// voxel and boundary instead of once per pixel and boundary, and per pixel only the radial
    /// factor and the chord's ends, in one walk
    /// ([`SectionTable::chord`](crate::table::SectionTable::chord)).
    pub fn shear_free(&self) -> bool {
        self.shear == [0.0, 0.0]
    }

    /// The most slabs one kernel overlaps (at most [`MAX_RING`]): how many slab accumulators a
    /// renderer keeps ([`SlabBuffers`](super::SlabBuffers)).
    pub fn ring(&self) -> usize {
        (ring_for(self.z_reach, self.thickness) as usize).min(self.count)
    }

    /// Number of slabs, front (0) to back.
    pub fn slab_count(&self) -> usize {
        self.count
    }

    /// Screen depth of slab `slab`'s front, pixels.
    pub fn front(&self, slab: usize) -> f32 {
        self.z0 + slab as f32 * self.thickness
    }

    /// Slab thickness, pixels of screen depth.
    pub fn thickness_px(&self) -> f32 {
        self.thickness
    }

    /// The first and last slab a kernel centred at depth `z` (pixels) overlaps, clamped to the
    /// frame's slabs.
    /// With depth phases ([`SlabSetup::with_depth_phases`]), those of the snapped depth.
    #[inline]
    pub fn slabs_of(&self, z: f32) -> (usize, usize) {
        let last = (self.count - 1) as f32;
        if self.depth_phases > 0 {
            let (j, _, delta) = self.place(z);
            let reach = self.z_reach / self.thickness;
            let f = |m: f32| (j as f32 + math::floor(m)).max(0.0).min(last) as usize;
            return (f(delta - reach), f(delta + reach));
        }
        let f = |v: f32| {
            math::floor((v - self.z0) / self.thickness)
                .max(0.0)
                .min(last) as usize
        };
        (f(z - self.z_reach), f(z + self.z_reach))
    }

    /// The image rows a voxel at screen y `y` can touch (pixel centres within its footprint's
    /// half-height), as a possibly empty range.
    #[inline]
    pub fn rows_of(&self, y: f32) -> core::ops::Range<usize> {
        centres_within(y - self.half[1], y + self.half[1], self.size[1])
    }
}

/// The pixels (or rows) of 0..`n` whose centres lie in [lo, hi] (screen pixels), the splat's own
/// rule ([`pixel_range`]).
#[inline]
pub(super) fn centres_within(lo: f32, hi: f32, n: usize) -> core::ops::Range<usize> {
    let (a, b) = pixel_range(lo, hi);
    let a = a.clamp(0, n as i64) as usize;
    let b = (b + 1).clamp(0, n as i64) as usize;
    a..b.max(a)
}

/// Slabs a depth span of 2·`reach` can overlap, at thickness `t`: ⌊2·reach/t⌋ + 2.
fn ring_for(reach: f32, t: f32) -> f32 {
    math::floor(2.0 * reach / t) + 2.0
}

/// A slab's accumulated [E, τ] as a premultiplied layer of the extinction model
/// ([`extinction_layer`]): α = 1 − e^(−τ), colour E·α/τ.
#[inline]
pub fn slab_layer(acc: [f32; 4]) -> [f32; 4] {
    extinction_layer(acc)
}
