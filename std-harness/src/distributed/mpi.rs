//! The bricks on MPI (cargo feature `mpi`: the `mpi` crate over the system's MPI, Open MPI in CI).
//! MPI carries every byte: the window's parts (all-reduce and all-gather), the images (binary
//! swap over `MPI_Sendrecv`, then `MPI_Gatherv` onto rank 0) and the per-rank costs (gather).
//!
//! **Why binary swap, not IceT.** Debian ships IceT only inside ParaView's build (the `paraview`
//! packages, as VTK's namespaced `vtkicet`), without a standalone library or headers to bind, so
//! CI would install ParaView for one compositor. Binary swap (Ma et al. 1994) is what IceT runs for
//! power-of-two groups; each of log₂P rounds exchanges half of a rank's current region with a
//! partner, so a rank sends (1 − 1/P) of an image in all, and the last step gathers 1/P from each.
//! A count that is not a power of two first folds: the first 2E ranks in visibility order (E = N −
//! P) pair up and one of each pair sends its whole image to the other.
//!
//! **Order.** Binary swap composites correctly for any order in which the participants are
//! numbered front to back: after round s, participant v holds, over its region, the composite of
//! the 2^(s+1) participants that share v's bits above s, a contiguous run of the order; its
//! partner's run lies wholly in front of it when v's bit s is 1.

use super::{over, BrickLayout, Composited, Header, Job, RankStats, Source as From};
use crate::io::brick::{BrickPlace, IndexBox};
use crate::io::volume::Volume;
use crate::CliError;
use mpi::collective::SystemOperation;
use mpi::datatype::PartitionMut;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use std::time::Instant;

/// MPI, started once per process (`None` where it is already started). Dropping it finalises MPI.
pub fn init() -> Option<mpi::environment::Universe> {
    mpi::initialize()
}

/// `result` as every rank agrees on it: `Ok` on every rank only where it is `Ok` on every rank.
/// Otherwise each rank that failed keeps its own error and every other rank gets one naming the
/// first rank that failed, so all of them leave the job together (none is left waiting in a
/// collective for one that has gone: the third campaign's hang). `what` names the phase.
/// A collective itself: every rank of `comm` must call it at the same point.
pub fn agree<T>(
    comm: &SimpleCommunicator,
    what: &str,
    result: Result<T, CliError>,
) -> Result<T, CliError> {
    // A rank that failed says why before the others can leave: once they do, mpirun ends the
    // job, and a message still to be printed at exit would be lost.
    let result = result.map_err(|e| {
        use std::io::Write as _;
        let mut err = std::io::stderr().lock();
        let _ = writeln!(err, "footprint: {e}");
        let _ = err.flush();
        CliError { said: true, ..e }
    });
    let mine = if result.is_ok() {
        i32::MAX
    } else {
        comm.rank()
    };
    let mut first = i32::MAX;
    comm.all_reduce_into(&mine, &mut first, SystemOperation::min());
    match result {
        Ok(_) if first != i32::MAX => Err(CliError::input(format!(
            "rank {first} of {} failed ({what}; its own message says why): every rank stops",
            comm.size()
        ))),
        r => r,
    }
}

/// Checks that every rank renders the same frame before a byte of volume or image is exchanged:
/// the output size, the camera, the classification, the plan, the grid and sample type, and the
/// bricks (a rank given other flags would otherwise send or expect buffers of another size).
/// The description of each is hashed (FNV-1a, 64 bits) and the hashes all-gathered; a rank
/// that differs is named on every rank. What only names the source (its path) may differ: ranks
/// may read their own copies of one volume.
pub fn agree_frame(
    comm: &SimpleCommunicator,
    job: &Job,
    layout: &BrickLayout,
) -> Result<(), CliError> {
    let i = &job.inputs;
    let description = format!(
        "size {:?} view {:?} zoom {:?} matrix {:?} perspective {:?} eye {:?} tf {:?} labels {:?} \
         window {:?} shading {:?} background {:?} gamma {:?} depth {} kernel {:?} absorption {:?} \
         plan {:?} grid {} bricks {:?}",
        i.size,
        i.view,
        i.zoom,
        i.view_matrix,
        i.perspective,
        i.eye_distance,
        i.tfs,
        i.labels,
        i.window,
        i.shading,
        i.background,
        i.gamma,
        i.depth,
        i.kernel,
        i.absorption,
        job.plan,
        job.grid_description(),
        layout.boxes,
    );
    let hash = description.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    let mut all = vec![0u64; comm.size() as usize];
    comm.all_gather_into(&hash, &mut all[..]);
    match all.iter().position(|&h| h != all[0]) {
        None => Ok(()),
        Some(r) => Err(CliError::input(format!(
            "the ranks were given different renders (rank {r} of {} differs from rank 0 in its \
             size, view, classification, plan, grid or bricks): give every rank the same flags",
            comm.size()
        ))),
    }
}

