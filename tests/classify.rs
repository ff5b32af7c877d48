//! The classifier's early-out: `TransferFunction::transparent_at_or_below` is a bound at or below
//! which every value's lookup has opacity exactly 0 (so skipping those values cannot drop a
//! visible voxel), and it is tight: the next `f32` above it is visible when every entry from the
//! first visible one on is. `visible_interval` is the set of values whose lookup has opacity
//! above 0, exactly, where that set is one interval, and the classifier that tests visibility
//! with it keeps exactly the voxels the lookup keeps. Checked against the lookup itself over
//! random functions and windows.

use footprint::frame::FrameSetup;
use footprint::geometry::FootprintOptions;
use footprint::render::{classify_sheet, SheetWindow, VisibleVoxel};
use footprint::shade::{Phong, Shader, Shading, TransferFunction, RAMP_MIN_OPACITY};
use footprint::{Grid, Kernel, View};
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

/// The lighting the tests' Phong and iso-surface shaders use.
const PHONG: Phong = Phong {
    ambient: 0.2,
    diffuse: 0.7,
    specular: 0.1,
    shininess: 10.0,
};

/// An iso-surface at `value` over `tf` (opacity from the distance to it, not from `tf`).
fn iso_at(tf: TransferFunction<'_>, value: f32) -> Shader<'_> {
    Shader {
        labels: None,
        tf,
        shading: Shading::Iso {
            value,
            opacity: 1.0,
            thickness: 1.0,
            phong: PHONG,
        },
    }
}

/// The next representable `f32` below a finite `v`.
fn next_down(v: f32) -> f32 {
    -next_up(-v)
}

/// Whether `v` lies in `interval` (NaN in none).
fn inside(interval: Option<(f32, f32)>, v: f32) -> bool {
    interval.is_some_and(|(low, high)| low <= v && v <= high)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Where every entry from the first visible one on is at least `RAMP_MIN_OPACITY`, the
    /// interval holds exactly the values whose lookup is visible: at its ends and one `f32`
    /// beyond them, over random bit patterns (NaN, ±∞, denormals, values whose position
    /// overflows), and across the window.
    #[test]
    fn the_visible_interval_is_exact(
        zeros in 0usize..6,
        alphas in prop::collection::vec(
            prop_oneof![Just(RAMP_MIN_OPACITY), RAMP_MIN_OPACITY..=1.0f32],
            1..20,
        ),
        lo in prop_oneof![-5000.0f32..5000.0, Just(0.0), -1e30f32..1e30],
        width in prop_oneof![1e-30f32..1e-20, 1e-3f32..1.0, 1.0f32..10_000.0, 1e30f32..1e36],
        bits in prop::collection::vec(any::<u32>(), 200),
        across in prop::collection::vec(-0.5f32..1.5, 200),
    ) {
        let lut = lut_with(zeros, &alphas);
        let tf = TransferFunction { lut: &lut, lo, hi: lo + width };
        prop_assume!(tf.check().is_ok());
        let interval = tf.visible_interval();
        let (low, high) = interval.expect("a ramp's visible values are one interval");
        let mut probes: Vec<f32> = bits.into_iter().map(f32::from_bits).collect();
        probes.extend(across.iter().map(|t| lo + t * width));
        probes.extend([low, high, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0]);
        probes.extend([f32::MAX, -f32::MAX, lo, lo + width]);
        if low > -f32::MAX {
            probes.push(next_down(low));
        }
        if high < f32::MAX {
            probes.push(next_up(high));
        }
        for v in probes {
            let visible = tf.lookup(v)[3] > 0.0;
            prop_assert_eq!(inside(interval, v), visible, "{} in [{}, {}]", v, low, high);
        }
        // The ends are visible themselves.
        prop_assert!(tf.lookup(low)[3] > 0.0 && tf.lookup(high)[3] > 0.0);
    }
}

/// No interval where opacity returns to 0 (or to below `RAMP_MIN_OPACITY`) after the first
/// visible entry, where nothing is visible, for an iso-surface, or for a function that does not
/// check.
#[test]
fn no_interval_where_visibility_is_not_one() {
    let tf = |lut: &[[f32; 4]]| {
        TransferFunction {
            lut,
            lo: 0.0,
            hi: 1.0,
        }
        .visible_interval()
    };
    assert!(tf(&lut_with(2, &[0.5, 0.0, 0.5])).is_none());
    assert!(tf(&lut_with(0, &[0.5, RAMP_MIN_OPACITY / 2.0])).is_none());
    assert!(tf(&lut_with(4, &[])).is_none());
    assert!(
        tf(&lut_with(0, &[0.5])).is_none(),
        "one entry does not check"
    );
    assert!(tf(&lut_with(1, &[0.5, 1.0])).is_some());
    let ramp = lut_with(1, &[0.5, 1.0]);
    let tf = TransferFunction {
        lut: &ramp,
        lo: 0.0,
        hi: 2.0,
    };
    let iso = iso_at(tf, 1.0);
    assert!(iso.visible_interval().is_none());
    let emission = Shader {
        labels: None,
        tf,
        shading: Shading::Emission,
    };
    assert_eq!(emission.visible_interval(), tf.visible_interval());
}

/// The classifier keeps exactly the voxels, in order, whose lookup is visible: through the
/// interval without a branch (emission), through the interval with gradients (Phong), and
/// through the lookup (a function whose opacity returns to 0), on sheets of values around the
/// interval's ends, NaN and ±∞ among them.
#[test]
fn the_classifier_keeps_what_the_lookup_keeps() {
    let dims = [37, 23, 3];
    let frame = FrameSetup::new(
        dims,
        &Grid::from_spacing([1.0; 3]).unwrap(),
        &View::new(glam::Mat3::IDENTITY * 2.0).unwrap(),
        &Kernel::PAPER_GAUSSIAN,
        FootprintOptions::default(),
        [64, 64],
    )
    .unwrap();
    let (len, na, _) = frame.sheet_shape();
    let ramp = lut_with(3, &[0.25, 0.5, 1.0]);
    let bump = lut_with(3, &[0.25, 0.0, 1.0]);
    let mut seed = 7u32;
    for (lut, shading) in [
        (&ramp, Shading::Emission),
        (&ramp, Shading::Phong(PHONG)),
        (&bump, Shading::Emission),
    ] {
        let tf = TransferFunction {
            lut,
            lo: 10.0,
            hi: 20.0,
        };
        let shader = Shader {
            labels: None,
            tf,
            shading,
        };
        let (low, high) = tf.visible_interval().unwrap_or((13.0, 20.0));
        let special = [
            low,
            high,
            next_down(low),
            next_up(high),
            f32::NAN,
            f32::INFINITY,
        ];
        let sheets: Vec<Vec<f32>> = (0..3)
            .map(|_| {
                (0..len)
                    .map(|i| {
                        seed ^= seed << 13;
                        seed ^= seed >> 17;
                        seed ^= seed << 5;
                        match seed % 4 {
                            // Long transparent runs, so whole groups are skipped too.
                            _ if (i / 40) % 3 == 0 => 0.0,
                            0 => special[(seed >> 8) as usize % special.len()],
                            _ => 5.0 + (seed >> 8) as f32 / (1u32 << 24) as f32 * 20.0,
                        }
                    })
                    .collect()
            })
            .collect();
        let window = SheetWindow {
            lower: Some(&sheets[0][..]),
            current: &sheets[1][..],
            upper: Some(&sheets[2][..]),
        };
        let empty = VisibleVoxel {
            u: 0,
            v: 0,
            value: 0.0,
        };
        let mut voxels = vec![empty; len];
        let mut gradients = vec![[0.0f32; 3]; len];
        let n = classify_sheet(
            &frame,
            &shader,
            1,
            window,
            &mut voxels,
            &mut gradients,
            &mut [],
        )
        .unwrap();
        let expected: Vec<VisibleVoxel> = (0..len)
            .filter(|&i| tf.lookup(sheets[1][i])[3] > 0.0)
            .map(|i| VisibleVoxel {
                u: (i % na) as u16,
                v: (i / na) as u16,
                value: sheets[1][i],
            })
            .collect();
        assert!(expected.len() > len / 8 && expected.len() < len / 2);
        assert_eq!(&voxels[..n], &expected[..], "{shading:?}");
        if let Shading::Phong(_) = shading {
            for (k, vox) in expected.iter().enumerate() {
                let g = footprint::render::gradient(&frame, &window, vox.u.into(), vox.v.into());
                assert_eq!(gradients[k], g.to_array());
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
        labels: None,
        tf,
        shading: Shading::Emission,
    };
    assert_eq!(emission.transparent_at_or_below(), bound);
    let iso = iso_at(tf, -3.0);
    assert_eq!(iso.transparent_at_or_below(), f32::NEG_INFINITY);
    // A value of -3 is on that iso-surface, below the function's bound, and visible.
    assert!(iso.visible(-3.0, || glam::Vec3::X));
}
