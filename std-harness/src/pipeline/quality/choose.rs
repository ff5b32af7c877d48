//! `--quality DB`'s entry point: the choice against the reference `--quality-reference` names,
//! from the sheet model ([`super::model`], the default) or the continuous pilot
//! ([`super::pilot`]), applied to the render's arguments.
//!
//! # Against the sheet reference, with levels of detail
//! `--quality DB` aims at the f64 sheet reference **at full resolution**: a level's own error
//! counts. The volume is prepared at level 0; the levels `--lod` allows (every level whose
//! samples project at most [`MAX_SPACING_PX`] apart for `auto`, the one given otherwise) are
//! measured against level 0 on a pilot of rows ([`super::level_pilot`]); the table is then chosen
//! for what the level leaves. Errors add at most as RMSEs do (the triangle inequality), so with
//! r(x) = 10^(−x/20) the RMSE of a PSNR x:
//!
//! r(DB) ≥ r(level's bound) + t₀(0) + t₀(L) + t(L),
//!
//! where t₀ is the RMSE the footprint model predicts for the configuration the pilot renders
//! with (the default table, at level 0 and at level L: the pilot compares those two images, not
//! the references) and t(L) the chosen configuration's at level L. A level is accepted when that
//! holds with t(L) = t₀(L) (the pilot's own table is always available); the deepest accepted level
//! is rendered, with the cheapest configuration whose t(L) fits what is left. A level is never
//! chosen for a perspective view or a stream too large to hold whole (`pipeline::stages::hold`; an explicit `--lod N` with
//! `--quality` is refused there), and `auto` tries nothing where level 0's samples are already
//! more than a pixel apart.
//!
//! [`MAX_SPACING_PX`]: super::level_pilot::MAX_SPACING_PX

use super::config::Config;
use super::level_pilot::{candidate_levels, measure};
use super::model::{self as quality, choose, footprint_error, predict_db, Choice};
use crate::pipeline::ends::run::{render_frame, CoreFrame};
use crate::pipeline::stages::prepare::Prepared;
use crate::pipeline::stages::visible::FrameCache;
use crate::plan::{End, Lod, Method, Plan, QualityReference};
use crate::scene::Scene;
use crate::CliError;

/// The frame of `plan` for `p`: the one the default plan's pilot rendered and kept in `choice`
/// (taken out of it, so the next call renders), else rendered now with `cache`; and whether it
/// was the pilot's (its time is then the pilot's, not the frame's).
pub fn chosen_frame(
    p: &Prepared,
    plan: &Plan,
    choice: &mut Option<Choice>,
    cache: &mut FrameCache,
) -> Result<(CoreFrame, bool), CliError> {
    match choice.as_mut().and_then(|c| c.frame.take()) {
        Some(f) => Ok((*f, true)),
        None => Ok((render_frame(p, plan, cache)?, false)),
    }
}

/// `plan` with `--quality`'s choice applied, or the default plan's (`--slicing auto`,
/// [`super::pilot::choose_slicing`]); unchanged without either. The plan returned has neither
/// `quality` nor `auto_slicing`; with it the prepared render at the level chosen (`p` itself at
/// level 0) and the choice.
pub fn apply_quality(
    p: Prepared,
    args: &Scene,
    plan: &Plan,
) -> Result<(Prepared, Plan, Option<Choice>), CliError> {
    let Some(quality) = plan.quality else {
        let auto = match plan.auto_slicing {
            Some(target) => super::pilot::choose_slicing(&p, plan, target)?,
            None => None,
        };
        let Some((chosen, choice)) = auto else {
            let mut plan = plan.clone();
            plan.auto_slicing = None;
            return Ok((p, plan, None));
        };
        let e = p.frame.footprint.half_extent;
        crate::say!("{}", choice.explain(2.0 * e[0].max(e[1])));
        return Ok((p, chosen, Some(choice)));
    };
    let q = quality.target_db;
    let (p, choice) = match quality.reference {
        QualityReference::Sheets if matches!(plan.end, End::Slabs { .. }) => {
            return Err(CliError::input(
                "--quality aims at the sheet reference by default and chooses among the table \
                 configurations of object slicing; image slicing has no table to choose: give \
                 --slab, or --quality-reference continuous to choose the slab",
            ));
        }
        QualityReference::Sheets => choose_sheets(p, args, plan, q)?,
        r @ (QualityReference::Continuous | QualityReference::Field) => {
            if let Lod::Level(n @ 1..) = plan.lod {
                return Err(CliError::input(format!(
                    "--quality-reference {} measures against the integral at full resolution \
                     and chooses among full-resolution renders: drop --lod {n}",
                    quality::reference_name(r)
                )));
            }
            let c = super::pilot::choose_continuous(&p, args, plan, q, r)?;
            (p, c)
        }
    };
    let e = p.frame.footprint.half_extent;
    crate::say!("{}", choice.explain(2.0 * e[0].max(e[1])));
    let mut chosen = choice.config.plan(plan);
    chosen.quality = None;
    Ok((p, chosen, Some(choice)))
}

