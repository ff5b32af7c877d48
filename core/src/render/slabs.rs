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
//! [`SectionTable`]. For an anisotropic grid z* ≠ 0: the chord's midpoint moves with the pixel.
//!
//! # Values and compositing
//! Voxels carry extinction and emission per world unit ([`SlabVoxel::from_unit_rgba`]): σ =
//! −ln(1 − α₁), α₁ the voxel's opacity over one world unit, and σ·c with c its straight colour.
//! A slab accumulates τ = ∫σ dl and E = ∫σc dl per pixel, and is composited as a layer of
//! constant colour E/τ and opacity 1 − e^(−τ): the emission–absorption integral of the continuous
//! field Σᵥ w(x − v)(σᵥ, σᵥcᵥ), with only the ordering inside each slab approximated. Thinner slabs
//! converge to that integral; a slab does not need the per-sheet opacity correction of object
//! slicing, and nothing depends on which grid axis is most parallel to the image (no pop at 45°).
//!
//! # Slabs
//! Slab j covers screen depths [z₀ + jT, z₀ + (j+1)T): slab 0 is the nearest. Boundaries are
//! anchored at the volume's centre (z₀ + kT passes through it for some k), so they move with
//! the volume, not with the view. T = `thickness` × the smallest grid spacing, along the ray.
//!
//! # Memory, streaming and precision
//! The core holds nothing but the [`SlabSetup`] (a few dozen floats) and reads the caller's
//! [`SectionTable`]; the caller supplies the slab accumulator, image and row spans (as for
//! sheets) and, per slab, the voxels that overlap it ([`SlabSetup::slabs_of`]). A slab of an
//! oblique view crosses every sheet of the volume, so a source that delivers sheets one at a
//! time cannot feed it from a bounded window: the caller buffers the volume's non-transparent
//! voxels (the harness: 32 bytes each) or reads the source once per slab. There is no fixed-point
//! variant (compositing takes an exponential per pixel and slab); perspective frames are refused
//! ([`SlabError::Perspective`]).

use super::precision::float_over_row;
use super::{RenderBuffers, RenderError, RenderStats};
use crate::composite::{over, RowSpan};
use crate::frame::{FrameSetup, Order};
use crate::geometry::box_corners;
use crate::kernel::Kernel;
use crate::math;
use crate::splat::BufferError;
use crate::table::{SectionError, SectionTable};
use core::fmt;
use glam::Vec3;

/// The most slabs a frame may have.
pub const MAX_SLABS: usize = 1 << 16;

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
    /// The kernel cannot be cut ([`SectionError`]).
    Kernel(SectionError),
    /// A perspective frame: slabs would have to be cut per ray (not supported).
    Perspective,
    /// The view or grid is singular or not finite.
    Singular,
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
            Self::Kernel(e) => e.fmt(f),
            Self::Perspective => f.write_str(
                "image-aligned slicing supports orthographic frames only (drop --perspective or \
                 use --slicing object)",
            ),
            Self::Singular => f.write_str("the view or grid is singular"),
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
    /// Screen position, pixels (x right, y down, z depth growing away from the viewer).
    pub position: [f32; 3],
    /// [σr, σg, σb, σ]: extinction σ per world unit and σ times the straight colour.
    pub value: [f32; 4],
}

impl SlabVoxel {
    /// The most opacity per world unit taken as is; above it α counts as this (σ ≈ 13.8).
    pub const MAX_UNIT_ALPHA: f32 = 1.0 - 1e-6;

    /// Extinction and emission per world unit from a voxel's premultiplied RGBA shaded for one
    /// world unit of thickness (the shader with `sheet_distance` = `reference_distance`). `None`
    /// for a transparent (or NaN) voxel.
    pub fn from_unit_rgba(position: [f32; 3], rgba: [f32; 4]) -> Option<SlabVoxel> {
        if !(rgba[3] > 0.0) {
            return None;
        }
        let a = rgba[3].min(Self::MAX_UNIT_ALPHA);
        let sigma = -math::ln(1.0 - a);
        let k = sigma / a;
        Some(SlabVoxel {
            position,
            value: [
                rgba[0].max(0.0) * k,
                rgba[1].max(0.0) * k,
                rgba[2].max(0.0) * k,
                sigma,
            ],
        })
    }
}

/// One orthographic frame's slab geometry (see the module docs for the derivation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabSetup {
    size: [usize; 2],
    origin: Vec3,
    columns: [Vec3; 3],
    /// ρ² = qxx·dx² + 2·qxy·dx·dy + qyy·dy².
    q: [f32; 3],
    /// z* = shear[0]·dx + shear[1]·dy.
    shear: [f32; 2],
    /// |d| / R: chord units per pixel of depth.
    kappa: f32,
    /// Half extents of the ρ² < 1 ellipse, pixels.
    half: [f32; 2],
    /// Depth half-extent of the kernel, pixels.
    z_reach: f32,
    /// Front of slab 0 and the slab thickness, pixels of depth.
    z0: f32,
    thickness: f32,
    count: usize,
    /// |G·d| / (|d|·R²): a section's weight per unit of table difference.
    scale: f32,
    /// The thickness asked for, voxel spacings.
    spacings: f32,
}

