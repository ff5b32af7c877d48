//! `--slicing image`: the core's image-aligned slabs (`footprint::render::slabs`) over the
//! visible voxels of a volume in memory, on several cores.
//!
//! 1. The visible lists (classified once per volume, as for sheets: [`crate::pipeline::stages::visible`]) are
//!    shaded for one world unit of thickness and valued as the `--absorption` model reads them
//!    ([`SlabSetup::voxel`]), placed on screen, and sorted by the slab each reaches
//!    first in compositing order (one counting sort), in runs of sheets on threads of their own
//!    (`SlabVoxels`: the order of splats does not depend on the thread count). On one thread
//!    this was all of a re-render's classify phase and serial: 230-255 ms of the 256³ blobs' 284
//!    ms frame on 16 threads at 512² (`benches/threads16.sh`, 2026-12-04).
//! 2. The image is cut into blocks of rows whose slab accumulators fit the cache
//!    ([`crate::pipeline::stages::blocks`]), each voxel listed in the blocks it reaches; threads
//!    take blocks as they come free. A block walks the slabs in compositing order: the voxels
//!    that reach slab j first (that reach the block) are splatted into every slab they overlap,
//!    then slab j is composited (the core's ring of slab accumulators, one plane per slab).
//! 3. With `--depth-phases N` each voxel's depth is snapped to one of N phases per slab and its
//!    sections are splatted from section stencils built once per frame
//!    (`footprint::render::SectionStencils`), shared read-only by every block; without, each
//!    kernel is cut pixel by pixel. Opacity-model slabs are composited through a table of the
//!    opacity correction (`footprint::render::absorption::OpacityLayers`, within 10⁻⁵).
//!
//! **Memory.** 28 bytes per visible voxel (its [`SlabVoxel`]; 76 while a run of sheets sorts
//! them) on top of the visible lists, and 4 per voxel and block it reaches; the sort's keys, 8
//! bytes per slab and back to front per slab of the ring, per run of sheets (64 MiB at most
//! together: `KEY_BYTES`); per thread the ring of `SlabSetup::ring`
//! slab accumulators of the block it renders (16 bytes per pixel each: on an isotropic grid a
//! kernel 1.6 voxels in radius spans at most 5 slabs of one spacing, 8 of half a spacing), and
//! the 13 KiB section table. A slab of an oblique
//! view crosses every sheet, so a streamed volume (`--stream`) is refused: feeding it from a
//! bounded window of sheets is not possible (see the core module's docs).

use crate::pipeline::stages::bands::{Bands, CoreFrame, Phases};
use crate::pipeline::stages::blocks::{block_rows, blocks, on_blocks, Members};
use crate::pipeline::stages::prepare::Prepared;
use crate::pipeline::stages::visible::FrameCache;
use crate::CliError;
use footprint::composite::RowSpan;
use footprint::frame::Order;
use footprint::render::absorption::OpacityLayers;
use footprint::render::{
    occlusion_len, RenderStats, SectionStencils, SlabBuffers, SlabRenderer, SlabSetup, SlabVoxel,
};
use footprint::shade::Lighting;
use footprint::table::SectionTable;
use std::time::Instant;

/// The section table's nodes: the radial factor over ρ², the depth integral over the chord (see
/// `footprint::table::SectionTable`: 2.4·10⁻⁶ of the peak at worst, 13 KiB).
const ROWS: usize = 257;
const COLUMNS: usize = 1025;

/// The most sub-pixel phases of section stencils: D · K sets of them must stay in the cache (at
/// 8 phases, 8 depth phases and the 256×256×113 CT phantom's 9 slab offsets at 512²: 1.1 MiB).
const SECTION_PHASES: usize = 8;

/// The most floats of section stencils a frame builds (32 MiB); past it the renderer cuts each
/// kernel per pixel.
const MAX_SECTION_FLOATS: usize = 1 << 23;

