//! The workspace's integration tests, linked into one executable (as tiny-skia does): one link of
//! the harness instead of one per file, which is most of `cargo test --workspace`'s build time and
//! disk. Each file beside this one is a module; run one with `cargo test --test suite MODULE::`.
//! `hostile.rs` stays its own executable: it runs its cases as child processes under limits.
mod bad_input;
mod bricks;
mod classify;
mod clip;
mod compact;
mod continuous;
mod cull;
mod cut;
mod default_plan;
mod degenerate;
mod depth;
mod display;
mod door;
mod ellipse_geometry;
mod fixed_point;
mod flat_field;
mod footprint_shapes;
mod formats;
mod freestanding_scene;
mod harness_render;
mod kernels;
mod keywords;
mod layering;
mod library;
mod lod;
mod minification;
mod newcomer;
mod outputs;
mod paraview_presets;
mod perspective;
mod post;
mod quality_continuous;
mod quality_lod;
mod real_writers;
mod refine;
mod render;
mod rotation_45;
mod same_picture;
mod single_sample;
mod slabs;
mod stencils;
mod subsample;
mod table_format;
mod threads;
