//! Running a prepared render: the core's sheet loop (float or fixed, any table method) over the
//! visible voxels of a volume in memory, on several cores ([`crate::pipeline::stages::bands`]), or driven through a
//! [`SheetRing`] as a streaming source would drive it; and the f64 reference.

use crate::dispatch::{with_size, TableSize};
use crate::io::progress::sheets;
use crate::io::stream::{ColouredMemorySource, FileSource, MemorySource, PipeSource};
use crate::io::try_filled;
pub use crate::pipeline::stages::bands::CoreFrame;
use crate::pipeline::stages::bands::{run_bands, Bands, Phases};
use crate::pipeline::stages::decorators::{self, Resample};
use crate::pipeline::stages::load::Voxels;
use crate::pipeline::stages::lod::{with_level, DynSource};
use crate::pipeline::stages::prepare::Prepared;
use crate::pipeline::stages::supersample::downsample;
use crate::pipeline::stages::visible::FrameCache;
use crate::plan::{End, Footprints, Plan, Precision as PlanPrecision};
use crate::reference::render::{render_reference, ReferenceScene};
use crate::CliError;
use footprint::fixed::stencil::FixedStencils;
use footprint::fixed::{self, FixedTable};
use footprint::render::occlusion_len;
use footprint::render::{
    FixedPath, FloatPath, PerVoxel, Precision, RenderBuffers, RenderStats, ShadeCacheEntry,
    SheetRenderer, SheetRing, SHADE_CACHE_LEN,
};
use footprint::shade::{Sample, OPACITY_TABLE_LEN};
use footprint::source::{render_from, SheetSource};
use footprint::splat::Direct;
use footprint::stencil::{self, Stencils};
use footprint::{composite::RowSpan, GenericTable, ViewTable};
use std::time::Instant;

/// The core's render of `p` with `plan`: premultiplied RGBA (fixed-point output converted
/// exactly to f32), counts, seconds.
pub fn render_core(
    p: &Prepared,
    plan: &Plan,
) -> Result<(Vec<[f32; 4]>, RenderStats, f64), CliError> {
    let f = render_frame(p, plan, &mut FrameCache::default())?;
    Ok((f.image, f.stats, f.seconds))
}

/// Renders one frame of `p` with `plan`, reusing (and filling) `cache`'s visible-voxel lists
/// when the volume is in memory. A streamed volume renders on one thread, straight from its
/// sheets. The subsampling decorator wraps every end point that allows it.
pub fn render_frame(
    p: &Prepared,
    plan: &Plan,
    cache: &mut FrameCache,
) -> Result<CoreFrame, CliError> {
    // Decorator (sub/supersample) off, the end, its resampling: one frame (`stages::decorators`).
    let start = Instant::now();
    let d = decorators::peel(p, plan)?;
    let mut f = end_frame(&d.prepared, &d.plan, cache)?;
    if d.resample == Resample::None {
        return Ok(f);
    }
    let resample = Instant::now();
    f.image = d
        .resample
        .finish(f.image, p.out_size(), plan.threads, d.under.as_deref())?;
    f.phases.resample = resample.elapsed().as_secs_f64();
    f.seconds = start.elapsed().as_secs_f64();
    Ok(f)
}