/// Renders one frame of `p` with image-aligned slabs `thickness` voxel spacings thick on
/// `plan`'s bands (float: the plan refuses fixed-point slabs), culling occluded voxels if it says
/// so, through section stencils where it has depth phases (and phases, at most
/// `SECTION_PHASES`, read by its phase lookup) and they fit `MAX_SECTION_FLOATS`.
pub fn render_slabs(
    p: &Prepared,
    thickness: f32,
    plan: &crate::plan::Plan,
    cache: &mut FrameCache,
) -> Result<CoreFrame, CliError> {
    let bands = Bands::of(plan);
    let refuse = |why: &str| CliError::input(format!("{}: --slicing image: {why}", p.name));
    let volume = p.volume().ok_or_else(|| {
        refuse(
            "a slab of an oblique view crosses every sheet, so it cannot be fed from a few \
             streamed sheets: drop --stream (the volume is loaded) or use --slicing object",
        )
    })?;
    let section_phases = plan.phases.min(SECTION_PHASES);
    let depth_phases = if section_phases > 0 {
        plan.depth_phases
    } else {
        0
    };
    let setup = SlabSetup::new(&p.frame, &p.kernel, thickness)
        .and_then(|s| s.with_depth_phases(depth_phases))
        .map_err(|e| refuse(&e.to_string()))?
        .with_absorption(p.absorption);
    let start = Instant::now();
    let mut table = Box::new(SectionTable::<ROWS, COLUMNS>::zeroed(p.kernel));
    table
        .build_into(p.kernel)
        .map_err(|e| refuse(&e.to_string()))?;
    let len = SectionStencils::len_for(&setup, section_phases).filter(|&n| n <= MAX_SECTION_FLOATS);
    let mut store = crate::io::try_filled(len.unwrap_or(0), 0.0f32, "the section stencils")?;
    let stencils = match len {
        Some(_) => Some(
            SectionStencils::build(&setup, &table, section_phases, &mut store)
                .map_err(|e| refuse(&e.to_string()))?
                .with_phase_lookup(plan.phase_lookup.unwrap_or_default()),
        ),
        _ => None,
    };
    let layers = OpacityLayers::new(setup.chord());
    let tables = start.elapsed().as_secs_f64();

    let t0 = Instant::now();
    let (lists, fresh) = cache.lists(p, volume, bands.threads, "image slicing")?;
    let classify_lists = if fresh {
        t0.elapsed().as_secs_f64()
    } else {
        0.0
    };
    let t1 = Instant::now();
    let [w, h] = p.frame.size;
    let rows = block_rows(w, setup.ring(), std::mem::size_of::<[f32; 4]>());
    let ranges = blocks(h, rows);
    let voxels = slab_voxels(p, &setup, lists, bands.threads, rows)?;
    let classify = classify_lists + t1.elapsed().as_secs_f64();

    let (setup, table, sv, stencils) = (&setup, &*table, &voxels, stencils.as_ref());
    let threads = bands.threads.clamp(1, ranges.len().max(1));
    let timing = (start, classify, tables);
    banded_frame(p, threads, timing, voxels.len(), |image| {
        on_blocks(
            image,
            w,
            &ranges,
            threads,
            p.background.as_deref(),
            |b, rows, band, bg| {
                let tables = (table, stencils, &layers);
                render_band(p, setup, tables, sv, b, bg, band, rows, bands.cull)
            },
        )
    })
}

/// A slab end's frame: the image rendered by `render` (given a clear image, it returns the image,
/// the counts and the busiest thread's phases) on `threads` threads, with the phases timed before
/// it (`timing`: the frame's start, classification and table seconds) and its `voxels` (every
/// band or block sees only those that reach it: the frame's are the list's), resampled to the
/// output size.
pub(crate) fn banded_frame<F>(
    p: &Prepared,
    threads: usize,
    timing: (Instant, f64, f64),
    voxels: usize,
    render: F,
) -> Result<CoreFrame, CliError>
where
    F: FnOnce(Vec<[f32; 4]>) -> Result<(Vec<[f32; 4]>, RenderStats, Phases), CliError>,
{
    let (start, classify, tables) = timing;
    let [w, h] = p.frame.size;
    let (image, mut stats, band_phases) =
        render(crate::io::try_filled(w * h, [0.0f32; 4], "the image")?)?;
    stats.voxels = voxels as u64;
    let phases = Phases {
        classify,
        tables,
        ..band_phases
    };
    Ok(CoreFrame {
        image,
        stats,
        seconds: start.elapsed().as_secs_f64(),
        phases,
        threads,
        visible: Some(voxels),
        refine: None,
    })
}

