//! The render pipeline every command shares, owned by none of them. Data flows one way through
//! it, and its folders are its stages:
//!
//! ```text
//! door: Renderer::open(&Scene, &Plan), frame(); render(&Scene, &Plan) ─▶ frame
//! (&Scene, &Plan) ─▶ entry::prepare ─▶ stages (load, window, prepare, lod, super/subsample,
//!                                      visible, spares, supply, bands) ─▶ Prepared
//! (&Prepared, &Plan) ─▶ stages::decorators::peel (subsample or supersample off)
//!                    ─▶ ends (run::end_frame: the core's sheets or the f64 reference; slabs; post;
//!                             refine; the continuous integral; single)
//!                    ─▶ Resample::finish (the decorator back on)                ─▶ image
//! quality (--quality, the default plan's pilot, chart): derives plans, measures them with the ends
//! ```
//!
//! - [`door`]: the one door every picture goes through ([`Renderer`], [`render`]): prepare,
//!   resolve the plan's automatic choices, render frames.
//! - [`stages`]: from the inputs to a [`Prepared`] render, and what a frame is split into:
//!   [`stages::load`] (where the voxels come from), [`stages::hold`] (a stream the default
//!   plan's pilot needs, read whole by [`entry::prepare`] first: the file's plan and picture),
//!   [`stages::window`], [`stages::prepare`],
//!   [`stages::lod`] (levels of detail), [`stages::supersample`] and [`stages::subsample`]
//!   (wrapped around any end by [`stages::decorators`]),
//!   [`stages::visible`] (visible-voxel lists kept across frames), [`stages::spares`],
//!   [`stages::supply`], [`stages::bands`] (bands of rows, byte-identical for any count),
//!   [`stages::refinement`] (what a refined frame carries).
//! - [`ends`]: what draws a frame, as the [`crate::plan::Plan`] says: [`ends::run`] (the core's
//!   sheets, float or fixed, and the f64 reference), [`ends::slabs`] (image-aligned slabs),
//!   [`ends::refine`] (the paper's adaptive re-sampling), [`ends::continuous`] (the continuous
//!   integral), [`ends::single`] (one voxel on its own, `footprint splat`).
//! - [`quality`](mod@quality): `--quality` and `chart`: [`quality::config`] (one configuration,
//!   and the plan it derives), [`quality::model`] (the error model), [`quality::choose`]
//!   (`--quality`'s entry), [`quality::level_pilot`] and [`quality::pilot`] (measured pilots),
//!   [`quality::sampling`], [`quality::field`] (the built-in scene's finer field).
//! - [`entry`]: [`entry::prepare`], with `--lod auto` validated on a pilot;
//!   [`describe`](mod@describe): the JSON fields every summary shares.
//!
//! A frame renders `(&Prepared, &Plan)` ([`render_frame`], [`crate::plan`]); preparing reads
//! [`crate::scene::Scene`] and the plan's resolution chain. No file here names the command-line struct (`tests/layering.rs`); it
//! calls down into [`crate::io`], [`crate::reference`] and the core, and imports no command;
//! stages import no end, and ends no quality module.

pub mod depth;
pub mod describe;
pub mod door;
pub mod ends;
pub mod entry;
pub mod quality;
pub mod stages;

pub use describe::describe;
pub use door::{render, Renderer};
pub use ends::continuous::{render_continuous_as, render_continuous_ref};
pub use ends::run::{render_core, render_frame, render_ref, CoreFrame};
pub use entry::prepare;
pub use stages::prepare::Prepared;
