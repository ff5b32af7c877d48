//! `--quality DB`: the cheapest configuration (table size, lookup, method, accumulation) expected
//! to reach DB of PSNR against the f64 reference for this scene and view (the default,
//! `--quality-reference sheets`; against the continuous integral, see [`super::pilot`]).
//!
//! # The model
//! An image's error comes from its footprints' error: every pixel sums footprint weights, so a
//! relative footprint error e shows up as an image error of about e times the local signal. The
//! model therefore measures, for each candidate, the **footprint error at this view**: one voxel
//! with this frame's footprint (its size in pixels, its anisotropy and orientation), splatted
//! through the candidate's table and lookup at a sub-pixel position and compared with the exact
//! f64 footprint (max |core − reference| / reference peak). That takes a few milliseconds per
//! candidate and captures both what the table resolution can resolve and how the footprint's
//! size in pixels samples it (`footprint chart`'s stability panel (c) shows that dependence).
//! The image PSNR is then predicted as
//!
//! `PSNR ≈ K − 20·log₁₀(e)`,
//!
//! K calibrated from `footprint chart` sweeps of every shared volume (docs/accuracy.md, "Choosing the
//! configuration"): K is the smallest PSNR + 20·log₁₀(e) measured over all of them, less a margin,
//! so the prediction errs low. Fixed-point accumulation adds < 10⁻⁵ of error (114–144 dB against
//! float), so it shares the float prediction.
//!
//! # Cost
//! Candidates are tried cheapest first, in the order of `RELATIVE_COST`, measured frame times
//! relative to the fastest configuration (`footprint chart`); at equal cost bilinear lookup
//! comes before nearest, and a smaller table before a larger one.

use super::config::Config;
use super::level_pilot::LevelPilot;
pub use super::sampling::Estimate;
use crate::io::json::Json;
use crate::pipeline::stages::bands::CoreFrame;
use crate::pipeline::stages::prepare::Prepared;
use crate::plan::{Method, Precision, QualityReference};
use crate::reference::ReferenceFootprint;
use crate::CliError;
use footprint::splat::{splat, Direct, ImageMut, Sampler};
use footprint::Lookup;
use footprint::{Footprint, ViewTable};

/// K, dB: the calibration constant of `PSNR ≈ K − 20·log₁₀(e)` (see the module docs).
pub const K_DB: f64 = CALIBRATED_K_DB - MARGIN_DB;
/// The smallest PSNR + 20·log₁₀(e) measured in the calibration sweeps: every shared volume at
/// 512×512, views 0,0,0 and 30,20,0, all 56 configurations (560 renders); the minimum, 21.8 dB,
/// is `heart` seen along z with a 5×5 nearest table. (Over those sweeps K ranged up to 61.7 dB:
/// the model is deliberately pessimistic.)
pub const CALIBRATED_K_DB: f64 = 21.8;
/// Safety margin below the calibrated value, dB.
pub const MARGIN_DB: f64 = 1.0;

/// Frame time relative to the fastest configuration, by (lookup, method, accumulation): for each
/// class, the median over its configurations of frame time over the chart's fastest
/// configuration, the mean of `footprint chart` of the built-in scene and of `headsq` at 512×512
/// (re-measured 2026-11-24 after the small-box splat, both cores; `docs/charts/default`,
/// `docs/charts/headsq`). Table size hardly matters within a class, and, since the view table is
/// sampled into phase stencils once per view, neither does the lookup: the two float view-table
/// classes measured 1.23 / 1.19 (bilinear / nearest, built-in scene) and 1.24 / 1.22 (`headsq`),
/// a difference inside the machine's run-to-run noise, so they share their mean, and at equal
/// cost the bilinear lookup (20–25 dB more accurate) is tried first ([`candidates`]).
///
/// The charts re-drawn later the same day (after the window splat and the scaled-centre phases)
/// put the classes in the same order except the first two: view-table float nearest 1.24 / 1.40
/// against bilinear 1.43 / 1.42 (on the built-in scene nearest is 13–15 % faster at equal N;
/// why is not measured), fixed 2.78–3.13, direct 5.46–9.86. These constants are kept until
/// `--quality`'s validation is re-run with nearest first: the 45 `verify --quality` runs CI
/// makes (every shared volume, three views, 30/40/50 dB) all met their targets with it, but its
/// choices and their documentation would change.
pub const RELATIVE_COST: [(Lookup, Method, Precision, f64); 8] = [
    (Lookup::Bilinear, Method::Robust, Precision::Float, 1.22),
    (Lookup::Nearest, Method::Robust, Precision::Float, 1.22),
    (Lookup::Nearest, Method::Robust, Precision::Fixed, 2.21),
    (Lookup::Bilinear, Method::Robust, Precision::Fixed, 2.26),
    (Lookup::Nearest, Method::Direct, Precision::Float, 4.28),
    (Lookup::Nearest, Method::Direct, Precision::Fixed, 5.32),
    (Lookup::Bilinear, Method::Direct, Precision::Float, 5.39),
    (Lookup::Bilinear, Method::Direct, Precision::Fixed, 6.73),
];

