//! `--quality DB --quality-reference continuous`: the cheapest configuration, slicing included,
//! whose image is measured to reach DB of PSNR against the continuous volume-rendering integral.
//!
//! # Why a measurement, not a model
//! Against the sheet reference the error is the table's, and one footprint predicts it
//! ([`super::model`]). Against the integral, object slicing's error is dominated by compositing
//! each kernel whole in one sheet, which depends on the data along every ray (27.9–77.9 dB over
//! the shared volumes at 256×256, docs/accuracy.md, "Image-aligned slicing"): no one-voxel model sees it.
//! So the choice is measured, on a **pilot**:
//!
//! 1. **Rays.** The output image is cut into S×S cells, S = ⌈√(W·H / [`PILOT_RAYS`])⌉, and one
//!    pixel per cell, at a fixed pseudo-random position inside it, is taken (stratified
//!    sampling: every part of the image is represented, and no sampling pattern can line up
//!    with a periodic error). The continuous reference is marched through those pixels only
//!    (each k×k block of a supersampled frame), converged by `verify --reference continuous`'s
//!    rule with its first two passes nested (`reference::continuous`, "The pilot's march"),
//!    about 1/S² of its cost.
//! 2. **Candidates**, cheapest first: object slicing with the table configuration the sheet
//!    model picks for DB, then the one it picks for DB + [`TABLE_HEADROOM_DB`] (so that the
//!    table's share of the error is negligible) if it differs; then, against `field` only
//!    ([`super::field`]: the grid's own field is what refinement moves away from), that table
//!    with the grid refined (`--refine 0`, the paper's adaptive re-sampling, 1.3–2.4× an
//!    unrefined frame on docs/modes.md's refinement chart), where refinement can add samples
//!    ([`crate::pipeline::ends::refine::worth_trying`]: float, the robust method, orthographic, in memory, full
//!    resolution, and grid steps projecting at least twice [`crate::pipeline::ends::refine::MIN_STEP_PX`]);
//!    then image slicing (3–13× an object frame) at each thickness of `Config::SLABS` the
//!    frame accepts, thickest (fastest) first. With `--slicing image` only the slabs are tried;
//!    a perspective frame or a non-Gaussian kernel has no slabs.
//! 3. **Measure.** Each candidate renders the whole frame; its squared error (RGB mean) at the n
//!    sampled pixels has mean m and standard deviation s. The estimate is 10·log₁₀(1/m) and the
//!    decision uses the upper confidence bound of the image's MSE, m + [`Z`]·s/√n·√(1 − n/N)
//!    (N the image's pixels; the bound is m itself when every pixel is sampled). The first
//!    candidate whose bound reaches DB is chosen; if none does, the most accurate one, said so.
//!
//! # Stages
//! Against the grid's own integral the reference is marched in stages ([`stages`]): first the
//! sampled pixels of the cells whose column and row are both multiples of 4 (a stratified
//! sample of its own at four times the cell side, about a sixteenth: 256 pixels at 256² and
//! 512²), then those of the other cells whose column and row are both even (with the first, a
//! quarter), then the rest; an early stage under [`MIN_FIRST_STAGE`] pixels is skipped. A
//! candidate is decided on the pixels marched so far when its upper bound reaches DB plus that
//! stage's margin ([`STAGE_MARGINS_DB`]: 5 dB on the sixteenth, 1 dB on the quarter, none on the
//! whole sample: taken) or its lower bound, m − Z·s/√n·√(1 − n/N), does not reach DB (more
//! pixels would not lift the estimate past it: rejected); otherwise the reference is marched
//! through the next stage's pixels (through the same field, built once and held until the last
//! stage: at most 16 bytes a voxel (`reference::sparse` keeps only the blocks holding a voxel
//! that can be seen), so stages only where that bound fits the visible lists' budget) and the
//! candidate, and every later one, is measured on all the pixels marched. A scene far from the
//! target on either side costs a sixteenth of the reference, one near it the whole (the pilot
//! reference took 0.00–0.08 s at 256² on the shared volumes, `docs/perf/default-plan.csv`).
//! Looking three times at Z = 3 leaves the chance of taking a candidate that misses DB at most
//! three times one look's, before the margins.
//!
//! **Why margins.** A part of the sample can miss the few pixels that carry most of the squared
//! error, and understate the standard error with them: the normal bound does not hold there.
//! - *The sixteenth.* Taking a candidate there on its bound alone took object slicing for the
//!   CT head (30,20,0, emission, 256²) on a bound of 44.9 dB whose whole image measured 43.9 dB.
//!   With a 2 dB margin, over 72 choices (the shared volumes and the built-in scene at 32³, six
//!   views, emission and Phong, 256², `docs/perf/pilot-sixteenth-2db.csv`: `verify --reference
//!   continuous` with `STAGE_MARGINS_DB` set to [2, 1]) the sixteenth decided 40, and its bound
//!   lay above the whole image's PSNR in 5 of them, by at most 2.37 dB (neghip, 75,-40,20,
//!   emission: 48.59 against 46.22 dB; its estimate was 6.45 dB above the whole image at worst).
//!   So the sixteenth takes a candidate only 5 dB past DB, twice that miss; 29 of those 40 had a
//!   bound that far above 44 dB.
//! - *The quarter.* With the pilot's march nested, the hydrogen orbital (CI's
//!   `--quality-reference continuous` step: 256², 75,-40,20, `--quality 55`) had a bound of
//!   55.0 dB on the quarter's 1 024 pixels for object slicing, and its whole image measured
//!   54.53 dB. So the quarter takes a candidate only 1 dB (a factor of 1.26 in MSE, twice that
//!   miss) past DB; nearer, the whole sample decides (it rejected that one at 53.2 dB).
//!
//! Rejecting early needs no margin: a wrong rejection costs time, never accuracy.
//!
//! **What the sixteenth saved.** `footprint bench --frames 1 --threads 1`, 512², 30,20,0, the
//! peers' volumes (docs/performance.md), 3 rounds alternated with 3568c24's binary, same plans
//! (2026-12-05): the default's fresh frame on the CT head 46.7–50.1 → 24.5–26.4 ms (its pilot
//! reference 11 ms on the sixteenth's 256 pixels), the blobs 132.1–144.5 → 114.4–116.4 ms, the
//! walnut 62.0–65.5 → 62.8–67.1 ms (undecided on the sixteenth, taken on the quarter). On
//! `benches/default_plan.sh` (20 cases, 256²) and CI's `--quality-reference continuous` step (20
//! choices) every choice and every whole-image figure stayed the same, to the digit; over 71
//! further `--quality 44` and `50` choices (`tools/validate_quality_continuous.py`, the shared
//! volumes and the built-in scene at 24³, views 0,0,0, 120,60,0 and -45,10,30, 256²) none
//! missed its target against the whole image.
//!
//! Under `--quality DB` the winner is rendered again by the command (its pilot render is not
//! kept, as its choice may change the level), so `--quality DB --quality-reference continuous`
//! costs the pilot reference, one frame per candidate tried, and the frame. The default stays
//! `--quality-reference sheets`: it costs milliseconds, and the sheet reference is what the
//! table configuration alone controls.
//!
//! # The default plan
//! [`choose_slicing`] runs the same pilot for `--slicing auto` (the default) at
//! [`crate::plan::DEFAULT_TARGET_DB`], with other candidates: the frame as the flags ask for it
//! (object slicing, its own table), read at the nearest phase first where that is a frame of its
//! own (`--phase-lookup auto`, blended stencils: [`footprint::stencil::PhaseLookup`], one
//! stencil row per pixel instead of four's blend: object re-renders 1.01–1.22× faster at 512² on
//! the peers' volumes, −0.01 to −0.44 dB against the continuous model, docs/modes.md), then
//! blended, then the slabs, thickest first; where `--subsample` is unset and `auto` would render
//! at 1/s of the size, s > 1, each of those subsampled first, in the same order, the full-size
//! ones only if none of those reaches the target (1/s² of the pixel updates; −0.46 to +0.03 dB
//! against the continuous model on docs/subsample-validation.md's 24 cases; the CT head's and
//! the walnut's default re-renders 3.7× and 1.7× faster at 512², `footprint bench --frames 6
//! --orbit 2 --threads 1` against `--subsample 1`, 4 pairs). Its chosen frame is kept in
//! the choice ([`Choice::frame`]) and is the command's frame, not rendered again (unless no
//! candidate reached the target: the most accurate is then rendered again).

