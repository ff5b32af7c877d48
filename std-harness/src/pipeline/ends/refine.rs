//! `--refine THRESHOLD`: the paper's adaptive re-sampling for magnified volumes (the core's
//! [`footprint::refine`] and `render/refined.rs`).
//!
//! 1. **Where.** Every coarse sample is classified through the transfer function (premultiplied
//!    RGBA for one world unit, emission: the colours the paper's test compares). Along each grid
//!    axis, interval i's variation is the largest channel difference between samples i and i + 1
//!    over the whole plane of the interval; [`footprint::refine::factor_for`] turns it into 1, 2
//!    or 4 steps. The volume is read once, a sheet at a time.
//!    The sheet axis is refined only with `--refine-sheets`.
//! 2. **How far.** A step never projects closer than [`MIN_STEP_PX`] pixels (the length of the
//!    grid step on screen, depth included): smaller footprints cost more per pixel than they
//!    gain (docs/modes.md, "Adaptive refinement": at 512², 16³ steps of 4.8 px gave +8.9 dB at 1.96×
//!    the unrefined time, steps of 9.5 px +6.2 dB at 1.30×).
//! 3. **Footprints**, built once per view, per spacing key the grid produces: a symmetric spacing's
//!    exact footprint (a view table, with phase stencils where many samples share it); a border
//!    spacing's [`ScaledFootprint`] as stencils where many samples share it, resampled into a
//!    table of its own where at least [`RESAMPLE_SAMPLES`] do; and the view tables of the rates
//!    ρ ∈ {¼, ½, 1, 2, 4} (the kernel scaled by ρ along the sheet axis) that the remaining border
//!    samples read at scaled coordinates.
//! 4. **Render.** On bands of rows like every render ([`crate::pipeline::stages::bands::on_bands`]): byte-identical
//!    for any number of threads.

use crate::io::volume::Volume;
use crate::pipeline::stages::bands::{equal_bands, on_bands, CoreFrame, Phases};
use crate::pipeline::stages::prepare::Prepared;
pub use crate::pipeline::stages::refinement::Refinement;
use crate::plan::{End, Plan};
use crate::CliError;
use footprint::composite::RowSpan;
use footprint::frame::FrameSetup;
use footprint::refine::{factor_for, RefinedAxis};
use footprint::render::{
    key_spacings, rate_index, sheet_map, spacing_key, FloatPath, RefineTables, RefinedGrid,
    RenderBuffers, RenderStats, ScaledFootprint, SheetRenderer, SPACING_KEYS,
};
use footprint::shade::{Lighting, Shader, Shading, OPACITY_TABLE_LEN};
use footprint::splat::{BufferError, ImageMut, Pixel, SplatStats, Splatter};
use footprint::stencil::{self, Stencils};
use footprint::Sampler;
use footprint::{Footprint, GenericTable, Lookup, ViewTable};
use std::time::Instant;

/// Samples that must share a border spacing for its scaled footprint to be resampled into a
/// table of its own (M² reads, then the row walk per pixel instead of the scaled walk).
pub const RESAMPLE_SAMPLES: usize = 32;

/// Most sub-pixel phases of a refined footprint's stencils.
pub const REFINE_PHASES: usize = 8;

/// The closest a refined step may project, pixels.
pub const MIN_STEP_PX: f32 = 6.0;

/// Checks that `p` can be refined, with a message saying what to drop if not (the plan has
/// checked what the flags decide: float, object slicing, the robust method, orthographic).
pub fn check(p: &Prepared) -> Result<(), CliError> {
    let refuse = |why: &str| Err(CliError::input(format!("--refine: {why}")));
    if p.frame.camera().is_some() {
        return refuse("orthographic views only (drop --perspective)");
    }
    if p.volume().is_none() {
        return refuse("the volume must be in memory (drop --stream)");
    }
    Ok(())
}

