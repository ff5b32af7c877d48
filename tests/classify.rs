//! The classifier's early-out: `TransferFunction::transparent_at_or_below` is a bound at or below
//! which every value's lookup has opacity exactly 0 (so skipping those values cannot drop a
//! visible voxel), and it is tight: the next `f32` above it is visible when every entry from the
//! first visible one on is. Checked against the lookup itself over random functions and windows.

use footprint::shade::{Shader, Shading, TransferFunction};
use proptest::prelude::*;

/// The next representable `f32` above a finite `v`.
fn next_up(v: f32) -> f32 {
    if v == 0.0 {
        return f32::from_bits(1);
    }
    let b = v.to_bits();
    f32::from_bits(if v > 0.0 { b + 1 } else { b - 1 })
}

fn lut_with(zeros: usize, alphas: &[f32]) -> Vec<[f32; 4]> {
    let mut lut = vec![[0.3, 0.6, 0.9, 0.0]; zeros];
    lut.extend(alphas.iter().map(|&a| [0.5, 0.5, 0.5, a]));
    lut
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn the_bound_is_exact(
        zeros in 0usize..12,
        alphas in prop::collection::vec(1e-4f32..=1.0, 1..24),
        lo in -5000.0f32..5000.0,
        width in prop_oneof![1e-3f32..1.0, 1.0f32..10_000.0],
        probes in prop::collection::vec(-1.0e5f32..1.0e5, 64),
    ) {
        let lut = lut_with(zeros, &alphas);
        let tf = TransferFunction { lut: &lut, lo, hi: lo + width };
        prop_assume!(tf.check().is_ok());
        let bound = tf.transparent_at_or_below();
        if zeros == 0 {
            prop_assert_eq!(bound, f32::NEG_INFINITY);
        } else {
            prop_assert!(bound.is_finite());
            // Sound at the bound and below it.
            prop_assert_eq!(tf.lookup(bound)[3], 0.0);
            prop_assert_eq!(tf.lookup(bound - width * 0.25)[3], 0.0);
            // Tight: every entry from the first visible one on is visible here.
            prop_assert!(tf.lookup(next_up(bound))[3] > 0.0, "bound {bound} is not tight");
        }
        // Brute force: no visible value lies at or below the bound.
        for v in probes.iter().map(|p| lo + p * width * 1e-3).chain(probes.iter().copied()) {
            if tf.lookup(v)[3] > 0.0 {
                prop_assert!(v > bound, "{v} is visible but at or below the bound {bound}");
            }
        }
    }
}

/// The ends: a function with no visible entry is transparent everywhere; one whose first entry is
/// visible has no bound; an iso-surface (opacity from the distance to the iso-value, not the
/// function) never skips.
#[test]
fn the_ends_and_the_iso_surface() {
    let clear = lut_with(5, &[]);
    let tf = TransferFunction {
        lut: &clear,
        lo: 0.0,
        hi: 1.0,
    };
    assert_eq!(tf.transparent_at_or_below(), f32::INFINITY);
    assert_eq!(tf.lookup(1e30)[3], 0.0);
    let ramp = lut_with(1, &[0.5, 1.0]);
    let tf = TransferFunction {
        lut: &ramp,
        lo: 0.0,
        hi: 2.0,
    };
    // Entry 0 is transparent, entry 1 (value 1.0) is not: the bound is the window's low end, or
    // the few denormals above it whose position still rounds to 0.
    let bound = tf.transparent_at_or_below();
    assert!((0.0..1e-37).contains(&bound), "{bound}");
    assert_eq!(tf.lookup(bound)[3], 0.0);
    assert!(tf.lookup(next_up(bound))[3] > 0.0);
    let emission = Shader {
        tf,
        shading: Shading::Emission,
    };
    assert_eq!(emission.transparent_at_or_below(), bound);
    let iso = Shader {
        tf,
        shading: Shading::Iso {
            value: -3.0,
            opacity: 1.0,
            thickness: 1.0,
            phong: footprint::shade::Phong {
                ambient: 0.2,
                diffuse: 0.7,
                specular: 0.1,
                shininess: 10.0,
            },
        },
    };
    assert_eq!(iso.transparent_at_or_below(), f32::NEG_INFINITY);
    // A value of -3 is on that iso-surface, below the function's bound, and visible.
    assert!(iso.visible(-3.0, || glam::Vec3::X));
}
