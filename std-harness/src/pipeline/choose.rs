//! `--quality DB`'s entry point: the choice against the reference `--quality-reference` names,
//! from the sheet model ([`super::quality`], the default) or the continuous pilot
//! ([`super::pilot`]), applied to the render's arguments.

use super::prepare::Prepared;
use super::quality::{choose, Choice};
use crate::args::{QualityReferenceArg, RenderArgs};
use crate::CliError;

/// `args` with `--quality`'s choice applied (unchanged without `--quality`), and the choice.
pub fn apply_quality(
    p: &Prepared,
    args: &RenderArgs,
) -> Result<(RenderArgs, Option<Choice>), CliError> {
    let Some(q) = args.quality else {
        return Ok((args.clone(), None));
    };
    let choice = match args.quality_reference {
        QualityReferenceArg::Sheets if args.slicing == crate::args::SlicingArg::Image => {
            return Err(CliError::input(
                "--quality aims at the sheet reference by default and chooses among the table \
                 configurations of object slicing; image slicing has no table to choose: give \
                 --slab, or --quality-reference continuous to choose the slab",
            ));
        }
        QualityReferenceArg::Sheets => choose(p, q)?,
        QualityReferenceArg::Continuous => super::pilot::choose_continuous(p, args, q)?,
    };
    let e = p.frame.footprint.half_extent;
    crate::say!("{}", choice.explain(2.0 * e[0].max(e[1])));
    let mut chosen = choice.config.apply(args);
    chosen.quality = None;
    Ok((chosen, Some(choice)))
}
