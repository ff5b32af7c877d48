//! The continuous reference of a prepared render (`crate::reference::continuous`): its scene,
//! each absorption model's image, the figures against every model, and a sample of pixels (the
//! pilots). What `verify --reference continuous`, `--quality` and `chart` measure against.

use crate::io::progress::sheets;
use crate::pipeline::stages::prepare::Prepared;
use crate::pipeline::stages::supersample::downsample;
use crate::reference::continuous::{
    render_continuous, Absorption, Continuous, ContinuousScene, Model, PixelMarcher,
    Reconstruction, DEFAULT_CAP, MAX_HALVINGS,
};
use crate::CliError;
use std::time::Instant;

/// `p`'s volume (it must be in memory) and the continuous reference's scene of it.
fn continuous_scene(
    p: &Prepared,
    reconstruction: Reconstruction,
    model: Model,
    cap: f64,
) -> Result<(&crate::io::volume::Volume, ContinuousScene<'_>), CliError> {
    let volume = p.volume().ok_or_else(|| {
        CliError::input("the continuous reference needs the volume in memory: drop --stream")
    })?;
    if volume.is_coloured() {
        return Err(CliError::input(format!(
            "the continuous reference integrates the volume at full resolution, not level {} of \
             it: give --lod 0",
            p.level
        )));
    }
    let scene = ContinuousScene {
        frame: &p.frame,
        kernel: &p.kernel,
        shader: p.shader(),
        background: p.background.as_deref(),
        reconstruction,
        model,
        cap,
        clip: p.clip.iter().map(|c| c.in_grid(&p.frame)).collect(),
        samples: super::post::sample_range(volume),
        grid: volume
            .grid
            .as_deref()
            .map(|c| crate::reference::warp::Warp::new(c.positions())),
        // A reference: every core (at most 16) unless the caller says otherwise.
        threads: std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .clamp(1, 16),
    };
    Ok((volume, scene))
}

/// The continuous reference of `p` in its own model (`--absorption`; see
/// [`crate::reference::continuous`]): the converged image (at the output size) and how it
/// converged, and its seconds. The volume must be in memory.
pub fn render_continuous_ref(
    p: &Prepared,
    reconstruction: Reconstruction,
) -> Result<(Continuous, f64), CliError> {
    render_continuous_model(p, reconstruction, p.absorption)
}

/// PSNR (RGB, dB) against each continuous model, the chosen one first.
pub type ModelFigures = Vec<(Model, f64)>;

/// The continuous reference of `p` in `chosen_model` (pre-classified in an absorption model, as
/// [`render_continuous_model`], or post-classified) and, for context, `core`'s PSNR (RGB, dB)
/// against each model, the chosen one first, then the others (both absorption models and
/// post-classification: values reconstructed, then classified, what ray casters compute): the
/// models differ by more than a renderer's error on opaque data, so the figure means little
/// without its model.
pub fn continuous_models(
    p: &Prepared,
    reconstruction: Reconstruction,
    chosen_model: Model,
    core: &[[f32; 4]],
) -> Result<(Continuous, f64, ModelFigures), CliError> {
    let (chosen, secs) = render_continuous_as(p, reconstruction, chosen_model, DEFAULT_CAP)?;
    let mut figures = vec![(
        chosen_model,
        crate::metrics::compare(core, &chosen.image).1.psnr_db,
    )];
    // A projection is compared with its own model only: the composited ones are other pictures.
    let all = match chosen_model {
        Model::Projection(_) => vec![],
        _ => vec![
            Model::Pre(Absorption::Opacity),
            Model::Pre(Absorption::Extinction),
            Model::Post,
        ],
    };
    for other in all.into_iter().filter(|&m| m != chosen_model) {
        let (c, _) = render_continuous_as(p, reconstruction, other, DEFAULT_CAP)?;
        figures.push((other, crate::metrics::compare(core, &c.image).1.psnr_db));
    }
    Ok((chosen, secs, figures))
}

/// The continuous reference's pixel filter, as `verify` states it.
pub const PIXEL_FILTER: &str = "one ray through each pixel centre; a frame supersampled k times \
                                (--supersample) averages its k x k rays per pixel (a box filter)";

/// `continuous.models` of `verify`'s JSON: PSNR (RGB, dB) against each absorption model.
pub fn models_json(models: &[(Model, f64)]) -> crate::io::json::Json {
    models
        .iter()
        .fold(crate::io::json::Json::object(), |j, (m, db)| {
            j.num(m.name(), *db)
        })
}

