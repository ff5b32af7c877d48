//! The resolution decorators (issue 76): what stands between the frame a [`Prepared`] render
//! describes at the output size and the frame its end draws, and how the end's image comes back.
//!
//! ```text
//! (&Prepared, &Plan) ─▶ peel ─▶ Decorated { the inner render, its plan, resample }
//!                                 ─▶ any end draws the inner frame ─▶ resample.finish ─▶ image
//! ```
//!
//! - **subsample** (`--subsample`, [`super::subsample`]): the end draws 1/s of the size with the
//!   view scaled; [`Resample::Magnify`] brings it back, and the background goes under after.
//! - **supersample** (`--supersample`, [`super::supersample`]): the end draws k× the size (the
//!   frame a supersampled [`Prepared`] holds, its background repeated to it);
//!   [`Resample::Average`] takes the mean of each k×k block.
//! - **level** (`--lod`, [`super::lod`]) wraps the source, not the end: a [`Prepared`] holds the
//!   volume at its level (coarsened in memory, or as a file streams), so every end reads it.
//!
//! The two wrap each other in one order only (subsampling refuses a supersampled frame,
//! [`super::subsample::factor`]), so [`peel`] takes off at most one. One process composites the
//! end's sheets inside the decorator ([`crate::pipeline::render_frame`]); bricks composite their
//! images there too, and then [`Resample::finish`] once (`crate::distributed`): both use
//! [`peel`], so a split frame is decorated as one process's.

use super::prepare::Prepared;
use super::{subsample, supersample};
use crate::plan::Plan;
use crate::CliError;
use std::borrow::Cow;
use std::sync::Arc;

/// How an end's image, composited at the inner frame's size, reaches the output size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Resample {
    /// Drawn at the output size.
    None,
    /// Drawn at k× the output size: the mean of each k×k block.
    Average { k: usize },
    /// Drawn at `low`, 1/s of the output size: magnified ([`subsample::magnify`]).
    Magnify { s: usize, low: (usize, usize) },
}

impl Resample {
    /// `image` (at the inner frame's size, premultiplied RGBA) at the output size `out`, with
    /// `background` (at `out`) composited under it when given. `threads` is the frame's count
    /// (magnification uses some of them, [`subsample::resample_threads`]).
    pub fn finish(
        self,
        image: Vec<[f32; 4]>,
        out: (usize, usize),
        threads: usize,
        background: Option<&[[f32; 4]]>,
    ) -> Result<Vec<[f32; 4]>, CliError> {
        let mut image = match self {
            Resample::None => image,
            Resample::Average { k } => supersample::to_output(image, out, k),
            Resample::Magnify { s, low } => {
                let threads = subsample::resample_threads(threads, out);
                subsample::magnify(&image, low, out, s, threads)?
            }
        };
        if let Some(bg) = background {
            subsample::under_background(&mut image, bg);
        }
        Ok(image)
    }
}

/// A render with its resolution decorator taken off: what the end draws, and how its image
/// comes back.
pub struct Decorated<'a> {
    /// The render the end draws: `p` itself (at the output size, or k× it when supersampled),
    /// or its subsampled frame (no background: it goes under after magnifying).
    pub prepared: Cow<'a, Prepared>,
    /// The plan the end draws with (subsampling off in a subsampled frame's).
    pub plan: Cow<'a, Plan>,
    /// How the end's image reaches [`Prepared::out_size`] of the render peeled.
    pub resample: Resample,
    /// The background [`Resample::finish`] puts under the image: a subsampled frame's (drawn
    /// over nothing, it is composited at the output size); none otherwise (a supersampled
    /// frame's end composites its own, repeated to k× the size).
    pub under: Option<Arc<[[f32; 4]]>>,
}

/// `p` drawn by `plan` with its resolution decorator taken off (see the module's docs); refuses
/// a `--subsample` the frame cannot honour ([`Prepared::subsample_factor`]).
pub fn peel<'a>(p: &'a Prepared, plan: &'a Plan) -> Result<Decorated<'a>, CliError> {
    let s = p.subsample_factor(plan)?;
    if s > 1 {
        let (low, at_low) = p.subsampled(plan, s)?;
        let low_size = low.out_size();
        return Ok(Decorated {
            prepared: Cow::Owned(low),
            plan: Cow::Owned(at_low),
            resample: Resample::Magnify { s, low: low_size },
            under: p.background.clone(),
        });
    }
    let resample = match p.supersample {
        1 => Resample::None,
        k => Resample::Average { k },
    };
    Ok(Decorated {
        prepared: Cow::Borrowed(p),
        plan: Cow::Borrowed(plan),
        resample,
        under: None,
    })
}