/// The job for `inputs` on this rank. A file read in part (raw samples at a known place) is
/// opened by every rank; a volume that must be loaded whole (compressed, VTK, VTI, NIfTI, the
/// built-in scene) is loaded by rank 0 alone, which broadcasts its grid ([`Header`]) and later
/// sends each rank its brick ([`render`]). Every step that can fail is agreed ([`agree`]) before
/// the next collective, so a rank that cannot read its volume ends every rank's job with exit 2.
pub fn job(
    comm: &SimpleCommunicator,
    inputs: &crate::scene::Scene,
    plan: &crate::plan::Plan,
) -> Result<Job, CliError> {
    let whole = agree(comm, "opening the volume", Job::loads_whole(inputs))?;
    // Every rank must take the same path below: a volume one rank loads whole and another
    // reads in part would leave them in different collectives.
    let mut wholes = [0i32; 2];
    comm.all_reduce_into(&i32::from(whole), &mut wholes[0], SystemOperation::min());
    comm.all_reduce_into(&i32::from(whole), &mut wholes[1], SystemOperation::max());
    if wholes[0] != wholes[1] {
        // A rank that would load the volume whole may be one that cannot read it as the others
        // do (an NRRD whose data file is missing): its own reason says more than the mismatch.
        let mismatch = CliError::input(
            "the ranks were given volumes of different kinds (a raw file one reads in part, \
             another loads whole): give every rank the same volume",
        );
        // Agreed, so that the failing rank has printed its reason before any rank leaves (else
        // mpirun's teardown could end it first: CI saw only the mismatch once).
        let mine = match whole.then(|| Job::new(inputs, plan)) {
            Some(Err(e)) => Err(e),
            _ => Ok(()),
        };
        agree(comm, "opening the volume", mine)?;
        return Err(mismatch);
    }
    if !whole {
        return agree(comm, "opening the volume", Job::new(inputs, plan));
    }
    agree(comm, "checking the flags", super::job::check(inputs, plan))?;
    let root = comm.process_at_rank(0);
    let mut header = [0.0f64; 16];
    let loaded = if comm.rank() == 0 {
        Job::new(inputs, plan).map(Some)
    } else {
        Ok(None)
    };
    let loaded = agree(comm, "loading the volume on rank 0", loaded)?;
    if let Some(job) = &loaded {
        let From::Whole { volume, .. } = &job.source else {
            unreachable!("loads_whole said whole")
        };
        header = Header::of(volume).to_f64s();
    }
    root.broadcast_into(&mut header[..]);
    let job = match loaded {
        Some(job) => Ok(job),
        None => Job::remote(inputs, plan, Header::from_f64s(&header)),
    };
    agree(comm, "opening the volume", job)
}

/// This rank's share of `job` split by `layout` (one brick per rank): reads its brick (or gets
/// it from rank 0, [`job`]), agrees the window with the others, renders, and composites onto
/// rank 0, which gets `Some`.
pub fn render(
    comm: &SimpleCommunicator,
    job: &Job,
    layout: &BrickLayout,
) -> Result<Option<Composited>, CliError> {
    let rank = comm.rank() as usize;
    let (brick, bytes) = match &job.source {
        From::Seekable { .. } => agree(comm, "reading a brick", job.brick(layout.boxes[rank]))?,
        From::Whole { .. } if comm.size() > 1 && rank == 0 => {
            // Rank 0 holds the volume: each other rank's brick is cut and sent in turn. A cut
            // that fails (memory) while the others wait to receive ends the job (MPI_Abort).
            for (r, b) in layout.boxes.iter().enumerate().skip(1) {
                let (v, _) = job.brick(*b).unwrap_or_else(|e| {
                    crate::warn!("rank 0 of {}: {e}", comm.size());
                    comm.abort(2)
                });
                send_samples(&comm.process_at_rank(r as i32), &v.samples);
            }
            agree(comm, "cutting the bricks", job.brick(layout.boxes[0]))?
        }
        From::Whole { .. } => agree(comm, "reading a brick", job.brick(layout.boxes[rank]))?,
        From::Elsewhere(h) => {
            // As many samples of the agreed type as the agreed brick holds: what rank 0 sends.
            let place = BrickPlace::around(layout.boxes[rank], job.dims);
            let samples = receive_samples(&comm.process_at_rank(0), h.ty, place.stored.count());
            let volume = Volume {
                dims: h.dims,
                spacing: h.spacing,
                directions: h.directions,
                samples,
                brick: Some(place),
                grid: None,
                // Set from the whole volume's range with the others' (`render_brick`).
                values: crate::io::volume::ValueMap::IDENTITY,
            };
            agree(comm, "cutting the bricks", Ok((volume, 0)))?
        }
    };
    render_brick(comm, job, layout, brick, bytes)
}

