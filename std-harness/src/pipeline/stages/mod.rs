//! (Hold →) load → prepare → classify → bands: the stages every render goes through (loading, the window, the frame and its levels, supersampling and subsampling, the visible lists, spare voxels, bands of rows, and what refinement carried).

pub mod bands;
pub mod blocks;
pub mod components;
pub mod decorators;
pub mod hold;
pub mod load;
pub mod lod;
pub mod prepare;
pub mod refinement;
pub mod spares;
pub mod subsample;
pub mod supersample;
pub mod supply;
pub mod tables;
pub mod visible;
pub mod window;
