//! The fixed-point path (`footprint::fixed`): exact 8-bit conversions, compositing that does not
//! drift, saturation instead of wrap-around, agreement with the float path from sub-pixel to
//! larger-than-the-image footprints, a thousand opaque sheets, typed range errors, and
//! bit-identical output on every run and thread.

use footprint::fixed::stencil::{len_for, FixedStencils};
use footprint::fixed::{self, composite, FixedError, FixedTable, ONE};
use footprint::frame::{FrameSetup, Order};
use footprint::geometry::FootprintOptions;
use footprint::render::FixedPath;
use footprint::splat::ImageMut;
use footprint::{GenericTable, Grid, Kernel, Lookup, View, ViewTable};
use footprint_suite::{assert_le, render_with};
use glam::Mat3;

/// One in the fixed path's value and image format, as f64.
const Q: f64 = ONE as f64;

fn frame(dims: [usize; 3], zoom: f32, size: usize) -> FrameSetup {
    let view = View::new(Mat3::from_rotation_z(0.3) * zoom).unwrap();
    FrameSetup::new(
        dims,
        &Grid::from_spacing([1.0; 3]).unwrap(),
        &view,
        &Kernel::PAPER_GAUSSIAN,
        FootprintOptions::default(),
        [size, size],
    )
    .unwrap()
}

/// The float (view table) and fixed (view table, same size and lookup) renders, both as f32.
fn float_and_fixed(
    f: &FrameSetup,
    order: Order,
    lookup: Lookup,
    sheet: &dyn Fn(usize) -> Vec<[f32; 4]>,
) -> (Vec<[f32; 4]>, Vec<[u32; 4]>) {
    let generic = GenericTable::<65>::build(Kernel::PAPER_GAUSSIAN);
    let view = ViewTable::<65>::build(&f.footprint, &generic, lookup, lookup);
    let float = render_with(f, footprint::render::FloatPath::new(&view), order, sheet);
    let mut table = Box::new(FixedTable::<65>::zeroed());
    table.build_view(f, &generic, lookup, lookup).unwrap();
    let fixed = render_with(f, FixedPath::new(f, &*table).unwrap(), order, sheet);
    (float, fixed)
}

