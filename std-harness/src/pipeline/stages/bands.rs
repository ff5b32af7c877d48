//! Rendering a frame on several cores: the image is cut into horizontal bands, one per thread,
//! and every thread renders every sheet's visible voxels into its own band (the core's
//! `SheetRenderer::with_band`). Each pixel receives the same additions in the same order as in a
//! one-band render, so the image is byte-identical for any thread count, float or fixed.

use super::prepare::Prepared;
use super::spares::Spares;
use super::supply::{BandLists, OnTheFly, SheetSupply};
use super::visible::{Visible, VisibleLists};
use crate::CliError;
use footprint::composite::RowSpan;
use footprint::lod::Coloured;
use footprint::render::{
    occlusion_len, Precision, RenderBuffers, RenderStats, ShadeCacheEntry, SheetRenderer,
    OCCLUSION_TILE, SHADE_CACHE_LEN,
};
use footprint::shade::OPACITY_TABLE_LEN;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Seconds spent in each phase of a frame. With several threads, splat and composite are the
/// slowest band's (the frame waits for it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Phases {
    /// Classifying voxels into visible lists (zero when a cached list was reused).
    pub classify: f64,
    /// Building the view (or fixed-point) table.
    pub tables: f64,
    /// Splatting (shading and placing included).
    pub splat: f64,
    /// Compositing sheets into the image.
    pub composite: f64,
    /// Bringing the frame to the output size (`pipeline::stages::decorators`): magnifying a
    /// subsampled frame (`--subsample`), averaging a supersampled one's k×k blocks; zero with
    /// neither.
    pub resample: f64,
}

/// One frame rendered by the core.
#[derive(Clone, Debug)]
pub struct CoreFrame {
    /// Premultiplied RGBA, linear, row-major, top row first (fixed-point output converted
    /// exactly to f32).
    pub image: Vec<[f32; 4]>,
    /// Counts (summed over bands).
    pub stats: RenderStats,
    /// Wall-clock seconds for the whole frame: tables, classification (unless cached), splat,
    /// composite.
    pub seconds: f64,
    /// Where the time went.
    pub phases: Phases,
    /// Threads (bands) used.
    pub threads: usize,
    /// Visible voxels in the lists the frame rendered (`None` when streamed).
    pub visible: Option<usize>,
    /// What `--refine` refined (`None` without it).
    pub refine: Option<super::refinement::Refinement>,
}

/// How a frame's sheets are cut into bands of rows, and what each band culls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bands {
    /// Threads asked for (one band each, at most one per row, or per tile row when culling).
    pub threads: usize,
    /// Occlusion culling's ε (`--cull`): bands then start on tile rows
    /// ([`footprint::render::OCCLUSION_TILE`]), which keeps the image the same for any count.
    pub cull: Option<f32>,
}

impl Bands {
    /// The bands `plan` asks for.
    pub fn of(plan: &crate::plan::Plan) -> Self {
        Bands {
            threads: plan.threads,
            cull: plan.cull,
        }
    }

    /// Bands used over an image `height` rows high ([`Bands::cut`] keeps them all).
    pub fn count(&self, height: usize) -> usize {
        let units = if self.cull.is_some() {
            height.div_ceil(OCCLUSION_TILE)
        } else {
            height
        };
        self.threads.clamp(1, units.max(1))
    }

    /// The final bands from `ranges` (tiling `height` rows, [`Bands::count`] of them): as given,
    /// or starting on tile rows when culling (`on_tile_rows`). The one place both the sheets'
    /// balanced bands and the slabs' equal ones are aligned.
    pub fn cut(
        &self,
        ranges: Vec<std::ops::Range<usize>>,
        height: usize,
    ) -> Vec<std::ops::Range<usize>> {
        if self.cull.is_some() {
            on_tile_rows(&ranges, height)
        } else {
            ranges
        }
    }
}

