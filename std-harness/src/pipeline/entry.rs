//! `prepare`, the pipeline's entry: load and set up everything the command line describes
//! ([`super::stages::prepare::prepare_as_asked`]; a stream a pilot needs held whole first,
//! [`super::stages::hold`]), with `--lod auto` validated on a pilot where it can be
//! ([`super::quality::level_pilot::validated_auto`]).

use super::quality::level_pilot::validated_auto;
use super::stages::hold::held;
use super::stages::prepare::{prepare_as_asked, Prepared};
use crate::io::stream::is_stdin;
use crate::plan::{Lod, Plan, Request};
use crate::scene::Scene;
use crate::CliError;

/// Loads and sets up everything `request` describes (its [`Scene`]). `--lod auto` keeps a
/// coarser level only where a pilot, rendered with the request's plan, measures it close to
/// level 0: on a volume in memory, or on a file streamed (read once per level tried); a pipe
/// keeps the geometric rule alone (it cannot be read twice).
///
/// A stream that a pilot needs is first read whole where it fits ([`super::stages::hold`]), so
/// that it is prepared, planned and rendered as the file it is would be.
pub fn prepare<R: Request + ?Sized>(request: &R) -> Result<Prepared, CliError> {
    // Resolved once, for the hold, the frame's resolution and the level pilot.
    prepare_scene(request.scene()?, &request.plan()?)
}

/// [`prepare`] of a scene and a plan already resolved (what the door opens with).
pub fn prepare_scene(mut args: Scene, plan: &Plan) -> Result<Prepared, CliError> {
    if args.stream.is_some() {
        if let Some(memory) = held(&args, plan)? {
            args = Scene {
                memory: Some(memory),
                stream: None,
                dims: None,
                sample_type: None,
                ..args
            };
        }
    }
    // A pipe is read once: it keeps the spacing rule's level, said so (a file stream is
    // measured as it streams).
    let piped = args.stream.as_deref().is_some_and(is_stdin);
    if plan.lod != Lod::Auto || plan.quality.is_some() || piped {
        let p = prepare_as_asked(&args, plan)?;
        if piped && plan.lod == Lod::Auto && p.level > 0 {
            crate::say!(
                "{}: --lod auto renders level {} by the spacing rule alone, not measured against \
                 level 0 (a pipe too large to hold is read once); give --lod 0 for full resolution",
                p.name,
                p.level
            );
        }
        return Ok(p);
    }
    let p = prepare_as_asked(&args, &plan.at_level_0())?;
    if p.labels.is_some() {
        // A label volume (or a multi-component one's palette) renders level 0: an average of
        // labels names none.
        return Ok(p);
    }
    validated_auto(p, &args, plan)
}