use super::config::Config;
use super::model::{self as quality, Choice, Estimate, Pilot};
use super::pixel_sample::{decide, stages, StageEnd, Verdict};
pub use super::pixel_sample::{
    estimate, sample_pixels, MIN_FIRST_STAGE, PILOT_RAYS, STAGE_MARGINS_DB, Z,
};
use crate::pipeline::ends::continuous::{continuous_at, PilotReference};
use crate::pipeline::ends::run::render_frame;
use crate::pipeline::stages::bands::CoreFrame;
use crate::pipeline::stages::prepare::Prepared;
use crate::pipeline::stages::visible::FrameCache;
use crate::plan::{End, Plan, QualityReference};
use crate::scene::Scene;
use crate::CliError;
use std::time::Instant;

/// The bytes the pilot's continuous field holds for `volume` (each voxel's classified RGBA, 16
/// bytes) and the budget it must fit: the visible lists' ([`list_budget`]). The default plan
/// measures only where it fits, and the stages hold the field only where it fits.
///
/// [`list_budget`]: crate::pipeline::stages::visible::list_budget
fn field_bytes(volume: &crate::io::volume::Volume) -> (usize, usize) {
    crate::pipeline::stages::visible::pilot_field(volume.len(), volume.bytes())
}

/// The second object-slicing candidate aims the table model this much above the target, dB.
pub const TABLE_HEADROOM_DB: f64 = 10.0;

