//! `--lod auto|N`: levels of detail for minified volumes (the core's `footprint::lod`).
//!
//! Level L averages each 2×2×2 block of level L − 1 into one sample with twice the spacing (the
//! core's module docs justify the box). A volume in memory is coarsened once, when prepared, into
//! an f32 volume of the level's dims; a streamed one is coarsened as it streams, through nested
//! [`Coarsened`] adaptors, each holding two sheets of the level above it (so a streamed level-L
//! render holds 2L more sheets than a level-0 one, each no larger than a level-0 sheet).
//!
//! **`auto`** picks the deepest level L whose blocks stay small on screen *and* in samples:
//! 4ᴸ·d ≤ [`AUTO_BUDGET_PX`], d the level-0 samples' projected spacing along the tightest
//! direction, pixels (2ᴸ·d is the level's own spacing; the other 2ᴸ is how many fine samples a
//! block merges along each axis), keeping at least [`MIN_SAMPLES`] samples along the longest axis;
//! a perspective frame stays at level 0 (the levels are placed for orthographic frames).
//!
//! Why both factors: a level's error grows with its depth as well as with its spacing, because
//! averaging merges the sub-block structure of a ray's compositing (a thin shell that covers part
//! of a block) that no sample value and colour keep. Measured (`footprint chart --lod-only`, view
//! 30,20,0, PSNR against level 0): the walnut's level 1 at 1.3 px spacing (128×128) 39.7 dB but
//! its level 2 at the same spacing (64×64) 30.4 dB; the blobs' level 2 at 0.58 px 46.5 dB, level 3
//! at 1.16 px 36.5 dB. A bound on the spacing alone cannot keep the first and refuse the second
//! and fourth; 4ᴸ·d ≤ 3 px does (2.6, 5.2, 2.3 and 9.3 px). The bound is empirical: fitted on
//! these two volumes and checked on every volume in `../shared/data` at 64², 128² and 512²
//! (docs/modes.md, "Levels of detail").

use crate::io::stream::{ColouredMemorySource, MemorySource};
use crate::io::try_filled;
use crate::io::volume::{Samples, Volume};
use crate::plan::Lod;
use crate::CliError;
use footprint::frame::FrameSetup;
use footprint::lod::{
    coarse_dims, level_dims, Averaging, Coarsened, Coloured, Extinction, Linear, MAX_LEVEL,
};
use footprint::shade::{Shading, TransferFunction};
use footprint::source::SheetSource;
use footprint::Kernel;

/// `auto`'s bound on 4ᴸ·d, pixels (see the module docs).
pub const AUTO_BUDGET_PX: f32 = 3.0;

/// `auto` keeps at least this many samples along the volume's longest axis.
pub const MIN_SAMPLES: usize = 8;

/// A source of f32 sheets that reports the harness's errors.
pub type DynSource<'a> = dyn SheetSource<Sample = f32, Error = CliError> + 'a;

/// A source of a coarser level's sheets ([`Coloured`] samples) that reports the harness's errors.
pub type ColouredSource<'a> = dyn SheetSource<Sample = Coloured, Error = CliError> + 'a;

/// The level `lod` asks for, given level 0's frame `fine` at the output size and the kernel.
pub fn choose_level(lod: Lod, fine: &FrameSetup, kernel: &Kernel) -> u32 {
    match lod {
        Lod::Level(n) => n,
        Lod::Auto => auto_level(fine, kernel.spread()),
    }
}

/// `auto`'s level for level 0's frame `fine` at the output size, reconstructed with a kernel of
/// radius `spread` grid steps (see the module docs).
pub fn auto_level(fine: &FrameSetup, spread: f32) -> u32 {
    let Some(spacing) = projected_spacing(fine, spread, 1) else {
        return 0;
    };
    let deepest = deepest_level(fine.dims);
    let mut level = 0;
    while level < deepest && spacing * (4u64 << (2 * level)) as f32 <= AUTO_BUDGET_PX {
        level += 1;
    }
    level
}

