//! Visible-voxel lists: each sheet's voxels that can be seen at all, classified once per volume,
//! transfer function, shading and sheet axis, then reused by every later frame whose sheets run
//! along the same axis (the re-render path; see the core's `render::classify_sheet`).
//!
//! **Memory.** The lists take [`VisibleLists::BYTES_PER_VOXEL`] bytes per visible voxel (8),
//! plus 12 with gradients (Phong, iso-surfaces) and 12 with colours (a coloured level of detail),
//! and are kept only while they fit [`list_budget`]: at most 1 GiB, or four bytes per byte of the
//! volume where that is less, never under 256 MiB. A volume whose lists would pass it is not
//! listed: each band classifies the sheets it renders as it goes ([`super::supply::OnTheFly`]), which costs a
//! sheet's worth of memory per band and a classification per band and frame, and renders the
//! same bits (the same visible voxels, in the same order, through the same splat).

use super::prepare::Prepared;
use super::spares::Spares;
use crate::io::volume::Volume;
use crate::CliError;
use footprint::lod::Coloured;
use footprint::render::{classify_sheet, SheetWindow, VisibleSheet, VisibleVoxel};
use footprint::shade::Sample;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The visible voxels of every sheet along one axis, in sheet index order.
#[derive(Clone, Debug, Default)]
pub struct VisibleLists {
    /// The sheet axis (0 = i, 1 = j, 2 = k).
    pub axis: usize,
    /// `voxels[offsets[s]..offsets[s + 1]]` are sheet s's.
    pub offsets: Vec<usize>,
    /// All visible voxels.
    pub voxels: Vec<VisibleVoxel>,
    /// Their world-space gradients, when the shading needs them (else empty).
    pub gradients: Vec<[f32; 3]>,
    /// Their straight colours, when the volume carries colours (a level of detail's; else empty).
    pub colours: Vec<[f32; 3]>,
    /// Per sheet row that holds visible voxels, where they lie: `runs[run_offsets[s]..
    /// run_offsets[s + 1]]` are sheet s's, in row order (what [`super::bands`] balances its
    /// bands with).
    pub runs: Vec<RowRun>,
    /// Where each sheet's runs start in `runs` (one more entry than sheets).
    pub run_offsets: Vec<usize>,
}

/// The visible voxels of one sheet row: row `v`, `count` voxels with u in `u0..=u1`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RowRun {
    /// The sheet row (index along the second in-sheet axis).
    pub v: u16,
    /// First visible voxel's u.
    pub u0: u16,
    /// Last visible voxel's u.
    pub u1: u16,
    /// Visible voxels in the row.
    pub count: u32,
}

/// Appends the runs of one sheet's visible voxels (in render order: rows `v` ascending, `u`
/// ascending within a row) to `runs`: one per row that holds any.
fn sheet_runs(voxels: &[VisibleVoxel], runs: &mut Vec<RowRun>) {
    runs.extend(voxels.chunk_by(|a, b| a.v == b.v).map(|row| RowRun {
        v: row[0].v,
        u0: row.iter().map(|x| x.u).min().unwrap_or(0),
        u1: row.iter().map(|x| x.u).max().unwrap_or(0),
        count: row.len() as u32,
    }));
}

