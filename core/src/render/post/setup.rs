//! What a post-classified frame sets up once: the kernel's weight table, the slab geometry at the
//! image's and at the values' resolution, and the classifier.

use super::super::slabs::{SlabError, SlabSetup};
use crate::frame::FrameSetup;
use crate::kernel::Kernel;
use crate::math;
use crate::shade::{Lighting, OpacityTable, Shader};
use glam::{Mat3, Vec3};

/// Nodes of the weight table the harness uses: linear interpolation of exp(−s²r²/2) with
/// 1 024 intervals is within 1.2·10⁻⁶ of the peak for s ≤ 4 (h²/8 · (s²/2)²).
pub const WEIGHT_NODES: usize = 1025;

/// The most a frame's values may be subsampled ([`PostSetup::with_value_scale`]).
pub const MAX_VALUE_SCALE: usize = 64;

/// The Gaussian's weight over r² ∈ [0, 1] (r in kernel radii): h(r²) = exp(−s²r²/2), `N` nodes
/// evenly spaced in r², read with linear interpolation; zero from r² = 1 on (the kernel's support
/// is the open ball).
#[derive(Clone, Debug)]
pub struct WeightTable<const N: usize> {
    nodes: [f32; N],
}

impl<const N: usize> WeightTable<N> {
    /// The table of `kernel` (a Gaussian; `N` ≥ 2).
    pub fn new(kernel: &Kernel) -> Result<Self, SlabError> {
        let Kernel::Gaussian { sigmas, .. } = *kernel else {
            return Err(crate::table::SectionError::NotAVolumeKernel.into());
        };
        if N < 2 {
            return Err(SlabError::Singular);
        }
        let k = 0.5 * sigmas * sigmas;
        let mut nodes = [0.0f32; N];
        for (i, n) in nodes.iter_mut().enumerate() {
            *n = math::exp(-k * i as f32 / (N - 1) as f32);
        }
        Ok(WeightTable { nodes })
    }

    /// h(r²) for r² ≥ 0; zero for r² ≥ 1 (or NaN).
    #[inline]
    pub fn at(&self, r2: f32) -> f32 {
        if !(r2 < 1.0) {
            return 0.0;
        }
        let x = r2 * (N - 1) as f32;
        let i = (x as usize).min(N - 2);
        let f = x - i as f32;
        let (a, b) = (self.nodes[i], self.nodes[i + 1]);
        a + f * (b - a)
    }
}

/// Turns a normalised slab sample into a premultiplied layer.
pub trait Classify {
    /// Whether [`Classify::layer`] reads the gradient (else voxels' gradients are not splatted).
    fn needs_gradient(&self) -> bool;
    /// A value at or below which every layer is transparent, whatever its gradient (−∞ if none
    /// is known): such samples are not classified.
    fn transparent_at_or_below(&self) -> f32;
    /// The premultiplied RGBA of a layer whose samples have `value` and world `gradient`, held
    /// over `fraction` ∈ (0, 1] of the slab's chord (one except where the ray enters or leaves
    /// the voxel box inside the slab); `index` is the grid voxel nearest the sample.
    fn layer(&self, value: f32, gradient: Vec3, index: [usize; 3], fraction: f32) -> [f32; 4];
    /// The premultiplied RGBA of a pixel whose ray projects to `value` (a [`super::Blend`] other
    /// than compositing): one classification for the whole ray, unshaded.
    fn projection(&self, value: f32) -> [f32; 4];
}

/// The renderer's classifier: a [`Shader`] at opacity per world unit, held over the slab's chord
/// (see the module docs); the full chord's opacity correction comes from an [`OpacityTable`].
#[derive(Clone, Copy, Debug)]
pub struct ShadedLayers<'a> {
    shader: Shader<'a>,
    /// Opacity corrected to the full chord.
    lighting: Lighting,
    table: OpacityTable<'a>,
    chord: f32,
    clear: f32,
    dims: [usize; 3],
}

impl<'a> ShadedLayers<'a> {
    /// `shader` for `frame`'s slabs of `setup`, the opacity correction tabulated in `table`
    /// (at least 2 entries; [`crate::shade::OPACITY_TABLE_LEN`] recommended).
    pub fn new(
        frame: &FrameSetup,
        setup: &PostSetup,
        shader: Shader<'a>,
        table: &'a mut [f32],
    ) -> Result<Self, crate::splat::BufferError> {
        let chord = setup.full.chord;
        let lighting = Lighting::per_world_unit(frame).with_opacity_exponent(chord);
        let table = OpacityTable::build(&lighting, table)?;
        Ok(ShadedLayers {
            shader,
            lighting,
            table,
            chord,
            clear: shader.transparent_at_or_below(),
            dims: frame.dims,
        })
    }
}