/// `ranges` (tiling `height` rows, at most one per tile row) with every start moved to a
/// multiple of the occlusion tile, the nearest that keeps the starts increasing and leaves a tile
/// row for each later band: as many bands as given, their work about as balanced, and every band
/// starting on a tile row, as culling needs.
fn on_tile_rows(ranges: &[std::ops::Range<usize>], height: usize) -> Vec<std::ops::Range<usize>> {
    let t = OCCLUSION_TILE;
    let tile_rows = height.div_ceil(t).max(1);
    let n = ranges.len().min(tile_rows);
    let mut starts: Vec<usize> = Vec::with_capacity(n);
    for (i, r) in ranges.iter().take(n).enumerate() {
        let lo = starts.last().map_or(0, |s| s + 1);
        let hi = (tile_rows - (n - i)).max(lo);
        starts.push(((r.start + t / 2) / t).clamp(lo, hi));
    }
    (0..n)
        .map(|i| {
            let end = starts.get(i + 1).map_or(height, |s| s * t);
            starts[i] * t..end
        })
        .collect()
}

/// [`equal_bands`] for `bands` over an image `height` rows high, starting on tile rows when
/// culling.
pub fn equal_bands_for(height: usize, bands: Bands) -> Vec<std::ops::Range<usize>> {
    bands.cut(equal_bands(height, bands.count(height)), height)
}

/// The rows of band `t` of `bands` over an image `height` rows high: as equal as can be, the
/// first bands one row taller.
pub fn band_rows(height: usize, bands: usize, t: usize) -> std::ops::Range<usize> {
    let (base, extra) = (height / bands, height % bands);
    let start = t * base + t.min(extra);
    start..start + base + usize::from(t < extra)
}

/// `threads` bands of [`band_rows`] (at most one per row).
pub fn equal_bands(height: usize, threads: usize) -> Vec<std::ops::Range<usize>> {
    let bands = threads.clamp(1, height.max(1));
    (0..bands).map(|t| band_rows(height, bands, t)).collect()
}

/// Renders the visible voxels (`visible`: kept lists, or classified by each band as it goes)
/// through `path` on `threads` bands. Returns the image, the counts summed over bands
/// (`voxels_splatted` counts a voxel once per band it reached; `voxels` is the visible voxels'
/// number, what one band over the whole image visits, for any number of bands) and the slowest
/// band's splat and composite seconds.
pub fn run_bands<P>(
    p: &Prepared,
    path: P,
    background: Option<&[P::Pixel]>,
    visible: Visible<'_>,
    spares: &Spares,
    bands: Bands,
) -> Result<(Vec<P::Pixel>, RenderStats, Phases), CliError>
where
    P: Precision + Copy + Send + Sync,
    P::Pixel: Send + Sync + 'static,
    P::Acc: Send + PartialEq + 'static,
{
    let [w, h] = p.frame.size;
    let threads = bands.count(h);
    let ranges = match visible {
        Visible::Kept(lists) => balanced_rows(&p.frame, lists, threads),
        Visible::OnTheFly(_) => equal_bands(h, threads),
    };
    let ranges = bands.cut(ranges, h);
    let cull = bands.cull;
    // Any image of the right size will do: each band's renderer starts its rows afresh.
    let image = spares.take_image(w * h, P::CLEAR, "the image")?;
    let found = AtomicU64::new(0);
    let (image, mut stats, phases) =
        on_bands(image, p.frame.size, ranges, background, |rows, band, bg| {
            let r = match visible {
                Visible::Kept(lists) => {
                    let mut lists = BandLists::new(lists, &p.frame, rows.clone());
                    render_band(p, path, bg, &mut lists, spares, band, rows, cull)
                }
                Visible::OnTheFly(v) if v.is_coloured() => {
                    let mut lists = OnTheFly::<Coloured>::new(p, v)?;
                    render_band(p, path, bg, &mut lists, spares, band, rows, cull)
                }
                Visible::OnTheFly(v) => {
                    let mut lists = OnTheFly::<f32>::new(p, v)?;
                    render_band(p, path, bg, &mut lists, spares, band, rows, cull)
                }
            }?;
            found.fetch_max(r.2, Ordering::Relaxed);
            Ok((r.0, r.1))
        })?;
    // A band visits only the voxels that can reach it, so no band's count is the frame's; every
    // band is supplied every visible voxel.
    stats.voxels = found.into_inner();
    Ok((image, stats, phases))
}

/// A voxel's own work (shading, placement, row set-up), in pixel updates' worth: about 50 ns
/// against 1.5 ns per update in profiles of the blobs and the CT head (`perf record`, 512²).
const VOXEL_COST_PX: f64 = 32.0;