impl VisibleLists {
    /// Sheet `s`'s visible voxels.
    pub fn sheet(&self, s: usize) -> VisibleSheet<'_> {
        let (a, b) = (self.offsets[s], self.offsets[s + 1]);
        VisibleSheet {
            voxels: &self.voxels[a..b],
            gradients: if self.gradients.is_empty() {
                &[]
            } else {
                &self.gradients[a..b]
            },
            colours: if self.colours.is_empty() {
                &[]
            } else {
                &self.colours[a..b]
            },
        }
    }

    /// Room for `n` more voxels (with gradients and colours as asked) and one more sheet, or
    /// false where memory refuses it. Grows by doubling, as `Vec` does.
    fn reserve(&mut self, n: usize, gradients: bool, colours: bool) -> bool {
        fn grow<T>(v: &mut Vec<T>, n: usize) -> bool {
            n <= v.capacity() - v.len() || v.try_reserve(n.max(v.len())).is_ok()
        }
        grow(&mut self.voxels, n)
            && grow(&mut self.runs, n)
            && (!gradients || grow(&mut self.gradients, n))
            && (!colours || grow(&mut self.colours, n))
            && grow(&mut self.offsets, 1)
            && grow(&mut self.run_offsets, 1)
    }

    /// Number of visible voxels.
    pub fn len(&self) -> usize {
        self.voxels.len()
    }

    /// Whether no voxel is visible.
    pub fn is_empty(&self) -> bool {
        self.voxels.is_empty()
    }

    /// Bytes a visible voxel takes in the lists without gradients or colours (its place and
    /// value; each takes 12 more).
    pub const BYTES_PER_VOXEL: usize = std::mem::size_of::<VisibleVoxel>();

    /// Appends the next sheets' lists (`part`, offsets relative to its first sheet).
    fn append(&mut self, part: VisibleLists) {
        let base = self.voxels.len();
        self.offsets
            .extend(part.offsets[1..].iter().map(|&o| o + base));
        let base = self.runs.len();
        self.run_offsets
            .extend(part.run_offsets[1..].iter().map(|&o| o + base));
        self.runs.extend_from_slice(&part.runs);
        self.voxels.extend_from_slice(&part.voxels);
        self.gradients.extend_from_slice(&part.gradients);
        self.colours.extend_from_slice(&part.colours);
    }
}

/// Most bytes the visible lists of `volume` may hold: four per byte of the volume, at least
/// 256 MiB and at most 1 GiB (see the module docs).
pub fn list_budget(volume: &Volume) -> usize {
    list_budget_of(volume.bytes())
}

/// [`list_budget`] of a volume whose samples take `bytes`.
pub fn list_budget_of(bytes: usize) -> usize {
    bytes
        .saturating_mul(4)
        .clamp(MIN_LIST_BUDGET, MAX_LIST_BUDGET)
}

/// Bytes a voxel the default plan's pilot reference field may hold (`reference::sparse`'s
/// bound).
pub const PILOT_FIELD_BYTES_PER_VOXEL: usize = 16;

/// The bytes the default plan's pilot reference field holds for a volume of `voxels` samples
/// taking `bytes` ([`PILOT_FIELD_BYTES_PER_VOXEL`] a voxel), and the budget it must fit
/// ([`list_budget_of`]): the pilot measures only where the first is at most the second.
pub fn pilot_field(voxels: usize, bytes: usize) -> (usize, usize) {
    (
        voxels.saturating_mul(PILOT_FIELD_BYTES_PER_VOXEL),
        list_budget_of(bytes),
    )
}

/// Whether the default plan's pilot measures a volume of `voxels` samples of `sample_bytes`
/// each ([`pilot_field`]: at most 16 Mi voxels for samples of 1 or 2 bytes, 64 Mi for 4 or 8).
pub fn pilot_fits(voxels: usize, sample_bytes: usize) -> bool {
    let (field, budget) = pilot_field(voxels, voxels.saturating_mul(sample_bytes));
    field <= budget
}

/// The lists' budget is never below this (256 MiB): a small volume keeps its lists.
const MIN_LIST_BUDGET: usize = 256 << 20;
/// Nor above this (1 GiB).
const MAX_LIST_BUDGET: usize = 1 << 30;