fn max_abs_diff(a: &[[f32; 4]], b: &[[u32; 4]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..4).map(move |c| (f64::from(x[c]) - f64::from(y[c]) / Q).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn eight_bit_conversions_round_exactly_and_invert() {
    for v in 0..=255u8 {
        assert_eq!(fixed::to_u8(fixed::from_u8(v)), v, "round trip of {v}");
    }
    for q in 0..=ONE {
        let exact = (f64::from(q) * 255.0 / Q + 0.5).floor() as u8;
        assert_eq!(fixed::to_u8(q), exact, "to_u8({q})");
    }
    assert_eq!(fixed::to_u8(ONE), 255);
    assert_eq!(fixed::to_u8(u32::MAX), 255, "clamped above one");
    assert_eq!(fixed::from_u8(255), ONE);
}

#[test]
fn transparent_sheets_leave_the_image_bit_identical() {
    // Pseudo-random premultiplied pixels.
    let mut seed = 0x2545_f491u32;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed % (ONE + 1)
    };
    let image: Vec<[u32; 4]> = (0..4096)
        .map(|_| {
            let a = next();
            [next() % (a + 1), next() % (a + 1), next() % (a + 1), a]
        })
        .collect();
    for order in [Order::BackToFront, Order::FrontToBack] {
        let mut img = image.clone();
        let mut acc = vec![[0i64; 4]; img.len()];
        for _ in 0..1000 {
            composite::composite_row(&mut acc, &mut img, 30, order);
        }
        assert_eq!(
            img, image,
            "{order:?}: a thousand empty sheets changed the image"
        );
    }
}

#[test]
fn a_thousand_translucent_sheets_do_not_drift() {
    // Sheet after sheet of colour c at opacity α, composited over: the exact result is
    // c·(1 − (1 − α)ⁿ). Each step rounds once (≤ ½ LSB), and earlier errors shrink by (1 − α),
    // so the error stays below ½ / α LSB whatever n is; a truncating or ×255/256 compositor
    // loses a whole LSB every sheet instead.
    for &(alpha, colour) in &[(0.01f64, 0.7f64), (0.002, 0.3), (0.5, 1.0)] {
        let s = [colour * alpha, colour * alpha, colour * alpha, alpha];
        let sq = s.map(|x| (x * Q).round() as u32);
        let (cq, aq) = (f64::from(sq[0]) / Q, f64::from(sq[3]) / Q);
        let (mut back, mut front) = ([0u32; 4], [0u32; 4]);
        for n in 1..=1000 {
            back = composite::over(sq, back);
            front = composite::over(front, sq);
            let exact_c = cq * (1.0 - (1.0 - aq).powi(n)) / aq;
            let exact_a = 1.0 - (1.0 - aq).powi(n);
            let bound = 0.5 / aq / Q + 1e-12;
            for (img, order) in [(back, "over"), (front, "under")] {
                assert_le((f64::from(img[0]) / Q - exact_c).abs(), bound, order);
                assert_le((f64::from(img[3]) / Q - exact_a).abs(), bound, order);
            }
        }
    }
}

#[test]
fn accumulator_and_image_saturate_instead_of_wrapping() {
    assert_eq!(composite::resolve([i64::MAX; 4], 30), [ONE; 4]);
    assert_eq!(composite::resolve([i64::MIN; 4], 30), [0; 4]);
    assert_eq!(composite::resolve([i64::MAX; 4], 0), [ONE; 4]);
    // Colours can exceed one only from invalid (colour > alpha) input; they stop at u32::MAX.
    assert_eq!(
        composite::over([u32::MAX, 0, 0, 0], [u32::MAX; 4])[0],
        u32::MAX
    );

    // A splat into an accumulator already at the top stays at the top.
    let f = frame([1, 1, 1], 8.0, 32);
    let generic = GenericTable::<33>::build(Kernel::PAPER_GAUSSIAN);
    let mut table = FixedTable::<33>::zeroed();
    table
        .build_view(&f, &generic, Lookup::Bilinear, Lookup::Bilinear)
        .unwrap();
    let mut acc = vec![[i64::MAX - 5, i64::MAX - 5, i64::MIN + 5, 0]; 32 * 32];
    let mut img = ImageMut::new(&mut acc, 32, 32, 32).unwrap();
    let center = [16i64 << 24, 16 << 24];
    let stats = fixed::splat::splat(
        &table,
        center,
        &[ONE, ONE, 0, 1 << 24],
        &mut img,
        |_, _, _| {},
    );
    assert!(stats.pixels_updated > 100);
    let touched: Vec<_> = acc.iter().filter(|p| p[3] != 0).collect();
    assert_eq!(touched.len(), stats.pixels_updated as usize);
    for p in touched {
        assert_eq!(p[0], i64::MAX, "wrapped instead of saturating");
        assert_eq!(p[2], i64::MIN + 5, "a zero value moved the channel");
        assert!(p[3] > 0);
    }
}

#[test]
fn out_of_range_views_are_typed_errors() {
    // A volume whose corners land beyond 2³⁰ px from the image (footprints of 8·10⁵ px are
    // still accepted by the geometry).
    let f = frame([16384, 16384, 1], 5e5, 64);
    assert!(matches!(
        footprint::fixed::Placement::new(&f),
        Err(FixedError::Range { .. })
    ));
    assert!(footprint::fixed::Placement::new(&frame([64, 64, 1], 5e5, 64)).is_ok());
}

#[test]
fn single_splats_match_float_from_subpixel_to_larger_than_the_image() {
    // One voxel at a fractional position, α = ½: footprint half-extents from under a pixel
    // (renormalised) to ~1200 px on a 64×64 image. Tolerance: 2⁻¹⁶ of the peak (measured:
    // 1.4·10⁻⁷ … 4.2·10⁻⁶), far below what 8-bit output shows.
    for &zoom in &[0.2f32, 1.0, 3.0, 20.0, 400.0] {
        for lookup in [Lookup::Nearest, Lookup::Bilinear] {
            let f = frame([1, 1, 1], zoom, 64);
            let (float, fixed) = float_and_fixed(&f, Order::BackToFront, lookup, &|_| {
                vec![[0.3, 0.4, 0.5, 0.5]]
            });
            let peak = float.iter().map(|p| p[3]).fold(0.0f32, f32::max);
            assert!(peak > 0.0, "zoom {zoom}: nothing rendered");
            let d = max_abs_diff(&float, &fixed);
            eprintln!(
                "zoom {zoom} {lookup:?}: max |fixed − float| = {:.2e} of peak",
                d / f64::from(peak)
            );
            assert_le(
                d,
                f64::from(peak) / 65536.0,
                &format!("zoom {zoom} {lookup:?}"),
            );
            let sum = |v: &mut dyn Iterator<Item = f64>| v.sum::<f64>();
            let (sf, sx) = (
                sum(&mut float.iter().map(|p| f64::from(p[3]))),
                sum(&mut fixed.iter().map(|p| f64::from(p[3]) / Q)),
            );
            assert_le(
                (sf - sx).abs(),
                1e-4 * sf.max(1e-3),
                &format!("zoom {zoom} total"),
            );
        }
    }
}

#[test]
fn direct_fixed_matches_direct_float() {
    let f = frame([1, 1, 1], 6.0, 64);
    let generic = GenericTable::<33>::build(Kernel::PAPER_GAUSSIAN);
    let direct = footprint::splat::Direct {
        footprint: f.footprint,
        table: &generic,
        lookup: Lookup::Bilinear,
    };
    let sheet = |_| vec![[0.2, 0.3, 0.4, 0.6]];
    let float = render_with(
        &f,
        footprint::render::FloatPath::new(&direct),
        Order::BackToFront,
        &sheet,
    );
    let mut table = FixedTable::<33>::zeroed();
    table.build_direct(&f, &generic, Lookup::Bilinear).unwrap();
    let fixed = render_with(
        &f,
        FixedPath::new(&f, &table).unwrap(),
        Order::BackToFront,
        &sheet,
    );
    assert_le(max_abs_diff(&float, &fixed), 0.6 / 65536.0, "direct method");
}

/// ≥ 1000 sheets of opacity-1 voxels whose footprints (~1300 px) dwarf the 64×64 image, and the
/// same with opacity 0.003 (which accumulates to ≈ 0.95 only through all 1000 sheets).
/// Tolerances against the float path: 2⁻²⁰ opaque (measured 0), 2⁻¹⁴ translucent (measured
/// 1.5·10⁻⁵: one rounding per sheet, weighted by the light that still gets through).
#[test]
fn a_thousand_opaque_sheets_with_huge_footprints() {
    let f = frame([3, 3, 1000], 400.0, 64);
    assert_eq!(f.sheet_count(), 1000);
    assert!(
        f.footprint.half_extent[0] > 600.0,
        "{:?}",
        f.footprint.half_extent
    );
    for (alpha, tol) in [(1.0f32, 1.0 / 1048576.0), (0.003, 1.0 / 16384.0)] {
        let sheet = move |s: usize| {
            let c = alpha * (s % 10) as f32 / 10.0;
            vec![[c, 0.5 * c, alpha - c, alpha]; 9]
        };
        for order in [Order::BackToFront, Order::FrontToBack] {
            let (float, fixed) = float_and_fixed(&f, order, Lookup::Bilinear, &sheet);
            for p in &fixed {
                assert!(p[3] <= ONE, "alpha {} beyond one", p[3]);
                assert!(
                    p.iter().all(|&c| c <= ONE + 4),
                    "wrapped or overflowed: {p:?}"
                );
            }
            let d = max_abs_diff(&float, &fixed);
            eprintln!("1000 sheets, α {alpha} {order:?}: max |fixed − float| = {d:.2e}");
            assert_le(d, tol, &format!("α {alpha} {order:?}"));
            let mean_alpha = fixed.iter().map(|p| f64::from(p[3])).sum::<f64>() / Q / 4096.0;
            assert!(
                mean_alpha > 0.9,
                "α {alpha} {order:?}: only {mean_alpha} opaque"
            );
        }
    }
}

#[test]
fn fixed_output_is_bit_identical_across_runs_and_threads() {
    let f = frame([24, 20, 16], 2.5, 96);
    let sheet = |s: usize| {
        (0..24 * 20)
            .map(|i| {
                let a = ((i * 7 + s * 13) % 17) as f32 / 40.0;
                [a * 0.9, a * 0.5, a * 0.2, a]
            })
            .collect::<Vec<_>>()
    };
    let run = || float_and_fixed(&f, Order::BackToFront, Lookup::Bilinear, &sheet).1;
    let first = fixed::checksum(&run());
    assert_eq!(fixed::checksum(&run()), first);
    let sums: Vec<u32> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|_| s.spawn(|| fixed::checksum(&run())))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(sums.iter().all(|&c| c == first), "{sums:x?} vs {first:x}");
}

