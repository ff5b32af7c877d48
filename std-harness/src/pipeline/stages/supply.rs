//! A band's supply of visible voxels, sheet by sheet: the kept lists ([`super::visible`]), or,
//! for a volume whose lists would pass their budget, each sheet classified as the band reaches it
//! ([`OnTheFly`]: a sheet and its two neighbours held, the same voxels in the same order).

use super::prepare::Prepared;
use super::visible::VisibleLists;
use crate::io::volume::Volume;
use crate::CliError;
use footprint::lod::Coloured;
use footprint::render::{classify_sheet, SheetWindow, VisibleSheet, VisibleVoxel};
use footprint::shade::Sample;

/// What a band reads each sheet's visible voxels from: kept lists, or an [`OnTheFly`]
/// classifier.
pub trait SheetSupply {
    /// Sheet `s`'s visible voxels (of the frame the supply was made for).
    fn sheet(&mut self, s: usize) -> Result<VisibleSheet<'_>, CliError>;
    /// Visible voxels supplied so far (over every sheet).
    fn supplied(&self) -> u64;
}

impl SheetSupply for &VisibleLists {
    fn sheet(&mut self, s: usize) -> Result<VisibleSheet<'_>, CliError> {
        Ok(VisibleLists::sheet(self, s))
    }
    fn supplied(&self) -> u64 {
        self.len() as u64
    }
}

/// The kept lists as one band of rows sees them: each sheet's voxels from the first row run
/// that can reach the band to the last one that can (the rows between them whole), instead of
/// the whole sheet. The core tests every voxel it is given against the band
/// (`SheetRenderer::with_band`), so the voxels left out are only ones that test would refuse:
/// the same splats in the same order, the same bits. On 16 bands a band was given every voxel of
/// every sheet and refused most of them one by one.
pub struct BandLists<'a> {
    lists: &'a VisibleLists,
    frame: &'a footprint::frame::FrameSetup,
    /// Screen rows (pixel centres at y + 0.5) a voxel must reach: the band's, widened by the
    /// footprint's half-height and the core's own margin (2 px), and one more pixel against the
    /// rounding of the two computations of y. `None`: no cut (perspective, or the whole image).
    reach: Option<(f32, f32)>,
}

impl<'a> BandLists<'a> {
    /// `lists` for the band of image rows `rows` of `frame`.
    pub fn new(
        lists: &'a VisibleLists,
        frame: &'a footprint::frame::FrameSetup,
        rows: std::ops::Range<usize>,
    ) -> Self {
        let whole = rows.start == 0 && rows.end >= frame.size[1];
        let margin = frame.footprint.half_extent[1] + 3.0;
        let reach = (!whole && frame.camera().is_none() && margin.is_finite())
            .then_some((rows.start as f32 - margin, rows.end as f32 + margin));
        BandLists {
            lists,
            frame,
            reach,
        }
    }

    /// The voxel range of sheet `s` (indices into the lists' voxels) the band is given.
    fn range(&self, s: usize) -> std::ops::Range<usize> {
        let l = self.lists;
        let all = l.offsets[s]..l.offsets[s + 1];
        let Some((top, bottom)) = self.reach else {
            return all;
        };
        // Screen y is affine in (u, v) on a sheet: y = y0 + ya·u + yb·v.
        let f = self.frame;
        let y = |u: usize, v: usize| f.affine_position(f.grid_index(s, u, v).map(|c| c as f32)).y;
        let y0 = y(0, 0);
        let (ya, yb) = (y(1, 0) - y0, y(0, 1) - y0);
        let (mut first, mut last) = (None, all.start);
        let mut at = all.start;
        for run in &l.runs[l.run_offsets[s]..l.run_offsets[s + 1]] {
            let base = y0 + yb * f32::from(run.v);
            let (a, b) = (base + ya * f32::from(run.u0), base + ya * f32::from(run.u1));
            let end = at + run.count as usize;
            // `!` keeps a NaN run in.
            if !(a.max(b) < top || a.min(b) > bottom) {
                first.get_or_insert(at);
                last = end;
            }
            at = end;
        }
        match first {
            Some(first) => first..last,
            None => all.start..all.start,
        }
    }
}

impl SheetSupply for BandLists<'_> {
    fn sheet(&mut self, s: usize) -> Result<VisibleSheet<'_>, CliError> {
        let r = self.range(s);
        let l = self.lists;
        fn part<'v>(v: &'v [[f32; 3]], r: &std::ops::Range<usize>) -> &'v [[f32; 3]] {
            if v.is_empty() {
                &[]
            } else {
                &v[r.clone()]
            }
        }
        Ok(VisibleSheet {
            voxels: &l.voxels[r.clone()],
            gradients: part(&l.gradients, &r),
            colours: part(&l.colours, &r),
        })
    }
    /// Every visible voxel: the band could be given any (what `run_bands` reports as the frame's).
    fn supplied(&self) -> u64 {
        self.lists.len() as u64
    }
}