/// What `--quality` chose, and why.
#[derive(Clone, Debug)]
pub struct Choice {
    pub target_db: f64,
    pub config: Config,
    /// Predicted PSNR of the choice, dB: the footprint model's (sheets), or the pilot's bound
    /// (continuous, [`super::pilot`]).
    pub predicted_db: f64,
    /// What the target is measured against.
    pub reference: QualityReference,
    /// Its footprint error at this view (sheets only).
    pub footprint_error: Option<f64>,
    /// Cheaper candidates and their predictions, cheapest first.
    pub rejected: Vec<(Config, f64)>,
    /// The pilot that measured the candidates (continuous only).
    pub pilot: Option<Pilot>,
    /// The level of detail rendered (0 = full resolution).
    pub level: u32,
    /// The pilot that measured the levels against full resolution (sheets, when levels were
    /// candidates; see [`super::level_pilot`]).
    pub level_pilot: Option<LevelPilot>,
    /// Made by the default plan (`--slicing auto`, [`super::pilot::choose_slicing`]), not by
    /// `--quality`.
    pub by_default: bool,
    /// The chosen plan's frame as the default plan's pilot rendered it, whole (the command
    /// takes it instead of rendering the frame again); `None` from `--quality`, and where no
    /// candidate reached the target.
    pub frame: Option<Box<CoreFrame>>,
}

impl Choice {
    /// One line for the terminal.
    pub fn explain(&self, footprint_px: f32) -> String {
        let rejected = match self.rejected.first() {
            Some((c, db)) => format!(
                "; {} cheaper configuration{} {} below it (the cheapest, {}, {:.1} dB)",
                self.rejected.len(),
                if self.rejected.len() == 1 { "" } else { "s" },
                if self.pilot.is_some() {
                    "measured"
                } else {
                    "predicted"
                },
                c.label(),
                db
            ),
            None => "; it is the cheapest configuration".into(),
        };
        let why = match (&self.pilot, self.footprint_error) {
            (Some(pilot), _) => format!(
                "measured against the continuous integral{} on a pilot of {} sampled pixels \
                 (one per {}x{} cell){}: estimate {:.1} dB, {:.1} dB at its bound; pilot \
                 reference {:.2} s, candidate renders ({}) {:.2} s",
                match pilot.field_size {
                    Some(n) => format!(" of the field sampled {n}^3"),
                    None => String::new(),
                },
                pilot.pixels,
                pilot.stride,
                pilot.stride,
                if pilot.converged { "" } else { " (not converged)" },
                pilot.tried.iter().find(|t| t.0 == self.config).map_or(f64::NAN, |t| t.1.estimate_db),
                self.predicted_db,
                pilot.reference_seconds,
                pilot.tried.len(),
                pilot.render_seconds
            ),
            (None, e) => format!(
                "predicted {:.1} dB: footprint error {:.2e} at this view's {:.1}-px footprint, K = {:.1} dB",
                self.predicted_db,
                e.unwrap_or(f64::NAN),
                footprint_px,
                K_DB
            ),
        };
        format!(
            "{} {:.1} dB ({}): chose {}{} ({why}){rejected}{}",
            if self.by_default {
                "default plan (--slicing auto),"
            } else {
                "--quality"
            },
            self.target_db,
            reference_name(self.reference),
            self.config.label(),
            match self.level {
                0 => String::new(),
                l => format!(" at level {l}"),
            },
            self.level_reason(),
        )
    }

