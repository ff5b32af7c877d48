//! The render pipeline every command shares, owned by none of them. Data flows one way through it:
//!
//! ```text
//! load (voxels: file, stream, stdin, built-in)  ─┐
//! prepare (grid, view, frame, transfer function, ├─▶ run (tables, the core's sheet loop) ─▶ image
//!          shading, order, background)          ─┘   reference (f64, no tables)          ─▶ image
//! ```
//!
//! - [`load`]: where the voxels come from.
//! - [`prepare`](mod@prepare): [`Prepared`], a render set up and ready to run.
//! - [`run`]: the core's render (float or fixed, view table or direct) and the f64 reference.
//! - [`visible`]: visible-voxel lists, classified once and kept across frames ([`visible::FrameCache`]).
//! - [`bands`]: a frame split into bands of rows, one per thread, byte-identical for any count.
//! - [`spares`]: bands' sheet accumulators (kept clear) and frame images kept for the next frame.
//! - [`config`]: one table configuration (size, lookup, method, accumulation).
//! - [`quality`]: `--quality`, the cheapest configuration predicted to reach a PSNR.
//! - [`choose`]: `--quality`'s entry: the sheet model or the pilot, as `--quality-reference` says.
//! - [`level_pilot`]: `--quality`'s level of detail, measured against full resolution on a pilot
//!   of image rows.
//! - [`pilot`]: `--quality DB --quality-reference continuous` (or `field`), measured on a pilot
//!   of sampled rays against the continuous integral (of the grid, or of a finer sampling).
//! - [`field`]: the built-in scene's field sampled finer, the reference refinement is chosen
//!   against.
//! - [`sampling`]: what the pilots share (a hash placing samples, an estimate's figures).
//! - [`slabs`]: `--slicing image`, the core's image-aligned slabs over the visible voxels.
//! - [`lod`]: `--lod`, levels of detail for minified volumes (coarser levels, built once or as they stream).
//! - [`refine`]: `--refine`, the paper's adaptive re-sampling for magnified volumes
//!   ([`refinement`]: what it refined, carried by a frame).
//! - [`single`]: one voxel rendered on its own (`footprint splat`, the stability charts).
//! - [`supersample`]: minified frames rendered larger and averaged; [`subsample`]: `--subsample`,
//!   magnified frames rendered smaller and resampled (image-space level of detail).
//! - [`describe`](mod@describe): the JSON fields every render and verify summary share.
//!
//! A frame renders `(&Prepared, &Plan)` ([`render_frame`], [`crate::plan`]): the end point
//! (sheets, slabs, refined), tables, phases, threads and the subsampling decorator come from the
//! plan, never from the command line. Loading and preparing still read the shared argument
//! structs of [`crate::args`]; it calls down into [`crate::io`], [`crate::reference`] and the
//! core, and imports no command.

pub mod bands;
pub mod choose;
pub mod config;
pub mod continuous;
pub mod describe;
pub mod entry;
pub mod field;
pub mod level_pilot;
pub mod load;
pub mod lod;
pub mod pilot;
pub mod prepare;
pub mod quality;
pub mod refine;
pub mod refinement;
pub mod run;
pub mod sampling;
pub mod single;
pub mod slabs;
pub mod spares;
pub mod subsample;
pub mod supersample;
pub mod supply;
pub mod visible;
pub mod window;

pub use continuous::render_continuous_ref;
pub use describe::describe;
pub use entry::prepare;
pub use prepare::Prepared;
pub use run::{render_core, render_frame, render_ref, CoreFrame};