/// The end `plan` names drawing `p`'s frame as it stands: at its internal size (k× the output
/// size when supersampled), with no resolution decorator; what [`render_frame`] wraps and a
/// brick of a split frame draws (`crate::distributed`).
pub fn end_frame(p: &Prepared, plan: &Plan, cache: &mut FrameCache) -> Result<CoreFrame, CliError> {
    // Only slabs cut kernels: any other end would draw the clipped region whole (a plan a
    // chart derives, say), so it is refused, not drawn wrong.
    if !p.clip.is_empty() && !matches!(plan.end, End::Slabs { .. }) {
        return Err(CliError::input(
            "--clip: only image-aligned slabs (--slicing image) cut kernels; this frame's end \
             composites each kernel whole",
        ));
    }
    // A rectilinear grid's samples each have their own footprint: the refined renderer's
    // sheets draw them (`super::refine::render_rectilinear`), and no other end can.
    if p.volume().is_some_and(|v| v.grid.is_some()) {
        return match plan.end {
            End::Refined { threshold, sheets } => {
                super::refine::render_refined(p, plan, threshold, sheets)
            }
            End::Sheets(PlanPrecision::Float) => super::refine::render_rectilinear(p, plan),
            _ => Err(CliError::input(
                "a rectilinear grid (.vtr) renders float sheets with a footprint per sample; \
                 this frame's end places every kernel on one uniform grid",
            )),
        };
    }
    match plan.end {
        End::Refined { threshold, sheets } => {
            super::refine::render_refined(p, plan, threshold, sheets)
        }
        End::Slabs { thickness } => super::slabs::render_slabs(p, thickness, plan, cache),
        End::Post {
            thickness,
            values,
            blend,
            reconstruction,
        } => super::post::render_post(
            p,
            (thickness, values, blend, reconstruction),
            plan.threads,
            cache,
        ),
        End::Sheets(precision) => render_sheets(p, plan, precision, cache),
        End::Reference => reference_frame(p),
    }
}

/// The f64 sheet reference as an end like the others: its image at the frame's internal size
/// rounded to f32 (premultiplied RGBA), on one thread, with no core counts.
fn reference_frame(p: &Prepared) -> Result<CoreFrame, CliError> {
    let (img, seconds) = render_ref_at_frame(p)?;
    Ok(CoreFrame {
        image: img.iter().map(|c| c.map(|x| x as f32)).collect(),
        stats: Default::default(),
        seconds,
        phases: Phases::default(),
        threads: 1,
        visible: None,
        refine: None,
    })
}

/// The paper's sheets of `p` through `plan`'s tables in `precision`.
fn render_sheets(
    p: &Prepared,
    plan: &Plan,
    precision: PlanPrecision,
    cache: &mut FrameCache,
) -> Result<CoreFrame, CliError> {
    struct Sheets<'a> {
        p: &'a Prepared,
        plan: &'a Plan,
        precision: PlanPrecision,
        cache: &'a mut FrameCache,
    }
    impl TableSize for Sheets<'_> {
        type Output = CoreFrame;
        fn run<const N: usize>(self) -> Result<CoreFrame, CliError> {
            sheets_at::<N>(self.p, self.plan, self.precision, self.cache)
        }
    }
    let work = Sheets {
        p,
        plan,
        precision,
        cache,
    };
    with_size(plan.table.size, work)
}