    /// What the level pilot measured, for the terminal (empty without one).
    fn level_reason(&self) -> String {
        let Some(lp) = &self.level_pilot else {
            return String::new();
        };
        let tried: Vec<String> = lp
            .tried
            .iter()
            .map(|(l, e)| {
                format!(
                    "level {l} {:.1} dB (bound {:.1}){}",
                    e.estimate_db,
                    e.bound_db,
                    if *l > self.level { ", refused" } else { "" }
                )
            })
            .collect();
        format!(
            "; levels measured against level 0 on {} of {} rows ({:.2} s): {}",
            lp.rows,
            lp.height,
            lp.seconds,
            tried.join(", ")
        )
    }
}

/// The name the command line and the JSON use for `r`.
pub fn reference_name(r: QualityReference) -> String {
    r.name().to_string()
}

/// PSNR predicted from a footprint error `e`.
pub fn predict_db(e: f64) -> f64 {
    if e > 0.0 {
        K_DB - 20.0 * e.log10()
    } else {
        f64::INFINITY
    }
}

fn cost(c: &Config) -> f64 {
    RELATIVE_COST
        .iter()
        .find(|(l, m, a, _)| *l == c.lookup && *m == c.method && *a == c.accum)
        .map_or(f64::INFINITY, |e| e.3)
}

/// The candidates for `frame`, cheapest first: by [`RELATIVE_COST`], then at equal cost bilinear
/// lookup before nearest, then a smaller table first (it builds faster and fits cache better).
pub fn candidates(frame: &footprint::frame::FrameSetup) -> Vec<Config> {
    let mut v = Config::for_frame(frame);
    let nearest = |c: &Config| c.lookup == Lookup::Nearest;
    v.sort_by(|a, b| {
        cost(a)
            .total_cmp(&cost(b))
            .then(nearest(a).cmp(&nearest(b)))
            .then(a.table.cmp(&b.table))
    });
    v
}

/// Sub-pixel positions (fractions of a pixel) at which the footprint error is measured.
const PHASES: [[f32; 2]; 4] = [[0.31, 0.17], [0.77, 0.59], [0.05, 0.88], [0.52, 0.41]];

/// The footprints the model measures, as (the core's footprint, its map V·G or Jacobian, f64):
/// an orthographic frame's one footprint; for a perspective frame, the footprints of the
/// voxel-centre box's nearest and farthest corners and of its centre (footprint sizes vary over
/// the image; the worst of them is taken).
fn footprints(p: &Prepared) -> Result<Vec<(Footprint, glam::DMat3)>, CliError> {
    let f = &p.frame;
    let Some(cam) = f.camera() else {
        return Ok(vec![(f.footprint, f.grid_to_screen.as_dmat3())]);
    };
    let d = f.dims.map(|n| (n - 1) as f32);
    let mut points = footprint::geometry::box_corners(f.dims, 0.0).map(|c| c.to_array());
    let depth = |i: &[f32; 3]| f.affine_position(*i).z;
    points.sort_by(|a, b| depth(a).total_cmp(&depth(b)));
    let picks = [points[0], d.map(|x| x * 0.5), points[7]];
    picks
        .iter()
        .map(|&i| {
            let pr = cam
                .project(f.affine_position(i), &f.grid_to_screen)
                .ok_or_else(|| CliError::input(format!("{}: a voxel is behind the eye", p.name)))?;
            let fp = Footprint::with_sheet_axis(&p.kernel, &pr.jacobian, p.options, f.sheet_axis)
                .map_err(|e| CliError::input(format!("{}: {e}", p.name)))?;
            Ok((fp, pr.jacobian.as_dmat3()))
        })
        .collect()
}

/// Max |core − reference| / reference peak for one voxel of `p`'s footprint through a table of
/// `c`'s size, lookup and method, over four sub-pixel positions (nearest lookup's error depends
/// strongly on where the centre falls); for a perspective frame, the worst over its
/// `footprints`.
pub fn footprint_error(p: &Prepared, c: &Config) -> Result<f64, CliError> {
    let mut worst = 0.0f64;
    for (fp, map) in footprints(p)? {
        worst = worst.max(one_footprint_error(p, c, fp, &map)?);
    }
    Ok(worst)
}