impl Classify for ShadedLayers<'_> {
    fn needs_gradient(&self) -> bool {
        self.shader.shading.needs_gradient()
    }

    fn transparent_at_or_below(&self) -> f32 {
        self.clear
    }

    #[inline]
    fn layer(&self, value: f32, gradient: Vec3, index: [usize; 3], fraction: f32) -> [f32; 4] {
        // The full chord's correction from the table; a part of it computed exactly.
        let (lighting, table) = if fraction == 1.0 {
            (self.lighting, Some(&self.table))
        } else {
            (
                self.lighting.with_opacity_exponent(self.chord * fraction),
                None,
            )
        };
        self.shader
            .shade_with(&lighting, table, value, || gradient, index, self.dims)
    }

    /// The transfer function's colour and opacity at `value`, premultiplied
    /// ([`crate::shade::TransferFunction::pixel`]).
    fn projection(&self, value: f32) -> [f32; 4] {
        self.shader.pixel(value)
    }
}

/// One orthographic frame's post-classified slabs: [`SlabSetup`]'s geometry at the image's size
/// and at the values' (1/`scale` of it), and the map back to grid coordinates (to keep samples
/// inside the voxel box).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PostSetup {
    pub(super) full: SlabSetup,
    pub(super) low: SlabSetup,
    pub(super) scale: usize,
    /// Screen (pixels, depth) → grid coordinates: g = to_grid·(s − origin).
    pub(super) to_grid: Mat3,
    origin: Vec3,
    /// The sample box per axis, grid coordinates: [0, dims − 1], or [−½, ½] along an axis one
    /// voxel thick (see [`sample_box`]).
    bottom: [f32; 3],
    top: [f32; 3],
    /// Largest grid index per axis (dims − 1).
    last: [usize; 3],
    /// How values are reconstructed between voxels.
    pub(super) reconstruction: PostReconstruction,
    /// Radius of the ball holding the reconstruction's support, grid steps.
    radius: f32,
}

/// How a post-classified frame reconstructs the values (and gradients) between voxels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PostReconstruction {
    /// The Gaussian kernel, read from a [`WeightTable`] (the default; the continuous reference's
    /// `kernel` reconstruction).
    #[default]
    Kernel,
    /// Trilinear interpolation, as VTK's, ParaView's and 3D Slicer's ray casters reconstruct:
    /// each voxel splats its tent Π(1 − |qₐ|)₊ (q its grid offset from the sample), which is its
    /// trilinear basis function, so the samples are the trilinear interpolant exactly
    /// (`core/src/render/post/tent.rs`).
    Trilinear,
}

/// Where post-classified samples exist along each axis of a grid of `dims` voxels, grid
/// coordinates: the voxel centres' extent [0, dims − 1], except along an axis one voxel thick,
/// where that extent has no depth: there the box is the voxel's own cell, [−½, ½], one grid step
/// deep, as deep as two voxels' extent (and as much as a pre-classified voxel's footprint
/// integrates). The continuous reference uses the same box.
pub fn sample_box(dims: [usize; 3]) -> ([f32; 3], [f32; 3]) {
    sample_box_of([0; 3], dims.map(|d| d.saturating_sub(1)))
}

/// [`sample_box`] of the voxels `first..=last` along each axis (a crop of the grid, whole-grid
/// indices): [first, last], or the voxel's own cell [first − ½, first + ½] along an axis one
/// voxel thick.
pub fn sample_box_of(first: [usize; 3], last: [usize; 3]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [0.0f32; 3];
    let mut hi = [0.0f32; 3];
    for a in 0..3 {
        let (f, l) = (first[a] as f32, last[a].max(first[a]) as f32);
        (lo[a], hi[a]) = if l > f { (f, l) } else { (f - 0.5, f + 0.5) };
    }
    (lo, hi)
}