impl SlabSetup {
    /// Slabs `thickness` smallest-grid-spacings thick for `frame` (orthographic), cutting
    /// `kernel` (a Gaussian).
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
        Ok(SlabSetup {
            size: frame.size,
            origin: frame.origin,
            columns: [m.col(0), m.col(1), m.col(2)],
            q,
            shear: [a, b],
            kappa: dl / r,
            half,
            z_reach,
            z0,
            thickness: t,
            count: (math::floor(needed) as usize + 1).max(1),
            scale: world_per_z / (dl * r2),
            spacings: thickness,
        })
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

    /// Slab thickness as asked, in smallest grid spacings (world units ÷ the smallest spacing).
    pub fn thickness_spacings(&self) -> f32 {
        self.spacings
    }

    /// Screen position (pixels, z depth) of grid point `index`.
    #[inline]
    pub fn position(&self, index: [usize; 3]) -> [f32; 3] {
        let [c0, c1, c2] = self.columns;
        let p = self.origin + c0 * index[0] as f32 + c1 * index[1] as f32 + c2 * index[2] as f32;
        p.to_array()
    }

    /// The first and last slab a kernel centred at depth `z` (pixels) overlaps, clamped to the
    /// frame's slabs.
    #[inline]
    pub fn slabs_of(&self, z: f32) -> (usize, usize) {
        let last = (self.count - 1) as f32;
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
        let h = self.size[1] as f32;
        let lo = math::ceil(y - self.half[1] - 0.5).max(0.0).min(h);
        let hi = (math::floor(y + self.half[1] - 0.5) + 1.0).max(0.0).min(h);
        lo as usize..(hi as usize).max(lo as usize)
    }
}

/// Renders slabs into caller-owned buffers, float only. Like
/// [`SheetRenderer`](super::SheetRenderer) it may own a band of image rows only, and each pixel
/// receives the same additions in the same order whatever the band, so bands put together are
/// bit-identical to one whole-image render.
pub struct SlabRenderer<'a, const R: usize, const T: usize> {
    setup: &'a SlabSetup,
    table: &'a SectionTable<R, T>,
    order: Order,
    band: (usize, usize),
    buffers: RenderBuffers<'a>,
    background: Option<&'a [[f32; 4]]>,
    stats: RenderStats,
}

impl<'a, const R: usize, const T: usize> SlabRenderer<'a, R, T> {
    /// Starts a frame over image rows `rows` (`0..height` for the whole image): `buffers` (and
    /// `background`) hold `rows.len()` rows. `order` says which end the caller starts from:
    /// front to back means slab 0 first. `background` as for sheets (the starting image back to
    /// front, composited under the result front to back).
    pub fn with_band(
        setup: &'a SlabSetup,
        table: &'a SectionTable<R, T>,
        order: Order,
        buffers: RenderBuffers<'a>,
        background: Option<&'a [[f32; 4]]>,
        rows: core::ops::Range<usize>,
    ) -> Result<Self, RenderError> {
        let [w, h] = setup.size;
        if rows.start > rows.end || rows.end > h {
            return Err(RenderError::Band {
                start: rows.start,
                end: rows.end,
                height: h,
            });
        }
        let n = w * rows.len();
        for len in [
            buffers.accumulator.len(),
            buffers.image.len(),
            background.map_or(n, <[_]>::len),
        ] {
            if len < n {
                return Err(BufferError::TooSmall {
                    needed: n,
                    got: len,
                }
                .into());
            }
        }
        if buffers.rows.len() < rows.len() {
            return Err(BufferError::TooSmall {
                needed: rows.len(),
                got: buffers.rows.len(),
            }
            .into());
        }
        let r = SlabRenderer {
            setup,
            table,
            order,
            band: (rows.start, rows.len()),
            buffers,
            background,
            stats: RenderStats::default(),
        };
        match (order, background) {
            (Order::BackToFront, Some(bg)) => r.buffers.image[..n].copy_from_slice(&bg[..n]),
            _ => r.buffers.image[..n].fill([0.0; 4]),
        }
        r.buffers.rows[..rows.len()].fill(RowSpan::EMPTY);
        Ok(r)
    }

    /// Counts so far (`sheets` counts slabs).
    pub fn stats(&self) -> RenderStats {
        self.stats
    }

