//! Per-splat and per-view costs against table size, lookup and method.
//!
//! Names spell the configuration: `splat/n=33/bilinear/robust/float/libm/fp=8px` is one voxel
//! whose footprint is about 8 px across, through a 33×33 view table read bilinearly, float
//! accumulation, libm backend. `view_table/n=33/bilinear` builds one view table.
//! `cargo bench --bench splat`; `cargo test --benches` runs each once as a smoke test.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use footprint::geometry::{Footprint, FootprintOptions};
use footprint::splat::{splat, Direct, ImageMut, Sampler};
use footprint::{math, GenericTable, Kernel, Lookup, ViewTable};
use glam::Mat3;
use std::hint::black_box;

/// Grid-to-screen for a footprint about `across` pixels wide (paper Gaussian, spread 1.6), an
/// oblique view with 2:1 anisotropy.
fn g2s(across: f32) -> Mat3 {
    let zoom = across / (2.0 * 1.6 * 2.0);
    Mat3::from_rotation_z(0.5)
        * Mat3::from_rotation_x(0.3)
        * Mat3::from_diagonal(glam::Vec3::new(2.0, 1.0, 1.0))
        * zoom
}

/// One splat per iteration at a varying sub-pixel position (as the voxels of a sheet), through a
/// sampler of a concrete type (monomorphised, as the renderer uses it).
fn bench_one<S: Sampler>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    sampler: &S,
) {
    let mut px = vec![0.0f32; 128 * 128];
    group.bench_function(BenchmarkId::from_parameter(name), |b| {
        let mut img = ImageMut::new(&mut px, 128, 128, 128).unwrap();
        let mut i = 0u32;
        b.iter(|| {
            i = i.wrapping_add(1);
            let centre = [64.0 + (i % 7) as f32 * 0.137, 64.0 + (i % 5) as f32 * 0.211];
            splat(black_box(sampler), centre, &1.0f32, &mut img).unwrap()
        });
    });
}

fn bench_splat_n<const N: usize>(c: &mut Criterion) {
    let kernel = Kernel::PAPER_GAUSSIAN;
    let generic = Box::new(GenericTable::<N>::build(kernel));
    let mut group = c.benchmark_group("splat");
    for across in [2.0f32, 8.0, 32.0] {
        let fp = Footprint::new(&kernel, &g2s(across), FootprintOptions::default()).unwrap();
        for (lookup, lname) in [(Lookup::Nearest, "nearest"), (Lookup::Bilinear, "bilinear")] {
            let table = Box::new(ViewTable::<N>::build(&fp, &generic, lookup, lookup));
            let direct = Direct {
                footprint: fp,
                table: &*generic,
                lookup,
            };
            bench_one(
                &mut group,
                &format!("n={N}/{lname}/robust/float/{}/fp={across}px", math::BACKEND),
                &*table,
            );
            bench_one(
                &mut group,
                &format!("n={N}/{lname}/direct/float/{}/fp={across}px", math::BACKEND),
                &direct,
            );
        }
    }
    group.finish();
    let fp = Footprint::new(&kernel, &g2s(32.0), FootprintOptions::default()).unwrap();
    let mut table = Box::new(ViewTable::<N>::zeroed(fp));
    c.bench_function(&format!("view_table/n={N}/bilinear"), |b| {
        b.iter(|| table.build_into(black_box(&fp), &generic, Lookup::Bilinear, Lookup::Bilinear))
    });
}

fn benches(c: &mut Criterion) {
    bench_splat_n::<11>(c);
    bench_splat_n::<33>(c);
    bench_splat_n::<65>(c);
    bench_splat_n::<129>(c);
}

criterion_group!(splat_benches, benches);
criterion_main!(splat_benches);
