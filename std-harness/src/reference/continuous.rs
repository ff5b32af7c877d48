//! The continuous reference (issue 12): what the voxels, the kernel and the transfer function
//! define, with no sheets, tables or splats. Every pixel's ray is marched through the field, in
//! f64, and the emission–absorption integral is evaluated, then composited over the background
//! (`I + T·background`, T the ray's transmittance; α = 1 − T). The voxels are pre-classified: each
//! voxel's straight colour cᵥ and opacity αᵥ *per world unit* come from the renderer's own shader
//! (transfer function, and Phong with the voxel's gradient, at an opacity exponent of one world
//! unit). The field is reconstructed with
//! - `Kernel`: the kernel itself, w(d) = h(|d|/R) / (R³ ∫_ball h), d in grid steps, so that the
//!   weights of a lattice sum to one (the renderer's own model, integrated exactly instead of as
//!   whole-kernel footprints in sheets); Gaussian kernels only (the others are 2D footprint
//!   models, not 3D kernels);
//! - `Trilinear`: the eight surrounding voxels, trilinearly, as ray casters such as VTK do.
//!
//! **Absorption model** ([`Absorption`], `--absorption`; the renderer's slicings composite the
//! same one, `footprint::render::absorption`).
//! - *Opacity reconstruction* (the default): α(x) = Σᵥ w(x − v) αᵥ and C(x) = Σᵥ w(x − v) αᵥcᵥ,
//!   and light crossing dl keeps (1 − α(x))^dl, emitting the straight colour C(x)/α(x):
//!
//!   ```text
//!   I = ∫ σ(t)·C(t)/α(t) · exp(−∫₀ᵗ σ) dt,   σ(x) = −ln(1 − α(x))
//!   ```
//!
//!   It is the continuous form of what the paper's sheets splat and needs no constant: where α(x)
//!   reaches one the ray ends there, with that colour.
//! - *Extinction reconstruction*: σ(x) = Σᵥ w(x − v) σᵥ and E(x) = Σᵥ w(x − v) σᵥcᵥ with
//!   σᵥ = −ln(1 − αᵥ), I = ∫ E(t)·exp(−∫₀ᵗ σ) dt. An opaque voxel has no finite σᵥ: αᵥ is capped at
//!   1 − [`ContinuousScene::cap`] (10⁻⁶, the renderer's), and an opaque scene's image moves with
//!   the cap (41.0 dB against image slicing at a cap of 10⁻⁶, 38.1 dB at 10⁻³ on a CT head);
//!   every opaque structure also thickens by most of a kernel radius.
//!
//! **Quadrature and convergence.** Each step of length h (world units) takes σ and E at its
//! midpoint and composites the step exactly for constant σ and E (T·E/σ·(1 − e^(−σh)), then
//! T·e^(−σh)): second order in h. The image is computed at h₀ = half the smallest spacing, then at
//! h₀/2, h₀/4, … until two successive images differ by at least [`CONVERGED_DB`] of PSNR (RGB);
//! with second-order convergence the finer one's own error is then about a third of that change
//! (≈ 9.5 dB better). At most [`MAX_HALVINGS`] halvings; the report says whether it converged.
//!
//! **The pilot's march** ([`PixelMarcher`], what the default plan and `--quality-reference
//! continuous` measure against) nests its first two passes: steps of 3/4 of the smallest spacing
//! and their thirds, from one march (the midpoint of a step is the middle one of its thirds'
//! midpoints), so the second pass has the same step as above (1/4 of the smallest spacing) and
//! the two cost 2 samples per 1/2 spacing instead of 3. Convergence is judged between them as
//! above; with second order the finer one's error is then about an eighth of the change
//! (≈ 18 dB better), as the coarse step's error is 9 times the fine one's. Halvings continue from
//! the finer one. The pilot's reference at the shared volumes' views moved by at most 0.07 dB of
//! the estimates it gave (walnut 52.64 → 52.67, CT head 53.56 → 53.56, blobs 72.55 → 72.48 dB;
//! `footprint bench --frames 1`, 512², 30,20,0) and its time at the minimum of three alternated
//! runs by 0.57–0.71×. `verify --reference continuous` marches as above.
//!
//! **Work.** Rays run only where the kernel's support around the voxel box is (a slab test), and a
//! block map skips 8³-voxel blocks whose neighbourhood holds no opaque voxel; rows are split
//! between all cores. The rays are the frame's own: parallel to the view (orthographic) or from
//! the eye through each pixel centre (perspective).