/// [`render_sheets`] with tables of side `N`.
fn sheets_at<const N: usize>(
    p: &Prepared,
    plan: &Plan,
    precision: PlanPrecision,
    cache: &mut FrameCache,
) -> Result<CoreFrame, CliError> {
    let lookup = plan.table.lookup;
    let bands = Bands::of(plan);
    let direct = plan.table.footprints == Footprints::Direct;
    let start = Instant::now();
    {
        let generic = cache.tables.generic::<N>(&plan.table, &p.kernel)?;
        // Each path gets its own monomorphised sheet loop: no virtual call per pixel.
        let perspective = p.frame.camera().is_some();
        let (image, stats, mut phases, visible) = match precision {
            PlanPrecision::Float if perspective => {
                // Every voxel its own footprint, sampled from the generic table (no view table).
                let per = PerVoxel::new(&p.frame, &p.kernel, p.options, &*generic, lookup)?;
                let path = FloatPath::new(&per).with_absorption(p.absorption);
                let tables = start.elapsed().as_secs_f64();
                let r = run_path(p, path, p.background.as_deref(), cache, bands)?;
                (r.0, r.1, Phases { tables, ..r.2 }, r.3)
            }
            PlanPrecision::Float if direct => {
                let sampler = Direct {
                    footprint: p.frame.footprint,
                    table: &*generic,
                    lookup,
                };
                let tables = start.elapsed().as_secs_f64();
                let r = run_path(
                    p,
                    FloatPath::new(&sampler).with_absorption(p.absorption),
                    p.background.as_deref(),
                    cache,
                    bands,
                )?;
                (r.0, r.1, Phases { tables, ..r.2 }, r.3)
            }
            PlanPrecision::Float => {
                let table = Box::new(ViewTable::<N>::build(
                    &p.frame.footprint,
                    &generic,
                    lookup,
                    lookup,
                ));
                let r = if let Some(len) = stencil_len(p, plan.phases) {
                    // Footprints up to 128 px across: the view table sampled once per phase.
                    let mut buffer = vec![0.0f32; len];
                    let stencils = build_stencils(&*table, plan, &mut buffer)?;
                    let tables = start.elapsed().as_secs_f64();
                    let path = FloatPath::new(&stencils).with_absorption(p.absorption);
                    let r = run_path(p, path, p.background.as_deref(), cache, bands)?;
                    (r.0, r.1, Phases { tables, ..r.2 }, r.3)
                } else {
                    let tables = start.elapsed().as_secs_f64();
                    let r = run_path(
                        p,
                        FloatPath::new(&*table).with_absorption(p.absorption),
                        p.background.as_deref(),
                        cache,
                        bands,
                    )?;
                    (r.0, r.1, Phases { tables, ..r.2 }, r.3)
                };
                r
            }
            PlanPrecision::Fixed => fixed_sheets(p, plan, &generic, cache, start)?,
        };
        phases.tables = phases.tables.max(0.0);
        Ok(CoreFrame {
            image,
            stats,
            seconds: start.elapsed().as_secs_f64(),
            phases,
            threads: if visible.is_some() {
                bands.count(p.frame.size[1])
            } else {
                1
            },
            refine: None,
            visible,
        })
    }
}

/// The fixed-point sheets of `p` through `plan`'s tables built from `generic` (integer table,
/// stencils where they serve), timed from `start`; the image converted exactly to f32.
fn fixed_sheets<const N: usize>(
    p: &Prepared,
    plan: &Plan,
    generic: &GenericTable<N>,
    cache: &mut FrameCache,
    start: Instant,
) -> Result<PathResult<[f32; 4]>, CliError> {
    let lookup = plan.table.lookup;
    let direct = plan.table.footprints == Footprints::Direct;
    let fixed_range =
        |e: fixed::FixedError| CliError::input(format!("{}: --accum fixed: {e}", p.name));
    let mut table = Box::new(FixedTable::<N>::zeroed());
    if direct {
        table.build_direct(&p.frame, generic, lookup)
    } else {
        table.build_view(&p.frame, generic, lookup, lookup)
    }
    .map_err(fixed_range)?;
    // Shaded voxels never exceed opacity 1: stencils may add unsaturated (sums stay in range).
    let path = FixedPath::new(&p.frame, &*table)
        .map_err(fixed_range)?
        .with_value_bound(fixed::ONE);
    // Footprints up to 128 px across: the integer table sampled once per phase (as the float
    // stencils, as many phases; blended to the edge where they are, else edged); wider ones, or
    // --phases 0, walk the table.
    let sp = stencil::plan_for(&p.frame.footprint, plan.phases);
    let blended = sp.is_some_and(|q| !q.edged);
    let phases = match sp {
        Some(q) if blended => q.phases,
        _ => stencil::edged_phases_for(&p.frame.footprint, plan.phases),
    };
    let len = (plan.phases > 0 && !direct)
        .then(|| fixed::stencil::len_for(&table, phases))
        .flatten();
    let mut buffer = vec![0i32; len.unwrap_or(0)];
    let build = if blended {
        FixedStencils::build_blended
    } else {
        FixedStencils::build
    };
    let lookup = plan.phase_lookup.unwrap_or_default();
    let path = match len.map(|_| build(&table, phases, &mut buffer)) {
        Some(Ok(stencils)) => path.with_stencils(stencils.with_phase_lookup(lookup)),
        // --phases 0, the direct method, a footprint past the stencils' limits, or
        // renormalised weights too large for 32 bits: the walk serves this view.
        _ => path,
    };
    let tables = start.elapsed().as_secs_f64();
    let bg: Option<Vec<[u32; 4]>> = p
        .background
        .as_ref()
        .map(|b| b.iter().map(|&c| fixed::quantise(c)).collect());
    // A kept float image (a frame handed back) serves as this one's: every pixel starts afresh.
    let [w, h] = p.frame.size;
    cache.reuse_image_as(w * h, |px: [f32; 4]| px.map(f32::to_bits));
    let (img, stats, phases, visible) = run_path(p, path, bg.as_deref(), cache, Bands::of(plan))?;
    Ok((
        img.into_iter().map(fixed::to_f32).collect(),
        stats,
        Phases { tables, ..phases },
        visible,
    ))
}

