//! `--slicing image`: the core's image-aligned slabs (`footprint::render::slabs`) over the
//! visible voxels of a volume in memory, on several cores.
//!
//! 1. The visible lists (classified once per volume, as for sheets: [`crate::pipeline::stages::visible`]) are
//!    shaded for one world unit of thickness and valued as the `--absorption` model reads them
//!    ([`SlabSetup::voxel`]), placed on screen, and sorted by the slab each reaches
//!    first in compositing order (counting sorts: the voxel order within a slab does not depend
//!    on the thread count).
//! 2. The image is cut into blocks of rows whose slab accumulators fit the cache
//!    ([`crate::pipeline::stages::blocks`]), each voxel listed in the blocks it reaches; threads
//!    take blocks as they come free. A block walks the slabs in compositing order: the voxels
//!    that reach slab j first (that reach the block) are splatted into every slab they overlap,
//!    then slab j is composited (the core's ring of slab accumulators).
//!
//! **Memory.** 40 bytes per visible voxel (its [`SlabVoxel`] and slab range) on top of the
//! visible lists, and 4 per voxel and block it reaches; per thread the ring of `SlabSetup::ring`
//! slab accumulators of the block it renders (16 bytes per pixel each: on an isotropic grid a
//! kernel 1.6 voxels in radius spans at most 5 slabs of one spacing, 8 of half a spacing), and
//! the 13 KiB section table. A slab of an oblique
//! view crosses every sheet, so a streamed volume (`--stream`) is refused: feeding it from a
//! bounded window of sheets is not possible (see the core module's docs).

use crate::pipeline::stages::bands::{Bands, CoreFrame, Phases};
use crate::pipeline::stages::blocks::{block_rows, blocks, on_blocks, Members};
use crate::pipeline::stages::prepare::Prepared;
use crate::pipeline::stages::supersample::to_output;
use crate::pipeline::stages::visible::FrameCache;
use crate::CliError;
use footprint::composite::RowSpan;
use footprint::frame::Order;
use footprint::render::{
    occlusion_len, RenderStats, SlabBuffers, SlabRenderer, SlabSetup, SlabVoxel,
};
use footprint::shade::Lighting;
use footprint::table::SectionTable;
use std::time::Instant;

/// The section table's nodes: the radial factor over ρ², the depth integral over the chord (see
/// `footprint::table::SectionTable`: 2.4·10⁻⁶ of the peak at worst, 13 KiB).
const ROWS: usize = 257;
const COLUMNS: usize = 1025;