/// Whether refining `p` as `plan` says (a [`End::Refined`] plan) can add samples to its grid:
/// [`check`] passes, `p` is at full resolution, and an in-sheet grid step (or, when it refines
/// across sheets, the sheet step) projects at least 2 × [`MIN_STEP_PX`] (otherwise every
/// interval keeps factor 1 and the refined render is the unrefined one).
pub fn worth_trying(p: &Prepared, plan: &Plan) -> bool {
    let End::Refined { sheets, .. } = plan.end else {
        return false;
    };
    if check(p).is_err() || p.level != 0 {
        return false;
    }
    (0..3).any(|axis| {
        (axis != p.frame.sheet_axis || sheets)
            && p.frame.grid_to_screen.col(axis).length() >= 2.0 * MIN_STEP_PX
    })
}

/// The refinement factors of `volume` for `p`'s transfer function, view and `threshold`; the
/// sheet axis stays unrefined unless `sheets`.
pub fn choose(
    p: &Prepared,
    volume: &Volume,
    threshold: f32,
    sheets: bool,
) -> Result<Refinement, CliError> {
    let dims = volume.dims;
    let shader = Shader {
        shading: Shading::Emission,
        ..p.shader()
    };
    let lighting = Lighting::per_world_unit(&p.frame);
    let classify = |n: usize| {
        shader.shade_with(
            &lighting,
            None,
            volume.value_in_grid(n),
            || glam::Vec3::ZERO,
            [0; 3],
            [1; 3],
        )
    };
    let diff = |a: [f32; 4], b: [f32; 4]| {
        (0..4).fold(0.0f32, |m, c| {
            let d = (a[c] - b[c]).abs();
            if d.is_nan() {
                m
            } else {
                m.max(d)
            }
        })
    };
    let [nx, ny, nz] = dims;
    let mut var = [
        vec![0.0f32; nx.saturating_sub(1)],
        vec![0.0f32; ny.saturating_sub(1)],
        vec![0.0f32; nz.saturating_sub(1)],
    ];
    let sheet = nx * ny;
    let mut prev = crate::io::try_filled(sheet, [0.0f32; 4], "a classified sheet")?;
    let mut cur = prev.clone();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let c = classify(i + nx * (j + ny * k));
                let here = i + nx * j;
                if i > 0 {
                    var[0][i - 1] = var[0][i - 1].max(diff(c, cur[here - 1]));
                }
                if j > 0 {
                    var[1][j - 1] = var[1][j - 1].max(diff(c, cur[here - nx]));
                }
                if k > 0 {
                    var[2][k - 1] = var[2][k - 1].max(diff(c, prev[here]));
                }
                cur[here] = c;
            }
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    let mut factors: [Vec<u8>; 3] = Default::default();
    for (axis, v) in var.iter().enumerate() {
        let px = p.frame.grid_to_screen.col(axis).length();
        let cap = if axis == p.frame.sheet_axis && !sheets {
            1
        } else {
            (px / MIN_STEP_PX).clamp(1.0, 4.0) as u8
        };
        factors[axis] = v
            .iter()
            .map(|&x| factor_for(x, threshold, cap))
            .collect::<Result<_, _>>()
            .map_err(|e| CliError::input(format!("--refine: {e}")))?;
    }
    let coarse_samples = dims.iter().product();
    let samples = (0..3)
        .map(|a| 1 + factors[a].iter().map(|&f| usize::from(f)).sum::<usize>())
        .product();
    Ok(Refinement {
        threshold,
        sheets,
        factors,
        coarse_samples,
        samples,
    })
}

/// Renders `p` refined at `threshold` (see the module docs; across sheets too if `sheets`) with
/// `plan`'s tables on `plan.threads` bands, after [`check`]ing that it can.
pub fn render_refined(
    p: &Prepared,
    plan: &Plan,
    threshold: f32,
    sheets: bool,
) -> Result<CoreFrame, CliError> {
    check(p)?;
    let volume = p.volume().expect("checked");
    let start = Instant::now();
    let refinement = choose(p, volume, threshold, sheets)?;
    let classify = start.elapsed().as_secs_f64();
    grid_frame(p, plan, Some(refinement), start, classify)
}