/// Bands of rows for `bands` threads with about equal work: each sheet row's visible voxels
/// ([`VisibleLists::runs`]) are placed on screen, and their work (each voxel's own, plus its
/// footprint's area in pixel updates) is spread evenly over the image rows their footprints
/// cover; the bands cut that profile into equal parts. Any cut gives the same image (see
/// [`on_bands`]), so this only moves work between threads. A perspective frame, or one with
/// nothing visible, gets [`band_rows`]' equal bands.
pub fn balanced_rows(
    f: &footprint::frame::FrameSetup,
    lists: &VisibleLists,
    bands: usize,
) -> Vec<std::ops::Range<usize>> {
    let h = f.size[1];
    let bands = bands.clamp(1, h.max(1));
    let equal = || equal_bands(h, bands);
    if bands == 1 || f.camera().is_some() || lists.run_offsets.len() < 2 {
        return equal();
    }
    let y_of = |s: usize, u: u16, v: u16| {
        let index = f.grid_index(s, usize::from(u), usize::from(v));
        f64::from(f.affine_position(index.map(|i| i as f32)).y)
    };
    let [hx, hy] = f.footprint.half_extent.map(f64::from);
    let per_voxel = VOXEL_COST_PX + (std::f64::consts::PI * hx * hy).max(1.0);
    // Work density per row, as differences (added at a run's first row, taken off past its last).
    let mut diff = vec![0.0f64; h + 1];
    for (s, w) in lists.run_offsets.windows(2).enumerate() {
        for run in &lists.runs[w[0]..w[1]] {
            let (a, b) = (y_of(s, run.u0, run.v), y_of(s, run.u1, run.v));
            let (lo, hi) = (a.min(b) - hy, a.max(b) + hy);
            if !(hi >= 0.0 && lo < h as f64) {
                continue;
            }
            let (r0, r1) = (lo.max(0.0) as usize, (hi.min(h as f64 - 1.0)) as usize);
            let share = f64::from(run.count) * per_voxel / (r1 - r0 + 1) as f64;
            diff[r0] += share;
            diff[r1 + 1] -= share;
        }
    }
    let mut cumulative = Vec::with_capacity(h);
    let (mut density, mut total) = (0.0, 0.0);
    for d in &diff[..h] {
        density += d;
        total += density.max(0.0);
        cumulative.push(total);
    }
    if !(total > 0.0) {
        return equal();
    }
    // Band t ends at the first row where the work so far reaches (t + 1)/bands of the total,
    // leaving at least a row for each band after it.
    let mut ranges = Vec::with_capacity(bands);
    let mut start = 0;
    for t in 0..bands {
        let end = if t + 1 == bands {
            h
        } else {
            let goal = total * (t + 1) as f64 / bands as f64;
            let at = cumulative.partition_point(|&c| c < goal) + 1;
            at.clamp(start + 1, h - (bands - t - 1))
        };
        ranges.push(start..end);
        start = end;
    }
    ranges
}

/// Cuts `image`, of `size` pixels, into the bands of rows `ranges` (in order, tiling the
/// image: [`equal_bands`] or [`balanced_rows`]) and runs `band(rows, band's pixels, band's
/// background)` on each, on its own thread; each band gets its rows as the image holds them.
/// Returns the image, the counts summed over bands (`sheets` and `voxels` are the last band's:
/// right where every band visits every sheet and voxel, as the slab renderer's do; [`run_bands`]
/// sets `voxels` itself) and the slowest band's splat and composite seconds.
pub fn on_bands<X, F>(
    mut image: Vec<X>,
    size: [usize; 2],
    ranges: Vec<std::ops::Range<usize>>,
    background: Option<&[X]>,
    band: F,
) -> Result<(Vec<X>, RenderStats, Phases), CliError>
where
    X: Copy + Send + Sync,
    F: Fn(
            std::ops::Range<usize>,
            &mut [X],
            Option<&[X]>,
        ) -> Result<(RenderStats, Phases), CliError>
        + Sync,
{
    let [w, h] = size;
    debug_assert!(ranges.first().is_some_and(|r| r.start == 0));
    debug_assert!(ranges.last().is_some_and(|r| r.end == h));
    debug_assert_eq!(image.len(), w * h);
    let mut chunks: Vec<&mut [X]> = Vec::with_capacity(ranges.len());
    let mut rest: &mut [X] = &mut image;
    for rows in &ranges {
        let (chunk, tail) = rest.split_at_mut(rows.len() * w);
        chunks.push(chunk);
        rest = tail;
    }
    let band = &band;
    let results: Vec<Result<(RenderStats, Phases), CliError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = chunks
            .into_iter()
            .enumerate()
            .map(|(t, chunk)| {
                let rows = ranges[t].clone();
                let bg = background.map(|b| &b[rows.start * w..rows.end * w]);
                crate::threads::spawn(scope, move || band(rows, chunk, bg))
            })
            .collect();
        handles
            .into_iter()
            .map(crate::threads::Task::join)
            .collect()
    });
    let mut stats = RenderStats::default();
    let mut phases = Phases::default();
    for r in results {
        let (s, ph) = r?;
        stats.sheets = s.sheets;
        stats.voxels = s.voxels;
        add_counts(&mut stats, &s);
        phases.splat = phases.splat.max(ph.splat);
        phases.composite = phases.composite.max(ph.composite);
    }
    Ok((image, stats, phases))
}

