//! `--quality DB`'s level of detail: how far each coarser level is from full resolution,
//! measured on a pilot of image rows.
//!
//! # Why a measurement
//! A level's error is the data's: one value and one colour per 2×2×2 block cannot stand in for
//! eight samples composited along a ray where a block holds structure (a thin shell beside empty
//! space, voxel-scale noise). `--lod auto`'s rule on the projected spacing does not see that: it
//! keeps the walnut's level 1 at 39.7 dB at 128×128, and gave 34.5 dB on voxel-scale speckle
//! (docs/modes.md, "Levels of detail"). So `--quality` renders the candidates and compares them.
//!
//! # The pilot
//! 1. **Rows.** The output image's H rows are cut into R = min(H, [`PILOT_ROWS`]) strata of about
//!    H/R rows and one row per stratum, at a position fixed by a hash of the stratum, is taken.
//! 2. **Renders.** Level 0 and each candidate level render those rows only (each output row is a
//!    band of k rows of a k×-supersampled frame; the core's bands give exactly the rows of the
//!    whole frame, bit for bit, and skip the voxels that cannot reach them), float through the
//!    frame's view table (`--table`, `--lookup`: the defaults, since `--quality` overrides them).
//! 3. **Estimate.** Rows are the sampling units (pixels along a row are not independent): each
//!    sampled row's mean squared error (RGB) m_r, their mean m and standard deviation s; the
//!    image's MSE is bounded by m + [`Z`]·s/√R·√(1 − R/H) (m itself when every row is sampled).
//!
//! Candidates are the levels 1, 2, … whose samples project at most [`MAX_SPACING_PX`] apart (a
//! level is for minified volumes); the first that fails its budget ends the search, since a
//! deeper level averages the failing level's blocks again. The caller
//! ([`super::choose`]) splits the target between the level and the table.

use super::sampling::{mix, Estimate};
use crate::io::stream::{ColouredMemorySource, FileSource, MemorySource};
use crate::io::try_filled;
use crate::pipeline::ends::run::{build_stencils, stencil_len};
use crate::pipeline::stages::load::Voxels;
use crate::pipeline::stages::lod::{averaging_for, with_level};
use crate::pipeline::stages::prepare::Prepared;
use crate::pipeline::stages::supersample::downsample;
use crate::plan::Plan;
use crate::scene::Scene;
use crate::CliError;
use footprint::composite::RowSpan;
use footprint::render::{FloatPath, RenderBuffers, SheetRenderer, SheetRing};
use footprint::shade::{Sample, OPACITY_TABLE_LEN};
use footprint::source::{render_all_from, SheetSource};
use footprint::splat::Splatter;
use footprint::ViewTable;
use std::time::Instant;

/// Rows the pilot samples (all of them in an image no taller).
pub const PILOT_ROWS: usize = 16;
/// Standard errors added to the sampled MSE before it is compared with the budget.
pub const Z: f64 = 3.0;
/// Levels whose samples project farther apart than this, pixels, are not tried.
pub const MAX_SPACING_PX: f32 = 2.0;

/// How the level pilot went.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelPilot {
    /// Output rows sampled, of `height`.
    pub rows: usize,
    pub height: usize,
    /// Seconds: level 0's rows, and everything (levels built and rendered included).
    pub base_seconds: f64,
    pub seconds: f64,
    /// Each level tried, in order, with its estimate against level 0.
    pub tried: Vec<(u32, Estimate)>,
}

/// The sampled rows of an image `h` rows high: one per stratum of about h/n rows, at a position
/// inside it fixed by a hash of the stratum, ascending; every row when h ≤ n.
pub fn pilot_rows(h: usize, n: usize) -> Vec<usize> {
    if h <= n {
        return (0..h).collect();
    }
    (0..n)
        .map(|i| {
            let (lo, hi) = (i * h / n, (i + 1) * h / n);
            lo + (mix(i as u64 ^ 0x6c65_7665_6c73) % (hi - lo) as u64) as usize
        })
        .collect()
}

