//! Rendering a slab frame in blocks of rows that fit the cache, handed out to threads as they
//! come free.
//!
//! A slab frame keeps a ring of slab accumulators per pixel (`SlabSetup::ring` of them, 16 bytes
//! each), and a voxel entering slab j adds into every slab its kernel spans. Rendered as one band
//! per thread, the slabs' accumulators for a band are megabytes (512 × 512 × 5 × 16 bytes = 20 MiB
//! on the walnut at one thread), so the pixels a voxel touches have left the core's cache by the
//! time the next voxel of a later slab touches them again: about one miss of a 512 KiB cache per
//! pixel update (`valgrind --tool=cachegrind --LL=524288,8,64`, walnut at 512², 13.1 M misses
//! for 14.4 M pixel updates). Cut into blocks of [`block_rows`] rows, each block's accumulators
//! stay within [`BLOCK_BYTES`] while every slab passes over it.
//!
//! **Identity.** The blocks depend on the frame only (its width, the ring and the height), not
//! on the thread count; each block is rendered on its own from the voxels that reach it, in the
//! frame's order, so each pixel receives the same additions in the same order whichever thread
//! renders its block and whenever: the image is the same bits for any thread count. (Against one
//! band over the whole image it is the same bits too, except with occlusion culling, which
//! judges a voxel by the part of its footprint inside the block.)

use super::bands::{add_counts, Phases};
use crate::CliError;
use footprint::render::{RenderStats, OCCLUSION_TILE};
use std::ops::Range;
use std::sync::{Mutex, PoisonError};

/// The accumulator bytes a block aims at: half the 512 KiB second-level cache of the machines
/// this was measured on, leaving room for the image rows, the voxels and the table.
pub const BLOCK_BYTES: usize = 256 << 10;

/// Rows per block of a frame `width` pixels wide with `ring` accumulators of `acc_bytes` each
/// per pixel: as many as keep one block's accumulators within [`BLOCK_BYTES`], in whole
/// occlusion tile rows ([`OCCLUSION_TILE`]: culling needs a block to start on one), at least
/// one tile row.
pub fn block_rows(width: usize, ring: usize, acc_bytes: usize) -> usize {
    let per_row = width.saturating_mul(ring).saturating_mul(acc_bytes).max(1);
    (BLOCK_BYTES / per_row / OCCLUSION_TILE).max(1) * OCCLUSION_TILE
}

/// The blocks of `rows` rows tiling an image `height` rows high (the last may be shorter).
pub fn blocks(height: usize, rows: usize) -> Vec<Range<usize>> {
    let rows = rows.max(1);
    (0..height.div_ceil(rows))
        .map(|b| b * rows..((b + 1) * rows).min(height))
        .collect()
}

/// Which of `blocks` of `rows` rows each item reaches, as one flat list: the items reaching
/// block b are `index[starts[b]..starts[b + 1]]`, in increasing order. `reach(i)` is the image
/// rows item i touches (clipped here to the image, `height` rows).
pub struct Members {
    /// Item indices, block by block.
    pub index: Vec<u32>,
    /// Where each block's run starts (blocks + 1 entries).
    pub starts: Vec<usize>,
}

impl Members {
    /// Buckets `items` items by the blocks of `rows` rows (over `height`) their `reach` touches.
    /// Refused (a typed error, not a truncation) past `u32::MAX` items or where memory is short.
    pub fn of(
        items: usize,
        height: usize,
        rows: usize,
        reach: impl Fn(usize) -> Range<usize>,
    ) -> Result<Members, CliError> {
        if u32::try_from(items).is_err() {
            return Err(CliError::input(format!(
                "{items} voxels to place in blocks: more than 2^32"
            )));
        }
        let (rows, count) = (rows.max(1), height.div_ceil(rows.max(1)));
        let span = |i: usize| {
            let r = reach(i);
            let (lo, hi) = (r.start, r.end.min(height));
            (lo < hi).then(|| (lo / rows, (hi - 1) / rows))
        };
        let mut starts = vec![0usize; count + 1];
        for i in 0..items {
            if let Some((a, b)) = span(i) {
                for s in &mut starts[a + 1..=b + 1] {
                    *s += 1;
                }
            }
        }
        for b in 0..count {
            starts[b + 1] += starts[b];
        }
        let mut index = crate::io::try_filled(starts[count], 0u32, "the voxels of each block")?;
        let mut next = starts.clone();
        for i in 0..items {
            if let Some((a, b)) = span(i) {
                for n in &mut next[a..=b] {
                    index[*n] = i as u32;
                    *n += 1;
                }
            }
        }
        Ok(Members { index, starts })
    }

    /// The items reaching block `b`.
    pub fn of_block(&self, b: usize) -> &[u32] {
        &self.index[self.starts[b]..self.starts[b + 1]]
    }
}