/// The figures against the models after the chosen one, as `verify` prints them after it.
pub fn others(models: &[(Model, f64)]) -> String {
    let other = |(m, db): &(Model, f64)| format!(", {db:.2} dB against the {} model", m.name());
    models.iter().skip(1).map(other).collect()
}

/// [`render_continuous_ref`] with the field's absorption model given (see
/// [`crate::reference::continuous`]).
pub fn render_continuous_model(
    p: &Prepared,
    reconstruction: Reconstruction,
    absorption: Absorption,
) -> Result<(Continuous, f64), CliError> {
    render_continuous_capped(p, reconstruction, absorption, DEFAULT_CAP)
}

/// [`render_continuous_model`] with the extinction model's cap given
/// ([`ContinuousScene::cap`]; the opacity model has none).
pub fn render_continuous_capped(
    p: &Prepared,
    reconstruction: Reconstruction,
    absorption: Absorption,
    cap: f64,
) -> Result<(Continuous, f64), CliError> {
    render_continuous_as(p, reconstruction, Model::Pre(absorption), cap)
}

/// The continuous reference of `p` in any [`Model`], post-classification included.
pub fn render_continuous_as(
    p: &Prepared,
    reconstruction: Reconstruction,
    model: Model,
    cap: f64,
) -> Result<(Continuous, f64), CliError> {
    let start = Instant::now();
    let (volume, scene) = continuous_scene(p, reconstruction, model, cap)?;
    let mut bar = sheets("continuous");
    let axis = p.frame.sheet_axis;
    let mut c = render_continuous(
        &scene,
        |s, out| volume.sheet_into(axis, s, out),
        |pass, _| bar(pass, MAX_HALVINGS + 1),
    )?;
    if p.supersample > 1 {
        c.image = downsample(&c.image, p.out_size(), p.supersample, |v| v);
    }
    Ok((c, start.elapsed().as_secs_f64()))
}

/// The continuous reference of `p` at listed pixels of the *output* image ((x, y), each below
/// [`Prepared::out_size`]; a supersampled frame marches the k×k rays of each and averages them,
/// as the renders are averaged): kernel reconstruction, `p`'s model, its field built once and
/// marched through as many lists of pixels as asked (the pilot's two stages). The volume must
/// be in memory.
pub struct PilotReference<'a> {
    marcher: PixelMarcher<'a>,
    k: usize,
}

impl<'a> PilotReference<'a> {
    /// The field of `p`, to be marched on `threads` threads (the image is the same for every
    /// count).
    pub fn new(p: &'a Prepared, threads: usize) -> Result<Self, CliError> {
        let (volume, mut scene) = continuous_scene(
            p,
            Reconstruction::Kernel,
            Model::Pre(p.absorption),
            DEFAULT_CAP,
        )?;
        scene.threads = threads.max(1);
        let axis = p.frame.sheet_axis;
        let marcher = PixelMarcher::new(scene, |s, out| volume.sheet_into(axis, s, out))?;
        Ok(PilotReference {
            marcher,
            k: p.supersample,
        })
    }

    /// The reference at `pixels`: their values in the order given and how it converged.
    pub fn at(&self, pixels: &[[usize; 2]]) -> Result<Continuous, CliError> {
        let k = self.k;
        let rays: Vec<[usize; 2]> = pixels
            .iter()
            .flat_map(|&[x, y]| (0..k * k).map(move |i| [x * k + i % k, y * k + i / k]))
            .collect();
        let mut bar = sheets("continuous pilot");
        let mut c = self
            .marcher
            .at(|pass, _| bar(pass, MAX_HALVINGS + 1), &rays)?;
        if k > 1 {
            let scale = 1.0 / (k * k) as f64;
            c.image = c
                .image
                .chunks(k * k)
                .map(|block| {
                    let mut sum = [0.0f64; 4];
                    for v in block {
                        for ch in 0..4 {
                            sum[ch] += v[ch];
                        }
                    }
                    sum.map(|v| v * scale)
                })
                .collect();
        }
        Ok(c)
    }
}

/// [`PilotReference`] of `p` at `pixels`, on `threads` threads, in one go: the values, how it
/// converged, and its seconds.
pub fn continuous_at(
    p: &Prepared,
    pixels: &[[usize; 2]],
    threads: usize,
) -> Result<(Continuous, f64), CliError> {
    let start = Instant::now();
    let c = PilotReference::new(p, threads)?.at(pixels)?;
    Ok((c, start.elapsed().as_secs_f64()))
}