/// r(x): the RMSE of a PSNR of x dB (peak 1).
fn rmse(db: f64) -> f64 {
    10f64.powf(-db / 20.0)
}

/// The PSNR of an RMSE, dB.
fn db_of(rmse: f64) -> f64 {
    if rmse > 0.0 {
        -20.0 * rmse.log10()
    } else {
        f64::INFINITY
    }
}

/// The footprint model's predicted RMSE of configuration `c` at `p`'s frame.
fn table_rmse(p: &Prepared, c: &Config) -> Result<f64, CliError> {
    Ok(rmse(predict_db(footprint_error(p, c)?)))
}

/// The level and the table against the sheet reference at full resolution (see the module docs).
fn choose_sheets(
    p0: Prepared,
    args: &Scene,
    plan: &Plan,
    target: f64,
) -> Result<(Prepared, Choice), CliError> {
    quality::check_target(target)?;
    let explicit = match plan.lod {
        Lod::Level(n) => Some(n),
        Lod::Auto => None,
    };
    if p0.volume().is_none() {
        if let Some(n @ 1..) = explicit {
            return Err(crate::plan::quality_level_of_stream(n));
        }
        let c = choose(&p0, target)?;
        return Ok((p0, c));
    }
    if let (Some(n @ 1..), Some(_)) = (explicit, p0.frame.camera()) {
        return Err(crate::plan::no_level_in_perspective(n));
    }
    let levels = candidate_levels(&p0, explicit);
    if levels.is_empty() {
        let c = choose(&p0, target)?;
        return Ok((p0, c));
    }
    // What the pilot renders with: the plan's table (the default; --quality overrides it).
    let c0 = Config {
        method: Method::Robust,
        ..Config::of_plan(plan)
    };
    let allowed = rmse(target);
    let t00 = table_rmse(&p0, &c0)?;
    // Per level tried: the RMSE it spends (its bound and the pilot's two table errors), and
    // the pilot table's own error at that level (the least a final table is sure to need).
    let mut spends: Vec<(f64, f64)> = Vec::new();
    let pilot_plan = c0.plan(plan);
    let (pilot, mut accepted) = measure(&p0, args, &pilot_plan, &levels, |_, p, e| {
        let t0l = table_rmse(p, &c0)?;
        let spent = rmse(e.bound_db) + t00 + t0l;
        spends.push((spent, t0l));
        // An explicit level is rendered whatever it measures (said below).
        Ok(explicit.is_some() || spent + t0l <= allowed)
    })?;
    if let (Some(n), Some(&(spent, t0l))) = (explicit, spends.first()) {
        if !(spent + t0l <= allowed) {
            crate::say!(
                "--quality {target:.1} dB: --lod {n} is measured at {:.1} dB against full                  resolution (pilot bound); rendering it as asked",
                pilot.tried[0].1.bound_db
            );
        }
    }
    let (p, spent) = match accepted.pop() {
        Some(p) => {
            let i = pilot.tried.iter().position(|t| t.0 == p.level).unwrap_or(0);
            (p, spends[i].0)
        }
        None => (p0, 0.0),
    };
    let left = allowed - spent;
    let table_target = if left > 0.0 { db_of(left) } else { f64::MAX };
    let (mut choice, _) = quality::pick(&p, table_target.min(1e3))?;
    let table = rmse(choice.predicted_db);
    choice.target_db = target;
    choice.predicted_db = db_of(spent + table);
    if choice.predicted_db < target && explicit.is_none() {
        crate::say!(
            "--quality {target:.1} dB: no configuration is predicted to reach it; using the most \
             accurate ({:.1} dB)",
            choice.predicted_db
        );
    }
    choice.level = p.level;
    choice.level_pilot = Some(pilot);
    Ok((p, choice))
}