/// Sends a brick's samples, in their own type.
fn send_samples(to: &mpi::topology::Process<'_>, s: &crate::io::volume::Samples) {
    use crate::io::volume::Samples;
    match s {
        Samples::U8(v) => to.send(&v[..]),
        Samples::I8(v) => to.send(&v[..]),
        Samples::U16(v) => to.send(&v[..]),
        Samples::I16(v) => to.send(&v[..]),
        Samples::U32(v) => to.send(&v[..]),
        Samples::I32(v) => to.send(&v[..]),
        Samples::F32(v) => to.send(&v[..]),
        Samples::F64(v) => to.send(&v[..]),
        // Colours come only from levels of detail, which bricks refuse.
        Samples::Coloured(v) => to.send(&v.iter().map(|c| c.value).collect::<Vec<f32>>()[..]),
    }
}

/// Receives `n` samples of type `ty` ([`Header::ty`]).
fn receive_samples(
    from: &mpi::topology::Process<'_>,
    ty: usize,
    n: usize,
) -> crate::io::volume::Samples {
    use crate::io::volume::Samples;
    fn get<T: Equivalence + Default + Clone>(
        from: &mpi::topology::Process<'_>,
        n: usize,
    ) -> crate::io::volume::Data<T> {
        let mut v = vec![T::default(); n];
        from.receive_into(&mut v[..]);
        v.into()
    }
    match ty {
        0 => Samples::U8(get(from, n)),
        1 => Samples::I8(get(from, n)),
        2 => Samples::U16(get(from, n)),
        3 => Samples::I16(get(from, n)),
        4 => Samples::U32(get(from, n)),
        5 => Samples::I32(get(from, n)),
        7 => Samples::F64(get(from, n)),
        _ => Samples::F32(get(from, n)),
    }
}

/// The in-situ entry point: a program whose ranks each hold one brick of a volume in memory (a
/// simulation) renders the whole volume without files. `samples` hold the `stored` box of the
/// grid (x fastest), which must contain `owned` grown by [`crate::io::brick::GHOST`] voxels
/// (clipped to the grid) where the shading needs gradients; `owned` boxes must tile the grid
/// of `dims` across the ranks of `comm`, and be separable by planes (any regular
/// decomposition is). `args` are the render flags (view, size, transfer function, …; its
/// volume is ignored). Rank 0 gets the composited image (premultiplied linear RGBA over the
/// background); the others `None`.
#[allow(clippy::too_many_arguments)]
pub fn render_in_situ(
    comm: &SimpleCommunicator,
    args: &crate::args::RenderArgs,
    dims: [usize; 3],
    spacing: [f32; 3],
    samples: crate::io::volume::Samples,
    stored: IndexBox,
    owned: IndexBox,
) -> Result<Option<Composited>, CliError> {
    let mut inputs = crate::args::scene(args)?;
    let plan = crate::args::plan(args)?;
    let held = [0, 1, 2].map(|c| stored.hi[c].saturating_sub(stored.lo[c]));
    if held.iter().product::<usize>() != samples_len(&samples)
        || !(0..3).all(|c| stored.lo[c] <= owned.lo[c] && owned.hi[c] <= stored.hi[c])
        || !(0..3).all(|c| stored.hi[c] <= dims[c] && owned.lo[c] < owned.hi[c])
    {
        return Err(CliError::input(format!(
            "in situ: the brick's samples ({}) must fill its stored box {stored:?} inside the \
             grid {dims:?}, and its owned box {owned:?} lie inside that",
            samples_len(&samples)
        )));
    }
    let volume = Volume {
        dims,
        spacing,
        directions: crate::io::volume::AXIS_ALIGNED,
        samples,
        brick: Some(BrickPlace { stored, owned }),
        grid: None,
        values: crate::io::volume::ValueMap::IDENTITY,
    };
    inputs.memory = Some(crate::io::stream::InMemory {
        volume: std::sync::Arc::new(volume.clone()),
        name: "in situ".into(),
    });
    inputs.volume = None;
    let job = Job::new(&inputs, &plan)?;
    let mine = [owned.lo, owned.hi].concat();
    let mut all = vec![0usize; 6 * comm.size() as usize];
    comm.all_gather_into(&mine[..], &mut all[..]);
    let boxes: Vec<IndexBox> = all
        .chunks_exact(6)
        .map(|c| IndexBox {
            lo: [c[0], c[1], c[2]],
            hi: [c[3], c[4], c[5]],
        })
        .collect();
    let layout = BrickLayout::from_boxes(dims, boxes)?;
    render_brick(comm, &job, &layout, volume, 0)
}