/// Every visible voxel as a [`SlabVoxel`], grouped by the compositing step at which it enters
/// (its first slab front to back, its last back to front; within a step, by first slab, then in
/// sheet order), cut into chunks of whole sheets that are classified, sorted and placed in blocks
/// on threads of their own.
///
/// **Identity.** The chunks are runs of consecutive sheets, in order, and each is sorted stably
/// by one key per (step, first slab) on its own; a block walks every chunk's voxels of one key,
/// chunk after chunk, before the next key. That is the order of one stable sort of the whole
/// list (step, first slab, sheet order), whatever the number of chunks: the same splats in the
/// same order for every thread count.
struct SlabVoxels {
    chunks: Vec<SlabChunk>,
}

/// The voxels of a run of sheets (see [`SlabVoxels`]).
struct SlabChunk {
    voxels: Vec<SlabVoxel>,
    /// `voxels[starts[j]..starts[j + 1]]` have key j = step · [`key_span`] + the rank of their
    /// first slab among those of the step (step k: slab k front to back, slab count − 1 − k back
    /// to front).
    starts: Vec<usize>,
    /// The chunk's voxels reaching each block, as indices into `voxels`.
    members: Members,
}

impl SlabVoxels {
    fn len(&self) -> usize {
        self.chunks.iter().map(|c| c.voxels.len()).sum()
    }
}

/// The sort keys' bytes all runs of sheets may hold together ([`slab_voxels`]): the runs are
/// fewer than the threads where a frame's keys would pass it (the order, and so the image, does
/// not depend on how many there are).
const KEY_BYTES: usize = 64 << 20;

/// Keys per compositing step: back to front, one per slab count a voxel can span (the ring), its
/// first slab ordering the voxels of a step; front to back the step is the first slab.
fn key_span(order: Order, setup: &SlabSetup) -> usize {
    match order {
        Order::FrontToBack => 1,
        Order::BackToFront => setup.ring().max(1),
    }
}

/// Shades, places and sorts the visible voxels of `lists` on up to `threads` threads (runs of
/// sheets with about the same number of voxels each), and lists each run's voxels by the blocks
/// of `rows` rows they reach.
fn slab_voxels(
    p: &Prepared,
    setup: &SlabSetup,
    lists: &crate::pipeline::stages::visible::VisibleLists,
    threads: usize,
    rows: usize,
) -> Result<SlabVoxels, CliError> {
    // Each run sorts by count · span keys of 8 bytes (up to 2^16 slabs of a ring of 40 on a
    // hostile view: 20 MiB): at most KEY_BYTES of them together, whatever the thread count.
    let keys = setup
        .slab_count()
        .saturating_mul(key_span(p.order, setup))
        .max(1);
    let threads = threads.min(KEY_BYTES / keys.saturating_mul(8)).max(1);
    let runs = sheet_runs(p.frame.sheet_count(), threads, |s| {
        lists.sheet(s).voxels.len()
    });
    let chunks: Vec<Result<SlabChunk, CliError>> = std::thread::scope(|scope| {
        let tasks: Vec<_> = runs
            .into_iter()
            .map(|sheets| {
                crate::threads::spawn(scope, move || slab_chunk(p, setup, lists, sheets, rows))
            })
            .collect();
        tasks.into_iter().map(crate::threads::Task::join).collect()
    });
    Ok(SlabVoxels {
        chunks: chunks.into_iter().collect::<Result<_, _>>()?,
    })
}

/// Cuts sheets 0..`count` into at most `parts` runs of consecutive sheets holding about the same
/// number of `voxels` each (none empty; one run, possibly empty, when there is nothing).
fn sheet_runs(
    count: usize,
    parts: usize,
    voxels: impl Fn(usize) -> usize,
) -> Vec<std::ops::Range<usize>> {
    let total: usize = (0..count).map(&voxels).sum();
    let parts = parts.clamp(1, count.max(1));
    let mut runs = Vec::with_capacity(parts);
    let (mut start, mut seen) = (0, 0usize);
    for s in 0..count {
        seen += voxels(s);
        // Close the run once it holds its share of the voxels seen so far.
        if runs.len() + 1 < parts
            && seen.saturating_mul(parts) >= total.saturating_mul(runs.len() + 1)
        {
            runs.push(start..s + 1);
            start = s + 1;
        }
    }
    if start < count || runs.is_empty() {
        runs.push(start..count);
    }
    runs
}

