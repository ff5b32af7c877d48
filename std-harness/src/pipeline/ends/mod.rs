//! What draws a frame: the end points a [`crate::plan::Plan`] names (the sheets of the core, image-aligned slabs, refined sheets), and the references (the f64 sheets, the continuous integral), plus one voxel on its own (`footprint splat`).

pub mod continuous;
pub mod post;
pub mod refine;
pub mod run;
pub mod single;
pub mod slabs;