/// What lies where a ray's accumulated opacity first reaches one half (issue 77: `render
/// --depth-map`, `footprint probe`), in the continuous model of the frame (its f64 march, not the
/// splatted sheets: a sheet's opacity is known only on its plane, so a crossing found there
/// would be quantised to the sheet spacing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// The crossing's screen z in world units: its distance along the view direction from the
    /// plane through the volume's centre, growing away from the viewer; NaN where the ray's
    /// opacity never reaches 0.5.
    pub depth: f64,
    /// The crossing in world coordinates (the grid's axes times their spacing, world units),
    /// the volume's centre at the origin (the convention of `--clip`); NaN where none.
    pub world: [f64; 3],
    /// The volume's value there, trilinearly interpolated from the samples, in the data's units;
    /// NaN where none.
    pub value: f64,
}

/// [`Probe`]s of `p`'s frame in `model` and `reconstruction`: every pixel's, row-major
/// (`pixels` None), or those listed ((x, y), each inside the frame), with their seconds. `p` must
/// be a level-0 volume in memory rendered without supersampling (the rays are the pixels').
pub fn probes(
    p: &Prepared,
    (model, reconstruction): (Model, Reconstruction),
    pixels: Option<&[[usize; 2]]>,
) -> Result<(Vec<Probe>, f64), CliError> {
    let start = Instant::now();
    let (volume, scene) = continuous_scene(p, reconstruction, model, DEFAULT_CAP)?;
    // A crop's brick stores only what it owns (no ghost voxel a split render's brick reads).
    let ghosts = volume.brick.is_some_and(|b| b.stored != b.owned);
    if p.supersample != 1 || ghosts {
        return Err(CliError::input(
            "depth: the frame must be rendered at its own size from the whole volume",
        ));
    }
    let axis = p.frame.sheet_axis;
    let mut bar = sheets("depth");
    let sheet = |s, out: &mut [f32]| volume.sheet_into(axis, s, out);
    let progress = |pass, _| bar(pass, MAX_HALVINGS + 1);
    let c = match pixels {
        None => render_continuous(&scene, sheet, progress)?,
        Some(px) => {
            crate::reference::continuous::render_continuous_at(&scene, sheet, progress, px)?
        }
    };
    let f = &p.frame;
    let grid = f.grid_inverse_transpose.as_dmat3().inverse().transpose();
    let g2s = f.grid_to_screen.as_dmat3();
    // The view direction in world units: the world vector screen z moves along.
    let away = (grid * g2s.inverse() * glam::DVec3::Z).normalize();
    let centre = glam::DVec3::from_array(f.dims.map(|n| (n as f64 - 1.0) / 2.0));
    let probe = |g: &[f64; 3]| {
        let world = grid * (glam::DVec3::from_array(*g) - centre);
        Probe {
            depth: world.dot(away),
            world: world.to_array(),
            // At the sample indices a rectilinear grid's crossing falls between.
            value: trilinear(volume, scene_grid_index(&scene, *g)),
        }
    };
    Ok((
        c.crossings.iter().map(probe).collect(),
        start.elapsed().as_secs_f64(),
    ))
}

/// `volume`'s value at grid point `g` (voxel steps), trilinearly interpolated between the eight
/// samples around it (clamped to the grid), in the data's units; NaN for a NaN point.
fn trilinear(volume: &crate::io::volume::Volume, g: [f64; 3]) -> f64 {
    if g.iter().any(|x| x.is_nan()) {
        return f64::NAN;
    }
    let d = volume.dims;
    let mut lo = [0usize; 3];
    let mut frac = [0.0f64; 3];
    for a in 0..3 {
        let x = g[a].clamp(0.0, (d[a] - 1) as f64);
        lo[a] = (x.floor() as usize).min(d[a].saturating_sub(2));
        frac[a] = x - lo[a] as f64;
    }
    let mut sum = 0.0;
    for corner in 0..8 {
        let mut w = 1.0;
        let mut at = [0usize; 3];
        for a in 0..3 {
            let up = corner >> a & 1 == 1;
            at[a] = (lo[a] + usize::from(up)).min(d[a] - 1);
            w *= if up { frac[a] } else { 1.0 - frac[a] };
        }
        if w > 0.0 {
            let n = at[0] + d[0] * (at[1] + d[1] * at[2]);
            sum += w * volume.values.to_data(volume.value_in_grid(n));
        }
    }
    sum
}

/// Sample-index coordinates of the frame's grid point `g` in `scene` (warped on a rectilinear
/// grid, `crate::reference::warp`).
fn scene_grid_index(scene: &ContinuousScene<'_>, g: [f64; 3]) -> [f64; 3] {
    let g = glam::DVec3::from_array(g);
    scene.grid.as_ref().map_or(g, |w| w.index(g)).to_array()
}