/// One run of sheets' voxels: shaded for one world unit, placed on screen, sorted by step with
/// one stable counting sort, and bucketed by block.
fn slab_chunk(
    p: &Prepared,
    setup: &SlabSetup,
    lists: &crate::pipeline::stages::visible::VisibleLists,
    sheets: std::ops::Range<usize>,
    rows: usize,
) -> Result<SlabChunk, CliError> {
    let f = &p.frame;
    let shader = p.shader();
    // Opacity per world unit (the slab integrates the model's field along the ray itself).
    let lighting = Lighting::per_world_unit(f);
    let needs_gradient = shader.shading.needs_gradient();
    let len: usize = sheets.clone().map(|s| lists.sheet(s).voxels.len()).sum();
    let mut placed: Vec<(SlabVoxel, (usize, usize))> = Vec::new();
    placed
        .try_reserve_exact(len)
        .map_err(|_| CliError::input("cannot allocate the slab voxel list"))?;
    for s in sheets {
        let sheet = lists.sheet(s);
        for (k, vox) in sheet.voxels.iter().enumerate() {
            let idx = f.grid_index(s, usize::from(vox.u), usize::from(vox.v));
            let g = || {
                if needs_gradient {
                    glam::Vec3::from_array(sheet.gradients[k])
                } else {
                    glam::Vec3::ZERO
                }
            };
            let colour = sheet.colours.get(k).copied();
            let rgba = shader.shade_coloured(&lighting, None, vox.value, colour, g, idx, f.dims);
            let position = f.affine_position(idx.map(|c| c as f32)).to_array();
            if let Some(v) = setup.voxel(position, rgba) {
                placed.push((v, setup.slabs_of(position[2])));
            }
        }
    }
    let (count, span) = (setup.slab_count(), key_span(p.order, setup));
    // One key per voxel whose order is (step, first slab); a stable sort keeps sheet order within
    // a key. Front to back the step is the first slab. Back to front it is count − 1 − last, and
    // a voxel spans d = last − first < `span` slabs (the ring holds them all), so first ascending
    // is d descending: key = step · span + (span − 1 − d).
    let key = |&(_, (a, b)): &(SlabVoxel, (usize, usize))| match p.order {
        Order::FrontToBack => a,
        Order::BackToFront => (count - 1 - b) * span + (span - 1 - (b - a).min(span - 1)),
    };
    let (voxels, starts) = counting_sort(
        placed.len(),
        count * span,
        |i| key(&placed[i]),
        |i| placed[i].0,
        "the slab voxel list",
    )?;
    drop(placed);
    let h = p.frame.size[1];
    let members = Members::of(voxels.len(), h, rows, |i| {
        setup.rows_of(voxels[i].position[1])
    })?;
    Ok(SlabChunk {
        voxels,
        starts,
        members,
    })
}

/// A stable counting sort of items 0..`n` by `key(i)` (each below `count`): the items, as
/// `value(i)`, in key order (index order within a key), and where each key's run starts
/// (`count + 1` entries). No index array: each value is written once into its place. Allocation
/// failures are errors naming `what`.
pub(crate) fn counting_sort<T: Copy>(
    n: usize,
    count: usize,
    key: impl Fn(usize) -> usize,
    value: impl Fn(usize) -> T,
    what: &str,
) -> Result<(Vec<T>, Vec<usize>), CliError> {
    let mut at = crate::io::try_filled(count + 1, 0usize, what)?;
    for i in 0..n {
        at[key(i) + 1] += 1;
    }
    for j in 0..count {
        at[j + 1] += at[j];
    }
    let Some(fill) = (n > 0).then(|| value(0)) else {
        return Ok((Vec::new(), at));
    };
    let mut sorted = crate::io::try_filled(n, fill, what)?;
    for i in 0..n {
        let k = key(i);
        sorted[at[k]] = value(i);
        at[k] += 1;
    }
    // Each key's slot now holds where the next key starts: shifted by one, the starts again.
    at.rotate_right(1);
    at[0] = 0;
    Ok((sorted, at))
}

