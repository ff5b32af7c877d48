//! The continuous field the reference marches ([`super::continuous`]): the voxels as each model
//! reads them, reconstructed between them by the kernel or trilinearly, and a block map of where
//! the field can be seen.
//!
//! - **Pre-classified** ([`Model::Pre`]): each voxel shaded once (colour and opacity per world
//!   unit, Phong with its own central-difference gradient), stored as the [`Absorption`] model
//!   reads it ([α, αr, αg, αb] or [σ, σr, σg, σb]) and reconstructed as is.
//! - **Post-classified** ([`Model::Post`]): each voxel's value and world gradient (the renderer's
//!   central differences) are reconstructed, *normalised by the weights that fall inside the
//!   volume* (so a constant field stays constant up to the faces, where the kernel's lattice sum
//!   drops below one), and classified and shaded per sample through the same shader: the sample
//!   has opacity α per world unit and premultiplied colour, marched as [α, αr, αg, αb] (light
//!   keeps (1 − α)^dl). This is what ray casters such as VTK's compute (they interpolate
//!   gradients the same way). Samples only exist inside the voxel box (the grid's own extent:
//!   nothing is extrapolated past its faces; along an axis one voxel thick, that voxel's cell,
//!   one grid step deep); a NaN value is a missing sample (weight zero) and a sample whose
//!   weights are all missing is transparent. A rectilinear grid warps the field's argument
//!   (`super::warp`, which the march applies): the field itself is the uniform one's.

use super::sparse::{dilate, SparseGrid};
use crate::CliError;
use footprint::frame::FrameSetup;
use footprint::render::{gradient, Blend, ShadeCache, ShadeCacheEntry, SheetRing, SHADE_CACHE_LEN};
use footprint::shade::{Lighting, Shader};
use footprint::Kernel;
use glam::{DVec3, Vec3};

/// How the continuous field is reconstructed from the voxels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reconstruction {
    /// The renderer's kernel (Gaussian only).
    Kernel,
    /// Trilinear interpolation of the pre-classified voxels.
    Trilinear,
}

impl Reconstruction {
    /// The name `--reconstruction` and the JSON use.
    pub fn name(self) -> &'static str {
        match self {
            Reconstruction::Kernel => "kernel",
            Reconstruction::Trilinear => "trilinear",
        }
    }
}

/// Which quantity the field reconstructs between voxels (see [`super::continuous`]): the core's
/// model, so the reference and both slicings read the same field.
pub use footprint::render::Absorption;

/// What the continuous reference renders.
pub struct ContinuousScene<'a> {
    pub frame: &'a FrameSetup,
    pub kernel: &'a Kernel,
    pub shader: Shader<'a>,
    pub background: Option<&'a [[f32; 4]]>,
    pub reconstruction: Reconstruction,
    /// Pre-classified in an absorption model, or post-classified ([`super::field`]).
    pub model: Model,
    /// The least transmittance per world unit a voxel keeps in the extinction model (its opacity
    /// is capped at 1 − `cap`): [`DEFAULT_CAP`], the renderer's. The opacity model has no cap and
    /// ignores it (`tests/continuous.rs` moves it from 10⁻⁴ to 10⁻⁹ and checks that).
    pub cap: f64,
    /// Worker threads the march spreads its rays over (at least 1; each ray is marched by one
    /// thread alone, so the image is the same for every count).
    pub threads: usize,
    /// `--clip`: the field is integrated inside every plane's half-space only (one interval of
    /// each ray: the kept region is convex); each plane in the frame's grid, (m, e) with
    /// m·g ≤ e kept (`crate::scene::ClipPlane::in_grid`).
    pub clip: Vec<([f64; 3], f64)>,
    /// Post-classified and projected: samples exist among voxels `first..=last` per axis (a
    /// crop; `footprint::render::post::sample_box_of`), or the whole grid's (`None`).
    pub samples: Option<([usize; 3], [usize; 3])>,
    /// A rectilinear grid's map from the frame's grid to sample indices.
    pub grid: Option<super::warp::Warp>,
}

/// [`ContinuousScene::cap`] as the renderer takes it: 1 − `SlabVoxel::MAX_UNIT_ALPHA` = 10⁻⁶.
pub const DEFAULT_CAP: f64 = 1e-6;

