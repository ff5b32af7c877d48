//! Image-aligned slicing (issue 12): the core's slab sections against brute-force line integrals
//! of the 3D kernel, and the flat-field and thin-slab limits.

use footprint::composite::RowSpan;
use footprint::frame::{FrameSetup, Order};
use footprint::geometry::{FootprintOptions, Grid, View};
use footprint::render::slabs::slab_layer;
use footprint::render::{
    SectionStencils, SlabBuffers, SlabError, SlabRenderer, SlabSetup, SlabVoxel,
};
use footprint::table::{SectionError, SectionTable};
use footprint::Kernel;
use footprint_suite::{ball_integral, gaussian_3d, simpson, view};
use glam::{DVec3, Mat3};

fn frame(dims: [usize; 3], spacing: [f32; 3], m: Mat3, kernel: &Kernel) -> FrameSetup {
    FrameSetup::new(
        dims,
        &Grid::from_spacing(spacing).unwrap(),
        &View::new(m).unwrap(),
        kernel,
        FootprintOptions::default(),
        [48, 48],
    )
    .unwrap()
}

fn table(kernel: Kernel) -> Box<SectionTable<257, 1025>> {
    let mut t = Box::new(SectionTable::zeroed(kernel));
    t.build_into(kernel).unwrap();
    t
}

/// Caller buffers for a slab render of a `side`×`side` frame: the ring of slab accumulators, the
/// image and the row spans, sized for `setup`.
struct Ring {
    acc: Vec<[f32; 4]>,
    img: Vec<[f32; 4]>,
    rows: Vec<RowSpan>,
    ring: usize,
    side: usize,
}

impl Ring {
    fn new(setup: &SlabSetup, side: usize) -> Self {
        let ring = setup.ring();
        Ring {
            acc: vec![[0.0; 4]; side * side * ring],
            img: vec![[0.0; 4]; side * side],
            rows: vec![RowSpan::EMPTY; side * ring],
            ring,
            side,
        }
    }

    /// A front-to-back renderer over the whole frame.
    fn renderer<'a>(
        &'a mut self,
        setup: &'a SlabSetup,
        sec: &'a SectionTable<257, 1025>,
    ) -> SlabRenderer<'a, 257, 1025> {
        let buffers = SlabBuffers {
            accumulators: &mut self.acc,
            image: &mut self.img,
            rows: &mut self.rows,
        };
        SlabRenderer::with_band(setup, sec, Order::FrontToBack, buffers, None, 0..self.side)
            .unwrap()
    }

    /// A front-to-back renderer over the whole frame splatting through `stencils`.
    fn stencilled<'a>(
        &'a mut self,
        setup: &'a SlabSetup,
        sec: &'a SectionTable<257, 1025>,
        stencils: &'a SectionStencils<'a>,
    ) -> SlabRenderer<'a, 257, 1025> {
        self.renderer(setup, sec).with_stencils(stencils).unwrap()
    }

    /// What pixel (x, y) has accumulated in slab `slab` (not yet composited).
    fn at(&self, x: usize, y: usize, slab: usize) -> [f32; 4] {
        self.acc[((slab % self.ring) * self.side + y) * self.side + x]
    }
}

