//! Scale-out, sort-last: a volume split into bricks ([`layout`]), each brick rendered on its own
//! into a premultiplied RGBA image of the whole frame, the images composited front to back in
//! the bricks' visibility order. Under MPI (cargo feature `mpi`, `mpi` module) each
//! rank reads and renders one brick and the images are composited by binary swap onto rank 0;
//! without it, `render --bricks X,Y,Z` renders the bricks one after another in one process and
//! composites them the same way (what the tests measure the border error with).
//!
//! **How a brick renders.** A rank holds its brick's voxels and one ghost layer around them
//! (the core's gradients read a voxel's six neighbours: [`crate::io::brick::GHOST`]) as a
//! [`Volume`](crate::io::volume::Volume) whose `brick` says where they sit; the frame is the whole volume's (same view,
//! same slabs, same table), and only the brick's own voxels are classified and splatted
//! (`pipeline::stages::visible::keep_owned`). So every voxel is splatted exactly as in one
//! process, with the same colour, gradient and footprint.
//!
//! **What differs across brick borders.** One process adds every voxel of a sheet (or slab)
//! into one accumulator and composites the sheets in order; here each brick composites its own
//! sheets and the bricks are composited in order. Where a cut lies between two sheets (the
//! default split cuts across the sheet axis: [`BrickLayout::balanced`]) the two are the same
//! sums in another association, equal to rounding. Elsewhere pixels whose ray passes within a
//! kernel radius of a cut see the two bricks' overlapping footprints composited one over the
//! other instead of added in one sheet. `docs/scale-out.md` bounds and measures that.

pub mod job;
pub mod layout;
#[cfg(feature = "mpi")]
pub mod mpi;

pub use crate::pipeline::stages::decorators::Resample;
pub use job::{BrickFrame, Header, Job, Source, WindowPart};
pub use layout::BrickLayout;

use crate::plan::Plan;
use crate::scene::Scene;
use crate::CliError;
use std::time::Instant;

/// `front` over `back`, in place in `front` (premultiplied: c = f + (1 − α_f)·b).
pub fn over(front: &mut [[f32; 4]], back: &[[f32; 4]]) {
    for (f, b) in front.iter_mut().zip(back) {
        *f = footprint::composite::over(*f, *b);
    }
}

/// Every brick of `layout` rendered in turn in this process and composited front to back (what
/// `render --bricks` does without MPI): the image at the output size with the background
/// under it, each brick's frame summary, and the bytes each read.
pub fn render_in_turn(job: &Job, layout: &BrickLayout) -> Result<Composited, CliError> {
    // One brick held at a time: a pass for the window's parts, then the bricks front to back,
    // each composited under what is in front of it as it comes (one image kept, not one each).
    // Wide samples: one map for every brick, from the whole volume's range (a pass of its own).
    let values = if job.is_wide() {
        let mut range = (f64::INFINITY, f64::NEG_INFINITY);
        for b in &layout.boxes {
            let (lo, hi) = job.brick(*b)?.0.sample_range();
            range = (range.0.min(lo), range.1.max(hi));
        }
        job.agreed_values(range.0, range.1)
    } else {
        crate::io::volume::ValueMap::IDENTITY
    };
    let mut parts = Vec::with_capacity(layout.len());
    for b in &layout.boxes {
        let (mut v, _) = job.brick(*b)?;
        v.values = values;
        parts.extend(job.window_part(&v));
    }
    let window = job.window(parts, values)?;
    let order = layout.front_to_back(job.ray()?);
    let mut ranks = vec![RankStats::default(); layout.len()];
    let (mut acc, mut last) = (None::<Vec<[f32; 4]>>, None::<BrickFrame>);
    let mut composite = 0.0;
    for &n in &order {
        let (mut v, bytes) = job.brick(layout.boxes[n])?;
        v.values = values;
        let mut f = job.render(v, window)?;
        ranks[n] = RankStats {
            bytes_read: bytes,
            render_seconds: f.seconds,
            voxels: f.voxels,
            ..RankStats::default()
        };
        let start = Instant::now();
        match &mut acc {
            None => acc = Some(std::mem::take(&mut f.image)),
            Some(a) => over(a, &f.image),
        }
        composite += start.elapsed().as_secs_f64();
        f.image = Vec::new();
        last = Some(f);
    }
    let (Some(acc), Some(last)) = (acc, last) else {
        return Err(CliError::input("a split into no bricks renders nothing"));
    };
    let start = Instant::now();
    let image = last.finish(acc)?;
    composite += start.elapsed().as_secs_f64();
    for r in &mut ranks {
        r.composite_seconds = composite / layout.len() as f64;
    }
    Ok(Composited {
        image,
        window: values.window_to_data(window),
        order,
        ranks,
    })
}

/// Most bricks `--bricks` renders in turn in one process: each is a whole frame rendered and
/// composited (one voxel a brick took about 27 minutes in the third hostile campaign).
pub const MAX_BRICKS_IN_TURN: usize = 512;

/// A composited frame and what each brick cost.
pub struct Composited {
    /// Premultiplied RGBA at the output size, with the background under it.
    pub image: Vec<[f32; 4]>,
    /// The window, in the data's units.
    pub window: [f64; 2],
    /// The bricks front to back.
    pub order: Vec<usize>,
    /// Per brick (rank).
    pub ranks: Vec<RankStats>,
}