fn one_footprint_error(
    p: &Prepared,
    c: &Config,
    fp: Footprint,
    map: &glam::DMat3,
) -> Result<f64, CliError> {
    let e = fp.half_extent[0].max(fp.half_extent[1]);
    let side = ((2.0 * e).ceil() as usize + 6).clamp(16, 256);
    let min_r = f64::from(p.options.min_radius_px);
    let reference = ReferenceFootprint::with_sheet_axis(&p.kernel, map, min_r, p.frame.sheet_axis)
        .map_err(|e| CliError::input(format!("{}: {e}", p.name)))?;
    /// The worst footprint error through tables of side N.
    struct Worst<'a> {
        p: &'a Prepared,
        c: &'a Config,
        fp: Footprint,
        reference: &'a ReferenceFootprint,
        side: usize,
    }
    impl crate::dispatch::TableSize for Worst<'_> {
        type Output = f64;
        fn run<const N: usize>(self) -> Result<f64, CliError> {
            let Worst {
                p,
                c,
                fp,
                reference,
                side,
            } = self;
            let lookup = c.lookup;
            let mut worst = 0.0f64;
            let generic = Box::new(footprint::GenericTable::<N>::build(p.kernel));
            let sampler: Box<dyn Sampler> = if c.method == Method::Direct {
                Box::new(Direct {
                    footprint: fp,
                    table: &*generic,
                    lookup,
                })
            } else {
                Box::new(ViewTable::<N>::build(&fp, &generic, lookup, lookup))
            };
            for phase in PHASES {
                let centre = [side as f32 / 2.0 + phase[0], side as f32 / 2.0 + phase[1]];
                let mut want = vec![0.0f64; side * side];
                let at = [f64::from(centre[0]), f64::from(centre[1])];
                reference.splat(at, side, side, &mut want);
                let mut got = vec![0.0f32; side * side];
                let mut image = ImageMut::new(&mut got, side, side, side)?;
                splat(&*sampler, centre, &1.0f32, &mut image)?;
                let peak = want.iter().fold(0.0f64, |m, &v| m.max(v));
                if peak > 0.0 {
                    let e = got
                        .iter()
                        .zip(&want)
                        .fold(0.0f64, |m, (&g, &w)| m.max((f64::from(g) - w).abs()));
                    worst = worst.max(e / peak);
                }
            }
            Ok(worst)
        }
    }
    let work = Worst {
        p,
        c,
        fp,
        reference: &reference,
        side,
    };
    crate::dispatch::with_size(c.table, work)
}

/// `Ok` if `target_db` is a PSNR `--quality` can aim at.
pub fn check_target(target_db: f64) -> Result<(), CliError> {
    if target_db.is_finite() && target_db > 0.0 {
        Ok(())
    } else {
        Err(CliError::input(format!(
            "--quality {target_db}: expected a PSNR in dB above 0"
        )))
    }
}

/// The cheapest configuration predicted to reach `target_db` against the sheet reference for
/// `p`; the most accurate one if none is, said so.
pub fn choose(p: &Prepared, target_db: f64) -> Result<Choice, CliError> {
    let (choice, reached) = pick(p, target_db)?;
    if !reached {
        crate::say!(
            "--quality {target_db:.1} dB: no configuration is predicted to reach it; using the most accurate ({:.1} dB)",
            choice.predicted_db
        );
    }
    Ok(choice)
}

/// [`choose`] without the message: the choice, and whether it is predicted to reach the target.
pub fn pick(p: &Prepared, target_db: f64) -> Result<(Choice, bool), CliError> {
    check_target(target_db)?;
    let mut rejected = Vec::new();
    let mut best: Option<(Config, f64, f64)> = None;
    let mut errors = std::collections::HashMap::new();
    for c in candidates(&p.frame) {
        // Fixed and float share a table error: measure it once.
        let key = (c.table, c.lookup, c.method);
        let e = match errors.get(&key) {
            Some(&e) => e,
            None => {
                let e = footprint_error(p, &c)?;
                errors.insert(key, e);
                e
            }
        };
        let db = predict_db(e);
        if db >= target_db {
            let choice = Choice {
                target_db,
                config: c,
                predicted_db: db,
                reference: QualityReference::Sheets,
                footprint_error: Some(e),
                rejected,
                pilot: None,
                level: 0,
                level_pilot: None,
                by_default: false,
                frame: None,
            };
            return Ok((choice, true));
        }
        if best.is_none_or(|b| db > b.2) {
            best = Some((c, e, db));
        }
        rejected.push((c, db));
    }
    let (config, e, db) = best.expect("at least one candidate");
    let choice = Choice {
        target_db,
        config,
        predicted_db: db,
        reference: QualityReference::Sheets,
        footprint_error: Some(e),
        rejected: Vec::new(),
        pilot: None,
        level: 0,
        level_pilot: None,
        by_default: false,
        frame: None,
    };
    Ok((choice, false))
}