/// Renders `image` (`width` pixels wide, tiled by `ranges`) block by block on up to `threads`
/// threads, each taking the next block not yet begun: `block(b, rows, pixels, background)`
/// renders block `b`, whose rows the image and `background` hold as given. Returns the image,
/// the counts summed over blocks (`sheets` is any block's: every block visits every slab) and
/// the busiest thread's splat and composite seconds.
pub fn on_blocks<X, F>(
    mut image: Vec<X>,
    width: usize,
    ranges: &[Range<usize>],
    threads: usize,
    background: Option<&[X]>,
    block: F,
) -> Result<(Vec<X>, RenderStats, Phases), CliError>
where
    X: Copy + Send + Sync,
    F: Fn(usize, Range<usize>, &mut [X], Option<&[X]>) -> Result<(RenderStats, Phases), CliError>
        + Sync,
{
    let mut work = Vec::with_capacity(ranges.len());
    let mut rest: &mut [X] = &mut image;
    for (b, rows) in ranges.iter().enumerate() {
        let (chunk, tail) = rest.split_at_mut(rows.len() * width);
        work.push((b, rows.clone(), chunk));
        rest = tail;
    }
    // Taken from the front: blocks begin in image order.
    work.reverse();
    let queue = Mutex::new(work);
    let next = || queue.lock().unwrap_or_else(PoisonError::into_inner).pop();
    let worker = || -> Result<(RenderStats, Phases), CliError> {
        let (mut stats, mut phases) = (RenderStats::default(), Phases::default());
        while let Some((b, rows, chunk)) = next() {
            let bg = background.map(|g| &g[rows.start * width..rows.end * width]);
            let (s, ph) = block(b, rows, chunk, bg)?;
            stats.sheets = s.sheets;
            add_counts(&mut stats, &s);
            phases.splat += ph.splat;
            phases.composite += ph.composite;
        }
        Ok((stats, phases))
    };
    let workers = threads.clamp(1, ranges.len().max(1));
    let results: Vec<Result<(RenderStats, Phases), CliError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|_| crate::threads::spawn(scope, worker))
            .collect();
        handles
            .into_iter()
            .map(crate::threads::Task::join)
            .collect()
    });
    let (mut stats, mut phases) = (RenderStats::default(), Phases::default());
    for r in results {
        let (s, ph) = r?;
        stats.sheets = stats.sheets.max(s.sheets);
        add_counts(&mut stats, &s);
        phases.splat = phases.splat.max(ph.splat);
        phases.composite = phases.composite.max(ph.composite);
    }
    Ok((image, stats, phases))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_tile_the_image_in_whole_tile_rows() {
        for (w, ring) in [
            (1usize, 1usize),
            (64, 3),
            (512, 5),
            (512, 40),
            (4096, 8),
            (usize::MAX, 40),
        ] {
            let rows = block_rows(w, ring, 16);
            assert!(
                rows >= OCCLUSION_TILE && rows.is_multiple_of(OCCLUSION_TILE),
                "{w} {ring}"
            );
            assert!(rows == OCCLUSION_TILE || w * ring * 16 * rows <= BLOCK_BYTES);
            for h in [1usize, 7, 8, 9, 513] {
                let b = blocks(h, rows);
                assert_eq!(b.first().map(|r| r.start), Some(0));
                assert_eq!(b.last().map(|r| r.end), Some(h));
                assert!(b.windows(2).all(|p| p[0].end == p[1].start));
                assert!(b
                    .iter()
                    .all(|r| r.start.is_multiple_of(OCCLUSION_TILE) && !r.is_empty()));
            }
        }
    }

    #[test]
    fn members_are_exactly_the_items_reaching_each_block_in_order() {
        let height = 37;
        let reach = |i: usize| {
            let lo = (i * 7) % 45;
            lo..lo + i % 11
        };
        for rows in [1usize, 3, 8, 40] {
            let m = Members::of(200, height, rows, reach).expect("small");
            for (b, r) in blocks(height, rows).into_iter().enumerate() {
                let want: Vec<u32> = (0..200)
                    .filter(|&i| {
                        let x = reach(i);
                        !x.is_empty() && x.start < r.end && x.end > r.start
                    })
                    .map(|i| i as u32)
                    .collect();
                assert_eq!(m.of_block(b), &want[..], "rows {rows} block {b}");
            }
        }
    }

    #[test]
    fn every_thread_count_fills_every_block_once() {
        let (w, h) = (5usize, 29usize);
        let ranges = blocks(h, 4);
        for threads in [1usize, 2, 3, 8, 100] {
            let image = vec![0u32; w * h];
            let (image, stats, _) =
                on_blocks(image, w, &ranges, threads, None, |b, rows, px, _| {
                    assert_eq!(px.len(), rows.len() * w);
                    for (k, p) in px.iter_mut().enumerate() {
                        *p += (rows.start * w + k) as u32 + 1;
                    }
                    let stats = RenderStats {
                        pixel_updates: b as u64 + 1,
                        ..RenderStats::default()
                    };
                    Ok((stats, Phases::default()))
                })
                .expect("runs");
            assert!(image.iter().enumerate().all(|(i, &p)| p == i as u32 + 1));
            let n = ranges.len() as u64;
            assert_eq!(stats.pixel_updates, n * (n + 1) / 2, "{threads} threads");
        }
    }
}