/// The candidates for `p` aiming at `target_db` (see the module docs), cheapest first; the
/// refined one only against the `field` reference.
fn candidates(
    p: &Prepared,
    base: &Plan,
    target_db: f64,
    reference: QualityReference,
) -> Result<Vec<Config>, CliError> {
    let mut v: Vec<Config> = Vec::new();
    if !matches!(base.end, End::Slabs { .. }) {
        for aim in [target_db, target_db + TABLE_HEADROOM_DB] {
            let c = quality::pick(p, aim)?.0.config;
            if !v.contains(&c) {
                v.push(c);
            }
        }
    }
    if let (Some(last), QualityReference::Field) = (v.last().copied(), reference) {
        if crate::pipeline::ends::refine::worth_trying(p, &last.refined().plan(base)) {
            v.push(last.refined());
        }
    }
    let mut slabs = Config::slabs(&p.frame, &p.kernel);
    slabs.sort_by_key(|c| std::cmp::Reverse(c.slab_quarters));
    v.extend(slabs);
    if v.is_empty() {
        return Err(CliError::input(format!(
            "{}: --quality-reference continuous with --slicing image: no slab thickness of {:?} \
             spacings can render this frame (image slicing needs a gaussian kernel and an \
             orthographic view)",
            p.name,
            super::config::SLABS
        )));
    }
    Ok(v)
}