use super::field::Field;
pub use super::field::{Absorption, ContinuousScene, Model, Reconstruction, DEFAULT_CAP};
use super::projection::pixel;
use crate::CliError;
use footprint::frame::FrameSetup;
use glam::{DMat3, DVec3};

/// Two successive refinements closer than this (PSNR between them, dB) count as converged.
pub const CONVERGED_DB: f64 = 60.0;
/// The most halvings of the step.
pub const MAX_HALVINGS: usize = 6;

/// The converged image and how it converged.
pub struct Continuous {
    /// Premultiplied RGBA, row-major, top row first.
    pub image: Vec<[f64; 4]>,
    /// The final step, world units.
    pub step: f64,
    /// Images computed (the first plus each halving).
    pub passes: usize,
    /// PSNR between the last two images, dB (RGB).
    pub change_db: f64,
    /// Whether that change reached [`CONVERGED_DB`].
    pub converged: bool,
    /// Per ray, in `image`'s order: the grid point (i, j, k, in voxel steps) where the ray's
    /// accumulated opacity first reaches one half in the final pass, found within its step as
    /// the exact crossing of that step's exponential attenuation; NaN where it never does. (The
    /// pilot's nested march leaves it NaN.)
    pub crossings: Vec<[f64; 3]>,
}

/// Which rays to march: every pixel's, or those through the listed pixels.
#[derive(Clone, Copy)]
enum Rays<'a> {
    All,
    Pixels(&'a [[usize; 2]]),
}

impl Rays<'_> {
    fn count(self, f: &FrameSetup) -> usize {
        match self {
            Rays::All => f.size[0] * f.size[1],
            Rays::Pixels(p) => p.len(),
        }
    }
    /// The (x, y) pixel of ray `i`.
    fn pixel(self, f: &FrameSetup, i: usize) -> (usize, usize) {
        match self {
            Rays::All => (i % f.size[0], i / f.size[0]),
            Rays::Pixels(p) => (p[i][0], p[i][1]),
        }
    }
}