/// Where a frame finds each sheet's visible voxels.
#[derive(Clone, Copy, Debug)]
pub enum Visible<'a> {
    /// The lists, classified once and kept.
    Kept(&'a VisibleLists),
    /// The volume, whose lists would pass [`list_budget`]: each band classifies as it goes.
    OnTheFly(&'a Volume),
}

/// The voxels a post-classified frame splats (`--classification post`: made by
/// `pipeline::ends::post`), view-independent: grid index, value and world gradient (zero where
/// the shading needs none), in grid order (x fastest).
#[derive(Debug, Default)]
pub struct PostSamples {
    pub index: Vec<[u32; 3]>,
    pub value: Vec<f32>,
    pub gradient: Vec<[f32; 3]>,
}

/// Per-volume state kept across frames of one volume, transfer function and shading: the visible
/// lists of each sheet axis met so far, and the bands' clear accumulators ([`Spares`]). A caller
/// that changes the transfer function, window or shading must start a new cache.
#[derive(Debug, Default)]
pub struct FrameCache {
    lists: [Option<VisibleLists>; 3],
    /// Axes whose lists were found to pass the budget (not tried again).
    over_budget: [bool; 3],
    /// The lists' budget in bytes, where not [`list_budget`]'s.
    budget: Option<usize>,
    spares: Spares,
    /// The voxels post-classified frames splat, once made, and their reach (2R, grid steps).
    pub post: Option<(f32, PostSamples)>,
    /// The generic table, built once ([`super::tables`]).
    pub tables: super::tables::TableCache,
}

impl FrameCache {
    /// A cache whose lists may hold at most `bytes` (instead of [`list_budget`]'s): 0 has every
    /// frame classify as it goes, as a volume too large for its lists does.
    pub fn with_list_budget(bytes: usize) -> Self {
        FrameCache {
            budget: Some(bytes),
            ..FrameCache::default()
        }
    }

    /// The lists for `p`'s sheet axis, classified now (on `threads` threads) if this cache has
    /// none yet; and whether they were classified now. Lists that would pass [`list_budget`] are
    /// refused, naming `what` needs them (a renderer that can classify as it goes takes
    /// [`FrameCache::visible_and_spares`] instead).
    pub fn lists<'a>(
        &'a mut self,
        p: &Prepared,
        volume: &'a Volume,
        threads: usize,
        what: &str,
    ) -> Result<(&'a VisibleLists, bool), CliError> {
        let budget = self.budget_for(volume);
        match self.visible_and_spares(p, volume, threads)? {
            (Visible::Kept(lists), fresh, _) => Ok((lists, fresh)),
            (Visible::OnTheFly(_), _, _) => Err(CliError::input(format!(
                "{}: {what} keeps every visible voxel in memory, and this volume's take more \
                 than {} MiB ({} bytes each): render a coarser level (--lod) or use --slicing object",
                p.name,
                budget >> 20,
                VisibleLists::BYTES_PER_VOXEL
            ))),
        }
    }

    /// The lists' budget this cache applies to a volume: [`list_budget`]'s, or the one it was
    /// made with.
    pub fn list_budget_for(&self, volume: &Volume) -> usize {
        self.budget_for(volume)
    }

    fn budget_for(&self, volume: &Volume) -> usize {
        self.budget.unwrap_or_else(|| list_budget(volume))
    }

    /// Keeps a finished frame's `image` (float, of its frame's size) for a later frame to render
    /// into instead of allocating one; an image of another size or type is never used.
    pub fn recycle(&self, image: Vec<[f32; 4]>) {
        self.spares.give_image(image);
    }

    /// Lets a frame whose pixels are `T` render into a kept float image of `n` pixels, each
    /// pixel through `convert` (see [`Spares::convert_image`]): the fixed path's frames are
    /// handed back as float.
    pub fn reuse_image_as<T: Copy + Send + 'static>(
        &self,
        n: usize,
        convert: impl Fn([f32; 4]) -> T,
    ) {
        self.spares.convert_image(n, convert);
    }

    /// Where `p`'s sheets find their visible voxels: the lists for its sheet axis (classified
    /// now, on `threads` threads, if this cache has none yet), or, where they would pass
    /// [`list_budget`], the volume itself ([`Visible::OnTheFly`]); whether anything was
    /// classified now; and the accumulators kept from earlier frames.
    pub fn visible_and_spares<'a>(
        &'a mut self,
        p: &Prepared,
        volume: &'a Volume,
        threads: usize,
    ) -> Result<(Visible<'a>, bool, &'a Spares), CliError> {
        let axis = p.frame.sheet_axis;
        let fresh = self.lists[axis].is_none() && !self.over_budget[axis];
        if fresh {
            match classify(p, volume, threads, self.budget_for(volume))? {
                Some(lists) => self.lists[axis] = Some(lists),
                None => self.over_budget[axis] = true,
            }
        }
        let visible = match &self.lists[axis] {
            Some(lists) => Visible::Kept(lists),
            None => Visible::OnTheFly(volume),
        };
        Ok((visible, fresh, &self.spares))
    }
}