/// A sheet sum with alpha pushed below zero (or above one) by a negative lobe while colour stays
/// positive becomes a valid premultiplied colour, alpha in [0, 1] and colour in [0, alpha], in
/// float and fixed alike (the render fuzz target found colour without coverage before this).
#[test]
fn resolved_sheet_pixels_are_valid_premultiplied_colours() {
    use footprint::composite::clamp_unit;
    let cases: [[f32; 4]; 6] = [
        [0.3, 0.1, 0.0, -0.2],
        [0.3, 0.1, 0.05, 0.2],
        [1.7, 0.4, -0.5, 1.3],
        [-0.1, -0.2, -0.3, -0.4],
        [0.25, 0.5, 0.75, 1.0],
        [f32::NAN, 0.1, 0.2, f32::NAN],
    ];
    let want: [[f32; 4]; 6] = [
        [0.0; 4],
        [0.2, 0.1, 0.05, 0.2],
        [1.0, 0.4, 0.0, 1.0],
        [0.0; 4],
        [0.25, 0.5, 0.75, 1.0],
        [0.0, 0.0, 0.0, 0.0],
    ];
    for (c, w) in cases.iter().zip(&want) {
        assert_eq!(clamp_unit(*c), *w, "float {c:?}");
        if c.iter().all(|v| v.is_finite()) {
            // The same sums in Q(24 + 8).
            let acc = c.map(|v| (f64::from(v) * f64::from(ONE) * 256.0).round() as i64);
            let q = w.map(|v| (f64::from(v) * f64::from(ONE)).round() as u32);
            assert_eq!(composite::resolve(acc, 8), q, "fixed {c:?}");
        }
    }
}