/// `got` against `want` (both `rows` output rows of `w` pixels, premultiplied RGBA), sampled from
/// an image `height` rows high (see the module docs).
pub fn row_estimate(got: &[[f32; 4]], want: &[[f32; 4]], w: usize, height: usize) -> Estimate {
    let per_row: Vec<f64> = got
        .chunks(w.max(1))
        .zip(want.chunks(w.max(1)))
        .map(|(a, b)| {
            let sum: f64 = a
                .iter()
                .zip(b)
                .map(|(p, q)| {
                    (0..3)
                        .map(|c| (f64::from(p[c]) - f64::from(q[c])).powi(2))
                        .sum::<f64>()
                })
                .sum();
            sum / (3 * w.max(1)) as f64
        })
        .collect();
    Estimate::of(&per_row, height, Z)
}

/// The core's float render of `p` (in memory, or streamed from a file: each thread reads it once,
/// coarsened as it streams at a level ≥ 1) at output rows `rows` only, with `plan`'s table size,
/// lookup and phases through the view table (the robust method): `rows.len()` rows of the output
/// width, in the order given. Each equals that row of the whole frame's float render with the
/// same plan, bit for bit.
pub fn render_rows(p: &Prepared, plan: &Plan, rows: &[usize]) -> Result<Vec<[f32; 4]>, CliError> {
    if let Voxels::Stdin { .. } = &p.voxels {
        return Err(CliError::input(
            "the level pilot renders a volume in memory or a file: a pipe is read once",
        ));
    }
    let h = p.out_size().1;
    if let Some(&y) = rows.iter().find(|&&y| y >= h) {
        return Err(CliError::input(format!(
            "pilot row {y} is outside an image {h} rows high"
        )));
    }
    /// The rows through tables of side N.
    struct Rows<'a> {
        p: &'a Prepared,
        plan: &'a Plan,
        rows: &'a [usize],
    }
    impl crate::dispatch::TableSize for Rows<'_> {
        type Output = Vec<[f32; 4]>;
        fn run<const N: usize>(self) -> Result<Vec<[f32; 4]>, CliError> {
            let Rows { p, plan, rows } = self;
            let (f, k, w) = (&p.frame, p.supersample, p.out_size().0);
            let lookup = plan.table.lookup;
            let generic = plan.table.generic::<N>(&p.kernel)?;
            let table = Box::new(ViewTable::<N>::build(
                &f.footprint,
                &generic,
                lookup,
                lookup,
            ));
            // The sampler the whole frame's render uses (`crate::pipeline::ends::run`): phase
            // stencils where the footprint allows them, read by the plan's phase lookup, else
            // the view table.
            let len = stencil_len(p, plan.phases);
            // A file streams once for all the rows: more threads would each read it whole and
            // hold a sheet cache of their own (8 MiB, `crate::io::stream::CACHE_BYTES`).
            let threads = match p.voxels {
                Voxels::File(_) => 1,
                _ => plan.threads,
            };
            let bands = match len {
                Some(len) => {
                    let mut buffer = vec![0.0f32; len];
                    let stencils = build_stencils(&*table, plan, &mut buffer)?;
                    split_rows(p, &stencils, rows, threads)?
                }
                None => split_rows(p, &*table, rows, threads)?,
            };
            let mut out = Vec::with_capacity(rows.len() * w);
            for band in bands {
                out.extend(downsample(&band, (w, 1), k, |v| v as f32));
            }
            Ok(out)
        }
    }
    let work = Rows { p, plan, rows };
    crate::dispatch::with_size(plan.table.size, work)
}

/// [`bands_from`] with `rows` split between `threads` cores, each reading the sheets for its
/// own rows (from memory, or from the file, coarsened as it streams at a level ≥ 1).
fn split_rows<S: Splatter + Sync + ?Sized>(
    p: &Prepared,
    sampler: &S,
    rows: &[usize],
    threads: usize,
) -> Result<Vec<Vec<[f32; 4]>>, CliError> {
    let per = rows
        .len()
        .div_ceil(threads.clamp(1, rows.len().max(1)))
        .max(1);
    let part_of = |part: &[usize]| match &p.voxels {
        Voxels::Memory(v) if v.is_coloured() => {
            bands_from(p, sampler, &mut ColouredMemorySource(v), part)
        }
        Voxels::Memory(v) => bands_from(p, sampler, &mut MemorySource(v), part),
        Voxels::File(layout) => {
            let mut file = FileSource::open(layout.clone())?;
            if p.level == 0 {
                return bands_from(p, sampler, &mut file, part);
            }
            let averaging = averaging_for(&p.shading, p.shader().tf, p.absorption);
            let (fine, level, axis) = (p.fine_dims, p.level, p.frame.sheet_axis);
            with_level(&mut file, fine, level, axis, &*averaging, &mut |c| {
                bands_from(p, sampler, c, part)
            })
        }
        Voxels::Stdin { .. } => Err(CliError::input("a pipe is read once")),
    };
    if per >= rows.len() {
        // One part: on this thread (a streamed file's buffers then go back to the allocator
        // the frame's own render uses; a thread's arena kept 16 MiB more at the peak).
        return part_of(rows);
    }
    let parts: Vec<Result<Vec<Vec<[f32; 4]>>, CliError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = rows
            .chunks(per)
            .map(|part| crate::threads::spawn(scope, move || part_of(part)))
            .collect();
        handles
            .into_iter()
            .map(crate::threads::Task::join)
            .collect()
    });
    let mut bands = Vec::with_capacity(rows.len());
    for part in parts {
        bands.extend(part?);
    }
    Ok(bands)
}

