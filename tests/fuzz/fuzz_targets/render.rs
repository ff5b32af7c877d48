#![no_main]
//! Fuzz target: the core renderer under random views, spacings, zooms, kernels, transfer functions
//! and sample values, float and fixed, both compositing orders. Asserts:
//! - every output pixel is finite premultiplied RGBA in [0, 1] (colour ≤ alpha, up to rounding);
//! - weight conservation: one voxel of premultiplied value `W` whose whole footprint lies on
//!   screen leaves `W × cell_area × S` in total in the sheet accumulator, where S is the sum of
//!   the exact f64 footprint (the harness's reference, no tables) over the same pixels: the
//!   renderer scales a splat by the screen area of a voxel cell so a sheet of equal voxels covers
//!   evenly, and its tables must neither lose nor add weight. The bound is 2 % of S: the largest
//!   `tests/footprint_shapes.rs` allows at table 129 with bilinear lookups (1 %, and 2 % for the
//!   bilinear kernel); the fixed path adds its quantisation. Checked with bilinear lookups (the
//!   default; nearest lookups step, and fuzzing found them 3 % off on a 77:1 footprint 2 pixels
//!   wide, which is their known cost, charted by `footprint chart`) and for the kernels without
//!   negative lobes (Gaussian, cone, bilinear). A sinc footprint's sum is what is left after its
//!   lobes cancel, so a table error relative to the lobes is unbounded relative to the sum
//!   (fuzzing found a 5-lobe sinc squeezed into a 2-pixel footprint whose table sum had the
//!   other sign); sinc renders are checked for finite, valid colour only.
//!   (S itself is not 1: a kernel cut off sharply, sampled by a few pixels, sums to 1 only in the
//!   limit.)
//!
//! Image-aligned slabs (`--slicing image`), level of detail 1 (`--lod 1`) and a refined grid
//! (`--refine`) are rendered too, checked for finite, valid colour.
//!
//! Input bytes are read as parameters in a fixed order (missing bytes read as 0).
use footprint::fixed::{FixedTable, ONE};
use footprint::frame::{FrameSetup, Order};
use footprint::lod::level_frame;
use footprint::render::{FixedPath, FloatPath, PerVoxel, SlabSetup};
use footprint::table::SectionTable;
use footprint::{FootprintOptions, GenericTable, Grid, Kernel, Lookup, View, ViewTable};
use footprint_harness::reference::ReferenceFootprint;
use libfuzzer_sys::fuzz_target;

const N: usize = 129;

struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        let (b, rest) = self.0.split_first().map_or((0, &[][..]), |(b, r)| (*b, r));
        self.0 = rest;
        b
    }
    /// 2^e with e uniform in [-range, range] (256 steps).
    fn log2(&mut self, range: f32) -> f32 {
        (2.0f32).powf((f32::from(self.u8()) - 127.5) / 127.5 * range)
    }
    fn angle(&mut self) -> f32 {
        f32::from(u16::from(self.u8()) << 8 | u16::from(self.u8())) / 65535.0 * 360.0 - 180.0
    }
}

fn kernel(b: &mut Bytes) -> Option<Kernel> {
    let spread = 0.5 + f32::from(b.u8()) / 255.0 * 2.5;
    match b.u8() % 4 {
        0 => Kernel::gaussian(spread, 1.0 + f32::from(b.u8()) / 255.0 * 3.0).ok(),
        1 => Kernel::cone(spread).ok(),
        2 => Kernel::sinc(spread, 1 + b.u8() % 5).ok(),
        _ => Kernel::bilinear(spread).ok(),
    }
}

