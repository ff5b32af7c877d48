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
//! # Two stages
//! Against the grid's own integral the reference is marched in two stages. The first takes the
//! sampled pixels of the cells whose column and row are both even (a stratified sample of its
//! own at twice the cell side, about a quarter; at least [`MIN_FIRST_STAGE`], else one stage). A
//! candidate is decided there when its upper bound reaches DB + [`FIRST_STAGE_MARGIN_DB`]
//! (taken) or its lower bound,
//! m − Z·s/√n·√(1 − n/N), does not (more pixels would not lift the estimate past it: rejected);
//! otherwise the reference is marched through the other pixels too (through the same field,
//! built once and held until then: at most 16 bytes a voxel (`reference::sparse` keeps only
//! the blocks holding a voxel that can be seen), so two stages only where that bound fits the
//! visible lists' budget) and the candidate, and every later one, is measured on all of them.
//! A scene far from the target on either side costs a quarter of the reference, one near it
//! the whole as before (the pilot reference took 0.01–0.21 s at 256² on the shared volumes,
//! `docs/perf/default-plan.csv`). Looking twice at Z = 3 leaves the chance of taking a
//! candidate that misses DB at most twice one look's.
//!
//! **Why not a smaller first stage.** A first stage of a sixteenth (256 pixels at 512², then a
//! quarter, then the rest) cut the pilot reference on the walnut and the CT head by half
//! (`footprint bench --frames 1`, 512², 99–119 → 56–59 and 86–97 → 25–35 ms), but on
//! `benches/default_plan.sh` it took object slicing for the CT head (30,20,0, emission, 256²)
//! on a bound of 44.9 dB whose whole image measured 43.9 dB, where the quarter rejects it
//! (41.6 dB on its 1 024 pixels) and takes slabs (60.2 dB). A sample of 256 can miss the few
//! pixels that carry most of the squared error, and understate the standard error with them:
//! the normal bound did not hold there.
//!
//! **Why a margin.** The quarter can miss them too: with the pilot's march nested, the hydrogen
//! orbital (CI's `--quality-reference continuous` step: 256², 75,-40,20, `--quality 55`) had a
//! first-stage bound of 55.0 dB on its 1 024 pixels for object slicing, and its whole image
//! measured 54.53 dB. So the first stage takes a candidate only [`FIRST_STAGE_MARGIN_DB`] (a
//! factor of 1.26 in MSE, twice that miss) past the target; nearer, the whole sample decides
//! (it rejected that one at 53.2 dB). Rejecting on the first stage stays as it was: a wrong
//! rejection costs time, never accuracy.
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
use super::pixel_sample::{decide, first_stage, Verdict};
pub use super::pixel_sample::{
    estimate, sample_pixels, FIRST_STAGE_MARGIN_DB, MIN_FIRST_STAGE, PILOT_RAYS, Z,
};
use crate::args::QualityReferenceArg;
use crate::pipeline::ends::continuous::{continuous_at, PilotReference};
use crate::pipeline::ends::run::render_frame;
use crate::pipeline::stages::bands::CoreFrame;
use crate::pipeline::stages::prepare::Prepared;
use crate::pipeline::stages::visible::FrameCache;
use crate::plan::Inputs;
use crate::plan::{End, Plan};
use crate::CliError;
use std::time::Instant;

/// The bytes the pilot's continuous field holds for `volume` (each voxel's classified RGBA, 16
/// bytes) and the budget it must fit: the visible lists' ([`list_budget`]). The default plan
/// measures only where it fits, and the two stages hold the field only where it fits.
///
/// [`list_budget`]: crate::pipeline::stages::visible::list_budget
fn field_bytes(volume: &crate::io::volume::Volume) -> (usize, usize) {
    let field = volume.len().saturating_mul(16);
    (field, crate::pipeline::stages::visible::list_budget(volume))
}

/// The second object-slicing candidate aims the table model this much above the target, dB.
pub const TABLE_HEADROOM_DB: f64 = 10.0;