/// A sample type a volume in memory gives a sheet of.
pub trait ReadSheet: Sample + Default + Clone {
    /// Writes sheet `s` of `axis` of `volume` into `out`.
    fn read(volume: &Volume, axis: usize, s: usize, out: &mut [Self]);
}

impl ReadSheet for f32 {
    fn read(volume: &Volume, axis: usize, s: usize, out: &mut [f32]) {
        volume.sheet_into(axis, s, out);
    }
}

impl ReadSheet for Coloured {
    fn read(volume: &Volume, axis: usize, s: usize, out: &mut [Coloured]) {
        volume.coloured_sheet_into(axis, s, out);
    }
}

/// Classifies each sheet when asked for it, from a volume in memory whose lists would pass the
/// budget (`super::visible::Visible::OnTheFly`): holds the sheet and its two neighbours (for gradients) and one
/// sheet's worth of voxels, gradients and colours. The voxels are those
/// `super::visible::classify` would list, in the same order: the same core function over the same samples.
pub struct OnTheFly<'a, T> {
    p: &'a Prepared,
    volume: &'a Volume,
    /// Up to three sheets, each with its index.
    held: Vec<(usize, Vec<T>)>,
    voxels: Vec<VisibleVoxel>,
    gradients: Vec<[f32; 3]>,
    colours: Vec<[f32; 3]>,
    supplied: u64,
}

impl<'a, T: ReadSheet> OnTheFly<'a, T> {
    /// A classifier of `p`'s sheets of `volume` (its buffers allocated fallibly).
    pub fn new(p: &'a Prepared, volume: &'a Volume) -> Result<Self, CliError> {
        let len = p.frame.sheet_shape().0;
        let needs_gradient = p.shader().shading.needs_gradient();
        let what = "a sheet's visible voxels";
        Ok(OnTheFly {
            p,
            volume,
            held: Vec::with_capacity(3),
            voxels: crate::io::try_filled(
                len,
                VisibleVoxel {
                    u: 0,
                    v: 0,
                    value: 0.0,
                },
                what,
            )?,
            gradients: crate::io::try_filled(if needs_gradient { len } else { 0 }, [0.0; 3], what)?,
            colours: crate::io::try_filled(if T::COLOURED { len } else { 0 }, [0.0; 3], what)?,
            supplied: 0,
        })
    }

    /// Makes sure sheet `s` is held (reusing the buffer of a sheet outside `keep`).
    fn hold(&mut self, s: usize, keep: std::ops::RangeInclusive<usize>) -> Result<(), CliError> {
        if self.held.iter().any(|(i, _)| *i == s) {
            return Ok(());
        }
        let f = &self.p.frame;
        let mut buf = match self.held.iter().position(|(i, _)| !keep.contains(i)) {
            Some(k) => self.held.swap_remove(k).1,
            None => {
                crate::io::try_filled(f.sheet_shape().0, T::default(), "a sheet of the volume")?
            }
        };
        T::read(self.volume, f.sheet_axis, s, &mut buf);
        self.held.push((s, buf));
        Ok(())
    }
}

impl<T: ReadSheet> SheetSupply for OnTheFly<'_, T> {
    fn sheet(&mut self, s: usize) -> Result<VisibleSheet<'_>, CliError> {
        let f = &self.p.frame;
        let shader = self.p.shader();
        let needs_gradient = shader.shading.needs_gradient();
        let count = f.sheet_count();
        let (first, last) = if needs_gradient {
            (s.saturating_sub(1), (s + 1).min(count - 1))
        } else {
            (s, s)
        };
        for i in first..=last {
            self.hold(i, first..=last)?;
        }
        let find = |i: usize| {
            self.held
                .iter()
                .find(|(j, _)| *j == i)
                .map(|(_, b)| b.as_slice())
        };
        let window = SheetWindow {
            lower: (needs_gradient && s > 0).then(|| find(s - 1)).flatten(),
            current: find(s).expect("held above"),
            upper: (needs_gradient && s + 1 < count)
                .then(|| find(s + 1))
                .flatten(),
        };
        let n = match self.volume.owned_in_sheet(f.sheet_axis, s) {
            Some(owned) => {
                let n = classify_sheet(
                    f,
                    &shader,
                    s,
                    window,
                    &mut self.voxels,
                    &mut self.gradients,
                    &mut self.colours,
                )?;
                super::visible::keep_owned(
                    owned,
                    n,
                    &mut self.voxels,
                    &mut self.gradients,
                    &mut self.colours,
                )
            }
            None => 0,
        };
        self.supplied += n as u64;
        Ok(VisibleSheet {
            voxels: &self.voxels[..n],
            gradients: if needs_gradient {
                &self.gradients[..n]
            } else {
                &[]
            },
            colours: if T::COLOURED { &self.colours[..n] } else { &[] },
        })
    }

    fn supplied(&self) -> u64 {
        self.supplied
    }
}