/// A rectilinear grid's sheets as they are (every factor 1; `footprint::refine`, "Rectilinear
/// grids"): what [`End::Sheets`] draws for a volume with coordinates (`crate::io::grid`).
pub fn render_rectilinear(p: &Prepared, plan: &Plan) -> Result<CoreFrame, CliError> {
    check(p).map_err(|e| CliError::input(format!("a rectilinear grid: {e}")))?;
    grid_frame(p, plan, None, Instant::now(), 0.0)
}

/// The frame of `p`'s grid (rectilinear where the volume has coordinates) split as
/// `refinement` says (unsplit for `None`), chosen at `start` in `classify` seconds, through
/// `plan`'s tables.
fn grid_frame(
    p: &Prepared,
    plan: &Plan,
    refinement: Option<Refinement>,
    start: Instant,
    classify: f64,
) -> Result<CoreFrame, CliError> {
    /// The refined frame through tables of side N.
    struct Refined<'a> {
        p: &'a Prepared,
        plan: &'a Plan,
        chosen: Chosen,
    }
    impl crate::dispatch::TableSize for Refined<'_> {
        type Output = CoreFrame;
        fn run<const N: usize>(self) -> Result<CoreFrame, CliError> {
            refined_at::<N>(self.p, self.plan, self.chosen)
        }
    }
    let chosen = Chosen {
        refinement,
        start,
        classify,
    };
    crate::dispatch::with_size(plan.table.size, Refined { p, plan, chosen })
}

/// What a refined frame was split by: the refinement (none: the grid as it is), when the frame
/// began and the seconds choosing it took.
struct Chosen {
    refinement: Option<Refinement>,
    start: Instant,
    classify: f64,
}

/// [`grid_frame`] with tables of side `N`. A rectilinear grid's samples have spacings of
/// their own, which no spacing key's footprint is built for: they read the rate tables at their
/// own scales.
fn refined_at<const N: usize>(
    p: &Prepared,
    plan: &Plan,
    chosen: Chosen,
) -> Result<CoreFrame, CliError> {
    let Chosen {
        refinement,
        start,
        classify,
    } = chosen;
    let f = &p.frame;
    let ones: [Vec<u8>; 3] = f.dims.map(|n| vec![1u8; n.saturating_sub(1)]);
    let factors = refinement.as_ref().map_or(&ones, |r| &r.factors);
    let coordinates = p.volume().and_then(|v| v.grid.as_deref());
    let positions: Option<[Vec<f32>; 3]> =
        coordinates.map(|c| c.positions().map(|a| a.iter().map(|&x| x as f32).collect()));
    let axis = |a: usize| {
        match &positions {
            Some(at) => RefinedAxis::rectilinear(a, &at[a], &factors[a]),
            None => RefinedAxis::new(a, f.dims[a], &factors[a]),
        }
        .map_err(|e| match positions {
            Some(_) => CliError::input(format!("a rectilinear grid, in f32 grid steps: {e}")),
            None => CliError::input(format!("--refine: {e}")),
        })
    };
    let grid = RefinedGrid {
        axes: [axis(0)?, axis(1)?, axis(2)?],
    };
    let t0 = Instant::now();
    let generic = plan.table.generic::<N>(&p.kernel)?;
    let lookup = plan.table.lookup;
    // Refined footprints are many and small: their stencils get at most REFINE_PHASES
    // phases per pixel (a 1/16-px placement), which keeps building them cheap.
    let phases = plan.phases.min(REFINE_PHASES);
    let keys = match positions {
        Some(_) => Vec::new(),
        None => spacing_keys(&grid, f),
    };
    let rate_tables = rate_tables::<N>(p, &grid, &keys, &generic, lookup)?;
    let base = &*rate_tables.iter().find(|(r, _)| *r == 2).expect("built").1;
    let rates = [0, 1, 2, 3, 4].map(|r| {
        rate_tables
            .iter()
            .find(|(j, _)| *j == r)
            .map_or(base, |t| &*t.1)
    });
    let (mut exact_tables, mut scaled) = key_tables(p, &keys, rates, &generic, lookup, phases)?;
    let mut splatters: Vec<Option<Exact<'_, N>>> = (0..SPACING_KEYS).map(|_| None).collect();
    for (key, table, buffer) in exact_tables.iter_mut() {
        splatters[*key] = Some(if buffer.is_empty() {
            Exact::Table(&**table)
        } else {
            Exact::Stencils(Stencils::build(&**table, phases, buffer)?)
        });
    }
    for (key, fp, buffer) in scaled.iter_mut() {
        splatters[*key] = Some(Exact::Scaled(Stencils::build(&*fp, phases, buffer)?));
    }
    let tables = RefineTables {
        rates,
        splatters: &splatters,
    };
    let table_secs = t0.elapsed().as_secs_f64();
    let (image, stats, phases) = refined_bands(p, plan.threads, &grid, &tables)?;
    Ok(CoreFrame {
        image,
        stats,
        seconds: start.elapsed().as_secs_f64(),
        phases: Phases {
            classify,
            tables: table_secs,
            ..phases
        },
        threads: plan.threads.clamp(1, f.size[1]),
        visible: None,
        refine: refinement,
    })
}

