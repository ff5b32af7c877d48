//! The compact path against brute force: every pixel's weight against the float footprint at
//! the phase's position, renormalised sums exact, the overflow proof's bound, compositing.
// Float is this file's purpose (the integer-only lints are the parent module's).
#![allow(clippy::float_arithmetic, clippy::disallowed_types)]

use super::*;
use crate::frame::FrameSetup;
use crate::geometry::FootprintOptions;
use crate::geometry::{Grid, View};
use crate::kernel::Kernel;
use crate::splat::Direct;
use crate::splat::Sampler;
use crate::table::{GenericTable, Lookup};
use glam::Mat3;
use std::vec;

/// The paper Gaussian's generic table.
fn gaussian() -> GenericTable<33> {
    GenericTable::<33>::build(Kernel::PAPER_GAUSSIAN)
}

/// `frame`'s footprint read straight from `table`.
fn direct<'a>(f: &FrameSetup, table: &'a GenericTable<33>) -> Direct<'a, 33> {
    Direct {
        footprint: f.footprint,
        table,
        lookup: Lookup::Bilinear,
    }
}

fn frame(zoom: f32, az: f32) -> FrameSetup {
    let m = Mat3::from_rotation_x(0.35) * Mat3::from_rotation_y(az) * zoom;
    FrameSetup::new(
        [16, 12, 9],
        &Grid::from_spacing([1.0, 1.0, 1.5]).unwrap(),
        &View::new(m).unwrap(),
        &Kernel::PAPER_GAUSSIAN,
        FootprintOptions::default(),
        [40, 40],
    )
    .unwrap()
}

/// Each pixel a splat updates gets the float footprint's weight at the voxel's phase centre
/// (times the cell area, renormalised over the box where the footprint is), within a rounding
/// LSB of W; a renormalised voxel deposits exactly round(area · 2^W) per unit value.
#[test]
fn a_splat_is_the_footprint_at_its_phase() {
    let table = gaussian();
    for (zoom, az) in [(1.3, 0.5), (0.9, 1.1), (1.6, 2.0), (1.0, 0.0)] {
        let f = frame(zoom, az);
        let sampler = direct(&f, &table);
        let phases = 8;
        let mut buf = vec![0i16; len_for(&f, phases).unwrap()];
        let st = CompactStencils::build(&f, &sampler, phases, &mut buf).unwrap();
        let w_scale = (1u32 << st.frac_bits()) as f32;
        let [bx, by] = st.box_size();
        let mut acc = vec![[0i32; 4]; 40 * 40];
        let mut seed = 0x9e37_79b9u32;
        for _ in 0..300 {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let c = [
                (10 << POS_FRAC) + (seed >> 12) as i32 % (20 << POS_FRAC),
                (10 << POS_FRAC) + (seed >> 3) as i32 % (20 << POS_FRAC),
            ];
            acc.iter_mut().for_each(|p| *p = [0; 4]);
            let mut image = ImageMut::new(&mut acc, 40, 40, 40).unwrap();
            st.splat(c, &[1, 0, 0, 0], &mut image, |_, _, _| {});
            // The phase centre the splat used, and the float weights over the box.
            let phi = |x: i32| (((x & 0xffff) * phases as i32) >> POS_FRAC) as f32 + 0.5;
            let centre = [
                (c[0] >> POS_FRAC) as f32 + phi(c[0]) / phases as f32,
                (c[1] >> POS_FRAC) as f32 + phi(c[1]) / phases as f32,
            ];
            let mut want = vec![0.0f32; 40 * 40];
            for (i, w) in want.iter_mut().enumerate() {
                let q = [
                    (i % 40) as f32 + 0.5 - centre[0],
                    (i / 40) as f32 + 0.5 - centre[1],
                ];
                let inside = q[0].abs() <= f.footprint.half_extent[0]
                    && q[1].abs() <= f.footprint.half_extent[1];
                if inside {
                    *w = sampler.weight(q) * f.cell_area;
                }
            }
            let sum: f32 = want.iter().sum();
            let total: i32 = acc.iter().map(|p| p[0]).sum();
            if f.footprint.renormalise && sum > 0.0 {
                want.iter_mut().for_each(|w| *w *= f.cell_area / sum);
                assert_eq!(total, (f.cell_area * w_scale).round() as i32, "zoom {zoom}");
            }
            for (i, (&got, &w)) in acc.iter().zip(&want).enumerate() {
                let w = w * w_scale;
                // One LSB of rounding, and the largest weight's share of the remainder.
                assert!(
                    (got[0] as f32 - w).abs() <= 1.5 + (bx * by) as f32 * 0.5,
                    "zoom {zoom}, pixel {i}: {} vs {w}",
                    got[0]
                );
            }
        }
    }
}

