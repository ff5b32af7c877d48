//! Per-splat, per-view and per-frame costs against table size, lookup, method and precision.
//!
//! Names spell the configuration:
//! - `splat/n=33/bilinear/direct/fixed/libm/fp=8px`: one voxel whose footprint is about 8 px
//!   across, read from a 33×33 table bilinearly, by the direct method (`view` is the two-stage
//!   view-table method), fixed-point accumulation, libm backend;
//! - `setup/n=33/view/fixed`: building one view's table (`view` float, `view` fixed, `direct`
//!   fixed);
//! - `frame/headsq/n=65/bilinear/view/float`: a whole 512×512 frame of a shared volume.
//!
//! `cargo bench --bench splat` runs them all; `cargo bench --bench splat --features micromath`
//! runs them with the micromath backend (the name's backend part follows). `cargo test --benches`
//! runs each once as a smoke test. Tests never assert on time.

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion};
use footprint::fixed::{self, FixedTable};
use footprint::frame::FrameSetup;
use footprint::geometry::FootprintOptions;
use footprint::splat::{splat, Direct, ImageMut, Sampler};
use footprint::{math, GenericTable, Grid, Kernel, Lookup, View, ViewTable};
use glam::Mat3;
use std::hint::black_box;
use std::time::Duration;

/// Table sizes benchmarked (the paper used 5, 11, 21 and 101).
macro_rules! for_sizes {
    ($f:ident, $c:expr) => {
        $f::<5>($c);
        $f::<11>($c);
        $f::<21>($c);
        $f::<33>($c);
        $f::<65>($c);
        $f::<101>($c);
        $f::<129>($c);
    };
}

/// A one-voxel frame whose footprint is about `across` pixels wide (paper Gaussian, spread 1.6):
/// an oblique view of a 2:1:1 grid.
fn frame(across: f32) -> FrameSetup {
    let zoom = across / (2.0 * 1.6 * 2.0);
    let view = Mat3::from_rotation_z(0.5) * Mat3::from_rotation_x(0.3) * zoom;
    FrameSetup::new(
        [1, 1, 1],
        &Grid::from_spacing([2.0, 1.0, 1.0]).unwrap(),
        &View::new(view).unwrap(),
        &Kernel::PAPER_GAUSSIAN,
        FootprintOptions::default(),
        [128, 128],
    )
    .unwrap()
}

/// The sub-pixel centre of iteration `i` (varying, as the voxels of a sheet).
fn centre(i: u32) -> [f32; 2] {
    [64.0 + (i % 7) as f32 * 0.137, 64.0 + (i % 5) as f32 * 0.211]
}

fn float_splat<S: Sampler>(g: &mut BenchmarkGroup<'_, WallTime>, name: &str, sampler: &S) {
    let mut px = vec![[0.0f32; 4]; 128 * 128];
    g.bench_function(name, |b| {
        let mut img = ImageMut::new(&mut px, 128, 128, 128).unwrap();
        let mut i = 0u32;
        let value = [0.3f32, 0.4, 0.5, 0.6];
        b.iter(|| {
            i = i.wrapping_add(1);
            splat(black_box(sampler), centre(i), &value, &mut img).unwrap()
        });
    });
}

fn fixed_splat<const N: usize>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    t: &FixedTable<N>,
) {
    let mut px = vec![[0i64; 4]; 128 * 128];
    g.bench_function(name, |b| {
        let mut img = ImageMut::new(&mut px, 128, 128, 128).unwrap();
        let mut i = 0u32;
        let value = fixed::quantise([0.3, 0.4, 0.5, 0.6]);
        b.iter(|| {
            i = i.wrapping_add(1);
            let c = centre(i).map(|x| (f64::from(x) * f64::from(1u32 << 24)) as i64);
            fixed::splat::splat(black_box(t), c, &value, &mut img, |_, _, _| {})
        });
    });
}

