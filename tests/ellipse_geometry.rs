//! Ellipse extent and mapping against brute-force projection of the region ellipsoid, for random
//! rotations and spacings from 1:1:1 to 1:1:1000.

use footprint::geometry::{paper_decomposition, Footprint, FootprintOptions, Mapping};
use footprint::{Grid, Kernel, View};
use footprint_suite::view;
use glam::DVec3;
use proptest::prelude::*;

/// `n` points spread evenly over the unit sphere (Fibonacci lattice).
fn sphere_points(n: usize) -> impl Iterator<Item = DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n).map(move |i| {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * i as f64;
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    })
}

/// Spacing with one axis `ratio` times the others (axis chosen by `which`), base 1.
fn spacing(ratio: f32, which: usize) -> [f32; 3] {
    let mut s = [1.0; 3];
    s[which] = ratio;
    s
}

fn check_geometry(
    rx: f32,
    ry: f32,
    rz: f32,
    ratio: f32,
    which: usize,
    zoom: f32,
) -> Result<(), TestCaseError> {
    let kernel = Kernel::PAPER_GAUSSIAN;
    let grid = Grid::from_spacing(spacing(ratio, which)).unwrap();
    let g2s = View::new(view(rx, ry, rz, zoom))
        .unwrap()
        .grid_to_screen(&grid);
    let fp = Footprint::new(&kernel, &g2s, FootprintOptions::default()).unwrap();
    // Every semi-axis is at least R·zoom·(smallest spacing) ≥ 1.6 px, so nothing was widened.
    prop_assert!(!fp.clamped);
    let m = g2s.as_dmat3() * f64::from(kernel.spread());
    let a = fp.to_unit.map(|r| r.map(f64::from));
    let (mut max_x, mut max_y, mut max_r) = (0.0f64, 0.0f64, 0.0f64);
    for u in sphere_points(20_000) {
        let p = m * u;
        max_x = max_x.max(p.x.abs());
        max_y = max_y.max(p.y.abs());
        let r = ((a[0][0] * p.x + a[0][1] * p.y).powi(2) + (a[1][0] * p.x + a[1][1] * p.y).powi(2))
            .sqrt();
        max_r = max_r.max(r);
    }
    let (ex, ey) = (f64::from(fp.half_extent[0]), f64::from(fp.half_extent[1]));
    // Brute force can only under-reach the true extent; 20 000 points come within ~3e-4 of it.
    prop_assert!(
        max_x <= ex * (1.0 + 1e-5) && max_x >= ex * (1.0 - 2e-3),
        "x extent {ex} vs brute {max_x}"
    );
    prop_assert!(
        max_y <= ey * (1.0 + 1e-5) && max_y >= ey * (1.0 - 2e-3),
        "y extent {ey} vs brute {max_y}"
    );
    // The map sends every projected surface point into the unit disc, and the silhouette onto its rim.
    prop_assert!(
        (1.0 - 2e-3..=1.0 + 1e-4).contains(&max_r),
        "max |A q| over the surface = {max_r}"
    );
    // AᵀA equals the conic (N Nᵀ)⁻¹ computed in f64.
    let (n0, n1) = (
        DVec3::new(m.x_axis.x, m.y_axis.x, m.z_axis.x),
        DVec3::new(m.x_axis.y, m.y_axis.y, m.z_axis.y),
    );
    let (sxx, sxy, syy) = (n0.dot(n0), n0.dot(n1), n1.dot(n1));
    let det = n0.cross(n1).length_squared();
    let conic = [syy / det, -sxy / det, sxx / det];
    let ata = [
        a[0][0] * a[0][0] + a[1][0] * a[1][0],
        a[0][0] * a[0][1] + a[1][0] * a[1][1],
        a[0][1] * a[0][1] + a[1][1] * a[1][1],
    ];
    let scale = conic[0].max(conic[2]);
    for (x, y) in ata.iter().zip(conic) {
        prop_assert!(
            (x - y).abs() <= 1e-4 * scale,
            "AᵀA {ata:?} vs conic {conic:?}"
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(footprint_suite::proptest_config(200))]

    #[test]
    fn extent_and_map_match_projected_ellipsoid(
        rx in -180.0f32..180.0, ry in -180.0f32..180.0, rz in -180.0f32..180.0,
        log_ratio in 0.0f32..3.0, which in 0usize..3, zoom in 1.0f32..8.0,
    ) {
        check_geometry(rx, ry, rz, 10f32.powf(log_ratio), which, zoom)?;
    }

    #[test]
    fn paper_map_agrees_away_from_45_degrees(
        rx in -180.0f32..180.0, ry in -180.0f32..180.0, rz in -180.0f32..180.0,
        log_ratio in 0.0f32..1.0, which in 0usize..3,
    ) {
        // Up to 10:1. Beyond that the paper's method loses precision even away from 45°; see
        // `paper_map_degrades_with_anisotropy`.
        let kernel = Kernel::PAPER_GAUSSIAN;
        let grid = Grid::from_spacing(spacing(10f32.powf(log_ratio), which)).unwrap();
        let g2s = View::new(view(rx, ry, rz, 2.0)).unwrap().grid_to_screen(&grid);
        let robust = Footprint::new(&kernel, &g2s, FootprintOptions::default()).unwrap();
        let conic = footprint::geometry::conic_of(&robust.covariance, {
            let c = robust.covariance; c.xx * c.yy - c.xy * c.xy
        });
        let d = paper_decomposition(&conic, 0.01).unwrap();
        let theta = d.theta.to_degrees();
        prop_assume!((theta.abs() - 45.0).abs() > 1.0);
        // Same conic: AᵀA of the paper map against the robust map's.
        let a = d.to_unit;
        let ata = [a[0][0] * a[0][0] + a[1][0] * a[1][0], a[0][0] * a[0][1] + a[1][0] * a[1][1], a[0][1] * a[0][1] + a[1][1] * a[1][1]];
        let want = [conic.xx, conic.xy, conic.yy];
        let scale = want[0].max(want[2]);
        for (x, y) in ata.iter().zip(want) {
            prop_assert!((x - y).abs() <= 1e-3 * scale, "θ = {theta}°: paper AᵀA {ata:?} vs conic {want:?}");
        }
        let paper = Footprint::new(&kernel, &g2s, FootprintOptions { mapping: Mapping::PAPER, ..Default::default() }).unwrap();
        for i in 0..2 {
            prop_assert!((paper.half_extent[i] - robust.half_extent[i]).abs() <= 1e-3 * robust.half_extent[i]);
        }
    }
}

#[test]
fn extreme_anisotropy_1_to_1000() {
    for which in 0..3 {
        for (rx, ry, rz) in [
            (0.0, 0.0, 0.0),
            (30.0, 20.0, 10.0),
            (89.0, 1.0, 45.0),
            (45.0, 45.0, 45.0),
        ] {
            check_geometry(rx, ry, rz, 1000.0, which, 1.0).unwrap();
        }
    }
}

/// The paper's θ method solves a 2×2 system whose entries cancel (X ≈ Y) for oblique, elongated
/// ellipses, so its error grows with anisotropy even well away from 45°, while the Cholesky map
/// stays at f32 rounding. Measured here at θ ≈ 47°: relative extent error 2e-6 at 10:1, 7e-3 at
/// 300:1 and 1e-2 at 1000:1.
#[test]
fn paper_map_degrades_with_anisotropy() {
    let kernel = Kernel::PAPER_GAUSSIAN;
    let mut report = Vec::new();
    for ratio in [10.0f32, 100.0, 300.0, 1000.0] {
        let grid = Grid::from_spacing([1.0, ratio, 1.0]).unwrap();
        let g2s = View::new(view(47.30228, -83.748665, 0.0, 2.0))
            .unwrap()
            .grid_to_screen(&grid);
        let m = g2s.as_dmat3() * f64::from(kernel.spread());
        let exact_x = (m.x_axis.x.powi(2) + m.y_axis.x.powi(2) + m.z_axis.x.powi(2)).sqrt();
        let err = |mapping| {
            let fp = Footprint::new(
                &kernel,
                &g2s,
                FootprintOptions {
                    mapping,
                    ..Default::default()
                },
            )
            .unwrap();
            (f64::from(fp.half_extent[0]) - exact_x).abs() / exact_x
        };
        let (robust, paper) = (err(Mapping::Robust), err(Mapping::PAPER));
        println!(
            "anisotropy {ratio}:1  relative x-extent error: robust {robust:.2e}, paper {paper:.2e}"
        );
        assert!(
            robust < 1e-5,
            "robust map must stay at f32 rounding, got {robust:e} at {ratio}:1"
        );
        report.push(paper);
    }
    assert!(
        report[0] < 1e-4,
        "paper map at 10:1 should still be accurate: {report:?}"
    );
    assert!(
        report[3] > 1e-3,
        "paper map at 1000:1 measured ~1e-2; if this now passes, update the docs: {report:?}"
    );
}
