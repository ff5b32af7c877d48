//! The pipeline's one door (issue 76): a [`Scene`] and a [`Plan`] in, frames out. Every command
//! that draws a picture (render, verify, bench, Python's `render`) opens a [`Renderer`]; charts
//! sweep derived plans over what it prepared.
//!
//! ```text
//! (&Scene, &Plan) ─▶ entry::prepare: hold a stream the pilot needs, load, classify, set the
//!                     frame up (level, supersampling), validate --lod auto     ─▶ Prepared
//!                 ─▶ quality::choose::apply_quality: --quality, the default plan's pilot
//!                                                      ─▶ the plan with every choice made
//!                 ─▶ ends::run::render_frame: subsample ▸ supersample ▸ level ▸ end
//!                    (sheets | slabs | post | refined | reference)             ─▶ CoreFrame
//! ```
//!
//! The resolution decorators wrap any end: subsampling in `render_frame`, supersampling and the
//! level of detail in the frame [`Prepared`] holds. The f64 reference is an end like the others.

use super::ends::run::CoreFrame;
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