/// Adds the work counts of `part` (a band's or block's: voxels splatted and culled, pixel updates
/// and composites) to `total`.
pub fn add_counts(total: &mut RenderStats, part: &RenderStats) {
    total.voxels_splatted += part.voxels_splatted;
    total.pixel_updates += part.pixel_updates;
    total.pixels_composited += part.pixels_composited;
    total.culled_voxels += part.culled_voxels;
}

/// One band: every sheet in compositing order, splat then composite, timed, and the visible
/// voxels `lists` supplied; occluded voxels culled at `cull`'s ε. Its accumulator is taken from
/// `spares` and given back clear.
#[allow(clippy::too_many_arguments)]
fn render_band<P: Precision>(
    p: &Prepared,
    path: P,
    background: Option<&[P::Pixel]>,
    lists: &mut impl SheetSupply,
    spares: &Spares,
    image: &mut [P::Pixel],
    rows: std::ops::Range<usize>,
    cull: Option<f32>,
) -> Result<(RenderStats, Phases, u64), CliError>
where
    P::Acc: Send + PartialEq + 'static,
{
    let f = &p.frame;
    let n = f.size[0] * rows.len();
    let mut acc = spares.take(n, P::ACC_ZERO, "a band's sheet accumulator")?;
    let mut spans = vec![RowSpan::EMPTY; rows.len()];
    let mut opacity = vec![0.0f32; OPACITY_TABLE_LEN];
    let mut shades = vec![ShadeCacheEntry::default(); SHADE_CACHE_LEN];
    let mut occluded = vec![0u8; cull.map_or(0, |_| occlusion_len(f.size[0], rows.len()))];
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image,
        rows: &mut spans,
    };
    let mut renderer =
        SheetRenderer::with_band(f, path, p.shader(), p.order, buffers, background, rows)?
            .with_opacity_table(&mut opacity)?
            .with_shade_cache(&mut shades);
    if let Some(eps) = cull {
        renderer = renderer.with_occlusion(&mut occluded, eps)?;
    }
    let mut phases = Phases::default();
    for k in 0..f.sheet_count() {
        crate::cancel::check()?;
        let s = f.sheet_at(p.order, k);
        let t0 = Instant::now();
        renderer.splat_visible_sheet(s, lists.sheet(s)?)?;
        let t1 = Instant::now();
        renderer.composite_sheet();
        phases.splat += (t1 - t0).as_secs_f64();
        phases.composite += t1.elapsed().as_secs_f64();
    }
    let stats = renderer.finish();
    // Every sheet was composited, which cleared each row it touched.
    spares.give(acc, P::ACC_ZERO);
    Ok((stats, phases, lists.supplied()))
}

#[cfg(test)]
mod tests {
    use super::{balanced_rows, band_rows, equal_bands, on_tile_rows, Bands, OCCLUSION_TILE};
    use crate::pipeline::stages::visible::{RowRun, VisibleLists};
    use footprint::frame::FrameSetup;
    use footprint::geometry::FootprintOptions;
    use footprint::{Grid, Kernel, View};