/// Level 0's samples' projected spacing along the tightest direction, output pixels, for
/// `frame` (orthographic, set up at `supersample` times the output size) reconstructed with a
/// kernel of radius `spread` grid steps; `None` for a perspective frame (its spacing varies) or
/// a degenerate one.
pub fn projected_spacing(frame: &FrameSetup, spread: f32, supersample: usize) -> Option<f32> {
    if frame.camera().is_some() {
        return None;
    }
    let spacing = frame.footprint.natural_minor_px / spread / supersample as f32;
    (spacing > 0.0 && spacing.is_finite()).then_some(spacing)
}

/// The deepest level of a `dims` volume whose longest axis keeps at least [`MIN_SAMPLES`]
/// samples (or all of them, for a volume with fewer), at most [`MAX_LEVEL`].
pub fn deepest_level(dims: [usize; 3]) -> u32 {
    let longest = |d: [usize; 3]| d.iter().copied().max().unwrap_or(0);
    let least = MIN_SAMPLES.min(longest(dims));
    let mut level = 0;
    while level < MAX_LEVEL && level_dims(dims, level + 1).is_some_and(|d| longest(d) >= least) {
        level += 1;
    }
    level
}

/// How the levels average their samples: keeping the quantity the `model` reconstructs (mean
/// opacity or mean extinction, [`Extinction::for_model`]) for emission and Phong shading through
/// a transfer function whose opacity never decreases with the value; the values themselves
/// otherwise (iso-surfaces and the texture shade from the value, not the opacity).
pub fn averaging_for<'a>(
    shading: &Shading,
    tf: TransferFunction<'a>,
    model: footprint::render::Absorption,
) -> Box<dyn Averaging + Sync + 'a> {
    match shading {
        Shading::Emission | Shading::Phong(_) => match Extinction::for_model(tf, model) {
            Some(e) => Box::new(e),
            None => Box::new(Linear),
        },
        _ => Box::new(Linear),
    }
}