/// What one rank (brick) cost.
#[derive(Clone, Copy, Debug, Default)]
pub struct RankStats {
    pub bytes_read: u64,
    pub render_seconds: f64,
    pub composite_seconds: f64,
    pub voxels: u64,
    /// The process's peak resident memory (Linux `VmHWM`), where it can be read; `None` for
    /// bricks rendered in turn in one process.
    pub peak_memory_bytes: Option<u64>,
}

/// This process's peak resident set, bytes (Linux: `VmHWM` of /proc/self/status).
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// `base` with the fields a split render adds: `ranks`, `bricks` (each brick's owned box,
/// `lo` and `hi`, brick n rendered by rank n), `order` (front to back) and `per_rank` (bytes
/// read, render and composite seconds, voxels splatted, peak resident memory).
pub fn json(
    base: crate::io::json::Json,
    layout: &BrickLayout,
    c: &Composited,
) -> crate::io::json::Json {
    use crate::io::json::Json;
    let bricks: Vec<Json> = layout
        .boxes
        .iter()
        .map(|b| Json::object().arr_usize("lo", &b.lo).arr_usize("hi", &b.hi))
        .collect();
    let per_rank: Vec<Json> = c
        .ranks
        .iter()
        .enumerate()
        .map(|(r, s)| {
            let j = Json::object()
                .num("rank", r as f64)
                .num("bytes_read", s.bytes_read as f64)
                .num("render_seconds", s.render_seconds)
                .num("composite_seconds", s.composite_seconds)
                .num("voxels", s.voxels as f64);
            match s.peak_memory_bytes {
                Some(m) => j.num("peak_memory_bytes", m as f64),
                None => j,
            }
        })
        .collect();
    base.num("ranks", layout.len() as f64)
        .arr_obj("bricks", bricks)
        .arr_usize("order", &c.order)
        .arr_obj("per_rank", per_rank)
}

/// A render split into bricks, as `render` runs it: under MPI with more than one rank, one brick
/// per rank (`mpi` module); otherwise, with `--bricks`, every brick in turn in this
/// process ([`render_in_turn`]). `Ok(None)`: the render is not split (one process, no
/// `--bricks`: the ordinary path, byte for byte). `Ok(Some(None))`: a rank other than 0, which
/// writes nothing. `Ok(Some(Some((image, summary))))`: the composited image (premultiplied,
/// background under it) and the JSON summary.
#[allow(clippy::type_complexity)]
pub fn render_split(
    inputs: &Scene,
    plan: &Plan,
) -> Result<Option<Option<(Vec<[f32; 4]>, crate::io::json::Json)>>, CliError> {
    let start = Instant::now();
    #[cfg(feature = "mpi")]
    {
        use ::mpi::traits::Communicator;
        if let Some(universe) = self::mpi::init() {
            let world = universe.world();
            if world.size() > 1 {
                // Every step that can fail on one rank (its flags, its read, its render) is
                // agreed by all before the next exchange (`mpi::agree`): a failure anywhere ends
                // every rank with exit 2, each saying why, and none waits for one that has gone.
                // The ranks must also agree on the frame before a byte is exchanged.
                let job = self::mpi::job(&world, inputs, plan)?;
                let layout = self::mpi::agree(
                    &world,
                    "splitting the volume",
                    job.layout(world.size() as usize, plan.bricks),
                )?;
                self::mpi::agree_frame(&world, &job, &layout)?;
                return Ok(match self::mpi::render(&world, &job, &layout)? {
                    Some(c) => Some(Some(summary(&job, &layout, c, start, "mpi"))),
                    None => Some(None),
                });
            }
        }
    }
    let Some(counts) = plan.bricks else {
        return Ok(None);
    };
    let n = counts.iter().fold(1usize, |a, &c| a.saturating_mul(c));
    if n > MAX_BRICKS_IN_TURN {
        return Err(CliError::input(format!(
            "--bricks {},{},{} makes {n} bricks, each a whole frame rendered and composited in \
             turn in this process: at most {MAX_BRICKS_IN_TURN} (under mpirun, one per rank)",
            counts[0], counts[1], counts[2]
        )));
    }
    let job = Job::new(inputs, plan)?;
    let layout = job.layout(counts.iter().product(), Some(counts))?;
    let c = render_in_turn(&job, &layout)?;
    Ok(Some(Some(summary(&job, &layout, c, start, "in turn"))))
}

fn summary(
    job: &Job,
    layout: &BrickLayout,
    c: Composited,
    start: Instant,
    how: &str,
) -> (Vec<[f32; 4]>, crate::io::json::Json) {
    let secs = start.elapsed().as_secs_f64();
    let slowest = c.ranks.iter().map(|r| r.render_seconds).fold(0.0, f64::max);
    crate::say!(
        "{}: {}x{} in {:.3} s from {} bricks ({how}; slowest brick {:.3} s), composited front to back",
        job.name,
        job.inputs.size.0,
        job.inputs.size.1,
        secs,
        layout.len(),
        slowest
    );
    let base = crate::io::json::Json::object()
        .str("volume", &job.name)
        .arr_usize("size", &[job.inputs.size.0, job.inputs.size.1])
        .arr_usize("dims", &job.dims)
        .str("bricks_rendered", how)
        .arr_f64("window", &c.window)
        .num("seconds", secs);
    let j = json(base, layout, &c);
    (c.image, j)
}
