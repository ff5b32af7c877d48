//! `prepare`, the pipeline's entry: load and set up everything the command line describes
//! ([`super::stages::prepare::prepare_as_asked`]), with `--lod auto` validated on a pilot where it can be
//! ([`super::quality::level_pilot::validated_auto`]).

use super::quality::level_pilot::validated_auto;
use super::stages::prepare::{prepare_as_asked, Prepared};
use crate::args::Lod;
use crate::plan::{Inputs, Request};
use crate::CliError;

/// Loads and sets up everything `request` describes (its [`Inputs`]). `--lod auto` on a volume
/// in memory keeps a coarser level only where a pilot, rendered with the request's plan,
/// measures it close to level 0; a stream keeps the geometric rule alone (it cannot be read
/// twice, and a file stream would be read once per level).
pub fn prepare<R: Request + ?Sized>(request: &R) -> Result<Prepared, CliError> {
    let args = request.inputs();
    if args.lod != Lod::Auto || args.quality || args.stream.is_some() {
        return prepare_as_asked(&args);
    }
    let at_full = Inputs {
        lod: Lod::Level(0),
        ..args.clone()
    };
    validated_auto(prepare_as_asked(&at_full)?, &args, &request.plan()?)
}
