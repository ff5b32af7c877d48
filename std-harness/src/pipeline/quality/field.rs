//! The finer field a coarse grid stands for: the built-in scene's analytic field sampled
//! `--field-size` N³ over the same box, whose continuous integral `--quality-reference field` and
//! `verify --reference field` measure against.
//!
//! # Why a finer sampling
//! The other two references are the grid's own field: the f64 render of its sheets, and the
//! continuous integral of the field its voxels and kernel define. Refinement (`--refine`, the
//! paper's adaptive re-sampling) interpolates samples the grid does not hold, so it moves the
//! image *away* from both (the built-in scene at 16³, 512×512, view 30,20,0: unrefined 35.85 dB
//! against the kernel field and 37.17 dB against the trilinear one; `--refine 0` 32.64 and
//! 36.72 dB), while it comes closer to the field the grid samples (32.44 → 37.07 dB against the
//! 128³ sampling's render). Choosing refinement therefore needs a reference that stands for
//! that finer field. For the built-in scene it exists: the same analytic function, sampled
//! finer. A volume file holds nothing finer than its samples, so this reference is refused for
//! one.
//!
//! The same box and the same view give the same world-to-screen map, so the finer sampling's
//! image lines up pixel for pixel with the coarse one (the refinement chart relies on the same).

use crate::pipeline::stages::prepare::Prepared;
use crate::plan::Plan;
use crate::scene::Scene;
use crate::CliError;

/// The finer sampling of `args`' built-in scene, prepared to render with `plan`'s order at full
/// resolution (no `--quality`).
pub fn prepare_field(args: &Scene, plan: &Plan) -> Result<Prepared, CliError> {
    if args.volume.is_some() || args.stream.is_some() {
        return Err(CliError::input(
            "the field reference is the built-in scene's analytic field sampled --field-size N³; \
             a volume file holds nothing finer than its own samples: give no volume, or measure \
             against --reference/--quality-reference continuous",
        ));
    }
    if let Some(c) = args.crop {
        return Err(CliError::input(format!(
            "--crop {c} indexes the grid rendered, not the field's finer one: measure a crop \
             against --reference/--quality-reference continuous"
        )));
    }
    if !args.clip.is_empty() {
        return Err(CliError::input(
            "--clip: the field reference does not cut kernels; measure a clipped frame against \
             --reference/--quality-reference continuous",
        ));
    }
    if args.field_size <= args.scene_size {
        return Err(CliError::input(format!(
            "--field-size {} must be finer than the grid rendered (--scene-size {})",
            args.field_size, args.scene_size
        )));
    }
    // At level 0 with no --quality there is no level to validate: prepared as asked.
    let field = Scene {
        scene_size: args.field_size,
        ..args.clone()
    };
    crate::pipeline::stages::prepare::prepare_as_asked(&field, &plan.at_level_0())
}