/// One voxel's section in every slab, read back from the accumulator before compositing, against
/// a Simpson integral of w = h(|q|/R)/(R³∫h) along each pixel's ray through the slab (grid
/// coordinates from M⁻¹, world length from G): an anisotropic grid at an oblique view, where the
/// chord's midpoint moves with the pixel. The same through section stencils (8 depth phases, 16
/// sub-pixel phases), against the integral at the depth the voxel is snapped to.
#[test]
fn sections_are_line_integrals_of_the_kernel_through_the_slab() {
    let kernel = Kernel::gaussian(1.6, 2.5).unwrap();
    let sec = table(kernel);
    for ((spacing, m, thickness), phased) in [
        ([1.0, 1.0, 1.0], view(20.0, 35.0, 0.0, 6.0), 0.5),
        ([1.0, 1.3, 2.0], view(30.0, 50.0, 10.0, 5.0), 0.7),
        ([0.7, 1.0, 1.0], view(-40.0, 10.0, 60.0, 7.0), 1.3),
        ([1.0, 1.0, 2.0], view(75.0, -40.0, 20.0, 2.5), 1.0),
    ]
    .into_iter()
    .flat_map(|c| [(c, false), (c, true)])
    {
        let f = frame([3, 3, 3], spacing, m, &kernel);
        let setup = SlabSetup::new(&f, &kernel, thickness).unwrap();
        let setup = setup.with_depth_phases(if phased { 8 } else { 0 }).unwrap();
        let mut store = vec![0.0; SectionStencils::len_for(&setup, 16).unwrap_or(0)];
        let stencils =
            phased.then(|| SectionStencils::build(&setup, &sec, 16, &mut store).unwrap());
        let g2s = f.grid_to_screen.as_dmat3();
        let inv = g2s.inverse();
        let to_world = f.grid_inverse_transpose.as_dmat3().inverse().transpose();
        let world_per_z = (to_world * inv.col(2)).length();
        let r = f64::from(kernel.spread());
        let norm = 1.0 / (r.powi(3) * ball_integral(gaussian_3d(2.5), 2000));
        let w = |q: DVec3| gaussian_3d(2.5)(q.length() / r) * norm;
        let voxel = SlabVoxel {
            position: f.affine_position([1.0; 3]).to_array(),
            value: [0.0, 0.0, 0.0, 1.0],
        };
        let mut c = DVec3::from_array(voxel.position.map(f64::from));
        if phased {
            // Snapped to the middle of its eighth of the slab.
            let (z0, t) = (f64::from(setup.front(0)), f64::from(setup.thickness_px()));
            let u = (c.z - z0) / t;
            c.z = z0 + t * (u.floor() + ((u - u.floor()) * 8.0).floor() / 8.0 + 1.0 / 16.0);
        }
        let (first, last) = setup.slabs_of(voxel.position[2]);
        assert!(last > first, "a kernel spans several slabs");
        let (mut worst, mut peak, mut total, mut wanted) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut bufs = Ring::new(&setup, 48);
        match &stencils {
            Some(st) => bufs
                .stencilled(&setup, &sec, st)
                .splat_voxel(&voxel)
                .unwrap(),
            None => bufs.renderer(&setup, &sec).splat_voxel(&voxel).unwrap(),
        }
        for slab in first..=last {
            // The slab's depth range, pixels: from its front, one thickness deep.
            let z0 = setup.front(slab) as f64;
            let z1 = z0 + f64::from(setup.thickness_px());
            for y in 0..48 {
                for x in 0..48 {
                    let (dx, dy) = (x as f64 + 0.5 - c.x, y as f64 + 0.5 - c.y);
                    let want = simpson(|z| w(inv * DVec3::new(dx, dy, z - c.z)), z0, z1, 2000)
                        * world_per_z;
                    let got = f64::from(bufs.at(x, y, slab)[3]);
                    worst = worst.max((got - want).abs());
                    peak = peak.max(want);
                    total += got;
                    wanted += want;
                }
            }
        }
        assert!(
            worst < 2e-3 * peak,
            "spacing {spacing:?} phased {phased}: worst {worst:.3e} against a peak of {peak:.3e}"
        );
        // The sections telescope to the kernel's whole integral over the pixels.
        assert!(
            (total - wanted).abs() < 1e-3 * wanted,
            "phased {phased}: total {total} against {wanted}"
        );
    }
}