/// The cheapest candidate measured to reach `target_db` against the continuous integral of
/// `p`'s grid (`reference` continuous) or of the finer sampling of its field (`field`,
/// [`super::field`]).
pub fn choose_continuous(
    p: &Prepared,
    args: &Scene,
    base: &Plan,
    target_db: f64,
    reference: QualityReference,
) -> Result<Choice, CliError> {
    quality::check_target(target_db)?;
    let fine = match reference {
        QualityReference::Field => Some(super::field::prepare_field(args, base)?),
        _ => None,
    };
    let candidates = candidates(p, base, target_db, reference)?
        .into_iter()
        .map(|c| (c, c.plan(base)))
        .collect();
    let mut run = Run::new(
        p,
        fine.as_ref().unwrap_or(p),
        target_db,
        reference,
        base.threads,
    )?;
    drop(fine);
    if reference == QualityReference::Field {
        run.field_size = Some(args.field_size);
    }
    let mut choice = run.measure(candidates, false)?.1;
    // `--quality`'s winner is rendered again by the command (its choice may change the level).
    choice.frame = None;
    Ok(choice)
}

/// The default plan (`--slicing auto`, [`crate::plan::DEFAULT_TARGET_DB`]): `base` itself
/// (object slicing, its own table) where the pilot measures it at `target_db` or more against
/// the continuous integral of `p`'s grid, else the thickest slabs that reach it (the most
/// accurate measured if none does, said so); returned with `auto_slicing` cleared, and the
/// choice. `None` where there is nothing to choose: no slab thickness can draw `p`'s frame (a
/// kernel other than the gaussian), or `p` renders a coarser level of detail (its own pilot
/// validated it against level 0, `super::level_pilot`).
pub fn choose_slicing(
    p: &Prepared,
    base: &Plan,
    target_db: f64,
) -> Result<Option<(Plan, Choice)>, CliError> {
    let Some(volume) = p.volume() else {
        return Ok(None);
    };
    let mut slabs = Config::slabs(&p.frame, &p.kernel);
    if slabs.is_empty() || p.level > 0 {
        return Ok(None);
    }
    // Past the budget the visible lists get, the default renders object slicing unmeasured and
    // says so.
    let (field, budget) = field_bytes(volume);
    if field > budget {
        crate::say!(
            "default plan (--slicing auto): object slicing, not measured: the pilot's continuous \
             reference would hold {} MiB for this volume (budget {} MiB); give --slicing image \
             for slabs",
            field >> 20,
            budget >> 20
        );
        return Ok(None);
    }
    slabs.sort_by_key(|c| std::cmp::Reverse(c.slab_quarters));
    let mut object = base.clone();
    object.auto_slicing = None;
    object.auto_subsample = false;
    let own = Config::of_plan(base);
    let mut candidates = Vec::new();
    if nearest_phase_differs(p, base) {
        let nearest = own.nearest();
        candidates.push((nearest, nearest.plan(&object)));
    }
    candidates.push((own, object.clone()));
    candidates.extend(slabs.into_iter().map(|c| (c, c.plan(&object))));
    if subsampling_differs(p, base)? {
        // Each candidate subsampled first (1/s² of its pixel updates), in the same order; the
        // full-size ones follow only where none of those reaches the target.
        let small: Vec<_> = candidates
            .iter()
            .map(|(c, _)| c.subsampled())
            .map(|c| (c, c.plan(&object)))
            .collect();
        candidates.splice(0..0, small);
    }
    let mut run = Run::new(p, p, target_db, QualityReference::Continuous, base.threads)?;
    Ok(Some(run.measure(candidates, true)?))
}

/// Whether `base`'s object slicing of `p` read at the nearest phase is a frame of its own: the
/// phase lookup left to the pilot (`--phase-lookup auto`), a plan that reads phase stencils
/// ([`Plan::reads_phase_stencils`]) in an orthographic frame, and a footprint whose stencils are
/// blended (an edged one is blended whatever the lookup, [`footprint::stencil::Plan::edged`]).
fn nearest_phase_differs(p: &Prepared, base: &Plan) -> bool {
    base.phase_lookup.is_none()
        && base.reads_phase_stencils()
        && p.frame.camera().is_none()
        && footprint::stencil::plan_for(&p.frame.footprint, base.phases).is_some_and(|s| !s.edged)
}

