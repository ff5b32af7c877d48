use super::setup::{cell_of, pixels_of_cell};
use super::*;

#[test]
fn cells_partition_the_pixels() {
    for s in 1..=7usize {
        for n in [1usize, 5, 16, 33] {
            let mut owner = std::vec![None; n];
            for c in -1..=(n as i64 / s as i64 + 1) {
                for x in pixels_of_cell(c, s, n) {
                    assert!(owner[x].is_none(), "s {s}: pixel {x} in two cells");
                    owner[x] = Some(c);
                }
            }
            for (x, o) in owner.iter().enumerate() {
                let (c, f) = cell_of(x, s);
                assert_eq!(*o, Some(c), "s {s} n {n} x {x}");
                let u = (x as f64 + 0.5) / s as f64 - 0.5;
                assert!((u - (c as f64 + f64::from(f))).abs() < 1e-6, "s {s} x {x}");
                assert!((0.0..1.0).contains(&f));
            }
        }
    }
}

#[test]
fn weight_table_follows_the_gaussian() {
    let kernel = crate::kernel::Kernel::gaussian(1.6, 2.5).unwrap();
    let t = WeightTable::<WEIGHT_NODES>::new(&kernel).unwrap();
    let crate::kernel::Kernel::Gaussian { sigmas, .. } = kernel else {
        unreachable!()
    };
    for i in 0..=1000 {
        let r2 = i as f32 / 1000.0 * 0.999;
        let exact = (-0.5 * f64::from(sigmas).powi(2) * f64::from(r2)).exp();
        // The interpolation's own bound, plus the math backend's error in the nodes.
        let bound = 2e-6 + f64::from(crate::math::ERROR_BOUNDS.exp_rel);
        assert!((f64::from(t.at(r2)) - exact).abs() < bound, "r² {r2}");
    }
    assert_eq!(t.at(1.0), 0.0);
    assert_eq!(t.at(f32::NAN), 0.0);
}