/// Stencil floats worth a thread of their own when the stencils are built. Measured on the
/// 16-core device machine (2026-12-04, `footprint bench --frames 8 --orbit 2 --threads 16`,
/// default plan, 512² and 1024², two rounds, the stencils built on T threads): the walnut's
/// tables phase took 1.38-1.71 ms with T = 16, 0.96-1.01 with 2, 0.74-0.96 with 4 and 1.12-1.26
/// with 8; the CT head's was shortest with T = 4-8 (0.95-1.34 ms against 1.67-1.85 with 16).
const STENCIL_FLOATS: usize = 32 << 10;

/// The float path's phase stencils of `sampler` for `plan` in `buffer` (at most `plan.phases`
/// per pixel, read by its phase lookup), sampled on `plan.threads` threads, whole stencils each:
/// the same bits for any number.
pub fn build_stencils<'a, S: footprint::Sampler + Sync + ?Sized>(
    sampler: &'a S,
    plan: &Plan,
    buffer: &'a mut [f32],
) -> Result<Stencils<'a, S>, footprint::splat::BufferError> {
    let threads = plan.threads;
    let stencils = Stencils::build_split(sampler, plan.phases, buffer, |weights, fill| {
        let cells = fill.cells();
        let count = weights.len() / cells.max(1);
        // A thread per STENCIL_FLOATS at most: more start up slower than they sample.
        let threads = threads.min(weights.len() / STENCIL_FLOATS).max(1);
        let per = count.div_ceil(threads.clamp(1, count.max(1))).max(1);
        std::thread::scope(|scope| {
            for (t, chunk) in weights.chunks_mut(per * cells).enumerate() {
                crate::threads::spawn(scope, move || {
                    for (i, stencil) in chunk.chunks_exact_mut(cells).enumerate() {
                        fill.fill(t * per + i, stencil);
                    }
                });
            }
        });
    })?;
    Ok(stencils.with_phase_lookup(plan.phase_lookup.unwrap_or_default()))
}

/// The buffer length of the float path's phase stencils for `p`'s footprint with `phases`
/// (`None`: `--phases 0`, or a footprint too large for them; the view table serves).
pub fn stencil_len(p: &Prepared, phases: usize) -> Option<usize> {
    (phases > 0)
        .then(|| stencil::len_for(&p.frame.footprint, phases))
        .flatten()
}

type PathResult<X> = (Vec<X>, RenderStats, Phases, Option<usize>);

