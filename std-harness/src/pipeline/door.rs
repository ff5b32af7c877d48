//! The pipeline's one door (issue 76): a [`Scene`] and a [`Plan`] in, frames out. Every command
//! that draws a picture (render, verify, bench, chart, Python's `render` and `render_stream`)
//! opens a [`Renderer`]; a chart opens one as given ([`Renderer::prepare`]) and sweeps the plans
//! it derives over what it prepared ([`Renderer::frame_of`]). A brick of a split frame
//! (`crate::distributed`) takes the same resolution decorator off and puts it back after the
//! bricks are composited.
//!
//! ```text
//! (&Scene, &Plan) ─▶ entry::prepare: hold a stream the pilot needs, load, classify, set the
//!                     frame up (level, supersampling), validate --lod auto     ─▶ Prepared
//!                 ─▶ quality::choose::apply_quality: --quality, the default plan's pilot
//!                                                      ─▶ the plan with every choice made
//!                 ─▶ ends::run::render_frame: stages::decorators::peel (subsample or
//!                    supersample) ▸ ends::run::end_frame (sheets | slabs | post | refined |
//!                    reference) ▸ Resample::finish                            ─▶ CoreFrame
//! ```
//!
//! The resolution decorators wrap any end ([`super::stages::decorators`]); the level of detail
//! wraps the source (the volume [`Prepared`] holds, coarsened in memory or as it streams). The f64
//! reference is an end like the others.

use super::ends::run::{render_frame, CoreFrame};
use super::entry::prepare_scene;
use super::quality::choose::{apply_quality, chosen_frame};
use super::quality::model::Choice;
use super::stages::prepare::Prepared;
use super::stages::visible::FrameCache;
use crate::plan::Plan;
use crate::scene::Scene;
use crate::CliError;
use std::time::Instant;

/// A scene prepared and its plan resolved, ready to render frames (turning the camera between
/// them reuses the volume, its level, its classification and its visible-voxel lists).
pub struct Renderer {
    prepared: Prepared,
    plan: Plan,
    choice: Option<Choice>,
    cache: FrameCache,
    choosing: f64,
}

impl Renderer {
    /// Prepares `scene` and resolves `plan`: every automatic choice made (the level, the
    /// default plan's slicing, `--quality`'s table), so [`Renderer::plan`] has none left.
    pub fn open(scene: &Scene, plan: &Plan) -> Result<Renderer, CliError> {
        let prepared = prepare_scene(scene.clone(), plan)?;
        let start = Instant::now();
        let (prepared, plan, choice) = apply_quality(prepared, scene, plan)?;
        Ok(Renderer {
            prepared,
            plan,
            choice,
            cache: FrameCache::default(),
            choosing: start.elapsed().as_secs_f64(),
        })
    }

    /// Prepares `scene` for `plan` and resolves nothing more: the plan stays as given (an
    /// automatic choice left in it is not made; its frames draw the end it names). What a chart
    /// opens, to sweep the plans it derives over one prepared volume ([`Renderer::frame_of`]).
    pub fn prepare(scene: &Scene, plan: &Plan) -> Result<Renderer, CliError> {
        Ok(Renderer {
            prepared: prepare_scene(scene.clone(), plan)?,
            plan: plan.clone(),
            choice: None,
            cache: FrameCache::default(),
            choosing: 0.0,
        })
    }

    /// A frame of `plan` over what was prepared, with this renderer's cache: `plan` derives from
    /// the one it was opened with (another end, table, precision or thread count; the same
    /// resolution chain and order, which the preparation fixed).
    pub fn frame_of(&mut self, plan: &Plan) -> Result<CoreFrame, CliError> {
        render_frame(&self.prepared, plan, &mut self.cache)
    }

    /// A frame of `plan` (as [`Renderer::frame_of`]) drawn as a fresh volume's first frame is:
    /// with an empty cache, so its visible voxels are classified and its tables built in it.
    pub fn fresh_frame_of(&self, plan: &Plan) -> Result<CoreFrame, CliError> {
        render_frame(&self.prepared, plan, &mut FrameCache::default())
    }

    /// Seconds spent choosing the plan after preparing (the default plan's pilot, `--quality`):
    /// part of a fresh volume's cost, which `footprint bench` reports as `plan_ms`.
    pub fn choosing_seconds(&self) -> f64 {
        self.choosing
    }

    /// Hands a frame's image back for the next frame to reuse.
    pub fn recycle(&mut self, image: Vec<[f32; 4]>) {
        self.cache.recycle(image);
    }

    /// What was prepared: the volume at its level, its classification and the frame.
    pub fn prepared(&self) -> &Prepared {
        &self.prepared
    }

    /// The plan that draws the frames, every choice made.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// What `--quality` or the default plan's pilot chose and measured, if either ran.
    pub fn choice(&self) -> Option<&Choice> {
        self.choice.as_ref()
    }

    /// The next frame, and whether it is the one the default plan's pilot rendered whole while
    /// choosing (the first frame's, when it did; its time is then the pilot's).
    pub fn frame(&mut self) -> Result<(CoreFrame, bool), CliError> {
        chosen_frame(
            &self.prepared,
            &self.plan,
            &mut self.choice,
            &mut self.cache,
        )
    }

    /// The camera of `scene` (its view, zoom, matrix and size; the rest as prepared): only the
    /// frame is set up again.
    pub fn reframe(&mut self, scene: &Scene) -> Result<(), CliError> {
        self.prepared.reframe(scene)
    }

    /// What was prepared, the plan and the choice, for a caller that sweeps further plans.
    pub fn into_parts(self) -> (Prepared, Plan, Option<Choice>) {
        (self.prepared, self.plan, self.choice)
    }
}

/// One frame of `scene` drawn by `plan`, through [`Renderer`]: the frame and the renderer (for
/// what it prepared, the plan it resolved and the choice).
pub fn render(scene: &Scene, plan: &Plan) -> Result<(CoreFrame, Renderer), CliError> {
    let mut r = Renderer::open(scene, plan)?;
    let (frame, _) = r.frame()?;
    Ok((frame, r))
}
