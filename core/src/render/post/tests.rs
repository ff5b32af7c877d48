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

/// A tent's row (`tent.rs`): its support in closed form is exactly where the brute-force tent
/// Π(1 − |q_a|)₊ of q = M·(dx, dy, dz) is non-zero, and its weight is that tent, for sheared
/// and axis-aligned screen-to-grid maps (an axis with m_a = 0 keeps the whole row or none).
#[test]
fn tent_rows_are_the_tent_in_closed_form() {
    use super::tent::TentRow;
    use glam::Mat3;
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 33) as f64 / (1u64 << 31) as f64) as f32 * 2.0 - 1.0
    };
    let mut maps: std::vec::Vec<Mat3> = (0..40)
        .map(|_| Mat3::from_cols_array(&core::array::from_fn(|_| 0.8 * rnd())))
        .collect();
    maps.push(Mat3::from_diagonal(glam::Vec3::new(0.5, 0.4, 0.7)));
    let mut inside = 0;
    for m in &maps {
        for _ in 0..30 {
            let (dy, dz) = (2.0 * rnd(), 2.0 * rnd());
            let inv = m.col(0).to_array().map(|c| 1.0 / c);
            let row = TentRow::with_inverse(m, inv, dy, dz);
            let support = row.support();
            for i in 0..=2000 {
                let dx = -6.0 + 12.0 * i as f32 / 2000.0;
                let q = *m * glam::Vec3::new(dx, dy, dz);
                let exact: f64 = q
                    .to_array()
                    .iter()
                    .map(|&c| (1.0 - f64::from(c).abs()).max(0.0))
                    .product();
                let w = f64::from(row.weight(dx));
                assert!((w - exact).abs() < 1e-5, "{m:?} dy {dy} dz {dz} dx {dx}");
                match support {
                    Some((lo, hi)) if dx > lo + 1e-4 && dx < hi - 1e-4 => {
                        assert!(exact > 0.0, "inside the support at {dx}: {exact}");
                        inside += 1;
                    }
                    Some((lo, hi)) if dx > lo - 1e-4 && dx < hi + 1e-4 => {}
                    _ => assert!(exact < 1e-6, "outside the support at {dx}: {exact}"),
                }
            }
        }
    }
    assert!(inside > 10_000, "the rows meet the tent ({inside})");
}