/// A flat field: a lattice of equal voxels (σ = 1 per world unit, grey) accumulates, at a pixel
/// whose ray crosses the middle slab deep inside the lattice, the brute-force integral of the
/// field Σᵥ w(x − v) along that stretch of ray; and that is the slab's world length within the
/// truncated kernel's lattice ripple (its weights sum to one on average).
#[test]
fn a_flat_field_accumulates_its_extinction_times_the_slab_length() {
    let kernel = Kernel::gaussian(1.6, 2.5).unwrap();
    let sec = table(kernel);
    for (spacing, m, thickness) in [
        ([1.0, 1.0, 1.0], view(25.0, 40.0, 0.0, 3.0), 1.0),
        ([1.0, 1.0, 2.0], view(10.0, 70.0, 30.0, 2.0), 0.5),
    ] {
        let dims = [24, 24, 24];
        let f = FrameSetup::new(
            dims,
            &Grid::from_spacing(spacing).unwrap(),
            &View::new(m).unwrap(),
            &kernel,
            FootprintOptions::default(),
            [64, 64],
        )
        .unwrap();
        let setup = SlabSetup::new(&f, &kernel, thickness).unwrap();
        let mut bufs = Ring::new(&setup, 64);
        let mid = setup.slab_count() / 2;
        {
            let mut rdr = bufs.renderer(&setup, &sec);
            for k in 0..dims[2] {
                for j in 0..dims[1] {
                    for i in 0..dims[0] {
                        let v = SlabVoxel {
                            position: f.affine_position([i, j, k].map(|c| c as f32)).to_array(),
                            value: [0.5, 0.5, 0.5, 1.0],
                        };
                        let (a, b) = setup.slabs_of(v.position[2]);
                        if (a..=b).contains(&mid) {
                            rdr.splat_voxel(&v).unwrap();
                        }
                    }
                }
            }
        }
        let min_spacing = spacing.iter().copied().fold(f32::INFINITY, f32::min);
        let length = f64::from(thickness * min_spacing);
        let got = f64::from(bufs.at(32, 32, mid)[3]);
        // Brute force: Simpson along the centre pixel's ray through the slab, of the sum over
        // every voxel of w(q), q the grid offset from that voxel.
        let inv = f.grid_to_screen.as_dmat3().inverse();
        let to_world = f.grid_inverse_transpose.as_dmat3().inverse().transpose();
        let world_per_z = (to_world * inv.col(2)).length();
        let r = f64::from(kernel.spread());
        let norm = 1.0 / (r.powi(3) * ball_integral(gaussian_3d(2.5), 2000));
        let h = gaussian_3d(2.5);
        let origin = f.origin.as_dvec3();
        let field = |z: f64| {
            let q = inv * (DVec3::new(32.5, 32.5, z) - origin);
            let mut sum = 0.0;
            for k in 0..dims[2] {
                for j in 0..dims[1] {
                    for i in 0..dims[0] {
                        let d = q - DVec3::new(i as f64, j as f64, k as f64);
                        if d.length_squared() < r * r {
                            sum += h(d.length() / r) * norm;
                        }
                    }
                }
            }
            sum
        };
        let z0 = f64::from(setup.front(mid));
        let want = simpson(field, z0, z0 + f64::from(setup.thickness_px()), 200) * world_per_z;
        assert!(
            (got - want).abs() < 1e-3 * want,
            "spacing {spacing:?}: τ {got}, brute force {want}"
        );
        assert!(
            (want - length).abs() < 0.03 * length,
            "spacing {spacing:?}: τ {want} for a slab {length} world units long"
        );
    }
}

#[test]
fn slab_layers_composite_as_emission_absorption() {
    // τ = ln 2: half the light passes; colour E·α/τ.
    let tau = std::f32::consts::LN_2;
    let l = slab_layer([0.3 * tau, 0.0, 0.0, tau]);
    assert!(
        (l[3] - 0.5).abs() < 1e-6 && (l[0] - 0.15).abs() < 1e-6,
        "{l:?}"
    );
    // Thin: α ≈ τ, colour ≈ E; negative and NaN sums become transparent black.
    let l = slab_layer([1e-5, 0.0, 0.0, 2e-5]);
    assert!((l[3] - 2e-5).abs() < 1e-9 && (l[0] - 1e-5).abs() < 1e-9);
    assert_eq!(slab_layer([-1.0, f32::NAN, 0.0, -3.0]), [0.0; 4]);
    assert_eq!(slab_layer([0.0, 0.0, 0.0, f32::NAN])[3], 0.0);
    // Unit-thickness opacity round-trips through extinction.
    let v = SlabVoxel::from_unit_rgba([0.0; 3], [0.2, 0.1, 0.0, 0.4]).unwrap();
    let back = slab_layer(v.value);
    assert!(
        (back[3] - 0.4).abs() < 1e-6 && (back[0] - 0.2).abs() < 1e-6,
        "{back:?}"
    );
    assert!(SlabVoxel::from_unit_rgba([0.0; 3], [0.0; 4]).is_none());
    assert!(SlabVoxel::from_unit_rgba([0.0; 3], [0.0, 0.0, 0.0, f32::NAN]).is_none());
}