/// The overflow proof's N holds: no pixel is covered by more voxels of a sheet than N (counted
/// by brute force from the splats' own touched rows, over whole sheets of several views), every
/// weight is at most 65 535 / N, and values above one splat as one.
#[test]
fn no_pixel_is_covered_by_more_voxels_than_the_bound() {
    let table = gaussian();
    for (zoom, az) in [
        (1.3, 0.5),
        (0.9, 1.1),
        (1.6, 2.0),
        (1.0, 0.0),
        (0.6, 0.8),
        (2.0, 2.6),
    ] {
        let f = frame(zoom, az);
        let sampler = direct(&f, &table);
        let mut buf = vec![0i16; len_for(&f, 4).unwrap()];
        let st = CompactStencils::build(&f, &sampler, 4, &mut buf).unwrap();
        let n = st.covering_bound();
        assert!(
            st.max_weight() * n <= 65_535,
            "zoom {zoom}: {} × {n}",
            st.max_weight()
        );
        let place = CompactPlacement::new(&f).unwrap();
        let (_, na, nb) = f.sheet_shape();
        let mut acc = vec![[0i32; 4]; 40 * 40];
        let mut most = 0;
        for s in [0, f.sheet_count() / 2] {
            let mut count = vec![0u32; 40 * 40];
            let mut image = ImageMut::new(&mut acc, 40, 40, 40).unwrap();
            for v in 0..nb {
                for u in 0..na {
                    let c = place.at(s, u, v);
                    st.splat(c, &[1, 0, 0, 0], &mut image, |y, x0, x1| {
                        count[y * 40 + x0..=y * 40 + x1]
                            .iter_mut()
                            .for_each(|k| *k += 1)
                    });
                }
            }
            most = most.max(*count.iter().max().unwrap());
        }
        assert!(
            most >= 2 && most <= n,
            "zoom {zoom}, az {az}: {most} voxels over a pixel, bound {n}"
        );
    }
    // A value above one is one.
    let f = frame(1.3, 0.5);
    let sampler = direct(&f, &table);
    let mut buf = vec![0i16; len_for(&f, 4).unwrap()];
    let st = CompactStencils::build(&f, &sampler, 4, &mut buf).unwrap();
    let c = [20 << POS_FRAC, 20 << POS_FRAC];
    let mut one = vec![[0i32; 4]; 40 * 40];
    let mut huge = one.clone();
    st.splat(
        c,
        &[ONE; 4],
        &mut ImageMut::new(&mut one, 40, 40, 40).unwrap(),
        |_, _, _| {},
    );
    st.splat(
        c,
        &[u16::MAX; 4],
        &mut ImageMut::new(&mut huge, 40, 40, 40).unwrap(),
        |_, _, _| {},
    );
    assert_eq!(one, huge);
    assert_eq!(resolve([i32::MAX; 4], st.frac_bits()), [ONE; 4]);
    assert_eq!(resolve([-5; 4], st.frac_bits()), [0; 4]);
}

/// Compositing a transparent layer changes nothing; an opaque one replaces; halves blend.
#[test]
fn over_is_exact_at_zero_and_one() {
    let back = [1234, 20000, 32768, 32768];
    assert_eq!(over([0; 4], back), back);
    assert_eq!(over([ONE; 4], back), [ONE; 4]);
    let half = ONE / 2;
    assert_eq!(
        over([half, 0, 0, half], [ONE, ONE, ONE, ONE]),
        [ONE, half, half, ONE]
    );
}

/// Footprints too wide for the box limit, no phases, short buffers and perspective are typed
/// refusals.
#[test]
fn refusals_are_typed() {
    let table = gaussian();
    let f = frame(1.3, 0.5);
    let sampler = direct(&f, &table);
    assert!(matches!(len_for(&f, 0), Err(CompactError::Phases { .. })));
    let mut short = [0i16; 4];
    assert!(matches!(
        CompactStencils::build(&f, &sampler, 4, &mut short),
        Err(CompactError::Buffer(_))
    ));
    let wide = frame(6.0, 0.5);
    assert!(matches!(len_for(&wide, 4), Err(CompactError::Wide { .. })));
}