    /// Adds the section of `voxel`'s kernel inside slab `slab` to the slab accumulator (nothing
    /// if the kernel misses the slab or the band).
    pub fn splat_section(&mut self, slab: usize, voxel: &SlabVoxel) {
        let s = self.setup;
        let [cx, cy, cz] = voxel.position;
        let rows = s.rows_of(cy);
        let (b0, bn) = self.band;
        let (y0, y1) = (rows.start.max(b0), rows.end.min(b0 + bn));
        if y0 >= y1 || slab >= s.count {
            return;
        }
        self.stats.voxels += 1;
        let w = s.size[0];
        let value = voxel.value.map(|c| c * s.scale);
        let [qxx, qxy, qyy] = s.q;
        // Chord coordinate of the slab's front at the voxel's own pixel offset (0, 0).
        let za = s.front(slab) - cz;
        let ta0 = s.kappa * za;
        let dt = s.kappa * s.thickness;
        let (ka, kb) = (s.kappa * s.shear[0], s.kappa * s.shear[1]);
        let mut updates = 0u64;
        for y in y0..y1 {
            let dy = y as f32 + 0.5 - cy;
            let disc = qxx - (qxx * qyy - qxy * qxy) * dy * dy;
            if !(disc > 0.0) {
                continue;
            }
            let root = math::sqrt(disc);
            let lo = cx + (-qxy * dy - root) / qxx - 0.5;
            let hi = cx + (-qxy * dy + root) / qxx - 0.5;
            let x0 = math::ceil(lo).max(0.0).min(w as f32) as usize;
            let x1 = ((math::floor(hi) + 1.0).max(0.0).min(w as f32) as usize).max(x0);
            if x0 >= x1 {
                continue;
            }
            let row = &mut self.buffers.accumulator[(y - b0) * w..(y - b0 + 1) * w];
            let ta_row = ta0 - kb * dy;
            let mut touched = false;
            for (x, px) in row[x0..x1].iter_mut().enumerate() {
                let dx = (x + x0) as f32 + 0.5 - cx;
                let rho2 = (qxx * dx + 2.0 * qxy * dy) * dx + qyy * dy * dy;
                let ta = ta_row - ka * dx;
                let g = self.table.section(rho2, ta, ta + dt);
                if g != 0.0 {
                    for (p, v) in px.iter_mut().zip(&value) {
                        *p += v * g;
                    }
                    touched = true;
                }
            }
            if touched {
                self.buffers.rows[y - b0].include(x0, x1 - 1);
                updates += (x1 - x0) as u64;
            }
        }
        self.stats.pixel_updates += updates;
        self.stats.voxels_splatted += u64::from(updates > 0);
    }

    /// Splats every voxel of `voxels` into slab `slab`, then composites it.
    pub fn render_slab<'v>(
        &mut self,
        slab: usize,
        voxels: impl IntoIterator<Item = &'v SlabVoxel>,
    ) {
        for v in voxels {
            self.splat_section(slab, v);
        }
        self.composite_slab();
    }

    /// Composites the accumulated slab (opacity 1 − e^(−τ), colour E·(1 − e^(−τ))/τ) into the
    /// image over the rows it touched, and clears what it used.
    pub fn composite_slab(&mut self) {
        let w = self.setup.size[0];
        let order = self.order;
        let (acc, img) = (&mut *self.buffers.accumulator, &mut *self.buffers.image);
        for (y, span) in self.buffers.rows[..self.band.1].iter_mut().enumerate() {
            if span.is_empty() {
                continue;
            }
            let (lo, hi) = (y * w + span.lo as usize, y * w + span.hi as usize + 1);
            for (a, i) in acc[lo..hi].iter_mut().zip(&mut img[lo..hi]) {
                let layer = slab_layer(*a);
                *a = [0.0; 4];
                *i = match order {
                    Order::BackToFront => over(layer, *i),
                    Order::FrontToBack => over(*i, layer),
                };
            }
            self.stats.pixels_composited += u64::from(span.hi - span.lo + 1);
            *span = RowSpan::EMPTY;
        }
        self.stats.sheets += 1;
    }

    /// Ends the frame (front to back: composites the background under the result); returns
    /// the counts.
    pub fn finish(self) -> RenderStats {
        if let (Order::FrontToBack, Some(bg)) = (self.order, self.background) {
            let n = self.setup.size[0] * self.band.1;
            float_over_row(&mut self.buffers.image[..n], &bg[..n]);
        }
        self.stats
    }
}

/// A slab's accumulated [E, τ] as a premultiplied layer: α = 1 − e^(−τ), colour E·α/τ.
#[inline]
pub fn slab_layer(acc: [f32; 4]) -> [f32; 4] {
    // max, not clamp: NaN becomes 0.
    let tau = acc[3].max(0.0);
    let (alpha, k) = if tau > 1e-3 {
        let alpha = 1.0 - math::exp(-tau);
        (alpha, alpha / tau)
    } else {
        // Series to τ³: relative error < τ³/24 < 5·10⁻¹¹.
        let k = 1.0 - tau * (0.5 - tau / 6.0);
        (tau * k, k)
    };
    [
        acc[0].max(0.0) * k,
        acc[1].max(0.0) * k,
        acc[2].max(0.0) * k,
        alpha,
    ]
}