#[test]
fn what_slabs_cannot_do_is_refused() {
    let gauss = Kernel::gaussian(1.6, 2.5).unwrap();
    let f = frame([4, 4, 4], [1.0; 3], view(10.0, 20.0, 0.0, 4.0), &gauss);
    for t in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert!(matches!(
            SlabSetup::new(&f, &gauss, t),
            Err(SlabError::BadThickness { .. })
        ));
    }
    assert!(matches!(
        SlabSetup::new(&f, &gauss, 1e-7),
        Err(SlabError::TooManySlabs { .. })
    ));
    // A grid eight times coarser along the view than its finest spacing: one kernel would span
    // hundreds of slabs a twentieth of that spacing thick.
    let deep = frame([4, 4, 4], [1.0, 1.0, 8.0], Mat3::IDENTITY, &gauss);
    assert!(matches!(
        SlabSetup::new(&deep, &gauss, 0.05),
        Err(SlabError::KernelTooDeep { .. })
    ));
    assert!(SlabSetup::new(&deep, &gauss, 1.0).is_ok());
    // A voxel reaching a slab already composited.
    let setup = SlabSetup::new(&f, &gauss, 1.0).unwrap();
    let sec = table(gauss);
    let mut bufs = Ring::new(&setup, 48);
    let mut rdr = bufs.renderer(&setup, &sec);
    let front = SlabVoxel {
        position: f.affine_position([0.0; 3]).to_array(),
        value: [1.0; 4],
    };
    let first = setup.slabs_of(front.position[2]).0;
    for _ in 0..=first {
        rdr.composite_next();
    }
    assert!(matches!(
        rdr.splat_voxel(&front),
        Err(footprint::render::RenderError::SlabOrder { .. })
    ));
    // Too small a ring buffer.
    let n = 48 * 48;
    let (mut acc, mut img, mut rows) = (
        vec![[0.0f32; 4]; n],
        vec![[0.0f32; 4]; n],
        vec![RowSpan::EMPTY; 48 * setup.ring()],
    );
    let buffers = SlabBuffers {
        accumulators: &mut acc,
        image: &mut img,
        rows: &mut rows,
    };
    assert!(
        SlabRenderer::with_band(&setup, &sec, Order::FrontToBack, buffers, None, 0..48).is_err()
    );
    let cone = Kernel::cone(1.5).unwrap();
    assert_eq!(
        SlabSetup::new(&f, &cone, 1.0),
        Err(SlabError::Kernel(SectionError::NotAVolumeKernel))
    );
    let p = FrameSetup::perspective(
        [4, 4, 4],
        &Grid::from_spacing([1.0; 3]).unwrap(),
        &View::new(Mat3::IDENTITY).unwrap(),
        &gauss,
        FootprintOptions::default(),
        [48, 48],
        20.0,
    )
    .unwrap();
    assert_eq!(SlabSetup::new(&p, &gauss, 1.0), Err(SlabError::Perspective));
}

// ---- The harness's `--slicing image` ----

use footprint_harness::args::parse_args;
use footprint_harness::args::plan;
use footprint_harness::metrics::compare;
use footprint_harness::pipeline::stages::visible::FrameCache;
use footprint_harness::pipeline::{prepare, render_continuous_ref, render_frame};
use footprint_harness::reference::continuous::Reconstruction;

const HEADSQ: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/headsq_64x64x93_int16_le.nhdr"
);

fn slab_image(extra: &[&str]) -> Vec<[f32; 4]> {
    let args = parse_args(extra).unwrap();
    let p = prepare(&args).unwrap();
    render_frame(&p, &plan(&args).unwrap(), &mut FrameCache::default())
        .unwrap()
        .image
}