/// Voxels per block side of the empty-space map, the sparse grid's blocks.
const BLOCK: usize = super::sparse::SIDE;

/// Which continuous integral the field defines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    /// Pre-classified voxels, reconstructed as the absorption model says.
    Pre(Absorption),
    /// Values and gradients reconstructed, then classified per sample.
    Post,
    /// Values reconstructed as for [`Model::Post`], projected along each ray and the projection
    /// classified (`footprint::render::post::Blend`, never `Composite`; `super::projection`).
    Projection(Blend),
}

impl Model {
    /// The name the JSON uses: `opacity`, `extinction` or `post-classified`.
    pub fn name(self) -> &'static str {
        match self {
            Model::Pre(a) => a.name(),
            Model::Post => "post-classified",
            Model::Projection(b) => b.name(),
        }
    }
}

/// Per-axis Gaussian factors and squared offsets of one sample, axis a at `[a·n ..][..n]`.
pub(super) struct Taps {
    n: usize,
    e: Vec<f64>,
    d2: Vec<f64>,
}

/// The voxels as the model reads them, in blocks allocated where a voxel is stored, and the
/// block map.
pub(super) struct Field<'s> {
    dims: [usize; 3],
    /// Pre: [α, αr, αg, αb] or [σ, σr, σg, σb], only those that can be seen (an absent voxel is
    /// transparent); post: [value, gx, gy, gz] (world gradient), every voxel.
    voxels: SparseGrid,
    model: Model,
    /// Post: the shader and lighting that classify each sample.
    classify: Option<(Shader<'s>, Lighting)>,
    /// Whether a block's neighbourhood (its voxels ± the reconstruction's reach) can be seen.
    active: Vec<bool>,
    blocks: [usize; 3],
    /// Reach of the reconstruction, grid steps (R for the kernel, 1 for trilinear).
    reach: f64,
    /// The kernel's (R, k = sigmas² / (2R²), exp(−2k), 1 / (R³ ∫h)): its factor at offset d
    /// is exp(−k·d²).
    kernel: Option<(f64, f64, f64, f64)>,
    /// Post-classified and projected: the box samples exist in, grid coordinates.
    sample_box: ([f32; 3], [f32; 3]),
}