    /// Balanced bands tile the image, and where the visible voxels crowd the top rows the first
    /// band is the short one.
    #[test]
    fn balanced_bands_tile_the_image_and_follow_the_work() {
        let view = View::new(glam::Mat3::from_diagonal(glam::Vec3::splat(2.0))).unwrap();
        let grid = Grid::from_spacing([1.0; 3]).unwrap();
        let f = FrameSetup::new(
            [32, 32, 32],
            &grid,
            &view,
            &Kernel::PAPER_GAUSSIAN,
            FootprintOptions::default(),
            [64, 64],
        )
        .unwrap();
        // Every sheet: rows 0..8 of 32 full of visible voxels (a quarter of the volume).
        let (_, na, nb) = f.sheet_shape();
        let mut lists = VisibleLists {
            run_offsets: vec![0],
            ..Default::default()
        };
        for _ in 0..f.sheet_count() {
            for v in 0..nb.min(8) {
                lists.runs.push(RowRun {
                    v: v as u16,
                    u0: 0,
                    u1: na as u16 - 1,
                    count: na as u32,
                });
            }
            lists.run_offsets.push(lists.runs.len());
        }
        // Which screen rows the top of the volume lands on (y grows downward or upward).
        let y_of = |v: f32| f.origin.y + f.grid_to_screen.col(f.in_sheet.1).y * v;
        let top_first = y_of(0.0) < y_of(31.0);
        for bands in 1..=5 {
            let r = balanced_rows(&f, &lists, bands);
            assert_eq!(r.len(), bands);
            assert_eq!(r[0].start, 0);
            assert_eq!(r[bands - 1].end, 64);
            assert!(r.windows(2).all(|w| w[0].end == w[1].start));
            assert!(r.iter().all(|b| !b.is_empty()), "{r:?}");
            if bands == 2 {
                let (busy, idle) = if top_first {
                    (&r[0], &r[1])
                } else {
                    (&r[1], &r[0])
                };
                assert!(busy.len() < 24 && idle.len() > 40, "{r:?}");
            }
        }
        // Nothing visible: equal bands.
        let empty = VisibleLists {
            run_offsets: vec![0; f.sheet_count() + 1],
            ..Default::default()
        };
        assert_eq!(balanced_rows(&f, &empty, 2), vec![0..32, 32..64]);
    }

    #[test]
    fn bands_tile_the_image() {
        for h in [1, 2, 7, 512, 513] {
            for bands in 1..=9.min(h) {
                let mut next = 0;
                for t in 0..bands {
                    let r = band_rows(h, bands, t);
                    assert_eq!(r.start, next);
                    assert!(!r.is_empty());
                    next = r.end;
                }
                assert_eq!(next, h);
            }
        }
    }

    /// Culling's bands start on tile rows, tile the image and keep their number (the JSON's
    /// `bands`), even where several equal bands would round to one tile row; lopsided cuts too.
    #[test]
    fn culled_bands_start_on_tile_rows_and_keep_their_number() {
        let t = OCCLUSION_TILE;
        for h in [1, 7, 8, 9, 17, 33, 64, 100, 513] {
            let bands = |threads| Bands {
                threads,
                cull: Some(0.004),
            };
            for threads in 1..=20 {
                let n = bands(threads).count(h);
                assert!(n <= h.div_ceil(t));
                let lopsided: Vec<_> = {
                    // All but the last band one row tall: starts crowd the first tile row.
                    let mut r: Vec<_> = (0..n.saturating_sub(1)).map(|i| i..i + 1).collect();
                    r.push(n - 1..h);
                    r
                };
                for ranges in [equal_bands(h, n), lopsided] {
                    let cut = bands(threads).cut(ranges, h);
                    assert_eq!(cut.len(), n, "h {h}, {threads} threads: {cut:?}");
                    assert_eq!(cut[0].start, 0);
                    assert_eq!(cut[n - 1].end, h);
                    assert!(cut.windows(2).all(|w| w[0].end == w[1].start));
                    assert!(
                        cut.iter().all(|b| !b.is_empty() && b.start % t == 0),
                        "{cut:?}"
                    );
                }
            }
        }
        // Without culling the ranges pass through.
        let plain = Bands {
            threads: 3,
            cull: None,
        };
        assert_eq!(plain.cut(vec![0..1, 1..2, 2..9], 9), vec![0..1, 1..2, 2..9]);
        assert_eq!(on_tile_rows(&[0..5, 5..9], 9), vec![0..8, 8..9]);
    }
}