/// Bands of rows give the same bits for any thread count, both compositing orders, emission and
/// Phong, cut per pixel and through section stencils (`--depth-phases`); and the two orders agree
/// to rounding.
#[test]
fn image_slicing_is_the_same_on_any_number_of_threads_and_in_both_orders() {
    for extra in [
        &["--view", "30,20,0"][..],
        &["--view", "75,-40,20", "--shading", "phong", "--slab", "0.5"],
        &["--view", "30,20,0", "--depth-phases", "8"],
        &[
            "--view",
            "75,-40,20",
            "--shading",
            "phong",
            "--slab",
            "0.5",
            "--depth-phases",
            "4",
        ],
    ] {
        let mut front: Option<Vec<[f32; 4]>> = None;
        for order in ["back-to-front", "front-to-back"] {
            let run = |threads: &str| {
                let mut a = vec!["--slicing", "image", "--size", "97x61", "--order", order];
                a.extend_from_slice(extra);
                a.extend_from_slice(&["--threads", threads]);
                slab_image(&a)
            };
            let one = run("1");
            assert!(one.iter().any(|p| p[3] > 0.01), "{extra:?}: visible");
            for t in ["2", "3", "7"] {
                let many = run(t);
                assert!(
                    one.iter()
                        .zip(&many)
                        .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits)),
                    "{extra:?} {order}: {t} threads differ from one"
                );
            }
            if let Some(f) = &front {
                let worst = one
                    .iter()
                    .zip(f)
                    .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
                    .fold(0.0f32, f32::max);
                assert!(worst < 1e-4, "{extra:?}: the two orders differ by {worst}");
            }
            front = Some(one);
        }
    }
}

/// Against the continuous integral, image slicing is closer than the paper's sheets on the CT
/// head at an oblique view, and thinner slabs come closer still (the slab approximates the
/// ordering inside itself only).
#[test]
fn image_slabs_converge_to_the_continuous_integral() {
    let base = [
        HEADSQ,
        "--size",
        "96x96",
        "--view",
        "30,20,0",
        "--threads",
        "2",
    ];
    let args = parse_args(&base).unwrap();
    let p = prepare(&args).unwrap();
    let (truth, _) = render_continuous_ref(&p, Reconstruction::Kernel).unwrap();
    let db = |extra: &[&str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        let img = slab_image(&a);
        compare(&img, &truth.image).1.psnr_db
    };
    let object = db(&[]);
    let (thick, unit, thin) = (
        db(&["--slicing", "image", "--slab", "2"]),
        db(&["--slicing", "image", "--slab", "1"]),
        db(&["--slicing", "image", "--slab", "0.25"]),
    );
    eprintln!("object {object:.1} dB; image slabs 2: {thick:.1}, 1: {unit:.1}, 0.25: {thin:.1}");
    // Section stencils (8 depth phases, 8 sub-pixel phases) stay within 1 dB of the per-pixel
    // cut against the model, and at one depth phase per slab (voxels moved up to half a slab)
    // they do not: the test can tell the depth snapping from the stencils' error.
    let stencilled = db(&["--slicing", "image", "--slab", "1", "--depth-phases", "8"]);
    let coarse = db(&["--slicing", "image", "--slab", "1", "--depth-phases", "1"]);
    eprintln!("slabs 1 through section stencils: 8 depth phases {stencilled:.1}, 1: {coarse:.1}");
    assert!(
        stencilled > unit - 1.0,
        "section stencils {stencilled:.1} dB vs per pixel {unit:.1} dB"
    );
    assert!(coarse < stencilled, "{coarse:.1} vs {stencilled:.1}");
    assert!(
        unit > object + 6.0,
        "image {unit:.1} dB vs object {object:.1} dB"
    );
    assert!(
        thin > unit && unit > thick,
        "{thick:.1} < {unit:.1} < {thin:.1} expected"
    );
    assert!(unit >= 60.0, "{unit:.1} dB");
}

/// With a narrow window most of the head is opaque (α = 1 over one world unit): the slabs and the
/// reference must cap its extinction alike, or thinner slabs stop converging (they did, at
/// 48 dB on neghip, while the reference capped at 1 − 10⁻⁹ and the slabs at 1 − 10⁻⁶).
#[test]
fn opaque_voxels_converge_too() {
    let base = [
        HEADSQ,
        "--size",
        "64x64",
        "--view",
        "30,20,0",
        "--window",
        "0,300",
        "--tf",
        "grey",
        "--threads",
        "2",
        // The continuous reference integrates full resolution.
        "--lod",
        "0",
    ];
    let args = parse_args(&base).unwrap();
    let p = prepare(&args).unwrap();
    let (truth, _) = render_continuous_ref(&p, Reconstruction::Kernel).unwrap();
    let db = |slab: &str| {
        let mut a = base.to_vec();
        a.extend_from_slice(&["--slicing", "image", "--slab", slab]);
        compare(&slab_image(&a), &truth.image).1.psnr_db
    };
    let (unit, thin) = (db("1"), db("0.25"));
    eprintln!("opaque head: image slabs 1: {unit:.1} dB, 0.25: {thin:.1} dB");
    assert!(thin > unit + 10.0, "{unit:.1} → {thin:.1} dB");
}

