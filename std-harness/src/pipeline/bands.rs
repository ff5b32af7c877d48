//! Rendering a frame on several cores: the image is cut into horizontal bands, one per thread,
//! and every thread renders every sheet's visible voxels into its own band (the core's
//! `SheetRenderer::with_band`). Each pixel receives the same additions in the same order as in a
//! one-band render, so the image is byte-identical for any thread count, float or fixed.

use super::prepare::Prepared;
use super::visible::VisibleLists;
use crate::CliError;
use footprint::composite::RowSpan;
use footprint::render::{Precision, RenderBuffers, RenderStats, SheetRenderer};
use footprint::shade::OPACITY_TABLE_LEN;
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

/// The rows of band `t` of `bands` over an image `height` rows high: as equal as can be, the
/// first bands one row taller.
pub fn band_rows(height: usize, bands: usize, t: usize) -> std::ops::Range<usize> {
    let (base, extra) = (height / bands, height % bands);
    let start = t * base + t.min(extra);
    start..start + base + usize::from(t < extra)
}

/// Renders `lists` through `path` on `threads` bands. Returns the image, the counts summed over
/// bands (`voxels_splatted` counts a voxel once per band it reached) and the slowest band's
/// splat and composite seconds.
pub fn run_bands<P>(
    p: &Prepared,
    path: P,
    background: Option<&[P::Pixel]>,
    lists: &VisibleLists,
    threads: usize,
) -> Result<(Vec<P::Pixel>, RenderStats, Phases), CliError>
where
    P: Precision + Copy + Send + Sync,
    P::Pixel: Send + Sync,
    P::Acc: Send,
{
    on_bands(
        p.frame.size,
        threads,
        P::CLEAR,
        background,
        |rows, band, bg| render_band(p, path, bg, lists, band, rows),
    )
}

/// Cuts a `size` image of `clear` pixels into one band of rows per thread (at most `threads`)
/// and runs `band(rows, band's pixels, band's background)` on each, on its own thread. Returns the
/// image, the counts summed over bands (`sheets` and `voxels` are the last band's: every band
/// visits every sheet and voxel) and the slowest band's splat and composite seconds.
pub fn on_bands<X, F>(
    size: [usize; 2],
    threads: usize,
    clear: X,
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
    let bands = threads.clamp(1, h);
    let mut image = crate::io::try_filled(w * h, clear, "the image")?;
    let mut chunks: Vec<&mut [X]> = Vec::with_capacity(bands);
    let mut rest: &mut [X] = &mut image;
    for t in 0..bands {
        let (chunk, tail) = rest.split_at_mut(band_rows(h, bands, t).len() * w);
        chunks.push(chunk);
        rest = tail;
    }
    let band = &band;
    let results: Vec<Result<(RenderStats, Phases), CliError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = chunks
            .into_iter()
            .enumerate()
            .map(|(t, chunk)| {
                let rows = band_rows(h, bands, t);
                let bg = background.map(|b| &b[rows.start * w..rows.end * w]);
                scope.spawn(move || band(rows, chunk, bg))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a render thread panicked"))
            .collect()
    });
    let mut stats = RenderStats::default();
    let mut phases = Phases::default();
    for r in results {
        let (s, ph) = r?;
        stats.sheets = s.sheets;
        stats.voxels = s.voxels;
        stats.voxels_splatted += s.voxels_splatted;
        stats.pixel_updates += s.pixel_updates;
        stats.pixels_composited += s.pixels_composited;
        phases.splat = phases.splat.max(ph.splat);
        phases.composite = phases.composite.max(ph.composite);
    }
    Ok((image, stats, phases))
}

/// One band: every sheet in compositing order, splat then composite, timed.
fn render_band<P: Precision>(
    p: &Prepared,
    path: P,
    background: Option<&[P::Pixel]>,
    lists: &VisibleLists,
    image: &mut [P::Pixel],
    rows: std::ops::Range<usize>,
) -> Result<(RenderStats, Phases), CliError> {
    let f = &p.frame;
    let n = f.size[0] * rows.len();
    let mut acc = crate::io::try_filled(n, P::ACC_ZERO, "a band's sheet accumulator")?;
    let mut spans = vec![RowSpan::EMPTY; rows.len()];
    let mut opacity = vec![0.0f32; OPACITY_TABLE_LEN];
    let buffers = RenderBuffers {
        accumulator: &mut acc,
        image,
        rows: &mut spans,
    };
    let mut renderer =
        SheetRenderer::with_band(f, path, p.shader(), p.order, buffers, background, rows)?
            .with_opacity_table(&mut opacity)?;
    let mut phases = Phases::default();
    for k in 0..f.sheet_count() {
        let s = f.sheet_at(p.order, k);
        let t0 = Instant::now();
        renderer.splat_visible_sheet(s, lists.sheet(s))?;
        let t1 = Instant::now();
        renderer.composite_sheet();
        phases.splat += (t1 - t0).as_secs_f64();
        phases.composite += t1.elapsed().as_secs_f64();
    }
    Ok((renderer.finish(), phases))
}

#[cfg(test)]
mod tests {
    use super::band_rows;

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
}