/// Whether the default plan may subsample `p` (`--subsample` unset, [`Plan::auto_subsample`]) and
/// `--subsample auto` would render it at 1/s of the size with s > 1 (a Gaussian kernel, an
/// orthographic view at level 0, footprints at least 2 px across their shorter semi-axis at 1/s;
/// `crate::pipeline::stages::subsample::factor`): otherwise the subsampled frame is the
/// full-size one.
fn subsampling_differs(p: &Prepared, base: &Plan) -> Result<bool, CliError> {
    if !base.auto_subsample {
        return Ok(false);
    }
    let mut auto = base.clone();
    auto.subsample = crate::plan::Supersample::Auto;
    Ok(p.subsample_factor(&auto)? > 1)
}

/// One pilot: the frames `p` renders, measured at sampled pixels against a continuous
/// integral marched through those pixels (in stages where it is `p`'s own).
struct Run<'a> {
    p: &'a Prepared,
    target_db: f64,
    reference: QualityReference,
    /// The side N of the finer field's sampling (`field` only).
    field_size: Option<usize>,
    /// The sampled pixels, stage by stage ([`stages`]).
    pixels: Vec<[usize; 2]>,
    /// Where each stage ends in `pixels`, and the margin it takes a candidate at, dB; the last
    /// is the whole sample (`None`: no margin, and never undecided).
    stages: Vec<StageEnd>,
    /// The index in `stages` of the last stage marched.
    stage: usize,
    stride: usize,
    /// The reference at the first `reference_image.image.len()` of `pixels`.
    reference_image: crate::reference::continuous::Continuous,
    reference_seconds: f64,
    /// The field the later stages march, while one is left to march (staged runs only).
    marcher: Option<PilotReference<'a>>,
}

impl<'a> Run<'a> {
    /// The pilot of `p`'s frame against the continuous integral of `against` (`p` itself, or
    /// the finer field), marched on `threads` threads through the sampled pixels: where
    /// `against` is `p`, through the first stage's only, its field kept for the later ones
    /// ([`Run::widen`]; 16 bytes a voxel, held while the candidates render, so only where that
    /// fits the visible lists' budget: one stage otherwise).
    fn new(
        p: &'a Prepared,
        against: &Prepared,
        target_db: f64,
        reference: QualityReference,
        threads: usize,
    ) -> Result<Self, CliError> {
        let (w, h) = p.out_size();
        let (pixels, stride) = sample_pixels(w, h, PILOT_RAYS);
        let start = Instant::now();
        let staged = std::ptr::eq(p, against)
            && p.volume().is_some_and(|v| {
                let (field, budget) = field_bytes(v);
                field <= budget
            });
        let (pixels, stages, reference_image, marcher) = if staged {
            let (pixels, stages) = stages(pixels, stride);
            let first = stages[0].0;
            let marcher = PilotReference::new(p, threads)?;
            let image = marcher.at(&pixels[..first])?;
            let marcher = (first < pixels.len()).then_some(marcher);
            (pixels, stages, image, marcher)
        } else {
            let n = pixels.len();
            let (image, _) = continuous_at(against, &pixels, threads)?;
            (pixels, vec![(n, None)], image, None)
        };
        Ok(Run {
            p,
            target_db,
            reference,
            field_size: None,
            pixels,
            stages,
            stage: 0,
            stride,
            reference_image,
            reference_seconds: start.elapsed().as_secs_f64(),
            marcher,
        })
    }

    /// `image` at the pixels the reference has reached.
    fn estimate(&self, image: &[[f32; 4]]) -> Estimate {
        let (w, h) = self.p.out_size();
        let marched = self.reference_image.image.len();
        estimate(
            image,
            w,
            &self.pixels[..marched],
            &self.reference_image.image,
            w * h,
        )
    }