fn check_image(img: &[[f32; 4]], what: &str) {
    for p in img {
        assert!(
            p.iter()
                .all(|c| c.is_finite() && (-1e-6..=1.0 + 1e-5).contains(c)),
            "{what}: pixel {p:?} is not finite RGBA in [0, 1]"
        );
        assert!(
            p[..3].iter().all(|c| *c <= p[3] + 1e-4),
            "{what}: colour above alpha in {p:?}"
        );
    }
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let dims = [0, 1, 2].map(|_| 1 + usize::from(b.u8() % 6));
    let spacing = [0, 1, 2].map(|_| b.log2(6.0));
    let angles = [b.angle(), b.angle(), b.angle()];
    let zoom = b.log2(5.0);
    let size = [0, 1].map(|_| 4 + usize::from(b.u8() % 61));
    let Some(kernel) = kernel(&mut b) else { return };
    let lookup = if b.u8() % 2 == 0 {
        Lookup::Bilinear
    } else {
        Lookup::Nearest
    };
    let lut: Vec<[f32; 4]> = (0..2 + b.u8() % 6)
        .map(|_| [0, 1, 2, 3].map(|_| f32::from(b.u8()) / 255.0))
        .collect();
    let samples: Vec<u8> = (0..dims.iter().product::<usize>())
        .map(|_| b.u8())
        .collect();

    let Ok(grid) = Grid::from_spacing(spacing) else {
        return;
    };
    let generic = GenericTable::<N>::build(kernel);
    let options = FootprintOptions::default();

    // A volume through the shader, float and fixed, both orders.
    if let Ok(view) = View::from_angles(angles, zoom, dims, &grid, size) {
        if let Ok(frame) = FrameSetup::new(dims, &grid, &view, &kernel, options, size) {
            let table = ViewTable::<N>::build(&frame.footprint, &generic, lookup, lookup);
            let mut fixed = Box::new(FixedTable::<N>::zeroed());
            let fixed_ok = fixed.build_view(&frame, &generic, lookup, lookup).is_ok();
            for order in [Order::BackToFront, Order::FrontToBack] {
                let img = footprint_fuzz::render_volume(
                    &frame,
                    FloatPath::new(&table),
                    order,
                    &samples,
                    &lut,
                );
                check_image(&img, "float render");
                if fixed_ok {
                    if let Ok(path) = FixedPath::new(&frame, &*fixed) {
                        let img =
                            footprint_fuzz::render_volume(&frame, path, order, &samples, &lut);
                        let img: Vec<[f32; 4]> = img
                            .iter()
                            .map(|p| p.map(|c| c as f32 / ONE as f32))
                            .collect();
                        check_image(&img, "fixed render");
                    }
                }
            }
        }
    }

    // Perspective: an eye at a random distance (a few voxels to far away); refusals are fine,
    // a frame that is accepted renders finite RGBA in [0, 1] both ways.
    let eye = 8.0 * b.log2(6.0);
    if let Ok(view) = View::from_angles(angles, zoom, dims, &grid, size) {
        if let Ok(frame) = FrameSetup::perspective(dims, &grid, &view, &kernel, options, size, eye)
        {
            if let Ok(per) = PerVoxel::new(&frame, &kernel, options, &generic, lookup) {
                let path = FloatPath::new(&per);
                for order in [Order::BackToFront, Order::FrontToBack] {
                    let img = footprint_fuzz::render_volume(&frame, path, order, &samples, &lut);
                    check_image(&img, "perspective render");
                }
            }
        }
    }

    // Image slicing: slabs 1/8 to 8 spacings thick; a setup that is accepted renders finite RGBA
    // in [0, 1] both ways (kernels other than the Gaussian are refused).
    let slab = b.log2(3.0);
    if let Ok(view) = View::from_angles(angles, zoom, dims, &grid, size) {
        if let Ok(frame) = FrameSetup::new(dims, &grid, &view, &kernel, options, size) {
            if let Ok(setup) = SlabSetup::new(&frame, &kernel, slab) {
                let mut table = Box::new(SectionTable::<257, 1025>::zeroed(kernel));
                if table.build_into(kernel).is_ok() {
                    for order in [Order::BackToFront, Order::FrontToBack] {
                        let img = footprint_fuzz::render_slabs(
                            &frame, &setup, &table, order, &samples, &lut,
                        );
                        check_image(&img, "slab render");
                    }
                }
            }
        }
    }

    // Level of detail 1, coarsened as it streams and placed where level 0 is seen: a frame that
    // is accepted renders finite RGBA in [0, 1] both ways.
    if let Ok(view) = View::from_angles(angles, zoom, dims, &grid, size) {
        if let Ok(fine) = FrameSetup::new(dims, &grid, &view, &kernel, options, size) {
            if let Ok(level) = level_frame(&fine, &grid, &view, &kernel, options, 1) {
                let table = ViewTable::<N>::build(&level.footprint, &generic, lookup, lookup);
                for order in [Order::BackToFront, Order::FrontToBack] {
                    let img = footprint_fuzz::render_level(
                        &level,
                        dims,
                        FloatPath::new(&table),
                        order,
                        &samples,
                        &lut,
                    );
                    check_image(&img, "level 1 render");
                }
            }
        }
    }

    // Adaptive refinement: factors 1, 2 or 4 per interval from the input, border samples with
    // different spacings on each side (the scaled read, and its stencils for one border key),
    // Catmull-Rom values: finite RGBA in [0, 1] both ways.
    let factors: [Vec<u8>; 3] = [0, 1, 2].map(|a| {
        (1..dims[a])
            .map(|_| [1, 2, 4][usize::from(b.u8() % 3)])
            .collect()
    });
    if let Ok(view) = View::from_angles(angles, zoom, dims, &grid, size) {
        if let Ok(frame) = FrameSetup::new(dims, &grid, &view, &kernel, options, size) {
            let table = ViewTable::<N>::build(&frame.footprint, &generic, lookup, lookup);
            for order in [Order::BackToFront, Order::FrontToBack] {
                let img =
                    footprint_fuzz::render_refined(&frame, &table, order, &samples, &lut, &factors);
                check_image(&img, "refined render");
            }
        }
    }

    // One voxel: its weight is conserved when its footprint is wholly on screen.
    let one = [1, 1, 1];
    let Ok(view) = View::from_angles(angles, zoom, one, &grid, size) else {
        return;
    };
    let Ok(frame) = FrameSetup::new(one, &grid, &view, &kernel, options, size) else {
        return;
    };
    let [ex, ey] = frame.footprint.half_extent;
    // Its support is the footprint's box around the voxel's position, plus a pixel.
    let (x, y) = (frame.origin.x, frame.origin.y);
    let inside = x - ex > 1.0
        && y - ey > 1.0
        && x + ex + 1.0 < size[0] as f32
        && y + ey + 1.0 < size[1] as f32;
    if !inside || matches!(kernel, Kernel::Sinc { .. }) || lookup != Lookup::Bilinear {
        return;
    }
    const W: f32 = 1.0 / 64.0;
    let Ok(exact) = ReferenceFootprint::new(
        &kernel,
        &frame.grid_to_screen.as_dmat3(),
        f64::from(options.min_radius_px),
    ) else {
        return;
    };
    let mut weights = vec![0.0f64; size[0] * size[1]];
    let center = [f64::from(frame.origin.x), f64::from(frame.origin.y)];
    exact.splat(center, size[0], size[1], &mut weights);
    let scale = f64::from(W) * f64::from(frame.cell_area);
    let expected = scale * weights.iter().sum::<f64>();
    let tolerance = 0.02 * expected;
    let table = ViewTable::<N>::build(&frame.footprint, &generic, lookup, lookup);
    let acc = footprint_fuzz::splat_one(&frame, &FloatPath::new(&table), W);
    assert!(
        acc.iter().flatten().all(|c| c.is_finite()),
        "float: non-finite weight"
    );
    let sum: f64 = acc.iter().map(|p| f64::from(p[3])).sum();
    assert!(
        (sum - expected).abs() <= tolerance,
        "float: weight {} of 1 (half extent {ex} x {ey} px)",
        sum / expected
    );
    let mut fixed = Box::new(FixedTable::<N>::zeroed());
    if fixed.build_view(&frame, &generic, lookup, lookup).is_ok() {
        if let Ok(path) = FixedPath::new(&frame, &*fixed) {
            let acc = footprint_fuzz::splat_one(&frame, &path, W);
            let unit = f64::from(ONE) * 2f64.powi(fixed.frac_bits() as i32);
            let sum: f64 = acc.iter().map(|p| p[3] as f64 / unit).sum();
            // Table entries are quantised to 2^-frac_bits of the weight (one rounding each, and
            // a bilinear read of rounded entries): at most one unit per pixel of the image, in
            // units of the voxel value, or of the value times the cell area if that is larger.
            let quantum = (size[0] * size[1]) as f64 / 2f64.powi(fixed.frac_bits() as i32);
            assert!(
                (sum - expected).abs() <= tolerance + quantum * scale.max(f64::from(W)),
                "fixed: weight {} of 1 (half extent {ex} x {ey} px)",
                sum / expected
            );
        }
    }
});