/// One renderer per output row of `rows` (a band of k frame rows), all fed from one pass over
/// `source`'s sheets: each band's k×-wide pixels.
fn bands_from<S, T, Src>(
    p: &Prepared,
    sampler: &S,
    source: &mut Src,
    rows: &[usize],
) -> Result<Vec<Vec<[f32; 4]>>, CliError>
where
    S: Splatter + ?Sized,
    T: Sample + Default,
    Src: SheetSource<Sample = T, Error = CliError> + ?Sized,
{
    let (f, k) = (&p.frame, p.supersample);
    let n = f.size[0] * k;
    let mut buffers = Vec::with_capacity(rows.len());
    for _ in rows {
        buffers.push((
            try_filled(n, [0.0f32; 4], "a pilot band's accumulator")?,
            try_filled(n, [0.0f32; 4], "a pilot band")?,
            vec![RowSpan::EMPTY; k],
            vec![0.0f32; OPACITY_TABLE_LEN],
        ));
    }
    let mut renderers = Vec::with_capacity(rows.len());
    for ((acc, image, spans, opacity), &y) in buffers.iter_mut().zip(rows) {
        let band = y * k..(y + 1) * k;
        let bg = p
            .background
            .as_deref()
            .map(|b| &b[band.start * f.size[0]..band.end * f.size[0]]);
        let buffers = RenderBuffers {
            accumulator: &mut acc[..],
            image: &mut image[..],
            rows: &mut spans[..],
        };
        let path = FloatPath::new(sampler).with_absorption(p.absorption);
        renderers.push(
            SheetRenderer::with_band(f, path, p.shader(), p.order, buffers, bg, band)?
                .with_opacity_table(&mut opacity[..])?,
        );
    }
    let mut storage = try_filled(3 * f.sheet_shape().0, T::default(), "three sheets")?;
    let mut ring = SheetRing::new(&mut storage, f, p.order)?;
    render_all_from(&mut renderers, &mut ring, &mut &mut *source)?;
    for r in renderers {
        r.finish();
    }
    Ok(buffers.into_iter().map(|b| b.1).collect())
}

/// The levels `--quality` may try for `p` (prepared at level 0, in memory, orthographic), in
/// order: `Some(n)` for an explicit `--lod n` (just n), else 1, 2, … while the level's samples
/// project at most [`MAX_SPACING_PX`] apart, down to the deepest `--lod` allows.
pub fn candidate_levels(p: &Prepared, explicit: Option<u32>) -> Vec<u32> {
    if let Some(n) = explicit {
        return if n == 0 { Vec::new() } else { vec![n] };
    }
    let spacing = match crate::pipeline::stages::lod::projected_spacing(
        &p.frame,
        p.kernel.spread(),
        p.supersample,
    ) {
        Some(d) if p.volume().is_some() => d,
        _ => return Vec::new(),
    };
    (1..=crate::pipeline::stages::lod::deepest_level(p.fine_dims))
        .take_while(|&l| spacing * (1u64 << l) as f32 <= MAX_SPACING_PX)
        .collect()
}

