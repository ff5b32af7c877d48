//! Levels of detail: a volume's coarser levels, built sheet by sheet while it streams.
//!
//! Level 0 is the volume. Level L + 1 halves level L along every axis: sample c is the mean of
//! the 2×2×2 samples 2c + {0, 1}³ of level L (an index past the end is clamped to the last one,
//! so an odd count's last sample averages its one plane with itself). Its spacing is twice level
//! L's; its sample c sits at level-L position 2c + ½, i.e. at level-0 position 2ᴸc + (2ᴸ − 1)/2
//! (the last plane of an odd count sits half a level-L spacing off that, the one place the
//! placement is approximate).
//!
//! **Why a box.** The renderer reconstructs level L with its kernel at 2ᴸ times the spacing, so
//! the coarse volume needs a pre-filter that removes what that spacing cannot carry and keeps the
//! volume's mean (opacity is integrated along rays: a filter that does not preserve the mean
//! changes the image's overall opacity). The 2×2×2 box is the smallest such filter that needs only
//! two input sheets per output sheet, so a streamed volume still holds a bounded number of sheets
//! (two per level); the Gaussian reconstruction at twice the spacing then supplies the rest of the
//! low-pass. Values are averaged before classification (the renderer classifies each sample it
//! splats), which is exact for a transfer function linear over the averaged values and an
//! approximation across sharp transfer-function edges; [`Extinction`] averaging keeps each
//! block's mean extinction in its value and its mean premultiplied colour in a colour the sample
//! carries ([`Coloured`]); the harness charts the error of each level against full resolution.
//! A coarser level is reconstructed with a narrower Gaussian ([`level_kernel`]: the box already
//! low-passed it). A missing (NaN) sample is left out of its mean; a coarse sample with
//! no finite input is NaN (transparent).
//!
//! [`Coarsened`] is a [`SheetSource`] adaptor: it asks its inner source for the two level-L
//! sheets of each level-(L+1) sheet, in ascending order (a sequential source stays sequential),
//! into two caller-owned scratch sheets, and averages them. Nest it for deeper levels.

use crate::frame::{FrameError, FrameSetup};
use crate::geometry::{FootprintOptions, Grid, View};
use crate::kernel::Kernel;
use crate::render::RenderError;
use crate::shade::Sample;
use crate::source::SheetSource;
use glam::Vec3;

mod average;
pub use average::{Averaging, Coloured, Extinction, Linear, MAX_ALPHA};

/// The deepest level [`level_dims`] accepts.
pub const MAX_LEVEL: u32 = 16;

/// The dims of the level below `dims`: ⌈n/2⌉ along every axis.
pub fn coarse_dims(dims: [usize; 3]) -> [usize; 3] {
    dims.map(|n| n.div_ceil(2))
}

/// The dims of level `level` of a `dims` volume (`None` past [`MAX_LEVEL`]).
pub fn level_dims(dims: [usize; 3], level: u32) -> Option<[usize; 3]> {
    if level > MAX_LEVEL {
        return None;
    }
    let mut d = dims;
    for _ in 0..level {
        d = coarse_dims(d);
    }
    Some(d)
}

/// Level `level`'s sample 0 in level-0 grid steps along each axis: (2ᴸ − 1)/2.
pub fn level_offset(level: u32) -> f32 {
    ((1u64 << level.min(MAX_LEVEL)) as f32 - 1.0) * 0.5
}

/// Why a level cannot be set up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LodError {
    /// A level past [`MAX_LEVEL`].
    TooDeep {
        /// The level asked for.
        level: u32,
    },
    /// Levels of detail are placed for orthographic frames; a perspective frame was given.
    Perspective,
    /// The level's frame could not be set up.
    Frame(FrameError),
}

impl core::fmt::Display for LodError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LodError::TooDeep { level } => {
                write!(
                    f,
                    "level of detail {level} is past the deepest, {MAX_LEVEL}"
                )
            }
            LodError::Perspective => {
                f.write_str("levels of detail above 0 need an orthographic view")
            }
            LodError::Frame(e) => write!(f, "level of detail: {e}"),
        }
    }
}

impl core::error::Error for LodError {}

impl From<FrameError> for LodError {
    fn from(e: FrameError) -> Self {
        LodError::Frame(e)
    }
}