/// Classifies every sheet of `p`'s axis, contiguous ranges of sheets on `threads` threads, the
/// results joined in sheet order (so the lists are the same for any thread count); `None` as
/// soon as they would hold more than `budget` bytes (all threads together; the join then needs
/// as much again, briefly), or memory refuses them.
pub fn classify(
    p: &Prepared,
    volume: &Volume,
    threads: usize,
    budget: usize,
) -> Result<Option<VisibleLists>, CliError> {
    let f = &p.frame;
    let count = f.sheet_count();
    let threads = threads.clamp(1, count.max(1));
    let per = count.div_ceil(threads);
    let spent = AtomicUsize::new(0);
    let budget = Budget {
        spent: &spent,
        limit: budget,
    };
    let parts: Vec<Result<Option<VisibleLists>, CliError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let range = (t * per).min(count)..((t + 1) * per).min(count);
                crate::threads::spawn(scope, move || classify_range(p, volume, range, budget))
            })
            .collect();
        handles
            .into_iter()
            .map(crate::threads::Task::join)
            .collect()
    });
    let Some(mut parts) = parts.into_iter().collect::<Result<Option<Vec<_>>, _>>()? else {
        return Ok(None);
    };
    if parts.len() == 1 {
        // One part is the whole list: no copy.
        return Ok(parts.pop());
    }
    let total = |n: fn(&VisibleLists) -> usize| parts.iter().map(n).sum::<usize>();
    let mut out = VisibleLists {
        axis: f.sheet_axis,
        offsets: vec![0],
        run_offsets: vec![0],
        ..Default::default()
    };
    let reserved = out.runs.try_reserve_exact(total(|p| p.runs.len())).is_ok()
        && out
            .voxels
            .try_reserve_exact(total(|p| p.voxels.len()))
            .is_ok()
        && out
            .gradients
            .try_reserve_exact(total(|p| p.gradients.len()))
            .is_ok()
        && out
            .colours
            .try_reserve_exact(total(|p| p.colours.len()))
            .is_ok();
    if !reserved {
        return Ok(None);
    }
    for part in parts {
        out.append(part);
    }
    Ok(Some(out))
}

/// The bytes the classification threads may add to their lists, all together.
#[derive(Clone, Copy)]
struct Budget<'a> {
    spent: &'a AtomicUsize,
    limit: usize,
}

impl Budget<'_> {
    /// Takes `bytes` more; false (taking nothing) where that passes the limit.
    fn take(&self, bytes: usize) -> bool {
        // `fetch_update` is deprecated on nightly for `try_update` (stable 1.95 has both);
        // the workspace's rust-version (1.88) has only the old name.
        #[allow(deprecated)]
        self.spent
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |s| {
                s.checked_add(bytes).filter(|&t| t <= self.limit)
            })
            .is_ok()
    }
}