fn splats<const N: usize>(c: &mut Criterion) {
    let generic = Box::new(GenericTable::<N>::build(Kernel::PAPER_GAUSSIAN));
    let mut g = c.benchmark_group("splat");
    let be = math::BACKEND;
    for across in [2.0f32, 8.0, 32.0] {
        let f = frame(across);
        for (lookup, l) in [(Lookup::Nearest, "nearest"), (Lookup::Bilinear, "bilinear")] {
            let view = Box::new(ViewTable::<N>::build(
                &f.footprint,
                &generic,
                lookup,
                lookup,
            ));
            let direct = Direct {
                footprint: f.footprint,
                table: &*generic,
                lookup,
            };
            float_splat(
                &mut g,
                &format!("n={N}/{l}/view/float/{be}/fp={across}px"),
                &*view,
            );
            float_splat(
                &mut g,
                &format!("n={N}/{l}/direct/float/{be}/fp={across}px"),
                &direct,
            );
            let mut t = Box::new(FixedTable::<N>::zeroed());
            t.build_view(&f, &generic, lookup, lookup).unwrap();
            fixed_splat(
                &mut g,
                &format!("n={N}/{l}/view/fixed/{be}/fp={across}px"),
                &*t,
            );
            t.build_direct(&f, &generic, lookup).unwrap();
            fixed_splat(
                &mut g,
                &format!("n={N}/{l}/direct/fixed/{be}/fp={across}px"),
                &*t,
            );
        }
    }
    g.finish();
}

fn setups<const N: usize>(c: &mut Criterion) {
    let generic = Box::new(GenericTable::<N>::build(Kernel::PAPER_GAUSSIAN));
    let f = frame(32.0);
    let be = math::BACKEND;
    let mut g = c.benchmark_group("setup");
    let mut view = Box::new(ViewTable::<N>::zeroed(f.footprint));
    g.bench_function(format!("n={N}/view/float/{be}"), |b| {
        b.iter(|| {
            view.build_into(
                black_box(&f.footprint),
                &generic,
                Lookup::Bilinear,
                Lookup::Bilinear,
            )
        })
    });
    let mut t = Box::new(FixedTable::<N>::zeroed());
    g.bench_function(format!("n={N}/view/fixed/{be}"), |b| {
        b.iter(|| {
            t.build_view(black_box(&f), &generic, Lookup::Bilinear, Lookup::Bilinear)
                .unwrap()
        })
    });
    g.bench_function(format!("n={N}/direct/fixed/{be}"), |b| {
        b.iter(|| {
            t.build_direct(black_box(&f), &generic, Lookup::Bilinear)
                .unwrap()
        })
    });
    g.finish();
}

/// A thin oblique footprint (a 30:1:1 grid turned 45° in the screen, about 68 px long and 3 px
/// wide, n = 129, bilinear): the view table over the screen box (the paper's layout, 7.6 % of peak
/// off the exact footprint), over the unit square (the layout such footprints get, 0.27 %), and
/// the direct method (0.27 %). The layout choice in `footprint::table::ViewLayout` rests on this.
fn thin(c: &mut Criterion) {
    use footprint::table::ViewLayout;
    let generic = Box::new(GenericTable::<129>::build(Kernel::PAPER_GAUSSIAN));
    let view = Mat3::from_rotation_z(core::f32::consts::FRAC_PI_4);
    let f = FrameSetup::new(
        [1, 1, 1],
        &Grid::from_spacing([30.0, 1.0, 1.0]).unwrap(),
        &View::new(view).unwrap(),
        &Kernel::PAPER_GAUSSIAN,
        FootprintOptions::default(),
        [128, 128],
    )
    .unwrap();
    let mut g = c.benchmark_group("thin");
    let be = math::BACKEND;
    let mut table = Box::new(ViewTable::<129>::zeroed(f.footprint));
    for (layout, name) in [(ViewLayout::ScreenBox, "box"), (ViewLayout::Unit, "unit")] {
        let l = Lookup::Bilinear;
        table.build_laid_out(&f.footprint, &generic, l, l, layout);
        float_splat(
            &mut g,
            &format!("n=129/bilinear/view-{name}/float/{be}"),
            &*table,
        );
    }
    let direct = Direct {
        footprint: f.footprint,
        table: &*generic,
        lookup: Lookup::Bilinear,
    };
    float_splat(
        &mut g,
        &format!("n=129/bilinear/direct/float/{be}"),
        &direct,
    );
    g.finish();
}

fn per_splat(c: &mut Criterion) {
    for_sizes!(splats, c);
}