/// The candidates for `p` aiming at `target_db` (see the module docs), cheapest first; the
/// refined one only against the `field` reference.
fn candidates(
    p: &Prepared,
    base: &Plan,
    target_db: f64,
    reference: QualityReferenceArg,
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
    if let (Some(last), QualityReferenceArg::Field) = (v.last().copied(), reference) {
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
    args: &Inputs,
    base: &Plan,
    target_db: f64,
    reference: QualityReferenceArg,
) -> Result<Choice, CliError> {
    quality::check_target(target_db)?;
    let fine = match reference {
        QualityReferenceArg::Field => Some(super::field::prepare_field(args)?),
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
    if reference == QualityReferenceArg::Field {
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
    let mut run = Run::new(
        p,
        p,
        target_db,
        QualityReferenceArg::Continuous,
        base.threads,
    )?;
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
    auto.subsample = crate::args::Supersample::Auto;
    Ok(p.subsample_factor(&auto)? > 1)
}

/// One pilot: the frames `p` renders, measured at sampled pixels against a continuous
/// integral marched through those pixels (in two stages where it is `p`'s own).
struct Run<'a> {
    p: &'a Prepared,
    target_db: f64,
    reference: QualityReferenceArg,
    /// The side N of the finer field's sampling (`field` only).
    field_size: Option<usize>,
    /// The sampled pixels, the first stage's first.
    pixels: Vec<[usize; 2]>,
    /// How many of `pixels` the first stage marched.
    first: usize,
    stride: usize,
    /// The reference at the first `reference_image.image.len()` of `pixels`.
    reference_image: crate::reference::continuous::Continuous,
    reference_seconds: f64,
    /// The field the second stage marches, while there is one to march (two stages only).
    marcher: Option<PilotReference<'a>>,
}

impl<'a> Run<'a> {
    /// The pilot of `p`'s frame against the continuous integral of `against` (`p` itself, or
    /// the finer field), marched on `threads` threads through the sampled pixels: where
    /// `against` is `p`, through the first stage's only, its field kept for the second
    /// ([`Run::widen`]; 16 bytes a voxel, held while the candidates render, so only where that
    /// fits the visible lists' budget: one stage otherwise).
    fn new(
        p: &'a Prepared,
        against: &Prepared,
        target_db: f64,
        reference: QualityReferenceArg,
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
        let (pixels, first, reference_image, marcher) = if staged {
            let (pixels, first) = first_stage(pixels, stride);
            let marcher = PilotReference::new(p, threads)?;
            let image = marcher.at(&pixels[..first])?;
            let marcher = (first < pixels.len()).then_some(marcher);
            (pixels, first, image, marcher)
        } else {
            let n = pixels.len();
            let (image, _) = continuous_at(against, &pixels, threads)?;
            (pixels, n, image, None)
        };
        Ok(Run {
            p,
            target_db,
            reference,
            field_size: None,
            pixels,
            first,
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

    /// Marches the reference through the second stage's pixels, if it has not yet: whether it
    /// did (only ever for `p`'s own reference, [`Run::new`]). The field is dropped after.
    fn widen(&mut self) -> Result<bool, CliError> {
        let Some(marcher) = self.marcher.take() else {
            return Ok(false);
        };
        let start = Instant::now();
        let marched = self.reference_image.image.len();
        let rest = marcher.at(&self.pixels[marched..])?;
        self.reference_image.image.extend(rest.image);
        self.reference_image.converged &= rest.converged;
        self.reference_seconds += start.elapsed().as_secs_f64();
        Ok(true)
    }

    /// Renders `candidates` (cheapest first) until one's bound reaches the target: that one's
    /// plan and the choice (the most accurate tried where none reaches it, said so, naming the
    /// default plan or `--quality` as `by_default` says). A
    /// candidate the first stage leaves undecided (its bound below the target, its lower bound
    /// above) is measured again on every sampled pixel.
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
            let mut e = self.estimate(&frame.image);
            let first_stage = self.marcher.is_some();
            if decide(&e, target_db, first_stage) == Verdict::Undecided && self.widen()? {
                e = self.estimate(&frame.image);
            }
            tried.push((*c, e));
            if decide(&e, target_db, false) == Verdict::Taken {
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
                first_pixels: self.first,
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