/// Marches the rays of `rays` with step `h` (world units) and returns their values, in the
/// order of `rays`; `nested`: also at step h/3, from the same samples (each step's midpoint is
/// the middle one of its thirds'), returned second (empty otherwise).
/// Returned third: each ray's [`Continuous::crossings`] at step `h` (NaN when `nested`).
fn march(
    scene: &ContinuousScene<'_>,
    field: &Field,
    h: f64,
    rays: Rays<'_>,
    nested: bool,
) -> Marched {
    let f = scene.frame;
    let w = f.size[0];
    let g2s: DMat3 = f.grid_to_screen.as_dmat3();
    let inv = g2s.inverse();
    let origin = f.origin.as_dvec3();
    // Grid steps to world: G = ((G⁻ᵀ)⁻¹)ᵀ.
    let grid = f.grid_inverse_transpose.as_dmat3().inverse().transpose();
    let camera = f.camera().copied();
    // A rectilinear grid: the field's box in the frame's grid, and its argument warped.
    let (lo, hi) = match &scene.grid {
        Some(w) => (w.grid(field.bounds().0), w.grid(field.bounds().1)),
        None => field.bounds(),
    };
    let warp = |g: DVec3| scene.grid.as_ref().map_or(g, |w| w.index(g));
    let clip = &scene.clip;
    let threads = scene.threads.max(1);
    let count = rays.count(f);
    let mut image = vec![[0.0f64; 4]; count];
    let mut thirds = vec![[0.0f64; 4]; if nested { count } else { 0 }];
    let mut crossings = vec![[f64::NAN; 3]; count];
    let band = count.div_ceil(threads).max(1);
    let mut fine_chunks = thirds.chunks_mut(band);
    let mut crossing_chunks = crossings.chunks_mut(band);
    std::thread::scope(|sc| {
        for (t, chunk) in image.chunks_mut(band).enumerate() {
            let fine_chunk = fine_chunks.next();
            let crossing_chunk = crossing_chunks
                .next()
                .expect("as many chunks as the image's");
            crate::threads::spawn(sc, move || {
                let mut taps = field.taps();
                let mut fine_chunk = fine_chunk;
                for (i, px) in chunk.iter_mut().enumerate() {
                    let (x, y) = rays.pixel(f, t * band + i);
                    let (xc, yc) = (x as f64 + 0.5, y as f64 + 0.5);
                    let (p0, d) = ray_of(camera.as_ref(), xc, yc);
                    // In grid coordinates: g(t) = g0 + t·dg.
                    let g0 = inv * (p0 - origin);
                    let dg = inv * d;
                    let (mut t0, t1) = ray_interval(g0, dg, (lo, hi), clip);
                    if camera.is_some() {
                        t0 = t0.max(0.0);
                    }
                    let mut coarse = Ray::default();
                    let mut fine = Ray::default();
                    let per_t = (grid * dg).length();
                    let bg = scene
                        .background
                        .map_or([0.0; 4], |b| b[y * w + x].map(f64::from));
                    if let Some(blend) = field.projection() {
                        let ray = ((g0, dg), (t0, t1), per_t);
                        let mut pixel =
                            |h| pixel(field, &scene.shader, blend, ray, h, &mut taps, bg);
                        *px = pixel(h);
                        if let Some(f) = fine_chunk.as_deref_mut() {
                            f[i] = pixel(h / 3.0);
                        }
                        continue;
                    }
                    if t1 > t0 {
                        let world = (t1 - t0) * per_t;
                        let steps = ((world / h).ceil() as usize).max(1);
                        let step = (t1 - t0) / steps as f64;
                        let hw = world / steps as f64;
                        let absorption = field.absorption();
                        for k in 0..steps {
                            if !nested {
                                let tm = t0 + (k as f64 + 0.5) * step;
                                if coarse.add(
                                    field.at(warp(g0 + dg * tm), &mut taps),
                                    hw,
                                    absorption,
                                ) {
                                    break;
                                }
                                continue;
                            }
                            for j in 0..3 {
                                let tm = t0 + (k as f64 + (2 * j + 1) as f64 / 6.0) * step;
                                let v = field.at(warp(g0 + dg * tm), &mut taps);
                                if j == 1 && !coarse.done() {
                                    coarse.add(v, hw, absorption);
                                }
                                if !fine.done() {
                                    fine.add(v, hw / 3.0, absorption);
                                }
                            }
                            if coarse.done() && fine.done() {
                                break;
                            }
                        }
                    }
                    *px = coarse.over(bg);
                    if let Some(f) = fine_chunk.as_deref_mut() {
                        f[i] = fine.over(bg);
                    } else if coarse.half.is_finite() {
                        let tc = t0 + coarse.half / per_t;
                        crossing_chunk[i] = (g0 + dg * tc).to_array();
                    }
                }
            });
        }
    });
    (image, thirds, crossings)
}

/// The ray through the pixel centre (`xc`, `yc`) in affine screen units: P(t) = p0 + t·d,
/// |d| = 1; parallel to the view without a `camera`, from its eye with one.
fn ray_of(camera: Option<&footprint::geometry::Perspective>, xc: f64, yc: f64) -> (DVec3, DVec3) {
    match camera {
        None => (DVec3::new(xc, yc, 0.0), DVec3::Z),
        Some(c) => {
            let eye = DVec3::new(
                f64::from(c.centre[0]),
                f64::from(c.centre[1]),
                -f64::from(c.focal_px),
            );
            let d = DVec3::new(
                xc - f64::from(c.centre[0]),
                yc - f64::from(c.centre[1]),
                f64::from(c.focal_px),
            );
            (eye, d.normalize())
        }
    }
}

/// The part [t0, t1] of the ray g0 + t·dg (grid units) inside the box `bounds` (lo, hi) and
/// every clipping plane's kept half-space m·g ≤ e: one interval, the region being convex; empty
/// when t1 ≤ t0.
fn ray_interval(
    g0: DVec3,
    dg: DVec3,
    (lo, hi): (DVec3, DVec3),
    clip: &[([f64; 3], f64)],
) -> (f64, f64) {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for a in 0..3 {
        if dg[a].abs() < 1e-15 {
            if g0[a] < lo[a] || g0[a] > hi[a] {
                t1 = f64::NEG_INFINITY;
            }
            continue;
        }
        let (u, v) = ((lo[a] - g0[a]) / dg[a], (hi[a] - g0[a]) / dg[a]);
        t0 = t0.max(u.min(v));
        t1 = t1.min(u.max(v));
    }
    for (m, e) in clip {
        let m = DVec3::from_array(*m);
        let (along, room) = (m.dot(dg), e - m.dot(g0));
        if along > 0.0 {
            t1 = t1.min(room / along);
        } else if along < 0.0 {
            t0 = t0.max(room / along);
        } else if room < 0.0 {
            t1 = f64::NEG_INFINITY;
        }
    }
    (t0, t1)
}