impl PostSetup {
    /// Slabs `thickness` smallest grid spacings thick for `frame` (orthographic), `kernel` a
    /// Gaussian, values at the image's size. Errors as [`SlabSetup::new`].
    ///
    /// Slabs must be thinner than the sample box is deep along the view
    /// ([`SlabError::ThickerThanVolume`]): slabs are cut from the box's centre, so then the two
    /// mid-planes beside the centre lie inside the box's depth range.
    pub fn new(frame: &FrameSetup, kernel: &Kernel, thickness: f32) -> Result<Self, SlabError> {
        let slab = SlabSetup::new(frame, kernel, thickness)?;
        let (bottom, top) = sample_box(frame.dims);
        let z = frame.grid_to_screen.row(2);
        let depth: f32 = (0..3).map(|a| z[a].abs() * (top[a] - bottom[a])).sum();
        if !(slab.thickness < depth) {
            return Err(SlabError::ThickerThanVolume {
                thickness,
                depth: depth / slab.thickness * thickness,
            });
        }
        Ok(PostSetup {
            full: slab,
            low: slab,
            scale: 1,
            to_grid: frame.grid_to_screen.inverse(),
            origin: frame.origin,
            bottom: sample_box(frame.dims).0,
            top: sample_box(frame.dims).1,
            last: frame.dims.map(|d| d.saturating_sub(1)),
            reconstruction: PostReconstruction::Kernel,
            radius: kernel.spread(),
        })
    }

    /// Slabs `thickness` smallest grid spacings thick for `frame` (orthographic) whose values are
    /// reconstructed trilinearly ([`PostReconstruction::Trilinear`]). The slab geometry (rows,
    /// slabs and ring a voxel reaches) is that of the ball of radius √3 that holds the tent's
    /// support, the cube |qₐ| < 1: a bound the renderer then cuts exactly, per slab and row.
    /// Errors as [`PostSetup::new`].
    pub fn trilinear(frame: &FrameSetup, thickness: f32) -> Result<Self, SlabError> {
        let setup = PostSetup::new(frame, &tent_bound(), thickness)?;
        Ok(PostSetup {
            reconstruction: PostReconstruction::Trilinear,
            ..setup
        })
    }

    /// How this frame reconstructs its values.
    pub fn reconstruction(&self) -> PostReconstruction {
        self.reconstruction
    }

    /// Radius of the ball that holds the reconstruction's support, grid steps: the kernel's R,
    /// or [`tent_bound`]'s for trilinear. A sample reads only voxels within it.
    pub fn support_radius(&self) -> f32 {
        self.radius
    }

    /// The same slabs with samples only inside the box of voxels `first..=last` (whole-grid
    /// indices, [`sample_box_of`]) instead of the whole grid's: what a cropped volume's samples
    /// are (the rest of the grid is missing).
    pub fn with_sample_box(self, first: [usize; 3], last: [usize; 3]) -> Self {
        let (bottom, top) = sample_box_of(first, last);
        PostSetup {
            bottom,
            top,
            ..self
        }
    }

    /// The same slabs with the values (and gradients) splatted at 1/`scale` of the image size
    /// and interpolated bilinearly at each pixel before it is classified: `scale`² fewer pixel
    /// updates, classification still per pixel. `scale` in 1..=[`MAX_VALUE_SCALE`].
    pub fn with_value_scale(self, scale: usize) -> Result<Self, SlabError> {
        if !(1..=MAX_VALUE_SCALE).contains(&scale) {
            return Err(SlabError::ValueScale { scale });
        }
        Ok(PostSetup {
            low: scaled(&self.full, scale),
            scale,
            ..self
        })
    }

    /// The slab geometry at the image's size (slab count, fronts, rows).
    pub fn slabs(&self) -> &SlabSetup {
        &self.full
    }

    /// The values' subsampling factor (1: at the image's size).
    pub fn value_scale(&self) -> usize {
        self.scale
    }

    /// The slab accumulators a renderer keeps per value pixel ([`SlabSetup::ring`]).
    pub fn ring(&self) -> usize {
        self.low.ring()
    }

    /// Width and height of the value buffers (the image's size / scale, rounded up).
    pub fn value_size(&self) -> [usize; 2] {
        self.low.size
    }

    /// The kernel's shorter semi-axis on screen, image pixels: how wide the smoothest feature of
    /// the reconstructed values is (what a value scale is chosen against).
    pub fn kernel_radius_px(&self) -> f32 {
        // The ρ < 1 ellipse: semi-axes 1/√λ for the eigenvalues λ of [[qxx, qxy], [qxy, qyy]].
        let [a, b, c] = self.full.q;
        let mean = 0.5 * (a + c);
        let dev = math::sqrt(0.25 * (a - c) * (a - c) + b * b);
        1.0 / math::sqrt(mean + dev)
    }