/// Runs one precision path: in memory, through the visible lists on `threads` bands; streamed,
/// through a sheet ring on one thread.
fn run_path<P>(
    p: &Prepared,
    path: P,
    background: Option<&[P::Pixel]>,
    cache: &mut FrameCache,
    bands: Bands,
) -> Result<PathResult<P::Pixel>, CliError>
where
    P: Precision + Copy + Send + Sync,
    P::Pixel: Send + Sync + 'static,
    P::Acc: Send + PartialEq + 'static,
{
    match &p.voxels {
        Voxels::Memory(volume) => {
            let t0 = Instant::now();
            let (visible, fresh, spares) = cache.visible_and_spares(p, volume, bands.threads)?;
            let classify = if fresh {
                t0.elapsed().as_secs_f64()
            } else {
                0.0
            };
            let (image, stats, phases) = run_bands(p, path, background, visible, spares, bands)?;
            let count = stats.voxels as usize;
            Ok((image, stats, Phases { classify, ..phases }, Some(count)))
        }
        _ => {
            let t0 = Instant::now();
            let (image, stats) = run_sheets(p, path, background, bands.cull)?;
            let phases = Phases {
                splat: t0.elapsed().as_secs_f64(),
                ..Phases::default()
            };
            Ok((image, stats, phases, None))
        }
    }
}

/// Drives the core renderer through a [`SheetRing`], as a streaming source would.
fn run_sheets<P: Precision>(
    p: &Prepared,
    path: P,
    background: Option<&[P::Pixel]>,
    cull: Option<f32>,
) -> Result<(Vec<P::Pixel>, RenderStats), CliError> {
    let f = &p.frame;
    // A pipe's first z-slice arrives before any buffer is allocated: a short stream costs only
    // what it delivered.
    let mut pipe = match &p.voxels {
        Voxels::Stdin {
            dims,
            ty,
            big_endian,
            pipe,
            values,
            ..
        } => {
            let (reader, name): (Box<dyn std::io::Read>, _) = match pipe {
                Some(pipe) => (
                    pipe.take().ok_or_else(|| {
                        CliError::input("the stream was read already: a stream renders once")
                    })? as Box<dyn std::io::Read>,
                    "the stream",
                ),
                None => (Box::new(std::io::stdin().lock()), "standard input"),
            };
            let mut src = PipeSource::new(
                std::io::BufReader::with_capacity(1 << 20, reader),
                *dims,
                *ty,
                *big_endian,
                name,
            )
            .with_values(*values);
            src.prime()?;
            Some(src)
        }
        _ => None,
    };
    let n = f.image_len();
    let (mut accum, mut image, mut rows) = (
        try_filled(n, P::ACC_ZERO, "the sheet accumulator")?,
        try_filled(n, P::CLEAR, "the image")?,
        vec![RowSpan::EMPTY; f.size[1]],
    );
    let buffers = RenderBuffers {
        accumulator: &mut accum,
        image: &mut image,
        rows: &mut rows,
    };
    let mut opacity = vec![0.0f32; OPACITY_TABLE_LEN];
    let mut shades = vec![ShadeCacheEntry::default(); SHADE_CACHE_LEN];
    let mut occluded = vec![0u8; occlusion_len(f.size[0], f.size[1])];
    let mut renderer = SheetRenderer::with_path(f, path, p.shader(), p.order, buffers, background)?
        .with_opacity_table(&mut opacity)?
        .with_shade_cache(&mut shades);
    if let Some(eps) = cull {
        renderer = renderer.with_occlusion(&mut occluded, eps)?;
    }
    let mut show = Progress {
        inner: sheets("render"),
        count: f.sheet_count(),
        done: 0,
    };
    // A streamed volume is coarsened to the frame's level as it streams (a volume in memory
    // already was, when prepared).
    let (axis, fine, level) = (f.sheet_axis, p.fine_dims, p.level);
    let averaging =
        crate::pipeline::stages::lod::averaging_for(&p.shading, p.shader().tf, p.absorption);
    let (r, s) = (&mut renderer, &mut show);
    match &p.voxels {
        Voxels::Memory(v) if v.is_coloured() => stream(r, s, &mut ColouredMemorySource(v))?,
        Voxels::Memory(v) => stream(r, s, &mut MemorySource(v))?,
        streamed => {
            let (mut file, mut piped, mut cut);
            let src: &mut DynSource<'_> = match streamed {
                Voxels::File(layout) => {
                    file = FileSource::open(layout.clone())?;
                    &mut file
                }
                Voxels::Stdin {
                    crop: Some(crop),
                    dims,
                    ..
                } => {
                    piped = pipe.take().expect("made above for standard input");
                    cut = footprint::source::Cropped {
                        source: &mut piped as &mut DynSource<'_>,
                        crop: *crop,
                        dims: *dims,
                    };
                    &mut cut
                }
                _ => {
                    piped = pipe.take().expect("made above for standard input");
                    &mut piped
                }
            };
            if level == 0 {
                stream(r, s, src)?
            } else {
                with_level(src, fine, level, axis, &*averaging, &mut |c| {
                    stream(r, s, c)
                })?
            }
        }
    }
    let stats = renderer.finish();
    Ok((image, stats))
}

