//! Kernels and generic tables against brute force.
//!
//! The Gaussian's closed-form (erf) footprint is checked against Simpson integration of the 3D
//! kernel along the chord; every kernel's generic table is checked against the exact footprint,
//! and its error must fall as the table grows. `cargo test --test suite kernels:: -- --nocapture` prints
//! the error table quoted in ARCHITECTURE.md.

use footprint::{GenericTable, Kernel, Lookup};
use footprint_harness::reference::{footprint_f64, integral_f64};
use footprint_suite::{assert_le, ball_integral, default_kernels, gaussian_3d, line_integral};

#[test]
fn gaussian_closed_form_matches_simpson_line_integral() {
    for sigmas in [1.0f32, 2.5, 4.0] {
        let k = Kernel::gaussian(1.6, sigmas).unwrap();
        let h = gaussian_3d(f64::from(sigmas));
        for i in 0..100 {
            let rho = i as f64 / 100.0;
            let brute = line_integral(&h, rho, 4000);
            let closed = footprint_f64(&k, [rho, 0.0]);
            assert_le(
                (brute - closed).abs(),
                1e-9,
                &format!("f64 erf form, sigmas {sigmas}, ρ {rho}"),
            );
            // The core's f32 evaluation (libm backend): a few ulp of the peak.
            let core = f64::from(k.footprint([rho as f32, 0.0]));
            assert_le(
                (core - closed).abs(),
                2e-6,
                &format!("core f32, sigmas {sigmas}, ρ {rho}"),
            );
        }
        let ball = ball_integral(&h, 4000);
        assert_le(
            (ball - integral_f64(&k)).abs() / ball,
            1e-9,
            "ball integral closed form",
        );
        assert_le(
            (f64::from(k.integral()) - ball).abs() / ball,
            1e-6,
            "core f32 ball integral",
        );
    }
}

#[test]
fn model_integrals_match_quadrature() {
    // ∫∫ F over the domain by a fine midpoint rule, against the closed forms.
    for k in default_kernels() {
        let n = 2000;
        let h = 2.0 / n as f64;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let u = [-1.0 + h * (i as f64 + 0.5), -1.0 + h * (j as f64 + 0.5)];
                sum += footprint_f64(&k, u);
            }
        }
        sum *= h * h;
        assert_le(
            (sum - integral_f64(&k)).abs() / integral_f64(&k),
            2e-3,
            &format!("{k} integral"),
        );
    }
}

/// Max |T(u) − F(u)/∫F| over a dense set of points, relative to the peak F(0)/∫F.
fn table_error<const N: usize>(k: Kernel, lookup: Lookup) -> f64 {
    let table = GenericTable::<N>::build(k);
    let norm = integral_f64(&k);
    let peak = footprint_f64(&k, [0.0, 0.0]) / norm;
    let mut worst = 0.0f64;
    let m = 301; // 301² points at offsets that never line up with table nodes
    for i in 0..m {
        for j in 0..m {
            let u = [
                -1.0 + 2.0 * (i as f64 + 0.37) / m as f64,
                -1.0 + 2.0 * (j as f64 + 0.61) / m as f64,
            ];
            let exact = footprint_f64(&k, u) / norm;
            let got = f64::from(table.sample([u[0] as f32, u[1] as f32], lookup));
            worst = worst.max((got - exact).abs());
        }
    }
    worst / peak
}

fn errors(k: Kernel, lookup: Lookup) -> [f64; 6] {
    [
        table_error::<5>(k, lookup),
        table_error::<11>(k, lookup),
        table_error::<21>(k, lookup),
        table_error::<33>(k, lookup),
        table_error::<65>(k, lookup),
        table_error::<101>(k, lookup),
    ]
}

#[test]
fn table_error_falls_as_n_grows() {
    println!("max |table − exact| / peak, generic table sampled at 301² off-node points");
    println!(
        "{:<34} {:<8} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "kernel", "lookup", "N=5", "11", "21", "33", "65", "101"
    );
    for k in default_kernels() {
        for lookup in [Lookup::Nearest, Lookup::Bilinear] {
            let e = errors(k, lookup);
            let exact = matches!(k, Kernel::Bilinear { .. }) && lookup == Lookup::Bilinear;
            println!(
                "{:<34} {:<8} {:>9.2e} {:>9.2e} {:>9.2e} {:>9.2e} {:>9.2e} {:>9.2e}",
                k.to_string(),
                format!("{lookup:?}"),
                e[0],
                e[1],
                e[2],
                e[3],
                e[4],
                e[5]
            );
            if exact {
                // Piecewise linear with its kinks on nodes (odd N): exact up to f32 rounding.
                assert!(
                    e.iter().all(|&v| v < 1e-6),
                    "{k} {lookup:?} should be exact: {e:?}"
                );
                continue;
            }
            for w in e.windows(2) {
                assert!(
                    w[1] < w[0],
                    "{k} {lookup:?}: error did not fall with N: {e:?}"
                );
            }
            // From N=5 to N=101 the error must fall by at least 4× (nearest: O(h); bilinear: O(h²)
            // in smooth regions, O(√h) at the Gaussian's truncation edge).
            assert!(
                e[5] * 4.0 < e[0],
                "{k} {lookup:?}: error fell too little: {e:?}"
            );
        }
    }
    // The configuration the issue names: the paper Gaussian at N = 65, bilinear. Measured 8.56e-3,
    // all of it next to the support edge, where the truncated kernel's footprint falls like
    // √(1−ρ²) and linear interpolation converges only as √h. 1e-2 is the 1 % the issue allows.
    assert_le(
        table_error::<65>(Kernel::PAPER_GAUSSIAN, Lookup::Bilinear),
        1e-2,
        "paper Gaussian N=65 bilinear",
    );
}

#[test]
fn table_is_normalised_to_unit_integral() {
    // Trapezoid sum of the node values × cell area ≈ 1 (the table stores F/∫F).
    let t = GenericTable::<257>::build(Kernel::PAPER_GAUSSIAN);
    let h = 2.0 / 256.0;
    let sum: f64 = t.as_slice().iter().map(|&v| f64::from(v)).sum::<f64>() * h * h;
    assert_le(
        (sum - 1.0).abs(),
        2e-3,
        "trapezoid integral of the N=257 table",
    );
}

#[test]
fn specs_parse_and_round_trip() {
    let k = Kernel::parse("gaussian:spread=1.6,sigmas=2.5").unwrap();
    assert_eq!(
        k,
        Kernel::Gaussian {
            spread: 1.6,
            sigmas: 2.5
        }
    );
    assert_eq!(k.spread(), 1.6);
    for k in default_kernels() {
        assert_eq!(Kernel::parse(&k.spec()).unwrap(), k, "round trip of {k}");
    }
    assert_eq!(
        Kernel::parse("sinc:lobes=3").unwrap(),
        Kernel::Sinc {
            spread: 5.0,
            lobes: 3
        }
    );
}