/// Classifies sheets `range` of `p`'s axis (offsets relative to the range's first sheet): a
/// level's [`Coloured`] samples with their colours, plain data as f32.
fn classify_range(
    p: &Prepared,
    volume: &Volume,
    range: std::ops::Range<usize>,
    budget: Budget<'_>,
) -> Result<Option<VisibleLists>, CliError> {
    let axis = p.frame.sheet_axis;
    if volume.is_coloured() {
        return classify_sheets(p, volume, range, budget, |s, buf: &mut [Coloured]| {
            volume.coloured_sheet_into(axis, s, buf)
        });
    }
    let (len, count) = (p.frame.sheet_shape().0, p.frame.sheet_count());
    let per_block = (SHEET_BLOCK_BYTES / (len * 4).max(1)).min(MAX_SHEET_BLOCK);
    if axis == 0 && per_block > 1 {
        // Sheets along x are strided in memory: read them a block at a time (see
        // [`footprint::volume::copy_sheets`]). Measured (bench --frames 1 --threads 1, 512²,
        // view 80,20,0): the 256³ blobs' classification along x took 126 ms one sheet at a
        // time and takes 40 ms in blocks (19 ms along z, view 30,20,0). Sheets over 4 MiB
        // (more than 1024² samples) are read one at a time, as before, rather than held twice.
        let mut block = Vec::new();
        let mut held = 0..0;
        classify_sheets(p, volume, range, budget, move |s, buf: &mut [f32]| {
            if !held.contains(&s) {
                held = s..(s + per_block).min(count);
                block.resize(held.len() * len, 0.0);
                volume.sheets_into(axis, held.clone(), &mut block);
            }
            buf.copy_from_slice(&block[(s - held.start) * len..][..len]);
        })
    } else {
        classify_sheets(p, volume, range, budget, |s, buf: &mut [f32]| {
            volume.sheet_into(axis, s, buf)
        })
    }
}

/// The most memory a classification thread spends on a block of sheets along x, bytes.
const SHEET_BLOCK_BYTES: usize = 8 << 20;

/// The most sheets along x read together (a 64-byte cache line holds 16 to 64 samples of 4 to 1
/// bytes).
const MAX_SHEET_BLOCK: usize = 16;

/// [`classify_range`] over the samples `fill(s, sheet)` writes.
fn classify_sheets<T: Sample + Default>(
    p: &Prepared,
    volume: &Volume,
    range: std::ops::Range<usize>,
    budget: Budget<'_>,
    mut fill: impl FnMut(usize, &mut [T]),
) -> Result<Option<VisibleLists>, CliError> {
    let f = &p.frame;
    let shader = p.shader();
    let needs_gradient = shader.shading.needs_gradient();
    let (len, axis, count) = (f.sheet_shape().0, f.sheet_axis, f.sheet_count());
    // Sheet buffers are reused (a sheet of a 256² volume is 256 KiB: allocating each afresh
    // costs a fresh mapping and its page faults, sheet after sheet).
    let mut spare: Vec<Vec<T>> = Vec::new();
    let mut read = |s: usize, spare: &mut Vec<Vec<T>>| {
        let mut buf = spare.pop().unwrap_or_else(|| vec![T::default(); len]);
        fill(s, &mut buf);
        buf
    };
    let mut out = VisibleLists {
        axis,
        offsets: vec![0],
        run_offsets: vec![0],
        ..Default::default()
    };
    let mut voxels = vec![
        VisibleVoxel {
            u: 0,
            v: 0,
            value: 0.0
        };
        len
    ];
    let mut gradients = vec![[0.0f32; 3]; if needs_gradient { len } else { 0 }];
    let mut colours = vec![[0.0f32; 3]; if T::COLOURED { len } else { 0 }];
    // The window of neighbours slides along the range (read only when gradients need them).
    let mut lower: Option<Vec<T>> = None;
    let mut current = range.clone().next().map(|s| read(s, &mut spare));
    let mut upper: Option<Vec<T>> = None;
    for s in range.clone() {
        let cur = current.take().expect("the sheet was read");
        if needs_gradient {
            if s > 0 && lower.is_none() {
                lower = Some(read(s - 1, &mut spare));
            }
            upper = (s + 1 < count).then(|| read(s + 1, &mut spare));
        }
        let window = SheetWindow {
            lower: lower.as_deref(),
            current: &cur,
            upper: upper.as_deref(),
        };
        let n = match volume.owned_in_sheet(axis, s) {
            Some(owned) => {
                let n = classify_sheet(
                    f,
                    &shader,
                    s,
                    window,
                    &mut voxels,
                    &mut gradients,
                    &mut colours,
                )?;
                keep_owned(owned, n, &mut voxels, &mut gradients, &mut colours)
            }
            None => 0,
        };
        // The sheet's voxels, gradients, colours, runs (at most one per voxel) and offsets.
        let per = VisibleLists::BYTES_PER_VOXEL
            + 12 * (usize::from(needs_gradient) + usize::from(T::COLOURED))
            + std::mem::size_of::<RowRun>();
        if !budget.take(n * per + 16) || !out.reserve(n, needs_gradient, T::COLOURED) {
            return Ok(None);
        }
        out.voxels.extend_from_slice(&voxels[..n]);
        sheet_runs(&voxels[..n], &mut out.runs);
        out.run_offsets.push(out.runs.len());
        if needs_gradient {
            out.gradients.extend_from_slice(&gradients[..n]);
        }
        if T::COLOURED {
            out.colours.extend_from_slice(&colours[..n]);
        }
        out.offsets.push(out.voxels.len());
        if s + 1 < range.end {
            current = Some(match upper.take() {
                Some(next) => next,
                None => read(s + 1, &mut spare),
            });
            let done = if needs_gradient {
                lower.replace(cur)
            } else {
                Some(cur)
            };
            spare.extend(done);
        }
    }
    Ok(Some(out))
}