/// The grid of level `level` of a volume on `grid`: every axis's step 2ᴸ times as long.
pub fn level_grid(grid: &Grid, level: u32) -> Result<Grid, LodError> {
    if level > MAX_LEVEL {
        return Err(LodError::TooDeep { level });
    }
    let scale = (1u64 << level) as f32;
    Grid::from_matrix(grid.to_world() * scale).map_err(|e| LodError::Frame(FrameError::Geometry(e)))
}

/// The narrowest Gaussian a coarser level is reconstructed with, standard deviations in the
/// level's grid steps: √(ln 40 / 2π²) ≈ 0.432, where a Gaussian's samples on a unit grid sum to a
/// constant within ±5 % (by Poisson summation the sum is 1 + 2Σₖ e^(−2π²σ²k²) cos 2πkx, whose
/// first term is 2e^(−2π²σ²)).
pub const LEVEL_SIGMA: f32 = 0.432;

/// The kernel level `level` is reconstructed with, given level 0's.
///
/// **Why narrower.** Level L's samples are already low-passed by the box (its variance, in level-0
/// steps, (4ᴸ − 1)/12 per axis: ¼ at level 1), so reconstructing them with level 0's kernel
/// stretched to the coarse spacing low-passes twice: level 0's Gaussian (σ = 0.64 steps) at level
/// 1 has σ = 1.28 level-0 steps, where matching level 0's total blur would need
/// √(0.64² − ¼) = 0.4, i.e. 0.2 level-1 steps. That is too narrow for its samples to sum to a
/// flat field, so a Gaussian is narrowed to [`LEVEL_SIGMA`] level steps (its truncation, in
/// standard deviations, kept), never widened: the ±5 % ripple it leaves sits at the coarse
/// spacing, which `--lod auto` keeps near a pixel, where the pixel filter averages it. Measured on
/// the walnut (grey, emission, view 30,20,0; level 1, colours carried, against level 0, PSNR over
/// RGB): at 128×128, 36.2 dB with level 0's kernel, 39.7 dB narrowed; at 64×64, 38.1 and 42.2 dB.
/// Other kernels are kept as given. Idempotent: the level kernel of a level kernel is itself.
pub fn level_kernel(kernel: &Kernel, level: u32) -> Kernel {
    match *kernel {
        Kernel::Gaussian { spread, sigmas } if level > 0 => Kernel::Gaussian {
            spread: spread.min(LEVEL_SIGMA * sigmas),
            sigmas,
        },
        k => k,
    }
}

/// The frame of level `level`, seen as `fine` (level 0's frame, set up with `grid` and `view`,
/// orthographic) sees level 0: the level's dims and grid ([`level_grid`]) through the same `view`
/// into the same image, placed so that its sample c lands on screen where level-0 position
/// 2ᴸc + (2ᴸ − 1)/2 does (`FrameSetup::new` would centre the coarse voxel box instead, which for
/// an odd count is half a fine step off). The footprint, sheet axis and opacity correction follow
/// from the level's spacing. Level 0 gives `fine` back.
pub fn level_frame(
    fine: &FrameSetup,
    grid: &Grid,
    view: &View,
    kernel: &Kernel,
    options: FootprintOptions,
    level: u32,
) -> Result<FrameSetup, LodError> {
    if fine.camera().is_some() && level > 0 {
        return Err(LodError::Perspective);
    }
    let dims = level_dims(fine.dims, level).ok_or(LodError::TooDeep { level })?;
    if level == 0 {
        return Ok(*fine);
    }
    let coarse_grid = level_grid(grid, level)?;
    let mut frame = FrameSetup::new(dims, &coarse_grid, view, kernel, options, fine.size)?;
    frame.origin = fine.origin + fine.grid_to_screen * Vec3::splat(level_offset(level));
    Ok(frame)
}

/// The in-sheet axes (a, b) of sheets along `axis`, as in [`crate::frame`].
fn in_sheet(axis: usize) -> (usize, usize) {
    crate::geometry::in_sheet_axes(axis)
}

/// A [`SheetSource`] delivering the level below `inner`'s volume (see the module docs), as
/// [`Coloured`] samples.
pub struct Coarsened<'b, S: SheetSource> {
    inner: S,
    fine: [usize; 3],
    scratch: [&'b mut [S::Sample]; 2],
    averaging: &'b dyn Averaging,
}

impl<'b, S: SheetSource> Coarsened<'b, S> {
    /// Samples each scratch sheet needs for sheets along `axis` of a `fine`-dims volume.
    pub fn scratch_len(fine: [usize; 3], axis: usize) -> usize {
        let (a, b) = in_sheet(axis.min(2));
        fine[a] * fine[b]
    }