fn samples_len(s: &crate::io::volume::Samples) -> usize {
    use crate::io::volume::Samples;
    match s {
        Samples::U8(v) => v.len(),
        Samples::I8(v) => v.len(),
        Samples::U16(v) => v.len(),
        Samples::I16(v) => v.len(),
        Samples::U32(v) => v.len(),
        Samples::I32(v) => v.len(),
        Samples::F32(v) => v.len(),
        Samples::F64(v) => v.len(),
        Samples::Coloured(v) => v.len(),
    }
}

fn render_brick(
    comm: &SimpleCommunicator,
    job: &Job,
    layout: &BrickLayout,
    mut brick: Volume,
    bytes: u64,
) -> Result<Option<Composited>, CliError> {
    // Wide samples: every rank maps its brick as the volume loaded whole would be mapped, from
    // the whole volume's range (all-reduced in f64).
    brick.values = if job.is_wide() {
        let (lo, hi) = brick.sample_range();
        let (mut all_lo, mut all_hi) = (0.0f64, 0.0f64);
        comm.all_reduce_into(&lo, &mut all_lo, SystemOperation::min());
        comm.all_reduce_into(&hi, &mut all_hi, SystemOperation::max());
        job.agreed_values(all_lo, all_hi)
    } else {
        crate::io::volume::ValueMap::IDENTITY
    };
    let values = brick.values;
    let window = agree(comm, "the window", agree_window(comm, job, &brick))?;
    let rendered = job
        .render(brick, window)
        .and_then(|frame| Ok((frame, layout.front_to_back(job.ray()?))));
    let (mut frame, order) = agree(comm, "rendering a brick", rendered)?;
    // Every rank's render done: the composite time that follows is compositing, not waiting.
    comm.barrier();
    let start = Instant::now();
    let image = binary_swap(comm, &order, std::mem::take(&mut frame.image));
    let composite = start.elapsed().as_secs_f64();
    let mine = [
        bytes as f64,
        frame.seconds,
        composite,
        frame.voxels as f64,
        super::peak_memory_bytes().map_or(-1.0, |m| m as f64),
    ];
    let root = comm.process_at_rank(0);
    let Some(image) = image else {
        root.gather_into(&mine[..]);
        return Ok(None);
    };
    let mut all = vec![0.0f64; 5 * comm.size() as usize];
    root.gather_into_root(&mine[..], &mut all[..]);
    let image = frame.finish(image)?;
    let ranks = all
        .chunks_exact(5)
        .map(|c| RankStats {
            bytes_read: c[0] as u64,
            render_seconds: c[1],
            composite_seconds: c[2],
            voxels: c[3] as u64,
            peak_memory_bytes: (c[4] >= 0.0).then_some(c[4] as u64),
        })
        .collect();
    Ok(Some(Composited {
        image,
        window: values.window_to_data(window),
        order,
        ranks,
    }))
}