/// What image slicing cannot do is refused with a message that says why.
#[test]
fn image_slicing_refusals_say_why() {
    let d = footprint_suite::tmpdir("slab-refusals");
    let raw = d.join("v.raw");
    std::fs::write(&raw, (0..512).map(|i| (i % 251) as u8).collect::<Vec<u8>>()).unwrap();
    let stream = [
        "--stream",
        raw.to_str().unwrap(),
        "--dims",
        "8,8,8",
        "--type",
        "u8",
    ];
    for (extra, says) in [
        (&["--accum", "fixed"][..], "fixed-point"),
        (&["--kernel", "cone"][..], "gaussian"),
        (&["--perspective", "40"][..], "orthographic"),
        (&stream[..], "--stream"),
    ] {
        let mut a = vec!["--slicing", "image", "--size", "32x32"];
        a.extend_from_slice(extra);
        let args = parse_args(&a).unwrap();
        // As `render` does: the plan first (it refuses a stream), then the frame.
        let err = plan(&args)
            .and_then(|pl| render_frame(&prepare(&args)?, &pl, &mut FrameCache::default()))
            .map(|_| ())
            .unwrap_err();
        assert!(err.message.contains(says), "{extra:?}: {}", err.message);
    }
}

/// The opacity model's layer (issue 41): a chord of L world units whose mean opacity per world
/// unit is ᾱ keeps (1 − ᾱ)^L of the light, emitting the mean straight colour; ᾱ ≥ 1 is opaque
/// whatever the sum (no cap), and faint layers keep their bits through the series.
#[test]
fn opacity_layers_hold_the_mean_opacity_over_the_chord() {
    use footprint::render::absorption::{opacity_layer, Absorption};
    for (mean, chord) in [(0.5f32, 1.0f32), (0.3, 2.5), (0.9, 0.25), (2e-4, 3.0)] {
        let a = mean * chord;
        // Straight colour 0.6 in red: C = 0.6·A.
        let l = opacity_layer([0.6 * a, 0.0, 0.0, a], chord);
        let want = 1.0 - (1.0 - f64::from(mean)).powf(f64::from(chord));
        assert!(
            (f64::from(l[3]) - want).abs() < 2e-6 * want.max(1e-3),
            "ᾱ {mean}, L {chord}: α {} against {want}",
            l[3]
        );
        assert!((l[0] / l[3] - 0.6).abs() < 1e-5, "{l:?}");
    }
    // Opaque: the sum past the chord's length, by any amount.
    for a in [1.0f32, 1.5, 1e6] {
        let l = opacity_layer([0.2 * a, 0.4 * a, 0.0, a], 1.0);
        assert_eq!(l[3], 1.0);
        assert!(
            (l[0] - 0.2).abs() < 1e-6 && (l[1] - 0.4).abs() < 1e-6,
            "{l:?}"
        );
    }
    assert_eq!(opacity_layer([-1.0, f32::NAN, 0.0, -3.0], 1.0), [0.0; 4]);
    assert_eq!(opacity_layer([0.1, 0.0, 0.0, f32::NAN], 1.0), [0.0; 4]);
    assert_eq!(opacity_layer([0.1, 0.0, 0.0, 0.2], 0.0), [0.0; 4]);
    // The model's voxel values: opacity as shaded (no cap), extinction capped.
    let v = Absorption::Opacity
        .voxel_value([0.2, 0.1, 0.0, 1.0])
        .unwrap();
    assert_eq!(v, [0.2, 0.1, 0.0, 1.0]);
    let e = Absorption::Extinction
        .voxel_value([0.2, 0.1, 0.0, 1.0])
        .unwrap();
    // σ = −ln(1 − (1 − 10⁻⁶)) ≈ 13.8 (in f32, 1 − 10⁻⁶ rounds to 1 − 1.013·10⁻⁶).
    assert!((e[3] - 13.8).abs() < 0.05, "{e:?}");
}