/// The JSON record of a `--quality` choice or of the default plan's: `by` (`quality` or
/// `default`), `target_db`, `reference` (`sheets`, `continuous` or `field`), `predicted_db`, `level`, `chosen`; with sheets `footprint_error` and `k_db`
/// (the table's, at the level chosen) and, when levels were measured, `level_pilot`; with
/// continuous `pilot` (`pixels`, `stride`, `converged`, seconds, and each candidate tried).
pub fn quality_json(c: &Choice) -> Json {
    let mut j = Json::object()
        .str("by", if c.by_default { "default" } else { "quality" })
        .num("target_db", c.target_db)
        .str("reference", &reference_name(c.reference))
        .num("predicted_db", c.predicted_db);
    if let Some(e) = c.footprint_error {
        j = j.num("footprint_error", e).num("k_db", K_DB);
    }
    if let Some(p) = &c.pilot {
        j = j.obj("pilot", pilot_json(p));
    }
    if let Some(lp) = &c.level_pilot {
        j = j.obj("level_pilot", level_pilot_json(lp));
    }
    j.num("level", f64::from(c.level))
        .str("chosen", &c.config.label())
}

/// `j` with an estimate's `estimate_db` and `bound_db`.
fn with_estimate(j: Json, e: &Estimate) -> Json {
    j.num("estimate_db", e.estimate_db)
        .num("bound_db", e.bound_db)
}

/// The JSON record of a level pilot: `rows`, `height`, `base_seconds`, `seconds`, and `tried`,
/// each level's `level`, `estimate_db` and `bound_db` against level 0.
fn level_pilot_json(p: &LevelPilot) -> Json {
    Json::object()
        .num("rows", p.rows as f64)
        .num("height", p.height as f64)
        .num("base_seconds", p.base_seconds)
        .num("seconds", p.seconds)
        .arr_obj(
            "tried",
            p.tried
                .iter()
                .map(|(l, e)| with_estimate(Json::object().num("level", f64::from(*l)), e))
                .collect(),
        )
}

/// How the pilot went.
#[derive(Clone, Debug)]
pub struct Pilot {
    /// Sampled output pixels the reference was marched through (rays per pixel: the
    /// supersampling squared).
    pub pixels: usize,
    /// Of those, the first stage's: a candidate is measured on these alone unless that leaves
    /// it undecided ([`super::pilot`], "Stages").
    pub first_pixels: usize,
    /// Cell side S, pixels.
    pub stride: usize,
    /// Whether the pilot reference converged (`reference::continuous::CONVERGED_DB`).
    pub converged: bool,
    /// Seconds of the pilot reference, and of the candidate renders.
    pub reference_seconds: f64,
    pub render_seconds: f64,
    /// Every candidate rendered, in order, with its estimate.
    pub tried: Vec<(Config, Estimate)>,
    /// Against `--quality-reference field`: the side N of the finer sampling (N³).
    pub field_size: Option<usize>,
}

/// The JSON record of a pilot: `pixels`, `first_pixels`, `stride`, `converged`, `reference_seconds`,
/// `render_seconds`, `field_size` (against the field reference), and `tried`, each candidate's
/// `config`, `estimate_db` and `bound_db`.
fn pilot_json(p: &Pilot) -> Json {
    let j = match p.field_size {
        Some(n) => Json::object().num("field_size", n as f64),
        None => Json::object(),
    };
    j.num("pixels", p.pixels as f64)
        .num("first_pixels", p.first_pixels as f64)
        .num("stride", p.stride as f64)
        .bool("converged", p.converged)
        .num("reference_seconds", p.reference_seconds)
        .num("render_seconds", p.render_seconds)
        .arr_obj(
            "tried",
            p.tried
                .iter()
                .map(|(c, e)| with_estimate(Json::object().str("config", &c.label()), e))
                .collect(),
        )
}
