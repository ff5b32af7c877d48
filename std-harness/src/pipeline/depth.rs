//! Depth (issue 77): where each pixel's ray first reaches an accumulated opacity of one half, in
//! the continuous model of a frame (`ends::continuous::probes`), at full resolution and the output
//! size whatever the frame's own plan chose for its picture; what `render --depth-map`, `footprint
//! probe` and Python's `depth_map` and `probe` ask for. docs/depth.md has the conventions.

use super::ends::continuous::probes as model_probes;
pub use super::ends::continuous::Probe;
use super::Renderer;
use crate::io::image::{encode_npy, encode_pfm, GreyImage};
use crate::plan::{End, Lod, Plan, Supersample};
use crate::reference::continuous::Model;
use crate::scene::Scene;
use crate::CliError;
use std::path::Path;

/// Extensions a depth map may have: single-channel PFM (NaN where no surface) or NumPy's `.npy`
/// (`<f4`, shape (height, width), top row first).
pub const DEPTH_EXTENSIONS: [&str; 2] = ["pfm", "npy"];

/// The [`Probe`]s of the frame of `scene` and `asked` at the listed pixels ((x, y); every pixel,
/// row-major, for None), and their seconds: the scene at level 0 and the output size (no
/// supersampling or subsampling), in the frame's model (the scene's absorption, or
/// post-classified where the plan's end is) and reconstruction.
pub fn probes(
    scene: &Scene,
    asked: &Plan,
    pixels: Option<&[[usize; 2]]>,
) -> Result<(Vec<Probe>, f64), CliError> {
    let model = match asked.end {
        End::Post { blend, .. } if blend.projects() => {
            return Err(CliError::input(format!(
                "--blend {}: a projection has no depth (no opacity accumulates along a ray): \
                 probe and --depth-map measure composited frames",
                blend.name()
            )))
        }
        End::Post { .. } => Model::Post,
        _ => Model::Pre(scene.absorption),
    };
    let plan = Plan {
        lod: Lod::Level(0),
        supersample: Supersample::Fixed(1),
        subsample: Supersample::Fixed(1),
        auto_subsample: false,
        auto_slicing: None,
        quality: None,
        bricks: None,
        ..asked.clone()
    };
    let r = Renderer::prepare(scene, &plan)?;
    model_probes(r.prepared(), (model, asked.reconstruction()), pixels)
}

/// The depth map of the frame of `scene` and `asked` encoded for `path` ([`DEPTH_EXTENSIONS`]):
/// every pixel's [`Probe::depth`] as f32, NaN where the opacity never reaches 0.5.
pub fn depth_map(scene: &Scene, asked: &Plan, path: &Path) -> Result<Vec<u8>, CliError> {
    let (found, secs) = probes(scene, asked, None)?;
    let (w, h) = scene.size;
    let data: Vec<f32> = found.iter().map(|p| p.depth as f32).collect();
    let hits = data.iter().filter(|d| !d.is_nan()).count();
    crate::say!(
        "depth map: {hits} of {} pixels reach opacity 0.5 ({secs:.3} s)",
        data.len()
    );
    Ok(match crate::io::outputs::extension(path).as_deref() {
        Some("npy") => encode_npy(&data, h, w),
        _ => encode_pfm(&GreyImage {
            width: w,
            height: h,
            data,
        }),
    })
}