/// What [`march`] returns: the image, the nested thirds' image (empty unless nested) and the
/// crossings.
type Marched = (Vec<[f64; 4]>, Vec<[f64; 4]>, Vec<[f64; 3]>);

/// One ray's emission and transmittance so far, front to back, and how far it has gone.
#[derive(Clone, Copy)]
struct Ray {
    colour: [f64; 3],
    trans: f64,
    /// World length marched so far.
    walked: f64,
    /// World length from the ray's entry at which its transmittance first fell to one half
    /// (its accumulated opacity reached 0.5); NaN until it does.
    half: f64,
}

impl Default for Ray {
    fn default() -> Self {
        Ray {
            colour: [0.0; 3],
            trans: 1.0,
            walked: 0.0,
            half: f64::NAN,
        }
    }
}

impl Ray {
    /// Composites one step of length `hw` (world units) whose field value is `v` (σ or α, then
    /// the colour terms) behind what the ray holds. Returns whether the ray is done (opaque).
    fn add(&mut self, v: [f64; 4], hw: f64, absorption: Absorption) -> bool {
        let from = self.walked;
        self.walked += hw;
        if v[0] <= 0.0 {
            return false;
        }
        // The step's transmittance: exp(−σh), or (1 − α)^h with σ = −ln(1 − α) (α ≥ 1: opaque,
        // the ray ends here). Either way the straight colour emitted is v[1..] / v[0].
        let att = match absorption {
            Absorption::Extinction => (-v[0] * hw).exp(),
            Absorption::Opacity => (1.0 - v[0].min(1.0)).powf(hw),
        };
        let share = self.trans * (1.0 - att) / v[0];
        for ch in 0..3 {
            self.colour[ch] += share * v[ch + 1];
        }
        if self.half.is_nan() && self.trans * att <= 0.5 {
            // Within the step the transmittance is trans·att^(s/hw): it is one half at
            // s = hw·ln(0.5/trans)/ln(att) (at the step's start for an opaque step, att = 0).
            let s = if att > 0.0 {
                hw * (0.5 / self.trans).ln() / att.ln()
            } else {
                0.0
            };
            self.half = from + s.clamp(0.0, hw);
        }
        self.trans *= att;
        if self.trans < 1e-12 {
            self.trans = 0.0;
            return true;
        }
        false
    }

    /// Whether nothing behind can show (its transmittance was cut to zero).
    fn done(&self) -> bool {
        self.trans == 0.0
    }

    /// The ray's value over background `bg` (premultiplied RGBA).
    fn over(&self, bg: [f64; 4]) -> [f64; 4] {
        let (c, t) = (self.colour, self.trans);
        [
            c[0] + t * bg[0],
            c[1] + t * bg[1],
            c[2] + t * bg[2],
            (1.0 - t) + t * bg[3],
        ]
    }
}

/// PSNR (RGB) between two images, dB.
fn change_db(a: &[[f64; 4]], b: &[[f64; 4]]) -> f64 {
    let mut sq = 0.0;
    for (p, q) in a.iter().zip(b) {
        for ch in 0..3 {
            sq += (p[ch] - q[ch]).powi(2);
        }
    }
    let mse = sq / (3 * a.len().max(1)) as f64;
    if mse > 0.0 {
        -10.0 * mse.log10()
    } else {
        f64::INFINITY
    }
}

/// The converged continuous image (see the module docs) of the sheets `sheet(s, buffer)`
/// supplies (along the frame's sheet axis); `progress(pass, step)` after each pass.
pub fn render_continuous(
    scene: &ContinuousScene<'_>,
    sheet: impl FnMut(usize, &mut [f32]),
    progress: impl FnMut(usize, f64),
) -> Result<Continuous, CliError> {
    converge(scene, sheet, progress, Rays::All)
}

/// [`render_continuous`] at the listed pixels only ((x, y) of the frame, each below its size):
/// `image` holds their values in the order given, and convergence is judged on them. What
/// `--quality-reference continuous` samples.
pub fn render_continuous_at(
    scene: &ContinuousScene<'_>,
    sheet: impl FnMut(usize, &mut [f32]),
    progress: impl FnMut(usize, f64),
    pixels: &[[usize; 2]],
) -> Result<Continuous, CliError> {
    check_pixels(scene.frame, pixels)?;
    converge(scene, sheet, progress, Rays::Pixels(pixels))
}