/// The spacing keys (the core's `spacing_key`) the refined grid's samples have, with how many
/// samples have each.
fn spacing_keys(grid: &RefinedGrid, f: &FrameSetup) -> Vec<(usize, usize)> {
    let (k, (a, b)) = (f.sheet_axis, f.in_sheet);
    let bins = |axis: usize| {
        let mut c = [0usize; 9];
        let _ = grid.axes[axis].for_each::<()>(true, |s| {
            c[spacing_key(s.spacing, [1.0; 2], 1.0) % 9] += 1;
            Ok(())
        });
        c
    };
    let (ca, cb) = (bins(a), bins(b));
    let mut cz = [0usize; 3];
    let _ = grid.axes[k].for_each::<()>(true, |s| {
        cz[spacing_key([1.0; 2], [1.0; 2], s.width()) / 81] += 1;
        Ok(())
    });
    (0..SPACING_KEYS)
        .map(|key| (key, ca[key % 9] * cb[(key / 9) % 9] * cz[key / 81]))
        .filter(|&(_, n)| n > 0)
        .collect()
}

/// Whether spacing `key` is symmetric (each in-sheet axis's two spacings equal): its samples
/// get an exact footprint of their own.
fn symmetric(key: usize) -> bool {
    let (sa, sb, _) = key_spacings(key);
    sa[0] == sa[1] && sb[0] == sb[1]
}

/// The footprint of a local grid-to-screen matrix `m`.
fn local_footprint(p: &Prepared, m: &glam::Mat3) -> Result<Footprint, CliError> {
    Footprint::with_sheet_axis(&p.kernel, m, p.options, p.frame.sheet_axis)
        .map_err(|e| CliError::input(format!("--refine: a local spacing's footprint: {e}")))
}

/// The view tables of the rates ([`RefineTables::RATES`]) some sample's scaled footprint reads,
/// by rate index; rate 1 (index 2) always.
fn rate_tables<const N: usize>(
    p: &Prepared,
    grid: &RefinedGrid,
    keys: &[(usize, usize)],
    generic: &GenericTable<N>,
    lookup: Lookup,
) -> Result<Vec<(usize, Box<ViewTable<N>>)>, CliError> {
    let f = &p.frame;
    let (k, (a, b)) = (f.sheet_axis, f.in_sheet);
    let mut needed = rates_needed(grid, k, (a, b));
    for &(key, _) in keys.iter().filter(|&&(key, _)| !symmetric(key)) {
        let (sa, sb, w) = key_spacings(key);
        needed[rate_index(sa, sb, w)] = true;
    }
    let mut rate_tables = Vec::with_capacity(5);
    for (r, rho) in RefineTables::<ViewTable<N>, Exact<'_, N>>::RATES
        .into_iter()
        .enumerate()
    {
        if rho != 1.0 && !needed[r] {
            continue;
        }
        let mut m = f.grid_to_screen;
        *m.col_mut(k) *= rho;
        let fp = if rho == 1.0 {
            f.footprint
        } else {
            local_footprint(p, &m)?
        };
        let table = ViewTable::<N>::build(&fp, generic, lookup, lookup);
        rate_tables.push((r, Box::new(table)));
    }
    Ok(rate_tables)
}