/// One band (a block of rows): every slab in compositing order: the voxels that reach it first
/// splatted (into every slab each overlaps), then the slab composited; occluded voxels culled at
/// `cull`'s ε. The band is block `block` of the voxels' [`Members`].
#[allow(clippy::too_many_arguments)]
fn render_band(
    p: &Prepared,
    setup: &SlabSetup,
    (table, stencils, layers): (
        &SectionTable<ROWS, COLUMNS>,
        Option<&SectionStencils>,
        &OpacityLayers,
    ),
    sv: &SlabVoxels,
    block: usize,
    background: Option<&[[f32; 4]]>,
    image: &mut [[f32; 4]],
    rows: std::ops::Range<usize>,
    cull: Option<f32>,
) -> Result<(RenderStats, Phases), CliError> {
    let w = p.frame.size[0];
    let ring = setup.ring();
    let mut occluded = vec![0u8; cull.map_or(0, |_| occlusion_len(w, rows.len()))];
    let n = w * rows.len();
    let mut acc = crate::io::try_filled(
        ring.saturating_mul(n),
        [0.0f32; 4],
        "a band's slab accumulators",
    )?;
    let mut spans = vec![RowSpan::EMPTY; ring * rows.len()];
    let buffers = SlabBuffers {
        accumulators: &mut acc,
        image,
        rows: &mut spans,
    };
    let clip = p.clip_planes()?;
    let mut renderer =
        SlabRenderer::with_band(setup, table, p.order, buffers, background, rows.clone())?
            .with_clip(&clip)
            .with_layers(layers);
    if let Some(eps) = cull {
        renderer = renderer.with_occlusion(&mut occluded, eps)?;
    }
    if let Some(st) = stencils {
        renderer = renderer
            .with_stencils(st)
            .map_err(|e| CliError::input(e.to_string()))?;
    }
    let mut phases = Phases::default();
    // Each chunk's voxels reaching the block, in the chunk's order.
    let mut mine: Vec<_> = sv
        .chunks
        .iter()
        .map(|c| {
            c.members
                .of_block(block)
                .iter()
                .map(|&i| i as usize)
                .peekable()
        })
        .collect();
    let span = key_span(p.order, setup);
    for k in 0..setup.slab_count() {
        crate::cancel::check()?;
        let t0 = Instant::now();
        // Each chunk's list is in key order, so its voxels of step k come next, key by key.
        for j in k * span..(k + 1) * span {
            for (c, mine) in sv.chunks.iter().zip(&mut mine) {
                while let Some(i) = mine.next_if(|&i| i < c.starts[j + 1]) {
                    renderer.splat_voxel(&c.voxels[i])?;
                }
            }
        }
        let t1 = Instant::now();
        renderer.composite_next();
        phases.splat += (t1 - t0).as_secs_f64();
        phases.composite += t1.elapsed().as_secs_f64();
    }
    Ok((renderer.finish(), phases))
}

#[cfg(test)]
mod tests {
    use super::sheet_runs;

    /// Runs tile the sheets in order, none empty, at most `parts` of them, and split the voxels
    /// about evenly where the sheets allow it.
    #[test]
    fn sheet_runs_tile_the_sheets_with_about_equal_voxels() {
        let weights: [&[usize]; 5] = [
            &[],
            &[0, 0, 0],
            &[5; 40],
            &[0, 0, 100, 0, 0, 1, 1, 1, 1, 90],
            &[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13],
        ];
        for w in weights {
            for parts in [1usize, 2, 3, 7, 16, 100] {
                let runs = sheet_runs(w.len(), parts, |s| w[s]);
                assert!(
                    !runs.is_empty() && runs.len() <= parts.max(1),
                    "{w:?} {parts}"
                );
                assert_eq!(runs[0].start, 0);
                assert_eq!(runs.last().map(|r| r.end), Some(w.len()));
                assert!(runs.windows(2).all(|p| p[0].end == p[1].start));
                if !w.is_empty() {
                    assert!(
                        runs.iter().all(|r| !r.is_empty()),
                        "{w:?} {parts}: {runs:?}"
                    );
                }
            }
        }
        // 40 equal sheets in 4 runs: 10 each.
        let runs = sheet_runs(40, 4, |_| 5);
        assert_eq!(runs, [0..10, 10..20, 20..30, 30..40]);
    }
}