/// A continuous field built once and marched through listed pixels as often as asked (what the
/// pilot's two stages share: the field is the costly part of a small sample).
pub struct PixelMarcher<'s> {
    scene: ContinuousScene<'s>,
    field: Field<'s>,
}

impl<'s> PixelMarcher<'s> {
    /// The field of `scene`, each sheet read once through `sheet(s, buffer)`.
    pub fn new(
        scene: ContinuousScene<'s>,
        mut sheet: impl FnMut(usize, &mut [f32]),
    ) -> Result<Self, CliError> {
        let field = Field::new(&scene, &mut sheet)?;
        Ok(PixelMarcher { scene, field })
    }

    /// [`render_continuous_at`] through this field, its first two passes nested (module docs,
    /// "The pilot's march"): values within the convergence of both.
    pub fn at(
        &self,
        progress: impl FnMut(usize, f64),
        pixels: &[[usize; 2]],
    ) -> Result<Continuous, CliError> {
        check_pixels(self.scene.frame, pixels)?;
        converge_on(
            &self.scene,
            &self.field,
            progress,
            Rays::Pixels(pixels),
            true,
        )
    }
}

/// An error naming the first of `pixels` outside `f`'s frame.
fn check_pixels(f: &FrameSetup, pixels: &[[usize; 2]]) -> Result<(), CliError> {
    match pixels
        .iter()
        .find(|p| p[0] >= f.size[0] || p[1] >= f.size[1])
    {
        Some(p) => Err(CliError::input(format!(
            "continuous reference: pixel ({}, {}) lies outside the {}x{} frame",
            p[0], p[1], f.size[0], f.size[1]
        ))),
        None => Ok(()),
    }
}

fn converge(
    scene: &ContinuousScene<'_>,
    mut sheet: impl FnMut(usize, &mut [f32]),
    progress: impl FnMut(usize, f64),
    rays: Rays<'_>,
) -> Result<Continuous, CliError> {
    let field = Field::new(scene, &mut sheet)?;
    converge_on(scene, &field, progress, rays, false)
}

/// Marches `rays` through `field`, halving the step until two passes agree (module docs);
/// `nested`: the first two passes from one march by thirds (module docs, the pilot's).
fn converge_on(
    scene: &ContinuousScene<'_>,
    field: &Field<'_>,
    mut progress: impl FnMut(usize, f64),
    rays: Rays<'_>,
    nested: bool,
) -> Result<Continuous, CliError> {
    let smallest = scene
        .frame
        .spacing
        .iter()
        .copied()
        .fold(f32::INFINITY, f32::min);
    // A rectilinear grid's: its shortest gap.
    let smallest = (scene.grid.as_ref())
        .and_then(|w| w.smallest_gap(scene.frame.spacing))
        .unwrap_or(f64::from(smallest));
    let mut h = 0.5 * smallest;
    let (mut image, mut crossings, mut passes, mut change, halvings) = if nested {
        // The first two passes from one march: steps of 3/4 of the smallest spacing and their
        // thirds (1/4 of it, the second pass's step without nesting), 2 samples per 1/2
        // spacing instead of 3.
        let (coarse, thirds, _) = march(scene, field, 3.0 * h / 2.0, rays, true);
        progress(1, 3.0 * h / 2.0);
        h /= 2.0;
        progress(2, h);
        let change = change_db(&coarse, &thirds);
        let none = vec![[f64::NAN; 3]; thirds.len()];
        (thirds, none, 2, change, MAX_HALVINGS - 1)
    } else {
        let (image, _, crossings) = march(scene, field, h, rays, false);
        progress(1, h);
        (image, crossings, 1, 0.0, MAX_HALVINGS)
    };
    for _ in 0..halvings {
        if passes > 1 && change >= CONVERGED_DB {
            break;
        }
        h *= 0.5;
        let (finer, _, finer_crossings) = march(scene, field, h, rays, false);
        passes += 1;
        progress(passes, h);
        change = change_db(&image, &finer);
        image = finer;
        crossings = finer_crossings;
        if change >= CONVERGED_DB {
            break;
        }
    }
    Ok(Continuous {
        image,
        step: h,
        passes,
        change_db: change,
        converged: change >= CONVERGED_DB,
        crossings,
    })
}