fn per_view(c: &mut Criterion) {
    for_sizes!(setups, c);
}

/// Whole 512×512 frames of `walnut` (from ../shared/data, when present) and `headsq`.
fn frames(c: &mut Criterion) {
    let shared = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    let volumes = [
        (
            "headsq",
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/data/headsq_64x64x93_int16_le.nhdr"),
        ),
        (
            "walnut",
            shared.join("walnut/walnut_128x96x114_uint16_le.nhdr"),
        ),
    ];
    let configs: [&[&str]; 5] = [
        &[
            "--table", "65", "--lookup", "bilinear", "--method", "robust", "--accum", "float",
        ],
        &[
            "--table", "65", "--lookup", "bilinear", "--method", "robust", "--accum", "fixed",
        ],
        &[
            "--table", "65", "--lookup", "bilinear", "--method", "direct", "--accum", "float",
        ],
        &[
            "--table", "33", "--lookup", "nearest", "--method", "robust", "--accum", "float",
        ],
        &[
            "--table", "129", "--lookup", "nearest", "--method", "robust", "--accum", "float",
        ],
    ];
    let mut g = c.benchmark_group("frame");
    g.sample_size(10);
    for (name, path) in &volumes {
        if !path.exists() {
            eprintln!(
                "frame benches: {} not found, {name} skipped",
                path.display()
            );
            continue;
        }
        for cfg in configs {
            let mut args = vec![
                path.to_str().unwrap(),
                "--size",
                "512x512",
                "--view",
                "30,20,0",
            ];
            args.extend_from_slice(cfg);
            let r = footprint_harness::args::parse_args(&args).unwrap();
            let p = footprint_harness::pipeline::prepare(&r).unwrap();
            let plan = footprint_harness::args::plan(&r).unwrap();
            let label = format!(
                "{name}/n={}/{}/{}/{}/{}",
                cfg[1],
                cfg[3],
                if cfg[5] == "robust" { "view" } else { "direct" },
                cfg[7],
                math::BACKEND
            );
            g.bench_function(label, |b| {
                b.iter(|| footprint_harness::pipeline::render_core(&p, &plan).unwrap())
            });
        }
    }
    g.finish();
}

/// One splat through the phase stencils (`footprint::stencil`, 32 phases, the 129 view table)
/// read by each [`PhaseLookup`], footprints about 3 to 14 px across (the small-box windows and the
/// general row loop): `stencil/phase=nearest/fp=8px`.
fn stencils(c: &mut Criterion) {
    use footprint::stencil::{self, PhaseLookup, Stencils, DEFAULT_PHASES};
    let generic = Box::new(GenericTable::<129>::build(Kernel::PAPER_GAUSSIAN));
    let mut g = c.benchmark_group("stencil");
    for across in [3.0f32, 6.0, 10.0, 14.0] {
        let f = frame(across);
        let view = Box::new(ViewTable::<129>::build(
            &f.footprint,
            &generic,
            Lookup::Bilinear,
            Lookup::Bilinear,
        ));
        let len = stencil::len_for(&f.footprint, DEFAULT_PHASES).expect("stencils fit");
        let mut buffer = vec![0.0f32; len];
        let built = Stencils::build(&*view, DEFAULT_PHASES, &mut buffer).unwrap();
        for (lookup, name) in [
            (PhaseLookup::Blend, "blend"),
            (PhaseLookup::Nearest, "nearest"),
        ] {
            let st = built.with_phase_lookup(lookup);
            let mut px = vec![[0.0f32; 4]; 128 * 128];
            g.bench_function(format!("phase={name}/fp={across}px"), |b| {
                let mut img = ImageMut::new(&mut px, 128, 128, 128).unwrap();
                let mut i = 0u32;
                let value = [0.3f32, 0.4, 0.5, 0.6];
                b.iter(|| {
                    i = i.wrapping_add(1);
                    black_box(&st)
                        .splat(centre(i), &value, &mut img, |_, _, _| {})
                        .unwrap()
                });
            });
        }
    }
    g.finish();
}

fn quick() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .sample_size(20)
}

criterion_group! {
    name = splat_benches;
    config = quick();
    targets = thin, per_splat, per_view, frames, stencils
}
criterion_main!(splat_benches);
