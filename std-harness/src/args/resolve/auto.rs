//! `--slicing auto`, the default (issue 42): which flags leave the slicing to a pilot.
//!
//! Object slicing composites each kernel whole in one sheet; where voxels are nearly opaque that
//! departs from the continuous integral by more than any table error (docs/accuracy.md), and by
//! how much depends on the data along every ray, so it is measured, not predicted
//! (`pipeline::quality::pilot::choose_slicing`). The flags decide only whether there is a choice
//! to make: there is none when they fix the end point (`--slicing object|image`,
//! `--classification post`, `--refine`, `--method reference`), when slabs cannot draw what they
//! ask (`--accum fixed`, `--perspective`) or when `--quality` chooses instead. The frame decides the
//! rest (a kernel with no slabs, a coarser level of detail, a stream too large to hold whole,
//! `pipeline::stages::hold`): the pilot is skipped there. Where
//! the pilot runs and `--subsample` is unset, it tries each candidate subsampled first
//! (`crate::plan::Plan::auto_subsample`).

use crate::args::{RenderArgs, SlicingArg};
use crate::plan::{End, Precision, DEFAULT_TARGET_DB};

/// [`DEFAULT_TARGET_DB`] where `args` leave the slicing to the pilot and `end` (what the flags
/// alone resolved) is float sheets; `None` otherwise.
pub fn slicing_target(end: &End, args: &RenderArgs) -> Option<f64> {
    let open = matches!(args.slicing, None | Some(SlicingArg::Auto));
    // A stream the pilot needs is held whole where it fits (`pipeline::stages::hold`); one
    // that is not has no volume to measure, and `choose_slicing` keeps object slicing.
    let drawable = args.perspective.is_none();
    (open && drawable && args.quality.is_none() && *end == End::Sheets(Precision::Float))
        .then_some(DEFAULT_TARGET_DB)
}
