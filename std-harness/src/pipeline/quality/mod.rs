//! `--quality` and `chart`: the error model, the configurations, the pilots that measure levels and slicings, and the finer field the built-in scene is measured against.

pub mod choose;
pub mod config;
pub mod field;
pub mod level_pilot;
pub mod model;
pub mod pilot;
pub mod pixel_sample;
pub mod sampling;