    /// The value rows a band of image rows `rows` reads (its pixels interpolate between the two
    /// value rows around them; a row that would be weighed by zero is left out), clamped to the
    /// value buffer. At scale 1, `rows` itself.
    pub fn value_rows(&self, rows: core::ops::Range<usize>) -> core::ops::Range<usize> {
        if rows.is_empty() {
            return 0..0;
        }
        let lh = self.low.size[1] as i64;
        let a = cell_of(rows.start, self.scale).0.clamp(0, lh);
        let (last, f) = cell_of(rows.end - 1, self.scale);
        let b = (last + 1 + i64::from(f > 0.0)).clamp(0, lh);
        a as usize..(b as usize).max(a as usize)
    }

    /// The part of slab `slab`'s depth range that pixel (x, y)'s ray spends inside the voxel box,
    /// as a fraction of the slab, and the grid voxel nearest its mid-plane sample.
    #[inline]
    pub(super) fn inside(&self, x: usize, y: usize, slab: usize) -> (f32, [usize; 3]) {
        let s = &self.full;
        let (front, t) = (s.front(slab), s.thickness);
        let p = Vec3::new(x as f32 + 0.5, y as f32 + 0.5, front) - self.origin;
        let g0 = self.to_grid * p;
        let d = self.to_grid.col(2);
        // Depth offsets from the slab's front, in [0, t], where every grid coordinate is in range.
        let (mut lo, mut hi) = (0.0f32, t);
        for a in 0..3 {
            let (g, da, bottom, top) = (g0[a], d[a], self.bottom[a], self.top[a]);
            if da.abs() < 1e-12 {
                if !(g >= bottom && g <= top) {
                    return (0.0, [0; 3]);
                }
                continue;
            }
            let (u, v) = ((bottom - g) / da, (top - g) / da);
            lo = lo.max(u.min(v));
            hi = hi.min(u.max(v));
        }
        let fraction = if hi > lo { (hi - lo) / t } else { 0.0 };
        let mid = g0 + d * (0.5 * t);
        // Rounded to the nearest voxel: the coordinate is at least −½ here, so truncation of
        // the non-negative value + ½ rounds.
        let near = |a: usize| ((mid[a] + 0.5).max(0.0) as usize).min(self.last[a]);
        (fraction.min(1.0), [near(0), near(1), near(2)])
    }
}

/// A Gaussian whose support (the ball of radius √3·(1 + 10⁻⁴) grid steps) holds the tent's cube
/// |qₐ| < 1 with room for rounding: the reach a trilinear frame's slabs and rows are found with.
pub fn tent_bound() -> Kernel {
    Kernel::Gaussian {
        spread: 1.732_051 * 1.0001,
        sigmas: 2.5,
    }
}

/// `slab`'s slabs seen at 1/`s` of the image size (every screen length, depth included,
/// divided by `s`; the size rounded up): slab j covers the same part of the volume.
fn scaled(slab: &SlabSetup, s: usize) -> SlabSetup {
    let f = s as f32;
    SlabSetup {
        size: slab.size.map(|n| n.div_ceil(s)),
        q: slab.q.map(|q| q * f * f),
        kappa: slab.kappa * f,
        half: slab.half.map(|h| h / f),
        z_reach: slab.z_reach / f,
        z0: slab.z0 / f,
        thickness: slab.thickness / f,
        ..*slab
    }
}

/// The value cell image pixel `x` (or row) lies in at value scale `s`, and where in it: value
/// pixel X's centre is at image coordinate (X + ½)·s, so pixel x's centre is at value coordinate
/// u = (x + ½)/s − ½ = X₀ + f, X₀ = ⌊u⌋ (−1 before the first centre), f ∈ [0, 1). In integers:
/// u = (2x + 1 − s)/(2s).
#[inline]
pub(super) fn cell_of(x: usize, s: usize) -> (i64, f32) {
    let (num, den) = (2 * x as i64 + 1 - s as i64, 2 * s as i64);
    let x0 = num.div_euclid(den);
    (x0, (num - x0 * den) as f32 / den as f32)
}

/// The image pixels of value cell `x0` at scale `s` (those whose [`cell_of`] is `x0`), clamped
/// to 0..`n`.
#[inline]
pub(super) fn pixels_of_cell(x0: i64, s: usize, n: usize) -> core::ops::Range<usize> {
    // x is in cell x0 iff 2s·x0 ≤ 2x + 1 − s < 2s·(x0 + 1): the cell's first pixel is
    // ⌈(2s·x0 + s − 1)/2⌉ = ⌊(2s·x0 + s)/2⌋.
    let start = |c: i64| (2 * s as i64 * c + s as i64).div_euclid(2);
    let (a, b) = (start(x0), start(x0 + 1));
    let clamp = |v: i64| v.clamp(0, n as i64) as usize;
    clamp(a)..clamp(b).max(clamp(a))
}
