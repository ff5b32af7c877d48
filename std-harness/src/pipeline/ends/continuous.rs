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
    let all = [
        Model::Pre(Absorption::Opacity),
        Model::Pre(Absorption::Extinction),
        Model::Post,
    ];
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