impl<'s> Field<'s> {
    pub(super) fn new(
        scene: &ContinuousScene<'s>,
        sheet: &mut dyn FnMut(usize, &mut [f32]),
    ) -> Result<Self, CliError> {
        // The reconstruction first: a kernel it cannot use is refused before any sheet is read.
        let (reach, kernel) = reconstruction(scene)?;
        let f = scene.frame;
        let dims = f.dims;
        let n = dims.iter().product::<usize>();
        // Post-classification stores every voxel; the pre-classified models only those seen.
        let mut voxels = SparseGrid::new(dims).ok_or_else(|| {
            CliError::input(format!(
                "cannot allocate the continuous reference's {n} voxels"
            ))
        })?;
        // Opacity per world unit: the shader at an exponent of one.
        let lighting = Lighting::per_world_unit(f);
        let (len, na, nb) = f.sheet_shape();
        // Each sheet read once, through a ring of three: a sheet's window is complete once the
        // next is in.
        let mut storage = vec![0.0f32; 3 * len];
        let mut ring = SheetRing::new(&mut storage, f, f.order_for_ascending())?;
        // A voxel that can be seen: pre, any opacity; post, a value above every transparent one
        // (a sample is a convex combination of its neighbours' values, so a block whose
        // neighbourhood stays at or below that bound is transparent throughout). Pre-classified
        // voxels at or below it are transparent whatever their gradient: not shaded at all.
        let clear = scene.shader.transparent_at_or_below();
        let seen = |v: &[f32; 4]| match scene.model {
            Model::Pre(_) => v[0] > 0.0,
            Model::Post => !(v[0] <= clear),
            Model::Projection(_) => v[0].is_finite(),
        };
        // The blocks holding a voxel that can be seen (dilated below by the reconstruction's
        // reach into the blocks it can be seen from).
        let blocks = voxels.count();
        let mut holds = vec![false; blocks.iter().product()];
        // Emission shades a voxel by its value alone (the sheets carry values, no colours), so
        // each distinct value is shaded once, as the renderer's own classification does: the
        // same bits (`ShadeCache`; the blobs' 256³ field build was 13 % of a fresh default frame
        // by `perf`, most of it shading).
        let mut shades = vec![ShadeCacheEntry::default(); SHADE_CACHE_LEN];
        let mut memo = ShadeCache::new(&scene.shader, &mut shades);
        let mut store = |ring: &SheetRing<'_, f32>, n: usize| {
            let (s, window) = (ring.sheet_index(n), ring.window(n));
            let pre = matches!(scene.model, Model::Pre(_));
            for v in 0..nb {
                let row = &window.current[v * na..][..na];
                // Pre-classified, a row whose every value is transparent stores nothing: one
                // count the compiler vectorises instead of a branch per voxel (most rows of a
                // scan's background).
                if pre && row.iter().filter(|&&x| !(x <= clear)).count() == 0 {
                    continue;
                }
                for (u, &value) in row.iter().enumerate() {
                    if pre && value <= clear {
                        continue;
                    }
                    let idx = f.grid_index(s, u, v);
                    // Central differences; a rectilinear grid's non-uniform ones.
                    let grad = |u, v, idx| {
                        let g = gradient(f, &window, u, v);
                        scene.grid.as_ref().map_or(g, |w| w.gradient(f, g, idx))
                    };
                    let stored = match scene.model {
                        Model::Pre(absorption) => {
                            let rgba = ShadeCache::shade(memo.as_mut(), value, false, || {
                                scene
                                    .shader
                                    .shade(&lighting, value, || grad(u, v, idx), idx, dims)
                            });
                            pre_classified(rgba, absorption, scene.cap)
                        }
                        Model::Post => {
                            let g = grad(u, v, idx);
                            Some([value, g.x, g.y, g.z])
                        }
                        Model::Projection(_) => Some([value, 0.0, 0.0, 0.0]),
                    };
                    if let Some(v) = stored {
                        voxels.set(idx, v);
                        if seen(&v) {
                            let b = idx.map(|c| c / BLOCK);
                            holds[(b[2] * blocks[1] + b[1]) * blocks[0] + b[0]] = true;
                        }
                    }
                }
            }
        };
        for s in 0..f.sheet_count() {
            let done = ring.push_with(|slot| {
                sheet(s, slot);
                Ok::<_, footprint::render::RenderError>(())
            })?;
            if let Some(n) = done {
                store(&ring, n);
            }
        }
        if let Some(n) = ring.last() {
            store(&ring, n);
        }
        // A voxel at x is read by samples within `reach` of it, so it makes the blocks of
        // x ± pad active: every block within ⌈pad / BLOCK⌉ blocks of one that holds it (a
        // superset, which only costs the march a few more looks at zero voxels).
        let pad = reach.ceil() as usize + 1;
        let active = dilate(&holds, blocks, pad.div_ceil(BLOCK));
        Ok(Field {
            dims,
            voxels,
            model: scene.model,
            classify: (scene.model == Model::Post).then_some((scene.shader, lighting)),
            active,
            blocks,
            reach,
            kernel,
            sample_box: match scene.samples {
                Some((first, last)) => footprint::render::post::sample_box_of(first, last),
                None => footprint::render::post::sample_box(dims),
            },
        })
    }

    /// Where the field can be non-zero, grid coordinates (lowest, highest per axis): the voxel
    /// box grown by the reconstruction's reach for pre-classified voxels; for
    /// post-classification the box samples exist in, the grid's own extent (one grid step deep,
    /// the voxel's cell, along an axis one voxel thick: `footprint::render::post::sample_box`,
    /// which the renderer uses too).
    pub(super) fn bounds(&self) -> (DVec3, DVec3) {
        match self.model {
            Model::Pre(_) => (
                DVec3::splat(-self.reach),
                DVec3::from_array(self.dims.map(|d| (d - 1) as f64 + self.reach)),
            ),
            Model::Post | Model::Projection(_) => {
                let (lo, hi) = self.sample_box;
                (
                    DVec3::from_array(lo.map(f64::from)),
                    DVec3::from_array(hi.map(f64::from)),
                )
            }
        }
    }

    /// How a marched step attenuates: extinction for the extinction model, else opacity.
    pub(super) fn absorption(&self) -> Absorption {
        match self.model {
            Model::Pre(a) => a,
            Model::Post | Model::Projection(_) => Absorption::Opacity,
        }
    }

    /// The projection this field's rays take, if it is one ([`Model::Projection`]).
    pub(super) fn projection(&self) -> Option<Blend> {
        match self.model {
            Model::Projection(b) => Some(b),
            _ => None,
        }
    }

    /// Whether the block of grid point `g` can hold a non-zero field (its neighbourhood holds a
    /// voxel that can be seen).
    #[inline]
    fn active_at(&self, g: DVec3) -> bool {
        let b = [g.x, g.y, g.z].map(|c| (c.max(0.0) as usize) / BLOCK);
        let bi = (b[2].min(self.blocks[2] - 1) * self.blocks[1] + b[1].min(self.blocks[1] - 1))
            * self.blocks[0]
            + b[0].min(self.blocks[0] - 1);
        self.active[bi]
    }

    /// The normalised reconstruction of the values at grid point `g`: Σw·f / Σw over the finite
    /// samples, a convex combination of them; `None` where no finite sample has a weight.
    #[inline]
    pub(super) fn value_at(&self, g: DVec3, taps: &mut Taps) -> Option<f64> {
        if !self.active_at(g) {
            return None;
        }
        let (mut total, mut sum) = (0.0f64, 0.0f64);
        self.weights(g, taps, |v, w| {
            if v[0].is_finite() {
                total += w;
                sum += w * f64::from(v[0]);
            }
        });
        (total > 0.0).then(|| sum / total)
    }

    /// Scratch for [`Field::at`]'s per-axis kernel factors, sized for this field's kernel (one
    /// per thread, reused for every sample).
    pub(super) fn taps(&self) -> Taps {
        // Lattice offsets within R of a point: at most ⌊2R⌋ + 1 per axis; one spare.
        let n = (2.0 * self.reach).floor() as usize + 2;
        Taps {
            n,
            e: vec![0.0; 3 * n],
            d2: vec![0.0; 3 * n],
        }
    }

    /// [σ, σr, σg, σb] (extinction) or [α, αr, αg, αb] (opacity, post-classified) at grid point
    /// `g` (continuous index coordinates).
    #[inline]
    pub(super) fn at(&self, g: DVec3, taps: &mut Taps) -> [f64; 4] {
        if !self.active_at(g) {
            return [0.0; 4];
        }
        let mut out = [0.0f64; 4];
        let Some((shader, lighting)) = &self.classify else {
            self.weights(g, taps, |v, w| {
                if v[0] > 0.0 {
                    for ch in 0..4 {
                        out[ch] += w * f64::from(v[ch]);
                    }
                }
            });
            return out;
        };
        let mut total = 0.0f64;
        self.weights(g, taps, |v, w| {
            if v[0].is_finite() {
                total += w;
                for ch in 0..4 {
                    out[ch] += w * f64::from(v[ch]);
                }
            }
        });
        if !(total > 0.0) {
            return [0.0; 4];
        }
        let [value, gx, gy, gz] = out.map(|c| (c / total) as f32);
        let nearest = [g.x, g.y, g.z]
            .map(|c| c.round().max(0.0) as usize)
            .iter()
            .zip(self.dims)
            .map(|(&c, d)| c.min(d - 1))
            .collect::<Vec<_>>();
        let rgba = shader.shade(
            lighting,
            value,
            || Vec3::new(gx, gy, gz),
            [nearest[0], nearest[1], nearest[2]],
            self.dims,
        );
        [rgba[3], rgba[0], rgba[1], rgba[2]].map(f64::from)
    }

    /// Calls `visit(voxel, weight)` for every voxel of the volume whose reconstruction weight at
    /// `g` is above zero (trilinear, or the kernel with its lattice normalisation).
    #[inline]
    fn weights(&self, g: DVec3, taps: &mut Taps, mut visit: impl FnMut(&[f32; 4], f64)) {
        let d = self.dims;
        let voxel = |x: i64, y: i64, z: i64| -> Option<&[f32; 4]> {
            if x < 0 || y < 0 || z < 0 || x >= d[0] as i64 || y >= d[1] as i64 || z >= d[2] as i64 {
                return None;
            }
            self.voxels.get(x as usize, y as usize, z as usize)
        };
        match self.kernel {
            None => {
                let f = [g.x.floor(), g.y.floor(), g.z.floor()];
                let t = [g.x - f[0], g.y - f[1], g.z - f[2]];
                let f = f.map(|v| v as i64);
                for c in 0..8 {
                    let o = [c & 1, (c >> 1) & 1, (c >> 2) & 1];
                    let w = (0..3)
                        .map(|a| if o[a] == 1 { t[a] } else { 1.0 - t[a] })
                        .product::<f64>();
                    if w == 0.0 {
                        continue;
                    }
                    if let Some(v) =
                        voxel(f[0] + o[0] as i64, f[1] + o[1] as i64, f[2] + o[2] as i64)
                    {
                        visit(v, w);
                    }
                }
            }
            Some((r, k, fall, norm)) => {
                // The Gaussian factors per axis (separable inside the ball), one per lattice
                // offset within R of the sample: at most `taps.n` per axis.
                let gc = [g.x, g.y, g.z];
                let lo = gc.map(|c| (c - r).ceil() as i64);
                let hi = gc.map(|c| (c + r).floor() as i64);
                let n = taps.n;
                for a in 0..3 {
                    let count = (hi[a] - lo[a] + 1).max(0) as usize;
                    let span = a * n..a * n + count;
                    let d0 = gc[a] - lo[a] as f64;
                    gaussian_taps(d0, k, fall, &mut taps.d2[span.clone()], &mut taps.e[span]);
                }
                let (e, d2) = (&taps.e, &taps.d2);
                let r2 = r * r;
                // Only the taps inside the grid: the rest have no voxel.
                let inside = |a: usize| lo[a].max(0)..=hi[a].min(d[a] as i64 - 1);
                for z in inside(2) {
                    let jz = (z - lo[2]) as usize;
                    for y in inside(1) {
                        let jy = (y - lo[1]) as usize;
                        let dyz = d2[2 * n + jz] + d2[n + jy];
                        if dyz >= r2 {
                            continue;
                        }
                        let eyz = e[2 * n + jz] * e[n + jy] * norm;
                        let row = self.voxels.row(y as usize, z as usize);
                        for x in inside(0) {
                            let jx = (x - lo[0]) as usize;
                            if dyz + d2[jx] >= r2 {
                                continue;
                            }
                            // An absent voxel is transparent: it adds nothing (pre-classified
                            // only; post-classification stores every voxel).
                            if let Some(v) = row.get(x as usize) {
                                visit(v, eyz * e[jx]);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A reconstruction's reach (grid steps) and, for the kernel, its (R, k = sigmas² / (2R²),
/// exp(−2k), 1 / (R³ ∫h)), as [`Field`] holds them.
type KernelFactors = (f64, Option<(f64, f64, f64, f64)>);

/// The reach and kernel factors of `scene`'s reconstruction; only a Gaussian reconstructs in 3D.
fn reconstruction(scene: &ContinuousScene<'_>) -> Result<KernelFactors, CliError> {
    Ok(match (scene.reconstruction, *scene.kernel) {
        (Reconstruction::Trilinear, _) => (1.0, None),
        (Reconstruction::Kernel, Kernel::Gaussian { spread, sigmas }) => {
            let r = f64::from(spread);
            let norm = 1.0 / (r.powi(3) * super::integral_f64(scene.kernel));
            let sigmas = f64::from(sigmas);
            let k = sigmas * sigmas / (2.0 * r * r);
            (r, Some((r, k, (-2.0 * k).exp(), norm)))
        }
        (Reconstruction::Kernel, other) => {
            return Err(CliError::input(format!(
                "--reference continuous reconstructs with the kernel in 3D, which only a \
                 Gaussian is ({other} is a footprint model): use a gaussian kernel or \
                 --reconstruction trilinear"
            )))
        }
    })
}

/// The squared offsets d² and Gaussian factors exp(−k·d²) of the taps d = `d0`, `d0` − 1, …
/// along one axis (as many as `d2` holds; `e` the same length), with `fall` = exp(−2k). The
/// offset falls by one per tap, so two exponentials give them all: e(d − 1) = e(d)·q with
/// q(d) = exp(k·(2d − 1)) and q(d − 1) = q(d)·`fall` (relative error a few ulps over the
/// ⌊2R⌋ + 1 taps of a sample; the test below checks it against `exp`).
#[inline]
fn gaussian_taps(d0: f64, k: f64, fall: f64, d2: &mut [f64], e: &mut [f64]) {
    let (mut ej, mut q) = ((-k * d0 * d0).exp(), (k * (2.0 * d0 - 1.0)).exp());
    for (j, (dd, ee)) in d2.iter_mut().zip(e.iter_mut()).enumerate() {
        let d = d0 - j as f64;
        *dd = d * d;
        *ee = ej;
        ej *= q;
        q *= fall;
    }
}

/// A voxel shaded to premultiplied `rgba` (opacity per world unit) as `absorption` stores it:
/// [α, αr, αg, αb] uncapped, or [σ, σr, σg, σb] with α capped at 1 − `cap`; `None` if
/// transparent.
fn pre_classified(rgba: [f32; 4], absorption: Absorption, cap: f64) -> Option<[f32; 4]> {
    match absorption {
        Absorption::Opacity => {
            (rgba[3] > 0.0).then(|| [rgba[3].min(1.0), rgba[0], rgba[1], rgba[2]])
        }
        Absorption::Extinction => {
            let a = f64::from(rgba[3]).clamp(0.0, 1.0 - cap);
            (a > 0.0).then(|| {
                let sigma = -(1.0 - a).ln();
                // Premultiplied colour / α = the straight colour.
                let c = [0, 1, 2].map(|ch| f64::from(rgba[ch]) / a);
                [sigma, sigma * c[0], sigma * c[1], sigma * c[2]].map(|x| x as f32)
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::sparse::dilate;
    use super::{gaussian_taps, BLOCK};

    #[test]
    fn dilated_blocks_cover_every_block_a_voxel_can_be_seen_from() {
        // A few voxels of a 37x20x9 grid; each must activate every block within `pad` voxels
        // of it (the rule the march relies on), and the dilation must not reach further than
        // one block past that.
        let dims = [37usize, 20, 9];
        let blocks = dims.map(|d| d.div_ceil(BLOCK));
        for pad in [1usize, 3, 8, 9] {
            for voxel in [[0usize, 0, 0], [36, 19, 8], [8, 7, 4], [15, 16, 0]] {
                let mut holds = vec![false; blocks.iter().product()];
                let b = voxel.map(|c| c / BLOCK);
                holds[(b[2] * blocks[1] + b[1]) * blocks[0] + b[0]] = true;
                let active = dilate(&holds, blocks, pad.div_ceil(BLOCK));
                for z in 0..dims[2] {
                    for y in 0..dims[1] {
                        for x in 0..dims[0] {
                            let near = [x, y, z]
                                .iter()
                                .zip(voxel)
                                .all(|(&c, v)| c.abs_diff(v) <= pad);
                            let bi = ((z / BLOCK) * blocks[1] + y / BLOCK) * blocks[0] + x / BLOCK;
                            assert!(!near || active[bi], "pad {pad}, {voxel:?}: ({x},{y},{z})");
                        }
                    }
                }
                let count = active.iter().filter(|&&a| a).count();
                let most = (2 * pad.div_ceil(BLOCK) + 1).pow(3);
                assert!(count <= most, "pad {pad}: {count} blocks");
            }
        }
    }

    #[test]
    fn the_tap_recurrence_matches_exp() {
        // Spreads 0.5–3 and sigma counts 1–4 (k = s²/2R²), sample offsets across a lattice cell.
        for (r, sigmas) in [(0.5f64, 1.0f64), (1.5, 2.0), (2.0, 3.0), (3.0, 4.0)] {
            let k = sigmas * sigmas / (2.0 * r * r);
            for i in 0..50 {
                let c = 7.0 + i as f64 / 50.0;
                let lo = (c - r).ceil();
                let count = ((c + r).floor() - lo + 1.0) as usize;
                let (mut d2, mut e) = (vec![0.0; count], vec![0.0; count]);
                gaussian_taps(c - lo, k, (-2.0 * k).exp(), &mut d2, &mut e);
                for j in 0..count {
                    let d = c - (lo + j as f64);
                    let want = (-k * d * d).exp();
                    assert!((d2[j] - d * d).abs() <= 1e-12, "d² at r={r} c={c} j={j}");
                    assert!(
                        (e[j] - want).abs() <= 1e-13 * want,
                        "r={r} s={sigmas} c={c} j={j}: {} vs {want}",
                        e[j]
                    );
                }
            }
        }
    }
}