/// Runs `f` on `source` (a volume of `dims`) seen at `level` ≥ 1 levels coarser, sheets along
/// `axis`: nested [`Coarsened`] adaptors averaging with `averaging`, each holding two scratch
/// sheets of the level above it. (Level 0 is `source` itself; a level is refused.)
pub fn with_level<R>(
    source: &mut DynSource<'_>,
    dims: [usize; 3],
    level: u32,
    axis: usize,
    averaging: &dyn Averaging,
    f: &mut dyn FnMut(&mut ColouredSource<'_>) -> Result<R, CliError>,
) -> Result<R, CliError> {
    if level == 0 {
        return Err(CliError::input(
            "level 0 is the volume itself: it has no coarser level to stream",
        ));
    }
    coarsen_once(source, dims, level - 1, axis, averaging, f)
}

/// `source` (a volume of `dims`, f32 or coloured samples) one level coarser through a
/// [`Coarsened`] adaptor with its two scratch sheets, then `more` levels below that, then `f`.
fn coarsen_once<S, R>(
    source: &mut S,
    dims: [usize; 3],
    more: u32,
    axis: usize,
    averaging: &dyn Averaging,
    f: &mut dyn FnMut(&mut ColouredSource<'_>) -> Result<R, CliError>,
) -> Result<R, CliError>
where
    S: SheetSource<Error = CliError> + ?Sized,
    S::Sample: Default,
{
    let len = Coarsened::<&mut S>::scratch_len(dims, axis);
    let blank = S::Sample::default();
    let mut lower = try_filled(len, blank, "a level-of-detail sheet")?;
    let mut upper = try_filled(len, blank, "a level-of-detail sheet")?;
    let mut coarse = Coarsened::new(source, dims, &mut lower, &mut upper).averaging(averaging);
    let (coarse_source, dims): (&mut ColouredSource<'_>, _) = (&mut coarse, coarse_dims(dims));
    if more == 0 {
        f(coarse_source)
    } else {
        coarsen_once(coarse_source, dims, more - 1, axis, averaging, f)
    }
}

/// Level `level` of `v`, in memory with 2ᴸ times the spacing, built sheet by sheet, averaging
/// with `averaging`: [`Samples::Coloured`] (values and the colours extinction averaging carries)
/// for a level ≥ 1, `v` itself for level 0. `v` may itself be a level (coloured samples): its
/// level `level` is then the volume's level `v`'s + `level`, the same samples the nested
/// adaptors of a stream deliver.
pub fn coarsen_volume(
    v: &Volume,
    level: u32,
    averaging: &(dyn Averaging + Sync),
) -> Result<Volume, CliError> {
    let dims = level_dims(v.dims, level).ok_or_else(|| {
        CliError::input(format!("--lod {level}: the deepest level is {MAX_LEVEL}"))
    })?;
    if level == 0 {
        return Ok(v.clone());
    }
    let sheet = dims[0] * dims[1];
    let mut out = try_filled(
        sheet * dims[2],
        Coloured::default(),
        "the level-of-detail volume",
    )?;
    // Coarse z-sheets are independent (each reads its own blocks of fine sheets): contiguous
    // runs of them are built on separate cores, each through its own adaptors. The samples do
    // not depend on the split.
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, dims[2]);
    let per = dims[2].div_ceil(threads);
    let results: Vec<Result<(), CliError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = out
            .chunks_mut(per * sheet)
            .enumerate()
            .map(|(t, run)| {
                crate::threads::spawn(scope, move || {
                    let mut fill = |s: &mut ColouredSource<'_>| {
                        for (i, slice) in run.chunks_mut(sheet).enumerate() {
                            s.read_sheet(2, t * per + i, slice)?;
                        }
                        Ok(())
                    };
                    if v.is_coloured() {
                        let mut src = ColouredMemorySource(v);
                        coarsen_once(&mut src, v.dims, level - 1, 2, averaging, &mut fill)
                    } else {
                        with_level(&mut MemorySource(v), v.dims, level, 2, averaging, &mut fill)
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .map(crate::threads::Task::join)
            .collect()
    });
    results.into_iter().collect::<Result<(), CliError>>()?;
    let scale = (1u64 << level) as f32;
    Ok(Volume {
        dims,
        spacing: v.spacing.map(|s| s * scale),
        directions: v.directions,
        samples: Samples::Coloured(out.into()),
        brick: None,
        grid: None,
        // Coarsened from the values, already mapped.
        values: crate::io::volume::ValueMap::IDENTITY,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_coarsened_volume_is_the_mean_of_its_blocks() {
        let dims = [4usize, 3, 2];
        let data: Vec<f32> = (0..24).map(|i| i as f32).collect();
        let v = Volume::new(dims, [1.0, 2.0, 3.0], Samples::F32(data.clone().into()));
        let c = coarsen_volume(&v, 1, &Linear).unwrap();
        assert_eq!(c.dims, [2, 2, 1]);
        assert_eq!(c.spacing, [2.0, 4.0, 6.0]);
        let Samples::Coloured(s) = &c.samples else {
            panic!("coloured samples")
        };
        let s: Vec<f32> = s.iter().map(|c| c.value).collect();
        // Coarse (1, 1, 0): fine x 2..3, y 2 (clamped: 2, 2), z 0..1.
        let mut want = 0.0;
        for z in 0..2 {
            for y in [2, 2] {
                for x in 2..4 {
                    want += data[(z * 3 + y) * 4 + x];
                }
            }
        }
        assert_eq!(s[3], want / 8.0);
        // Level 2 of the volume is level 1 of its level 1.
        let data: Vec<f32> = (0..8 * 6 * 4).map(|i| ((i * 37) % 11) as f32).collect();
        let big = Volume::new([8, 6, 4], [1.0; 3], Samples::F32(data.into()));
        let two = coarsen_volume(&big, 2, &Linear).unwrap();
        let one = coarsen_volume(&big, 1, &Linear).unwrap();
        assert_eq!(coarsen_volume(&one, 1, &Linear).unwrap(), two);
        // Built on several cores, the level is the one the adaptors deliver in sequence.
        let mut sequential = vec![Coloured::default(); 4 * 3 * 2];
        with_level(&mut MemorySource(&big), big.dims, 1, 2, &Linear, &mut |s| {
            for (z, slice) in sequential.chunks_mut(12).enumerate() {
                s.read_sheet(2, z, slice)?;
            }
            Ok(())
        })
        .unwrap();
        assert_eq!(one.samples, Samples::Coloured(sequential.into()));
        let c0 = coarsen_volume(&v, 0, &Linear).unwrap();
        assert_eq!(c0, v);
        assert!(coarsen_volume(&v, MAX_LEVEL + 1, &Linear).is_err());
    }
}