/// Of a sheet's `n` classified voxels (and their gradients and colours, where held), keeps those
/// inside `owned` (index ranges along u and v: a brick's own voxels, [`Volume::owned_in_sheet`]),
/// in order; returns how many. A whole volume's sheet keeps all of them, untouched.
pub fn keep_owned(
    (us, vs): (std::ops::Range<usize>, std::ops::Range<usize>),
    n: usize,
    voxels: &mut [VisibleVoxel],
    gradients: &mut [[f32; 3]],
    colours: &mut [[f32; 3]],
) -> usize {
    let inside =
        |x: &VisibleVoxel| us.contains(&usize::from(x.u)) && vs.contains(&usize::from(x.v));
    if voxels[..n].iter().all(inside) {
        return n;
    }
    let mut kept = 0;
    for i in 0..n {
        if inside(&voxels[i]) {
            voxels[kept] = voxels[i];
            if !gradients.is_empty() {
                gradients[kept] = gradients[i];
            }
            if !colours.is_empty() {
                colours[kept] = colours[i];
            }
            kept += 1;
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::{sheet_runs, RowRun, VisibleVoxel};

    /// A sheet's runs are one per row that holds voxels, in row order, with that row's smallest
    /// and largest u and its count (checked against a count per row over random sheets).
    #[test]
    fn runs_summarise_each_row() {
        let mut seed = 0x1234_5678_9abc_def1u64;
        let mut next = |m: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % m
        };
        for _ in 0..500 {
            let (na, nb) = (1 + next(40) as u16, 1 + next(40) as u16);
            let density = next(100);
            let mut voxels = Vec::new();
            for v in 0..nb {
                for u in 0..na {
                    if next(100) < density {
                        voxels.push(VisibleVoxel { u, v, value: 1.0 });
                    }
                }
            }
            let mut runs = vec![RowRun::default()];
            sheet_runs(&voxels, &mut runs);
            let mut want = vec![RowRun::default()];
            for v in 0..nb {
                let row: Vec<u16> = voxels.iter().filter(|x| x.v == v).map(|x| x.u).collect();
                if let (Some(&u0), Some(&u1)) = (row.iter().min(), row.iter().max()) {
                    want.push(RowRun {
                        v,
                        u0,
                        u1,
                        count: row.len() as u32,
                    });
                }
            }
            assert_eq!(runs, want);
        }
    }
}
