//! Classification once, rendering many times: the voxels of a sheet that can be seen at all (their
//! opacity is above zero before the per-view correction), kept by the caller so that the next
//! frame of the same volume and transfer function visits only those. The list depends on the
//! sheet axis (a view whose sheets run along another axis needs its own list), not on the rest of
//! the view: the per-view opacity correction, lighting and placement are applied when the list is
//! rendered. This is the splatting counterpart of the run-length encoded, pre-classified volume of
//! shear-warp renderers.

use super::sheets::{gradient, SheetWindow};
use super::RenderError;
use crate::frame::FrameSetup;
use crate::shade::{Sample, Shader};
use crate::splat::BufferError;

/// A voxel of a sheet that can be seen: its in-sheet position (u along the first in-sheet axis,
/// v along the second, as in [`FrameSetup::sheet_shape`]) and its sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisibleVoxel {
    /// Index along the sheet's first in-sheet axis.
    pub u: u16,
    /// Index along the sheet's second in-sheet axis.
    pub v: u16,
    /// The sample, in data units.
    pub value: f32,
}

/// The visible voxels of one sheet, in the order the renderer visits a sheet (v outer, u inner),
/// and, for shadings that need it, each one's world-space gradient (value units per world unit).
#[derive(Clone, Copy, Debug)]
pub struct VisibleSheet<'s> {
    /// The voxels.
    pub voxels: &'s [VisibleVoxel],
    /// One gradient per voxel when the shading needs gradients; may be empty otherwise.
    pub gradients: &'s [[f32; 3]],
    /// One straight colour per voxel when the samples carry colours ([`Sample::colour`], a
    /// level of detail's); empty otherwise (the transfer function colours them).
    pub colours: &'s [[f32; 3]],
}

/// Samples tested together for the transparent early-out in [`classify_sheet`].
const CLEAR_GROUP: usize = 16;

/// Writes the visible voxels of sheet `index` (with its neighbours in `window`, for gradients)
/// into `voxels`, their gradients into `gradients` when `shader` needs them, and their colours
/// into `colours` when the sample type carries colours ([`Sample::COLOURED`]; a sample without
/// one gets the transfer function's), in render order; returns how many. `voxels` (and
/// `gradients` and `colours`, when needed) must hold a whole sheet's worth in the worst case
/// (`dims[a] × dims[b]`); sheets wider than 65 536 voxels along an axis are refused; entries
/// past the count returned may be overwritten. A sample type without colours leaves `colours`
/// alone (it may then be empty).
pub fn classify_sheet<T: Sample>(
    frame: &FrameSetup,
    shader: &Shader<'_>,
    index: usize,
    window: SheetWindow<'_, T>,
    voxels: &mut [VisibleVoxel],
    gradients: &mut [[f32; 3]],
    colours: &mut [[f32; 3]],
) -> Result<usize, RenderError> {
    let needs_gradient = shader.shading.needs_gradient();
    let coloured = T::COLOURED;
    let lengths = [voxels.len(), gradients.len(), colours.len()];
    let (na, nb) = check_sheet(frame, index, &window, lengths, needs_gradient)?;
    // Values the transfer function makes transparent whatever the gradient are skipped with one
    // comparison (exact: the bound is where its lookup's opacity stops being 0).
    let clear = shader.transparent_at_or_below();
    // Where visibility is one interval of values, two comparisons replace the lookup.
    let interval = shader.visible_interval();
    let mut n = 0;
    for (v, row) in window.current.chunks_exact(na.max(1)).enumerate().take(nb) {
        // Groups of samples all at or below the bound are skipped with one test (a branch-free
        // loop the compiler vectorises); in the rest each sample is tested on its own.
        for (k, group) in row.chunks(CLEAR_GROUP).enumerate() {
            if group
                .iter()
                .fold(true, |all, s| all & (s.to_f32() <= clear))
            {
                continue;
            }
            if let (Some((low, high)), false, false) = (interval, needs_gradient, coloured) {
                // Visible exactly where low ≤ value ≤ high: each sample written, and counted
                // if it is (no branch per sample; the slot is overwritten otherwise).
                for (i, &sample) in group.iter().enumerate() {
                    let value = sample.to_f32();
                    voxels[n] = VisibleVoxel {
                        u: (k * CLEAR_GROUP + i) as u16,
                        v: v as u16,
                        value,
                    };
                    n += usize::from(low <= value && value <= high);
                }
                continue;
            }
            for (i, &sample) in group.iter().enumerate() {
                let u = k * CLEAR_GROUP + i;
                let value = sample.to_f32();
                if value <= clear {
                    continue;
                }
                let mut g = glam::Vec3::ZERO;
                let seen = match interval {
                    Some((low, high)) => {
                        let seen = low <= value && value <= high;
                        if seen && needs_gradient {
                            g = gradient(frame, &window, u, v);
                        }
                        seen
                    }
                    None => shader.visible(value, || {
                        g = gradient(frame, &window, u, v);
                        g
                    }),
                };
                if !seen {
                    continue;
                }
                voxels[n] = VisibleVoxel {
                    u: u as u16,
                    v: v as u16,
                    value,
                };
                if needs_gradient {
                    // Emission never asks for the gradient; every other shading computed it above.
                    gradients[n] = g.to_array();
                }
                if coloured {
                    // A sample of a coloured type without a colour of its own takes the transfer
                    // function's, as the renderer would give it.
                    colours[n] = sample.colour().unwrap_or_else(|| {
                        let c = shader.lookup(value);
                        [c[0], c[1], c[2]]
                    });
                }
                n += 1;
            }
        }
    }
    Ok(n)
}

/// [`classify_sheet`]'s preconditions: `index` a sheet of `frame`, every sheet of `window` a
/// whole sheet long, the sheet at most 65 536 voxels along each axis, and room for a whole
/// sheet in the voxels (`lengths[0]`), the gradients (`lengths[1]`, where `needs_gradient`) and
/// the colours (`lengths[2]`, for a coloured sample type). The sheet's shape (na, nb) if so.
fn check_sheet<T: Sample>(
    frame: &FrameSetup,
    index: usize,
    window: &SheetWindow<'_, T>,
    [voxels, gradients, colours]: [usize; 3],
    needs_gradient: bool,
) -> Result<(usize, usize), RenderError> {
    let count = frame.sheet_count();
    if index >= count {
        return Err(RenderError::SheetIndex { index, count });
    }
    let (len, na, nb) = frame.sheet_shape();
    if na > 1 << 16 || nb > 1 << 16 {
        return Err(BufferError::TooLarge {
            width: na,
            height: nb,
        }
        .into());
    }
    for got in [
        Some(window.current.len()),
        window.lower.map(<[T]>::len),
        window.upper.map(<[T]>::len),
    ]
    .into_iter()
    .flatten()
    {
        if got != len {
            return Err(RenderError::SheetLength { expected: len, got });
        }
    }
    let room = if needs_gradient {
        voxels.min(gradients)
    } else {
        voxels
    };
    if room < len {
        return Err(BufferError::TooSmall {
            needed: len,
            got: room,
        }
        .into());
    }
    if T::COLOURED && colours < len {
        return Err(BufferError::TooSmall {
            needed: len,
            got: colours,
        }
        .into());
    }
    Ok((na, nb))
}