/// Integer phase stencils (`fixed::stencil`) against the table walk they are sampled from: one
/// voxel at many Q24 positions, footprints from renormalised (half-extent 1.5 px) to wide ones
/// (boxes of 23 and 39 px at 14 and 8 phases, the edge read from the table), round and sheared.
/// At a phase node a stencil is the walk's own weights (renormalised there the same way): within
/// 10⁻⁵ of the peak (2·10⁻⁴ when P is not a power of two, as the node's Q24 position then rounds
/// to just before it). Between nodes the blend of the four around it differs from the walk by
/// the interpolation error over 1/P px, which for a narrow footprint is largest at the support's
/// edge, where the truncated Gaussian drops from 4.4 % of its peak to zero between phases, and
/// for renormalised footprints, whose normalisation changes between phases: within 1.2·10⁻² of
/// the peak (measured up to 8.2·10⁻³; wide footprints blended up to the edge, 7.9·10⁻³; edged ones,
/// whose edge is read exactly, 6.9·10⁻⁴).
/// The float stencils blend the same way, and `verify` measures the effect on whole images. A
/// renormalised voxel's total deposit equals the walk's up to per-pixel rounding.
#[test]
fn integer_stencils_match_the_table_walk() {
    let generic = GenericTable::<65>::build(Kernel::PAPER_GAUSSIAN);
    let (mut checked, mut blended_checked) = (0, 0);
    for (zoom, shear) in [
        (0.6f32, 0.0f32),
        (1.0, 0.3),
        (1.7, 0.0),
        (2.5, 0.6),
        (3.5, 0.2),
        (6.0, 0.4),
        (11.0, 0.1),
    ] {
        let m = Mat3::from_rotation_x(shear) * Mat3::from_rotation_z(0.3 + shear) * zoom;
        let f = FrameSetup::new(
            [1, 1, 1],
            &Grid::from_spacing([1.0, 1.0, 1.4]).unwrap(),
            &View::new(m).unwrap(),
            &Kernel::PAPER_GAUSSIAN,
            FootprintOptions::default(),
            [64, 64],
        )
        .unwrap();
        let mut table = Box::new(FixedTable::<65>::zeroed());
        table
            .build_view(&f, &generic, Lookup::Bilinear, Lookup::Bilinear)
            .unwrap();
        // As the harness picks them: 32 for narrow footprints, fewer for wide ones, edged and
        // (where the float plan blends them) blended up to the edge.
        let plan = footprint::stencil::plan_for(&f.footprint, 32).unwrap();
        let wide = plan.side > footprint::stencil::NARROW_SIDE;
        for blended in [false, true] {
            if blended && (plan.edged || !wide) {
                continue;
            }
            let p = if blended {
                plan.phases as i64
            } else {
                footprint::stencil::edged_phases_for(&f.footprint, 32) as i64
            };
            let Some(len) = len_for(&table, p as usize) else {
                panic!("zoom {zoom}: expected stencils")
            };
            let mut buffer = vec![0i32; len];
            let build = if blended {
                FixedStencils::build_blended
            } else {
                FixedStencils::build
            };
            let stencils = build(&table, p as usize, &mut buffer).unwrap();
            blended_checked += usize::from(blended);
            let mut most = 0.0f64;
            let mut at_nodes = 0.0f64;
            for k in 0..97i64 {
                // Q24 positions spread over the pixel, phase cells and their edges included; every
                // fourth exactly on a phase node (a · 2²⁴ / P, rounded down as the stencils are).
                let node = k % 4 == 0;
                let center = if node {
                    [
                        (31 << 24) + ((k % (p + 1)) << 24) / p,
                        (32 << 24) + ((k * 7 % (p + 1)) << 24) / p,
                    ]
                } else {
                    [
                        (31 << 24) + (k * 0x2F_5A3B) % (1 << 24),
                        (32 << 24) + (k * 0x61_C88F + (k & 3) * (1 << 22)) % (1 << 24),
                    ]
                };
                let value = [ONE / 3, ONE / 2, ONE / 4, ONE];
                let splat = |use_stencils: bool| {
                    let mut acc = vec![[0i64; 4]; 64 * 64];
                    let mut img = ImageMut::new(&mut acc, 64, 64, 64).unwrap();
                    if use_stencils {
                        stencils.splat(center, &value, &mut img, |_, _, _| {});
                    } else {
                        fixed::splat::splat(&table, center, &value, &mut img, |_, _, _| {});
                    }
                    acc
                };
                let (walk, st) = (splat(false), splat(true));
                let peak = walk.iter().map(|p| p[3]).max().unwrap() as f64;
                let worst = walk
                    .iter()
                    .zip(&st)
                    .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs() as f64))
                    .fold(0.0, f64::max);
                let what = format!("zoom {zoom} shear {shear} k {k}");
                if !blended && stencils.side() > footprint::stencil::NARROW_SIDE {
                    // Edged: no blend crosses the support's edge, so no pixel outside the walk's
                    // support gets weight (a blend there would, from the corners inside it).
                    for (i, (a, b)) in walk.iter().zip(&st).enumerate() {
                        assert!(
                            a[3] != 0 || b[3] == 0,
                            "{what}: pixel {i} outside the support"
                        );
                    }
                }
                if node {
                    at_nodes = at_nodes.max(worst / peak);
                    // Exact up to rounding for P a power of two; otherwise a node a·2²⁴/P rounds
                    // down to 255/256 of the way from the node before it.
                    let bound = if p.count_ones() == 1 { 1e-5 } else { 2e-4 };
                    assert_le(worst, bound * peak, &what);
                } else {
                    most = most.max(worst / peak);
                    assert_le(worst, 1.2e-2 * peak, &what);
                }
                let total = |a: &[[i64; 4]]| a.iter().map(|p| p[3] as f64).sum::<f64>();
                if f.footprint.renormalise {
                    // Both deposit the cell area's share exactly, up to per-pixel rounding.
                    assert_le(
                        (total(&walk) - total(&st)).abs(),
                        1e-6 * total(&walk),
                        &format!("zoom {zoom} total"),
                    );
                }
                checked += 1;
            }
            eprintln!(
            "zoom {zoom} shear {shear} (blended to the edge: {blended}): half-extent {:?} px, {p} phases, box {} px, renormalised {}, max |stencils − walk| = {most:.2e} of peak ({at_nodes:.2e} at phase nodes)",
            f.footprint.half_extent, stencils.side(), f.footprint.renormalise
        );
        }
    }
    assert_eq!(checked, (7 + blended_checked) * 97);
    assert!(
        blended_checked >= 2,
        "{blended_checked} wide footprints blended to the edge"
    );
}

