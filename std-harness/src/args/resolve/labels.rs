//! What `--labels` cannot be combined with: a label volume is classified by label, voxel by
//! voxel, before reconstruction (`footprint::shade::Labels`), so every flag that classifies by
//! value, lights by the values' gradient or reconstructs values between voxels is refused with
//! the reason.

use crate::args::{BlendArg, ClassificationArg, Lod, RenderArgs};
use crate::CliError;

/// The rules `--labels` adds (none without it).
pub(super) fn label_rules(args: &RenderArgs) -> Result<(), CliError> {
    if args.labels.is_none() {
        return Ok(());
    }
    let lod = match args.lod {
        Lod::Level(n @ 1..) => Some(format!("--lod {n}")),
        _ => None,
    };
    let why = if !args.tf.is_empty() {
        Some(("--tf", "the labels give each voxel its colour: drop --tf"))
    } else if args.window.is_some() {
        Some((
            "--window",
            "the labels classify exact sample values, not a window: drop --window",
        ))
    } else if args.shading != "emission" {
        Some((
            "--shading",
            "label values name materials, so their differences are no gradient to light by: \
             labels render unlit (drop --shading)",
        ))
    } else if args.classification == ClassificationArg::Post {
        Some((
            "--classification post",
            "labels are classified before reconstruction, so no label is interpolated into \
             another's colour (drop --classification post)",
        ))
    } else if args.blend != BlendArg::Composite {
        Some((
            "--blend",
            "a projection classifies a reconstructed value, and a value between two labels \
             names neither (drop --blend)",
        ))
    } else if let Some(flag) = &lod {
        Some((
            flag.as_str(),
            "a coarser level averages the values, and an average of labels names none (give \
             --lod 0 or auto)",
        ))
    } else if args.quality.is_some() {
        Some((
            "--quality",
            "--quality chooses among levels of detail, which average values: give --slab or \
             --slicing instead",
        ))
    } else {
        None
    };
    match why {
        Some((flag, why)) => Err(CliError::input(format!("--labels with {flag}: {why}"))),
        None => Ok(()),
    }
}