/// The window every rank renders with: `--window`, or the default window of the whole volume
/// from every rank's range (all-reduced) and strided sample (all-gathered).
fn agree_window(
    comm: &SimpleCommunicator,
    job: &Job,
    brick: &Volume,
) -> Result<[f32; 2], CliError> {
    let Some(part) = job.window_part(brick) else {
        return job.window(Vec::new(), brick.values);
    };
    let (mut lo, mut hi) = (0.0f32, 0.0f32);
    comm.all_reduce_into(&part.range.0, &mut lo, SystemOperation::min());
    comm.all_reduce_into(&part.range.1, &mut hi, SystemOperation::max());
    let n = comm.size() as usize;
    let mut counts = vec![0i32; n];
    comm.all_gather_into(&(part.sample.len() as i32), &mut counts[..]);
    let displs: Vec<i32> = counts
        .iter()
        .scan(0, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect();
    let total = counts.iter().map(|&c| c as usize).sum();
    let mut sample = vec![0.0f32; total];
    {
        let mut part_mut = PartitionMut::new(&mut sample[..], &counts[..], &displs[..]);
        comm.all_gather_varcount_into(&part.sample[..], &mut part_mut);
    }
    job.window(
        vec![super::WindowPart {
            range: (lo, hi),
            sample,
        }],
        brick.values,
    )
}

/// Composites every rank's `image` in the front-to-back `order` of ranks by binary swap (with a
/// fold for a count that is not a power of two) and gathers the result onto rank 0 (`Some`
/// there, `None` elsewhere).
pub fn binary_swap(
    comm: &SimpleCommunicator,
    order: &[usize],
    mut image: Vec<[f32; 4]>,
) -> Option<Vec<[f32; 4]>> {
    let rank = comm.rank() as usize;
    let n = order.len();
    let pixels = image.len();
    let p = 1usize << (usize::BITS - 1 - n.leading_zeros());
    let extra = n - p;
    let pos = order
        .iter()
        .position(|&r| r == rank)
        .expect("every rank is in the order");
    // Fold: the first `extra` pairs in order merge into their front member.
    let mut participants: Vec<usize> = Vec::with_capacity(p);
    for (i, &r) in order.iter().enumerate() {
        if i < 2 * extra && i % 2 == 1 {
            continue;
        }
        participants.push(r);
    }
    let mut region = 0..pixels;
    let active = if pos < 2 * extra {
        let (front, back) = (order[pos & !1], order[pos | 1]);
        if rank == back {
            comm.process_at_rank(front as i32)
                .send(image.as_flattened());
            false
        } else {
            let mut got = vec![[0.0f32; 4]; pixels];
            comm.process_at_rank(back as i32)
                .receive_into(got.as_flattened_mut());
            over(&mut image, &got);
            true
        }
    } else {
        true
    };
    if active {
        let v = participants
            .iter()
            .position(|&r| r == rank)
            .expect("a participant");
        let mut got = Vec::new();
        let mut bit = 1;
        while bit < p {
            let partner = participants[v ^ bit];
            let mid = region.start + region.len() / 2;
            let (keep, give) = if v & bit == 0 {
                (region.start..mid, mid..region.end)
            } else {
                (mid..region.end, region.start..mid)
            };
            got.clear();
            got.resize(keep.len(), [0.0f32; 4]);
            let other = comm.process_at_rank(partner as i32);
            mpi::point_to_point::send_receive_into(
                image[give].as_flattened(),
                &other,
                got.as_flattened_mut(),
                &other,
            );
            let mine = &mut image[keep.clone()];
            if v & bit == 0 {
                over(mine, &got);
            } else {
                // The partner's run is in front: partner over mine.
                for (m, f) in mine.iter_mut().zip(&got) {
                    *m = footprint::composite::over(*f, *m);
                }
            }
            region = keep;
            bit <<= 1;
        }
    } else {
        region = 0..0;
    }
    // Gather the regions onto rank 0 (each at its own offset).
    let root = comm.process_at_rank(0);
    let bounds = [region.start as i32 * 4, region.len() as i32 * 4];
    let part = image[region].as_flattened().to_vec();
    if rank != 0 {
        root.gather_into(&bounds[..]);
        root.gather_varcount_into(&part[..]);
        return None;
    }
    let mut all = vec![0i32; 2 * comm.size() as usize];
    root.gather_into_root(&bounds[..], &mut all[..]);
    let displs: Vec<i32> = all.chunks_exact(2).map(|c| c[0]).collect();
    let counts: Vec<i32> = all.chunks_exact(2).map(|c| c[1]).collect();
    let mut out = vec![[0.0f32; 4]; pixels];
    {
        let mut part_mut = PartitionMut::new(out.as_flattened_mut(), &counts[..], &displs[..]);
        root.gather_varcount_into_root(&part[..], &mut part_mut);
    }
    Some(out)
}
