//! The charts of `footprint chart`: speed against accuracy on one scene, and stability where methods
//! fail. [`sweep`] measures, [`stability`] runs the single-voxel sweeps, [`plot`] draws (plotters,
//! SVG and PNG with a bundled font).
//!
//! **Trade-off** (`DIR/tradeoff.csv`, `.svg`, `.png`): every configuration of table size
//! N ∈ {5, 11, 21, 33, 65, 101, 129}, lookup (nearest, bilinear), method (`view`: the two-stage
//! view table; `direct`) and accumulation (float, fixed), and image-aligned slabs of the
//! [`crate::pipeline::quality::config::SLABS`] thicknesses the frame can run, renders the scene `--runs`
//! times. Time is
//! the whole frame as `render` does it (table build, every sheet), median and min–max; error is
//! against the f64 reference of the same scene (PSNR over RGB, max abs), as in `verify`. The
//! math backend is a build-time choice and is recorded in every row. A configuration is on the
//! Pareto frontier when no other is at least as fast and at least as accurate, and strictly
//! better in one of the two. Every row is also measured against the continuous integral
//! (`tradeoff-continuous.svg`, `.png`, with its own frontier); the sheet reference's chart and
//! frontier hold object slicing only.
//!
//! **Stability** (`DIR/stability.svg`, `.png`): one voxel of the paper Gaussian against the exact
//! footprint (max |core − reference| / reference peak), table 65, bilinear:
//! (a) against rotation about the view axis, 0–90° with 0.01° steps from 44.5° to 45.5° and
//! points 10⁻⁴° and 8·10⁻⁵° from 45°, for the robust map and the paper's θ map (with its 0.01°
//! cheat, and without: `--paper-cheat 0`), on a 2:1 grid;
//! (b) against anisotropy 1–1000 (grid spacing r:1:1, seen obliquely); (c) against footprint size
//! 0.1–1000 px across, nearest and bilinear. A configuration that fails (a typed error, a non-finite
//! result) is drawn as a cross on the top edge. (d) popping ([`popping`], `DIR/popping.csv`):
//! the scene turned through azimuth 40°–50° in 0.1° steps at `--popping-size`, the change between
//! consecutive frames for object slicing, image slicing and the continuous reference.
//!
//! **Post-classification** ([`post`], `DIR/post.csv`, `.svg`, `.png`; `--classification post`
//! charts this alone): slab thicknesses and value subsamplings, frame time against PSNR against
//! the post-classified continuous integral.
//!
//! **Levels of detail** ([`lod`], `DIR/lod.csv`, `.svg`, `.png`): every level of the scene, its
//! frame time and its PSNR against level 0 (`--lod 0`), and the level `--lod auto` picks.
//!
//! **Refinement** ([`refine`], `DIR/refine.csv`, `.svg`, `.png`, with `--refine-only`): the
//! built-in scene at `--scene-size`, unrefined and at each `--refine` threshold, its frame time
//! and its PSNR against the same field sampled at `--refine-reference`.

use crate::args::RenderArgs;
use crate::pipeline::Renderer;
use crate::CliError;

pub mod colorbar;
pub mod lod;
pub mod plot;
pub mod popping;
pub mod post;
pub mod refine;
pub mod stability;
pub mod sweep;

/// The door a chart opens on `a`'s scene: prepared for `a`'s plan, nothing more resolved (the
/// chart derives the plans it sweeps: [`Renderer::frame_of`]).
pub fn open(a: &RenderArgs) -> Result<Renderer, CliError> {
    Renderer::prepare(&crate::args::scene(a)?, &crate::args::plan(a)?)
}
