//! In situ: a "simulation" whose MPI ranks each hold one slab of a field renders the whole field
//! without writing it anywhere (`footprint_harness::distributed::mpi::render_in_situ`).
//!
//! ```text
//! cargo build --release -p footprint-harness --features mpi --example in_situ
//! mpirun -np 4 target/release/examples/in_situ out.pfm [whole.raw]
//! ```
//!
//! Each rank computes its own voxels of a 96×80×64 field (three Gaussian blobs, f32) over its
//! slab of z-slices and one ghost slice each side (the gradients read them); rank 0 writes the
//! composited image as a PFM, and, given a second path, the whole field as raw f32 (rank by rank
//! over MPI), so a check can render that file with one process and compare
//! (`.ci/mpi`: `footprint render whole.raw --dims 96,80,64 --type f32 …`).

use footprint_harness::distributed::mpi::{init, render_in_situ};
use footprint_harness::io::brick::{IndexBox, GHOST};
use footprint_harness::io::volume::Samples;
use mpi::traits::*;

const DIMS: [usize; 3] = [96, 80, 64];

/// The simulation's field at voxel (i, j, k).
fn field(i: usize, j: usize, k: usize) -> f32 {
    let blobs = [
        ([30.0, 40.0, 20.0], 14.0, 1.0),
        ([62.0, 30.0, 40.0], 18.0, 0.8),
        ([50.0, 58.0, 30.0], 9.0, 0.6),
    ];
    let p = [i as f32, j as f32, k as f32];
    blobs
        .iter()
        .map(|(c, r, a)| {
            let d2: f32 = (0..3).map(|n| (p[n] - c[n]).powi(2)).sum();
            a * (-d2 / (r * r)).exp()
        })
        .sum()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out: Vec<String> = std::env::args().skip(1).collect();
    let Some(image_path) = out.first() else {
        return Err("usage: in_situ OUT.pfm [WHOLE.raw]".into());
    };
    let universe = init().ok_or("MPI was already started")?;
    let world = universe.world();
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    // The simulation's decomposition: z-slabs, rank r owning slices [r·D/N, (r+1)·D/N).
    let owned = IndexBox {
        lo: [0, 0, rank * DIMS[2] / size],
        hi: [DIMS[0], DIMS[1], (rank + 1) * DIMS[2] / size],
    };
    let stored = owned.grown(GHOST, DIMS);
    let d = stored.dims();
    let mut samples = Vec::with_capacity(stored.count());
    for k in stored.lo[2]..stored.hi[2] {
        for j in 0..d[1] {
            for i in 0..d[0] {
                samples.push(field(i, j, k));
            }
        }
    }
    let args = footprint_harness::args::parse_args(&["--size", "256x256", "--view", "30,20,0"])?;
    let own: Vec<f32> =
        samples[(owned.lo[2] - stored.lo[2]) * d[0] * d[1]..][..owned.count()].to_vec();
    let image = render_in_situ(
        &world,
        &args,
        DIMS,
        [1.0; 3],
        Samples::F32(samples.into()),
        stored,
        owned,
    )?;
    // The whole field, for the check: every rank's own slices, gathered in rank order.
    let root = world.process_at_rank(0);
    if let Some(g) = image {
        let bytes = footprint_harness::io::image::encode_pfm_rgb(&g.image, 256, 256);
        std::fs::write(image_path, bytes)?;
        println!(
            "in situ: {size} ranks composited a {}x{}x{} field (ranks front to back {:?}) into {image_path}",
            DIMS[0], DIMS[1], DIMS[2], g.order
        );
        if let Some(raw) = out.get(1) {
            let mut whole = vec![0.0f32; DIMS.iter().product()];
            let counts: Vec<i32> = (0..size)
                .map(|r| {
                    ((r + 1) * DIMS[2] / size - r * DIMS[2] / size) as i32
                        * (DIMS[0] * DIMS[1]) as i32
                })
                .collect();
            let displs: Vec<i32> = (0..size)
                .map(|r| (r * DIMS[2] / size * DIMS[0] * DIMS[1]) as i32)
                .collect();
            let mut part =
                mpi::datatype::PartitionMut::new(&mut whole[..], &counts[..], &displs[..]);
            root.gather_varcount_into_root(&own[..], &mut part);
            let bytes: Vec<u8> = whole.iter().flat_map(|x| x.to_le_bytes()).collect();
            std::fs::write(raw, bytes)?;
        }
    } else if out.len() > 1 {
        root.gather_varcount_into(&own[..]);
    }
    Ok(())
}