    /// The level below `inner`, whose volume has `fine` dims; `lower` and `upper` hold one fine
    /// sheet each (at least [`Self::scratch_len`] samples for the axis the frame asks for).
    pub fn new(
        inner: S,
        fine: [usize; 3],
        lower: &'b mut [S::Sample],
        upper: &'b mut [S::Sample],
    ) -> Self {
        Coarsened {
            inner,
            fine,
            scratch: [lower, upper],
            averaging: &Linear,
        }
    }

    /// The same, averaging through `averaging` (e.g. [`Extinction`]) instead of the values.
    pub fn averaging(mut self, averaging: &'b dyn Averaging) -> Self {
        self.averaging = averaging;
        self
    }

    /// The coarse volume's dims.
    pub fn dims(&self) -> [usize; 3] {
        coarse_dims(self.fine)
    }

    /// The inner source back.
    pub fn into_inner(self) -> S {
        self.inner
    }
}

impl<S: SheetSource> SheetSource for Coarsened<'_, S> {
    type Sample = Coloured;
    type Error = S::Error;

    fn read_sheet(
        &mut self,
        axis: usize,
        index: usize,
        out: &mut [Coloured],
    ) -> Result<(), S::Error> {
        let axis = axis.min(2);
        let coarse = coarse_dims(self.fine);
        let (a, b) = in_sheet(axis);
        let (na, nb) = (self.fine[a], self.fine[b]);
        let (ca, cb) = (coarse[a], coarse[b]);
        if out.len() != ca * cb {
            return Err(RenderError::SheetLength {
                expected: ca * cb,
                got: out.len(),
            }
            .into());
        }
        if index >= coarse[axis] {
            return Err(RenderError::SheetIndex {
                index,
                count: coarse[axis],
            }
            .into());
        }
        let len = na * nb;
        let [lower, upper] = &mut self.scratch;
        if lower.len() < len || upper.len() < len {
            return Err(RenderError::SheetLength {
                expected: len,
                got: lower.len().min(upper.len()),
            }
            .into());
        }
        let (lower, upper) = (&mut lower[..len], &mut upper[..len]);
        let first = 2 * index;
        self.inner.read_sheet(axis, first, lower)?;
        // The second sheet, or (past the end of an odd count) the first again, without reading
        // it twice: a sequential source delivers each sheet once.
        let pair = first + 1 < self.fine[axis];
        if pair {
            self.inner.read_sheet(axis, first + 1, upper)?;
        }
        let second: &[S::Sample] = if pair { upper } else { lower };
        for v in 0..cb {
            let rows = [2 * v, (2 * v + 1).min(nb - 1)];
            for u in 0..ca {
                let cols = [2 * u, (2 * u + 1).min(na - 1)];
                let mut block = [[Coloured::default(); 2]; 4];
                let coloured = |s: S::Sample| Coloured {
                    value: s.to_f32(),
                    colour: s.colour(),
                };
                for (i, (r, c)) in [(0, 0), (0, 1), (1, 0), (1, 1)].into_iter().enumerate() {
                    let at = rows[r] * na + cols[c];
                    block[i] = [coloured(lower[at]), coloured(second[at])];
                }
                out[v * ca + u] = self.averaging.block(axis, &block);
            }
        }
        Ok(())
    }

    fn sequential_axis(&self) -> Option<usize> {
        self.inner.sequential_axis()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::MemoryVolume;

    fn brute(fine: &[f32], d: [usize; 3], c: [usize; 3]) -> f32 {
        let mut sum = 0.0;
        for dz in 0..2 {
            for dy in 0..2 {
                for dx in 0..2 {
                    let i = [
                        (2 * c[0] + dx).min(d[0] - 1),
                        (2 * c[1] + dy).min(d[1] - 1),
                        (2 * c[2] + dz).min(d[2] - 1),
                    ];
                    sum += fine[(i[2] * d[1] + i[1]) * d[0] + i[0]];
                }
            }
        }
        sum / 8.0
    }

    #[test]
    fn every_axis_matches_the_brute_force_box() {
        let d = [5usize, 4, 3];
        let fine: [f32; 60] = core::array::from_fn(|i| ((i * 37) % 11) as f32 + 0.25 * i as f32);
        let c = coarse_dims(d);
        assert_eq!(c, [3, 2, 2]);
        for axis in 0..3 {
            let vol = MemoryVolume::new(&fine, d).unwrap();
            let (mut lo, mut hi) = ([0.0f32; 20], [0.0f32; 20]);
            let mut src = Coarsened::new(vol, d, &mut lo, &mut hi);
            let (a, b) = in_sheet(axis);
            for s in 0..c[axis] {
                let mut out = [Coloured::default(); 6];
                let out = &mut out[..c[a] * c[b]];
                src.read_sheet(axis, s, out).unwrap();
                for v in 0..c[b] {
                    for u in 0..c[a] {
                        let mut idx = [0; 3];
                        idx[axis] = s;
                        idx[a] = u;
                        idx[b] = v;
                        let want = brute(&fine, d, idx);
                        assert!(
                            (out[v * c[a] + u].value - want).abs() < 1e-5
                                && out[v * c[a] + u].colour.is_none(),
                            "axis {axis} {idx:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn missing_samples_are_left_out_and_bad_requests_are_errors() {
        let d = [2usize, 2, 2];
        let mut fine = [1.0f32; 8];
        fine[0] = f32::NAN;
        let vol = MemoryVolume::new(&fine, d).unwrap();
        let (mut lo, mut hi) = ([0.0f32; 4], [0.0f32; 4]);
        let mut src = Coarsened::new(vol, d, &mut lo, &mut hi);
        let mut out = [Coloured::default(); 1];
        src.read_sheet(2, 0, &mut out).unwrap();
        assert_eq!(out[0].value, 1.0);
        assert!(
            src.read_sheet(2, 1, &mut out).is_err(),
            "index past the coarse count"
        );
        assert!(
            src.read_sheet(2, 0, &mut [Coloured::default(); 2]).is_err(),
            "wrong sheet length"
        );
        let nan = [f32::NAN; 8];
        let vol = MemoryVolume::new(&nan, d).unwrap();
        let (mut lo, mut hi) = ([0.0f32; 4], [0.0f32; 4]);
        let mut src = Coarsened::new(vol, d, &mut lo, &mut hi);
        src.read_sheet(2, 0, &mut out).unwrap();
        assert!(out[0].value.is_nan());
        // Scratch too small.
        let vol = MemoryVolume::new(&fine, d).unwrap();
        let (mut lo, mut hi) = ([0.0f32; 3], [0.0f32; 4]);
        let mut src = Coarsened::new(vol, d, &mut lo, &mut hi);
        assert!(src.read_sheet(2, 0, &mut out).is_err());
    }

    #[test]
    fn a_level_frame_puts_its_samples_where_their_fine_positions_project() {
        use glam::Mat3;
        let grid = Grid::from_spacing([1.0, 1.5, 2.0]).unwrap();
        let view =
            View::new(Mat3::from_rotation_y(0.4) * Mat3::from_rotation_x(0.3) * 3.0).unwrap();
        let kernel = Kernel::PAPER_GAUSSIAN;
        let options = FootprintOptions::default();
        let fine = FrameSetup::new([9, 8, 7], &grid, &view, &kernel, options, [96, 80]).unwrap();
        for level in 1..=2u32 {
            let f = level_frame(&fine, &grid, &view, &kernel, options, level).unwrap();
            assert_eq!(Some(f.dims), level_dims(fine.dims, level));
            let k = (1u32 << level) as f32;
            for c in [[0.0f32, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 0.0, 1.0]] {
                let want = fine.affine_position(c.map(|x| k * x + level_offset(level)));
                let got = f.affine_position(c);
                assert!(
                    (want - got).length() < 1e-3,
                    "level {level} {c:?}: {got} vs {want}"
                );
            }
            // Twice the spacing: the footprint grows with it.
            assert!(f.footprint.half_extent[0] > fine.footprint.half_extent[0]);
        }
        assert_eq!(
            level_frame(&fine, &grid, &view, &kernel, options, 0).unwrap(),
            fine
        );
        assert!(matches!(
            level_frame(&fine, &grid, &view, &kernel, options, MAX_LEVEL + 1),
            Err(LodError::TooDeep { .. })
        ));
    }

    #[test]
    fn levels_and_offsets() {
        assert_eq!(level_dims([256, 217, 1], 2), Some([64, 55, 1]));
        assert_eq!(level_dims([7, 7, 7], 0), Some([7, 7, 7]));
        assert_eq!(level_dims([7, 7, 7], MAX_LEVEL + 1), None);
        assert_eq!(level_offset(0), 0.0);
        assert_eq!(level_offset(1), 0.5);
        assert_eq!(level_offset(2), 1.5);
    }
}