/// Measures `levels` of `p0` (level 0, in memory, prepared from `args`) in order against level 0
/// on the pilot rows rendered with `plan`, keeping each level's prepared render; stops after the
/// first level `accept` refuses. Returns the pilot and the prepared levels accepted, in order.
pub fn measure(
    p0: &Prepared,
    args: &Scene,
    plan: &Plan,
    levels: &[u32],
    mut accept: impl FnMut(u32, &Prepared, &Estimate) -> Result<bool, CliError>,
) -> Result<(LevelPilot, Vec<Prepared>), CliError> {
    let start = Instant::now();
    let (_, h) = p0.out_size();
    let rows = pilot_rows(h, PILOT_ROWS);
    let w = p0.out_size().0;
    let base = render_rows(p0, plan, &rows)?;
    let base_seconds = start.elapsed().as_secs_f64();
    let mut tried = Vec::new();
    let mut accepted: Vec<Prepared> = Vec::new();
    for &level in levels {
        let p = p0.at_level(args, level, accepted.last())?;
        let got = render_rows(&p, plan, &rows)?;
        let e = row_estimate(&got, &base, w, h);
        tried.push((level, e));
        if !accept(level, &p, &e)? {
            break;
        }
        accepted.push(p);
    }
    let pilot = LevelPilot {
        rows: rows.len(),
        height: h,
        base_seconds,
        seconds: start.elapsed().as_secs_f64(),
        tried,
    };
    Ok((pilot, accepted))
}

/// The least PSNR (dB, the pilot's lower bound, RGB against level 0) at which `--lod auto` keeps
/// a coarser level.
pub const AUTO_MIN_DB: f64 = 40.0;

/// `--lod auto` for `p0` (prepared at level 0, `args` otherwise as given): the deepest level the
/// geometric rule allows ([`crate::pipeline::stages::lod::auto_level`]) whose pilot bound stays at or above
/// [`AUTO_MIN_DB`] against level 0, the levels tried from 1 down and the first to fail ending the
/// search; level 0 when none passes or in perspective. A file streamed (too large to hold,
/// `pipeline::stages::hold`) is measured as it streams, read once per level tried and once for
/// level 0, so that it keeps the level its loaded file keeps; a pipe, read once, keeps the rule's. The geometric rule alone
/// was fitted on grey ramps and kept the CT head's level 1 at 64² at 30.9 dB under a transfer
/// function with sharp opacity steps (`ct-bone-skin`); the pilot sees what the data and the
/// transfer function do to a level.
pub fn validated_auto(p0: Prepared, args: &Scene, plan: &Plan) -> Result<Prepared, CliError> {
    // The level the geometric rule picks for `args` (`--lod auto`), as prepare would have.
    let (_, _, deepest) = crate::pipeline::stages::prepare::setup_frame(
        args,
        plan.resolution(),
        p0.fine_dims,
        &p0.grid,
        &p0.kernel,
        p0.options,
    )?;
    if deepest == 0 || matches!(p0.voxels, Voxels::Stdin { .. }) {
        return Ok(p0);
    }
    let levels: Vec<u32> = (1..=deepest).collect();
    let (_, mut accepted) = measure(&p0, args, plan, &levels, |_, _, e| {
        Ok(e.bound_db >= AUTO_MIN_DB)
    })?;
    Ok(accepted.pop().unwrap_or(p0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pilot_rows_take_one_row_per_stratum() {
        for (h, n) in [(64, 16), (512, 16), (17, 16), (1000, 7)] {
            let r = pilot_rows(h, n);
            assert_eq!(r.len(), n);
            for (i, &y) in r.iter().enumerate() {
                assert!((i * h / n..(i + 1) * h / n).contains(&y), "{h} {n}: {r:?}");
            }
        }
        assert_eq!(pilot_rows(5, 16), vec![0, 1, 2, 3, 4]);
    }

    #[test]
    fn the_row_estimate_is_exact_on_every_row_and_bounded_on_a_sample() {
        // Two rows of two pixels: squared errors 0.01 and 0.09 in every RGB channel of row 1.
        let want = [[0.0f32; 4]; 4];
        let got = [
            [0.0; 4],
            [0.0; 4],
            [0.1, 0.1, 0.1, 0.0],
            [0.3, 0.3, 0.3, 0.0],
        ];
        let mse = (0.01f64 + 0.09) / 4.0;
        let e = row_estimate(&got, &want, 2, 2);
        assert!((e.estimate_db - -10.0 * mse.log10()).abs() < 1e-4, "{e:?}");
        assert_eq!(e.estimate_db, e.bound_db);
        let sampled = row_estimate(&got, &want, 2, 40);
        assert!(sampled.bound_db < sampled.estimate_db, "{sampled:?}");
        assert_eq!(row_estimate(&want, &want, 2, 2).bound_db, f64::INFINITY);
    }
}