/// Renders every sheet `source` delivers through a ring of three sheets of its samples.
fn stream<P: Precision, T: Sample + Default>(
    renderer: &mut SheetRenderer<'_, P>,
    show: &mut Progress<impl FnMut(usize, usize)>,
    source: &mut (impl SheetSource<Sample = T, Error = CliError> + ?Sized),
) -> Result<(), CliError> {
    let f = renderer.frame();
    let mut storage = try_filled(
        3usize.saturating_mul(f.sheet_shape().0),
        T::default(),
        "three sheets of the volume",
    )?;
    let mut ring = SheetRing::new(&mut storage, f, renderer.order())?;
    render_from(renderer, &mut ring, &mut show.wrap(source))
}

/// Shows progress as a source delivers sheets.
struct Progress<F> {
    inner: F,
    count: usize,
    done: usize,
}

/// A source that reports each sheet read.
struct Reporting<'p, S, F> {
    source: S,
    progress: &'p mut Progress<F>,
}

impl<F: FnMut(usize, usize)> Progress<F> {
    fn wrap<S>(&mut self, source: S) -> Reporting<'_, S, F> {
        Reporting {
            source,
            progress: self,
        }
    }
}

impl<S: SheetSource<Error = CliError>, F: FnMut(usize, usize)> SheetSource for Reporting<'_, S, F> {
    type Sample = S::Sample;
    type Error = CliError;
    fn read_sheet(
        &mut self,
        axis: usize,
        index: usize,
        out: &mut [S::Sample],
    ) -> Result<(), CliError> {
        crate::cancel::check()?;
        self.source.read_sheet(axis, index, out)?;
        let p = &mut *self.progress;
        p.done += 1;
        (p.inner)(p.done, p.count);
        Ok(())
    }
    fn sequential_axis(&self) -> Option<usize> {
        self.source.sequential_axis()
    }
}

/// The f64 reference render of `p` and its seconds (the volume must be in memory), at the
/// output size: a supersampled frame's k×k blocks averaged in f64.
pub fn render_ref(p: &Prepared) -> Result<(Vec<[f64; 4]>, f64), CliError> {
    let (img, seconds) = render_ref_at_frame(p)?;
    let img = match p.supersample {
        1 => img,
        k => downsample(&img, p.out_size(), k, |v| v),
    };
    Ok((img, seconds))
}

/// [`render_ref`] at the frame's internal size (k× the output size when supersampled).
fn render_ref_at_frame(p: &Prepared) -> Result<(Vec<[f64; 4]>, f64), CliError> {
    let volume = p.volume().ok_or_else(|| {
        CliError::input("the f64 reference needs the volume in memory: drop --stream")
    })?;
    let start = Instant::now();
    let scene = ReferenceScene {
        frame: &p.frame,
        kernel: &p.kernel,
        min_radius_px: p.options.min_radius_px,
        shader: p.shader(),
        order: p.order,
        background: p.background.as_deref(),
        absorption: p.absorption,
    };
    let axis = p.frame.sheet_axis;
    let img = render_reference(
        &scene,
        |s, out| volume.coloured_sheet_into(axis, s, out),
        sheets("reference"),
    )?;
    Ok((img, start.elapsed().as_secs_f64()))
}
