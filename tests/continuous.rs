//! The continuous reference (`verify --reference continuous`, issue 12) against an analytic case:
//! one Gaussian blob of constant colour in an otherwise empty volume, whose emission–absorption
//! integral has a closed form along every ray.

use footprint_harness::args::parse_args;
use footprint_harness::pipeline::{prepare, render_continuous_ref};
use footprint_harness::reference::continuous::{Reconstruction, CONVERGED_DB};
use footprint_suite::tmpdir;

/// A 9³ volume, zero except its centre voxel (255); the transfer function maps 255 to white at
/// opacity 0.5 per world unit, so σ = ln 2 there. Seen along z (orthographic, 64×64, spacing 1),
/// the field σ(x) = σᵥ·h(|x − v|/R)/(R³∫h) has optical depth τ(ρ) = σᵥ·R·chord(ρ)/(R³∫h) along
/// the ray at distance ρR from the voxel (chord(ρ) = ∫h along the unit-ball chord, the Gaussian's
/// closed form), and the pixel is (1 − e^(−τ))·(1, 1, 1, 1). The converged reference must match
/// that to 65 dB (PSNR over RGB), and its step must have been refined until two passes agreed to
/// [`CONVERGED_DB`]. Two kernels: the paper's (spread 1.6) and a wide one (spread 5, eleven voxels
/// across, more than the reference's per-axis tables once held).
#[test]
fn a_single_gaussian_blob_matches_its_closed_form() {
    // (spread, sigmas, the least peak the blob must show: a wider kernel spreads its depth).
    for (r, sigmas, least) in [(1.6f64, 2.5f64, 0.2), (5.0, 2.5, 0.02)] {
        blob_matches_closed_form(r, sigmas, least);
    }
}

fn blob_matches_closed_form(r: f64, sigmas: f64, least_peak: f64) {
    let d = tmpdir("continuous-blob");
    let kernel = format!("gaussian:spread={r},sigmas={sigmas}");
    let mut v = vec![0u8; 9 * 9 * 9];
    v[(4 * 9 + 4) * 9 + 4] = 255;
    let raw = d.join("blob.raw");
    std::fs::write(&raw, &v).unwrap();
    let tf = d.join("tf.txt");
    std::fs::write(&tf, "0 0 0 0 0\n1 1 1 1 0.5\n").unwrap();
    let args = parse_args(&[
        raw.to_str().unwrap(),
        "--dims",
        "9,9,9",
        "--type",
        "u8",
        "--window",
        "0,255",
        "--tf",
        tf.to_str().unwrap(),
        "--size",
        "64x64",
        "--supersample",
        "1",
        "--kernel",
        &kernel,
    ])
    .unwrap();
    let p = prepare(&args).unwrap();
    let (c, _) = render_continuous_ref(&p, Reconstruction::Kernel).unwrap();
    let img = &c.image;
    assert!(
        c.converged && c.change_db >= CONVERGED_DB,
        "{} dB",
        c.change_db
    );
    // The closed form.
    let sigma = 1.0 / sigmas;
    let ball = {
        let a = sigmas / std::f64::consts::SQRT_2;
        let pi = std::f64::consts::PI;
        4.0 * pi * (pi.sqrt() * libm::erf(a) / (4.0 * a.powi(3)) - (-a * a).exp() / (2.0 * a * a))
    };
    let chord = |rho2: f64| {
        if rho2 >= 1.0 {
            return 0.0;
        }
        (-rho2 / (2.0 * sigma * sigma)).exp()
            * sigma
            * (2.0 * std::f64::consts::PI).sqrt()
            * libm::erf((1.0 - rho2).sqrt() / (sigma * std::f64::consts::SQRT_2))
    };
    let sv = 2f64.ln();
    // VTK's ResetCamera scale: 64 px over the bounding sphere's diameter, 2·(8√3/2).
    let scale = 64.0 / (8.0 * 3f64.sqrt());
    let mut sq = 0.0;
    let mut peak = 0.0f64;
    for y in 0..64 {
        for x in 0..64 {
            let q = [
                (x as f64 + 0.5 - 32.0) / scale,
                (y as f64 + 0.5 - 32.0) / scale,
            ];
            let rho2 = (q[0] * q[0] + q[1] * q[1]) / (r * r);
            let tau = sv * r * chord(rho2) / (r.powi(3) * ball);
            let want = 1.0 - (-tau).exp();
            peak = peak.max(want);
            sq += img[y * 64 + x][..3]
                .iter()
                .map(|c| (c - want).powi(2))
                .sum::<f64>();
        }
    }
    let psnr = -10.0 * (sq / (3.0 * 64.0 * 64.0)).log10();
    assert!(peak > least_peak, "{kernel}: the blob shows: peak {peak}");
    assert!(
        psnr >= 65.0,
        "{kernel}: continuous reference vs closed form: {psnr:.1} dB"
    );
    eprintln!(
        "blob, {kernel}: {psnr:.1} dB against the closed form, step {}, {} passes",
        c.step, c.passes
    );
    std::fs::remove_dir_all(&d).unwrap();
}