/// Per spacing key, its footprint and stencil storage: (key, a symmetric spacing's exact table
/// or a border spacing's resampled one, stencil floats (empty: walk the table)), and (key, a
/// border spacing's scaled footprint, its stencil floats).
type KeyTables<'r, const N: usize> = (
    Vec<(usize, Box<ViewTable<N>>, Vec<f32>)>,
    Vec<(usize, ScaledFootprint<'r, ViewTable<N>>, Vec<f32>)>,
);

/// The footprints of `keys` (see [`KeyTables`]); a border spacing neither shared enough for
/// stencils nor for a table of its own gets none (its samples read the rate tables).
fn key_tables<'r, const N: usize>(
    p: &Prepared,
    keys: &[(usize, usize)],
    rates: [&'r ViewTable<N>; 5],
    generic: &GenericTable<N>,
    lookup: Lookup,
    phases: usize,
) -> Result<KeyTables<'r, N>, CliError> {
    let f = &p.frame;
    let (k, (a, b)) = (f.sheet_axis, f.in_sheet);
    let map = sheet_map(f);
    let mut exact_tables = Vec::new();
    let mut scaled = Vec::new();
    for &(key, n) in keys {
        let (sa, sb, w) = key_spacings(key);
        if symmetric(key) {
            let mut sigma = [1.0f32; 3];
            (sigma[a], sigma[b], sigma[k]) = (sa[0], sb[0], w);
            let m = f.grid_to_screen * glam::Mat3::from_diagonal(glam::Vec3::from_array(sigma));
            let fp = local_footprint(p, &m)?;
            let table = Box::new(ViewTable::<N>::build(&fp, generic, lookup, lookup));
            let len = stencil_len(table.footprint(), n, phases);
            exact_tables.push((key, table, vec![0.0f32; len.unwrap_or(0)]));
        } else if let Some(fp) = ScaledFootprint::new(rates[rate_index(sa, sb, w)], map, [sa, sb]) {
            // A scaled footprint's read costs about twice a table's: half the samples' worth
            // for stencils; else, shared by a few samples, its own table (the row walk).
            if let Some(len) = stencil_len(fp.footprint(), n / 2, phases) {
                scaled.push((key, fp, vec![0.0f32; len]));
            } else if n >= RESAMPLE_SAMPLES {
                let mut t = Box::new(ViewTable::<N>::zeroed(*fp.footprint()));
                t.resample_into(&fp, lookup);
                exact_tables.push((key, t, Vec::new()));
            }
        }
    }
    Ok((exact_tables, scaled))
}

/// Renders the refined grid through `tables` on `threads` bands of rows: the image (render
/// size), the counts and the phases' seconds.
fn refined_bands<const N: usize>(
    p: &Prepared,
    threads: usize,
    grid: &RefinedGrid,
    tables: &RefineTables<'_, ViewTable<N>, Exact<'_, N>>,
) -> Result<(Vec<[f32; 4]>, RenderStats, Phases), CliError> {
    let f = &p.frame;
    let volume = p.volume().expect("checked");
    let dims = volume.dims;
    let value = |[i, j, k]: [usize; 3]| volume.value_in_grid(i + dims[0] * (j + dims[1] * k));
    on_bands(
        crate::io::try_filled(f.size[0] * f.size[1], [0.0f32; 4], "the image")?,
        f.size,
        equal_bands(f.size[1], threads),
        p.background.as_deref(),
        |rows, image, bg| {
            let n = f.size[0] * rows.len();
            let mut acc = crate::io::try_filled(n, [0.0f32; 4], "a band's sheet accumulator")?;
            let mut spans = vec![RowSpan::EMPTY; rows.len()];
            let mut opacity = vec![0.0f32; OPACITY_TABLE_LEN];
            let mut scratch =
                crate::io::try_filled(2 * f.sheet_shape().0, 0.0f32, "refinement scratch sheets")?;
            let buffers = RenderBuffers {
                accumulator: &mut acc,
                image,
                rows: &mut spans,
            };
            let path = FloatPath::new(tables.rates[2]).with_absorption(p.absorption);
            let mut r = SheetRenderer::with_band(f, path, p.shader(), p.order, buffers, bg, rows)?
                .with_opacity_table(&mut opacity)?;
            let t = Instant::now();
            r.render_refined(grid, tables, value, &mut scratch)?;
            let splat = t.elapsed().as_secs_f64();
            Ok((
                r.finish(),
                Phases {
                    splat,
                    ..Phases::default()
                },
            ))
        },
    )
}