/// Renders one frame of `p` with image-aligned slabs `thickness` voxel spacings thick on
/// `bands` (float: the plan refuses fixed-point slabs), culling occluded voxels if they say so.
pub fn render_slabs(
    p: &Prepared,
    thickness: f32,
    bands: Bands,
    cache: &mut FrameCache,
) -> Result<CoreFrame, CliError> {
    let refuse = |why: &str| CliError::input(format!("{}: --slicing image: {why}", p.name));
    let volume = p.volume().ok_or_else(|| {
        refuse(
            "a slab of an oblique view crosses every sheet, so it cannot be fed from a few \
             streamed sheets: drop --stream (the volume is loaded) or use --slicing object",
        )
    })?;
    let setup = SlabSetup::new(&p.frame, &p.kernel, thickness)
        .map_err(|e| refuse(&e.to_string()))?
        .with_absorption(p.absorption);
    let start = Instant::now();
    let mut table = Box::new(SectionTable::<ROWS, COLUMNS>::zeroed(p.kernel));
    table
        .build_into(p.kernel)
        .map_err(|e| refuse(&e.to_string()))?;
    let tables = start.elapsed().as_secs_f64();

    let t0 = Instant::now();
    let (lists, fresh) = cache.lists(p, volume, bands.threads, "image slicing")?;
    let classify_lists = if fresh {
        t0.elapsed().as_secs_f64()
    } else {
        0.0
    };
    let t1 = Instant::now();
    let voxels = slab_voxels(p, &setup, lists)?;

    let [w, h] = p.frame.size;
    let rows = block_rows(w, setup.ring(), std::mem::size_of::<[f32; 4]>());
    let ranges = blocks(h, rows);
    let members = Members::of(voxels.voxels.len(), h, rows, |i| {
        setup.rows_of(voxels.voxels[i].position[1])
    })?;
    let classify = classify_lists + t1.elapsed().as_secs_f64();

    let (setup, table, sv, members) = (&setup, &*table, &voxels, &members);
    let threads = bands.threads.clamp(1, ranges.len().max(1));
    let timing = (start, classify, tables);
    banded_frame(p, threads, timing, voxels.voxels.len(), |image| {
        on_blocks(
            image,
            w,
            &ranges,
            threads,
            p.background.as_deref(),
            |b, rows, band, bg| {
                let mine = members.of_block(b);
                render_band(p, setup, table, sv, mine, bg, band, rows, bands.cull)
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
    let image = to_output(image, p.out_size(), p.supersample);
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

/// Every visible voxel as a [`SlabVoxel`], grouped by the compositing step at which it enters:
/// its first slab front to back, its last back to front (a stable sort, so voxels keep the order
/// of the sort before it: sheet order, then first slab).
struct SlabVoxels {
    voxels: Vec<SlabVoxel>,
    /// `voxels[starts[k]..starts[k + 1]]` enter at step k (slab k front to back, slab
    /// count − 1 − k back to front).
    starts: Vec<usize>,
}

fn slab_voxels(
    p: &Prepared,
    setup: &SlabSetup,
    lists: &crate::pipeline::stages::visible::VisibleLists,
) -> Result<SlabVoxels, CliError> {
    let f = &p.frame;
    let shader = p.shader();
    // Opacity per world unit (the slab integrates the model's field along the ray itself).
    let lighting = Lighting::per_world_unit(f);
    let needs_gradient = shader.shading.needs_gradient();
    let mut placed: Vec<(SlabVoxel, (usize, usize))> = Vec::new();
    placed
        .try_reserve_exact(lists.len())
        .map_err(|_| CliError::input("cannot allocate the slab voxel list"))?;
    for s in 0..f.sheet_count() {
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
    let count = setup.slab_count();
    let (mut order, mut starts) = buckets(placed.iter().map(|(_, (a, _))| *a), count);
    if p.order == Order::BackToFront {
        let (by_last, s) = buckets(order.iter().map(|&i| count - 1 - placed[i].1 .1), count);
        order = by_last.into_iter().map(|j| order[j]).collect();
        starts = s;
    }
    Ok(SlabVoxels {
        voxels: order.into_iter().map(|i| placed[i].0).collect(),
        starts,
    })
}

/// A stable counting sort of `keys` (each below `count`): the positions in key order, and where
/// each key's run starts (`count + 1` entries).
pub(crate) fn buckets(
    keys: impl Iterator<Item = usize> + Clone,
    count: usize,
) -> (Vec<usize>, Vec<usize>) {
    let mut starts = vec![0usize; count + 1];
    for k in keys.clone() {
        starts[k + 1] += 1;
    }
    for j in 0..count {
        starts[j + 1] += starts[j];
    }
    let mut next = starts.clone();
    let mut order = vec![0usize; starts[count]];
    for (i, k) in keys.enumerate() {
        order[next[k]] = i;
        next[k] += 1;
    }
    (order, starts)
}

/// One band (a block of rows): every slab in compositing order: the voxels that reach it first
/// splatted (into every slab each overlaps), then the slab composited; occluded voxels culled at
/// `cull`'s ε. `mine` lists the voxels that reach the band's rows, in the list's order.
#[allow(clippy::too_many_arguments)]
fn render_band(
    p: &Prepared,
    setup: &SlabSetup,
    table: &SectionTable<ROWS, COLUMNS>,
    sv: &SlabVoxels,
    mine: &[u32],
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
    let mut renderer =
        SlabRenderer::with_band(setup, table, p.order, buffers, background, rows.clone())?;
    if let Some(eps) = cull {
        renderer = renderer.with_occlusion(&mut occluded, eps)?;
    }
    let mut phases = Phases::default();
    let mut mine = mine.iter().map(|&i| i as usize).peekable();
    for k in 0..setup.slab_count() {
        let t0 = Instant::now();
        // `mine` is in list order, so the voxels entering at step k come next.
        while let Some(i) = mine.next_if(|&i| i < sv.starts[k + 1]) {
            renderer.splat_voxel(&sv.voxels[i])?;
        }
        let t1 = Instant::now();
        renderer.composite_next();
        phases.splat += (t1 - t0).as_secs_f64();
        phases.composite += t1.elapsed().as_secs_f64();
    }
    Ok((renderer.finish(), phases))
}