    /// Marches the reference through the next stage's pixels, if one is left: whether it did
    /// (only ever for `p`'s own reference, [`Run::new`]). The field is dropped after the last.
    fn widen(&mut self) -> Result<bool, CliError> {
        let Some(marcher) = self.marcher.take() else {
            return Ok(false);
        };
        let start = Instant::now();
        let marched = self.reference_image.image.len();
        self.stage += 1;
        let end = self.stages[self.stage].0;
        let rest = marcher.at(&self.pixels[marched..end])?;
        if self.stage + 1 < self.stages.len() {
            self.marcher = Some(marcher);
        }
        self.reference_image.image.extend(rest.image);
        self.reference_image.converged &= rest.converged;
        self.reference_seconds += start.elapsed().as_secs_f64();
        Ok(true)
    }

    /// Renders `candidates` (cheapest first) until one's bound reaches the target: that one's
    /// plan and the choice (the most accurate tried where none reaches it, said so, naming the
    /// default plan or `--quality` as `by_default` says). A candidate an early stage leaves
    /// undecided (its bound below the target plus the stage's margin, its lower bound above the
    /// target) is measured again with the next stage's pixels added.
    fn measure(
        &mut self,
        candidates: Vec<(Config, Plan)>,
        by_default: bool,
    ) -> Result<(Plan, Choice), CliError> {
        let (p, target_db, reference) = (self.p, self.target_db, self.reference);
        let start = Instant::now();
        let widen_before = self.reference_seconds;
        let mut cache = FrameCache::default();
        let mut tried: Vec<(Config, Estimate)> = Vec::new();
        let mut chosen = None;
        // The frame of the candidate that reaches the target: the command's frame. One that
        // falls short is dropped before the next renders (one frame held at a time); if none
        // reaches it, the command renders the most accurate again.
        let mut kept: Option<CoreFrame> = None;
        for (c, plan) in &candidates {
            let frame = render_frame(p, plan, &mut cache)?;
            // Stage by stage until decided; the last stage always decides.
            let (e, verdict) = loop {
                let e = self.estimate(&frame.image);
                let verdict = decide(&e, target_db, self.stages[self.stage].1);
                if verdict != Verdict::Undecided || !self.widen()? {
                    break (e, verdict);
                }
            };
            tried.push((*c, e));
            if verdict == Verdict::Taken {
                kept = Some(frame);
                chosen = Some(tried.len() - 1);
                break;
            }
        }
        let index = match chosen {
            Some(i) => i,
            None => {
                let best = (0..tried.len())
                    .max_by(|&a, &b| tried[a].1.bound_db.total_cmp(&tried[b].1.bound_db))
                    .expect("at least one candidate");
                let slabs = if tried.iter().any(|(c, _)| c.slab().is_some()) {
                    ""
                } else {
                    " (image slicing cannot render this frame: it needs a gaussian kernel and an \
                     orthographic view)"
                };
                crate::say!(
                    "{} {target_db:.1} dB ({}): no candidate was measured to reach it; using \
                     the most accurate, {} ({:.1} dB on the pilot){slabs}",
                    if by_default {
                        "default plan (--slicing auto),"
                    } else {
                        "--quality"
                    },
                    quality::reference_name(reference),
                    tried[best].0.label(),
                    tried[best].1.bound_db
                );
                best
            }
        };
        let (config, e) = tried[index];
        // Candidates are distinct, so those tried before the choice are the cheaper ones.
        let rejected = tried[..index]
            .iter()
            .map(|(c, e)| (*c, e.bound_db))
            .collect();
        let widened = self.reference_seconds - widen_before;
        let choice = Choice {
            target_db,
            config,
            predicted_db: e.bound_db,
            reference,
            footprint_error: None,
            rejected,
            pilot: Some(Pilot {
                pixels: self.reference_image.image.len(),
                first_pixels: self.stages[0].0,
                stride: self.stride,
                converged: self.reference_image.converged,
                reference_seconds: self.reference_seconds,
                render_seconds: start.elapsed().as_secs_f64() - widened,
                tried,
                field_size: self.field_size,
            }),
            level: 0,
            level_pilot: None,
            by_default,
            frame: kept.map(Box::new),
        };
        Ok((candidates[index].1.clone(), choice))
    }
}