/// For each zoom, the frame (`size` px) and its 65-node table, and for each of blended and edged
/// the integer stencils built for it (skipped where they do not apply): `check(zoom, blended,
/// frame, table, stencils)`.
fn with_stencils(
    zooms: &[f32],
    size: usize,
    mut check: impl FnMut(f32, bool, &FrameSetup, &FixedTable<65>, FixedStencils<'_, 65>),
) {
    let generic = GenericTable::<65>::build(Kernel::PAPER_GAUSSIAN);
    for &zoom in zooms {
        let f = frame([9, 8, 7], zoom, size);
        let mut table = Box::new(FixedTable::<65>::zeroed());
        table
            .build_view(&f, &generic, Lookup::Bilinear, Lookup::Bilinear)
            .unwrap();
        for blended in [false, true] {
            let p = if blended {
                footprint::stencil::phases_for(&f.footprint, 32)
            } else {
                footprint::stencil::edged_phases_for(&f.footprint, 32)
            };
            let Some(len) = len_for(&table, p) else {
                continue;
            };
            let mut buffer = vec![0i32; len];
            let build = if blended {
                FixedStencils::build_blended
            } else {
                FixedStencils::build
            };
            if let Ok(st) = build(&table, p, &mut buffer) {
                check(zoom, blended, &f, &table, st);
            }
        }
    }
}

/// With a value bound (`FixedPath::with_value_bound`) the integer stencils add without
/// saturating where the bound proves every pixel's sum stays inside `i64`: the image is the
/// saturating path's, bit for bit, from minified to magnified footprints (narrow, blended and
/// edged); a voxel above the bound is refused with a typed error, not splatted.
#[test]
fn unsaturated_stencil_adds_match_saturating_ones() {
    use footprint::render::RenderError;
    let generic = GenericTable::<65>::build(Kernel::PAPER_GAUSSIAN);
    let mut unsaturated = 0;
    let zooms = [0.3f32, 1.0, 2.5, 7.0, 14.0];
    with_stencils(&zooms, 96, |zoom, blended, f, table, st| {
        let (_, na, nb) = f.sheet_shape();
        let sheet = |s: usize| -> Vec<[f32; 4]> {
            (0..na * nb)
                .map(|i| {
                    let a = ((i * 37 + s * 11) % 17) as f32 / 16.0;
                    [a * 0.9, a * 0.5, a * 0.2, a]
                })
                .collect()
        };
        let path = || FixedPath::new(f, table).unwrap().with_stencils(st);
        let bounded = path().with_value_bound(ONE);
        unsaturated += usize::from(bounded.unsaturated());
        assert_eq!(
            render_with(f, path(), Order::BackToFront, &sheet),
            render_with(f, bounded, Order::BackToFront, &sheet),
            "zoom {zoom}, blended {blended}"
        );
    });
    assert!(
        unsaturated >= 6,
        "{unsaturated} configurations added unsaturated"
    );

    // Above the bound: refused.
    let f = frame([9, 8, 7], 2.5, 96);
    let mut table = Box::new(FixedTable::<65>::zeroed());
    table
        .build_view(&f, &generic, Lookup::Bilinear, Lookup::Bilinear)
        .unwrap();
    let mut buffer = vec![0i32; len_for(&table, 32).unwrap()];
    let st = FixedStencils::build(&table, 32, &mut buffer).unwrap();
    let path = FixedPath::new(&f, &*table)
        .unwrap()
        .with_stencils(st)
        .with_value_bound(ONE / 2);
    assert!(path.unsaturated());
    let (len, _, _) = f.sheet_shape();
    let err = footprint_suite::try_render_with(&f, path, Order::BackToFront, &|_| {
        vec![[0.9, 0.9, 0.9, 0.9]; len]
    })
    .unwrap_err();
    assert!(
        matches!(err, RenderError::ValueAboveBound { bound, .. } if bound == ONE / 2),
        "{err}"
    );
}

/// A grey voxel (R = G = B) is splatted by the stencils with each colour product computed once:
/// its red, green and alpha sums equal those of a voxel whose blue differs (which takes the
/// per-channel loop), and its blue equals its red, for the saturating and the unsaturated adds,
/// from narrow to edged footprints, at centres all over the phase grid and across the image edge.
#[test]
fn grey_voxels_splat_as_the_per_channel_loop() {
    let size = 48;
    let mut checked = 0;
    with_stencils(&[0.3, 1.0, 2.5, 7.0], size, |zoom, _, _, _, st| {
        let (c, a) = (ONE / 3 + 7, ONE / 2 + 11);
        for unsaturated in [false, true] {
            let mut grey = vec![[0i64; 4]; size * size];
            let mut other = grey.clone();
            for k in 0..97i64 {
                // Centres (Q24 px) over the image and past its edges, at every sort of phase.
                let at = |n: i64| (n * 1_234_567 + k * 7_654_321) % (60 << 24) - (6 << 24);
                let centre = [at(3 + k), at(5 + 2 * k)];
                for (acc, value) in [(&mut grey, [c, c, c, a]), (&mut other, [c, c, c + 1, a])] {
                    let mut img = ImageMut::new(acc, size, size, size).unwrap();
                    if unsaturated {
                        st.splat_unsaturated(centre, &value, &mut img, |_, _, _| {});
                    } else {
                        st.splat(centre, &value, &mut img, |_, _, _| {});
                    }
                }
            }
            assert!(
                grey.iter().any(|p| p[0] != 0),
                "zoom {zoom}: nothing splatted"
            );
            for (g, o) in grey.iter().zip(&other) {
                assert_eq!(
                    [g[0], g[1], g[2], g[3]],
                    [o[0], o[1], o[0], o[3]],
                    "zoom {zoom}"
                );
            }
            checked += 1;
        }
    });
    assert!(checked >= 6, "{checked} configurations checked");
}

/// Integer stencils read at the nearest phase (`FixedStencils::with_phase_lookup`): a voxel
/// anywhere in a pixel splats exactly what the blended stencils splat at the phase node nearest
/// it (a + [f ≥ ½] per axis, f the Q8 fraction), bit for bit, where that node's Q24 position is
/// exact (P a power of two); and for any P within the node bound of the table walk at that
/// node. So the footprint is only moved, by at most 1/(2P) px per axis, and each voxel deposits
/// what its stencil sums to. Narrow and blended footprints, renormalised ones included; an
/// edged footprint ignores the lookup and is blended.
#[test]
fn nearest_phase_integer_stencils_are_the_nearest_nodes_blend() {
    use footprint::stencil::PhaseLookup;
    let value = [ONE / 3, ONE / 2, ONE / 4, ONE];
    let (mut exact, mut nodes, mut edged) = (0, 0, 0);
    let zooms = [0.6f32, 1.0, 1.7, 3.5, 6.0, 11.0];
    with_stencils(&zooms, 64, |zoom, blended, _, table, st| {
        let p = st.phases() as i64;
        let nearest = st.with_phase_lookup(PhaseLookup::Nearest);
        let wide = st.side() > footprint::stencil::NARROW_SIDE && !blended;
        assert_eq!(
            nearest.phase_lookup(),
            if wide {
                PhaseLookup::Blend
            } else {
                PhaseLookup::Nearest
            }
        );
        let splat = |center: [i64; 2], how: u8| {
            let mut acc = vec![[0i64; 4]; 64 * 64];
            let mut img = ImageMut::new(&mut acc, 64, 64, 64).unwrap();
            match how {
                0 => nearest.splat(center, &value, &mut img, |_, _, _| {}),
                1 => st.splat(center, &value, &mut img, |_, _, _| {}),
                _ => fixed::splat::splat(table, center, &value, &mut img, |_, _, _| {}),
            };
            acc
        };
        for k in 0..61i64 {
            let center = [
                (31 << 24) + (k * 0x2F_5A3B + (k & 1) * (1 << 23)) % (1 << 24),
                (32 << 24) + (k * 0x61_C88F + (k & 2) * (1 << 22)) % (1 << 24),
            ];
            if wide {
                // Edged: blended whatever the lookup.
                assert_eq!(splat(center, 0), splat(center, 1), "zoom {zoom} k {k}");
                edged += 1;
                continue;
            }
            // The nearest node per axis, as the splat picks it from the Q8 fraction.
            let snap = |c: i64| {
                let i = c >> 24;
                let t = (c - (i << 24)) * p;
                let cell = (t >> 24).min(p - 1);
                let f = (t - (cell << 24)) >> 16;
                (i << 24) + (((cell + i64::from(f >= 128)) << 24) / p)
            };
            let node = center.map(snap);
            let got = splat(center, 0);
            let what = format!("zoom {zoom} blended {blended} P {p} k {k}");
            if p.count_ones() == 1 {
                assert_eq!(got, splat(node, 1), "{what}: the node's blend");
                exact += 1;
            }
            let walk = splat(node, 2);
            let peak = walk.iter().map(|q| q[3]).max().unwrap() as f64;
            let worst = walk
                .iter()
                .zip(&got)
                .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs() as f64))
                .fold(0.0, f64::max);
            let bound = if p.count_ones() == 1 { 1e-5 } else { 2e-4 };
            assert_le(worst, bound * peak, &what);
            nodes += 1;
        }
    });
    assert!(
        exact >= 61 * 4 && nodes > exact && edged > 0,
        "{exact} {nodes} {edged}"
    );
}