/// One spacing's footprint: a symmetric spacing's exact footprint (its phase stencils, or its
/// view table where stencils do not pay or apply), or the stencils of a scaled one.
#[derive(Clone, Copy)]
enum Exact<'a, const N: usize> {
    Stencils(Stencils<'a, ViewTable<N>>),
    Table(&'a ViewTable<N>),
    Scaled(Stencils<'a, ScaledFootprint<'a, ViewTable<N>>>),
}

impl<const N: usize> Splatter for Exact<'_, N> {
    fn splat_voxel<P: Pixel>(
        &self,
        center: [f32; 2],
        value: &P,
        image: &mut ImageMut<'_, P>,
        touched: impl FnMut(usize, usize, usize),
    ) -> Result<SplatStats, BufferError> {
        match self {
            Exact::Stencils(s) => s.splat_voxel(center, value, image, touched),
            Exact::Table(t) => t.splat_voxel(center, value, image, touched),
            Exact::Scaled(s) => s.splat_voxel(center, value, image, touched),
        }
    }
}

/// The least and greatest width (mean of the two spacings, grid steps) of an axis's samples.
fn widths(axis: &RefinedAxis) -> (f32, f32) {
    let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
    let _ = axis.for_each::<()>(true, |s| {
        (lo, hi) = (lo.min(s.width()), hi.max(s.width()));
        Ok(())
    });
    (lo.min(hi), hi)
}

/// Which rates ([`RefineTables::rate_index`]) some sample of `grid` can ask for: every one
/// between the least and the greatest (the rate grows with the sheet's width and falls with the
/// in-sheet widths).
fn rates_needed(grid: &RefinedGrid, sheet: usize, (a, b): (usize, usize)) -> [bool; 5] {
    let ((za, zb), (aa, ab), (ba, bb)) = (
        widths(&grid.axes[sheet]),
        widths(&grid.axes[a]),
        widths(&grid.axes[b]),
    );
    let (least, most) = (
        rate_index([ab; 2], [bb; 2], za),
        rate_index([aa; 2], [ba; 2], zb),
    );
    std::array::from_fn(|r| (least..=most).contains(&r))
}

/// Stencil floats for a footprint that `samples` samples share, if stencils pay: they cost
/// (P + 1)² footprint reads per box pixel to build and save part of a table walk per pixel
/// update (about a fifth of a read, measured on the refinement chart), so a spacing gets them when
/// at least 8·(P + 1)² samples share it (and stencils apply, within [`REFINE_STENCIL_FLOATS`]).
fn stencil_len(fp: &Footprint, samples: usize, phases: usize) -> Option<usize> {
    let p = stencil::phases_for(fp, phases);
    (phases > 0 && samples >= 8 * (p + 1) * (p + 1))
        .then(|| stencil::len_for(fp, phases))
        .flatten()
        .filter(|&len| len <= REFINE_STENCIL_FLOATS)
}

/// Largest stencils (floats, 2 MiB) for one spacing of a refined render, which holds one set per
/// spacing that pays for them: the core allows 8 MiB for a frame's single set
/// ([`stencil::MAX_STENCIL_FLOATS`]), which over many spacings would hold 4× the memory; a
/// spacing whose stencils are larger walks its table.
const REFINE_STENCIL_FLOATS: usize = 1 << 19;
