//! The built-in default scene: an electron-density-like field, after the paper's Image 8 (the
//! p-orbitals of copper chloride): |ψ|² of a hydrogen-like 3d_xy orbital (four lobes) plus a
//! weaker 2p_z pair, tilted 30° about x and 20° about y so the default front view shows all of
//! them, on a 64³ grid of spacing 1, normalised to a peak of 1. [`volume`] samples the same field
//! on an n³ grid over the same box (spacing 63/(n − 1)), with the same normalisation, so grids of
//! any side render to the same image up to their sampling.

use crate::io::volume::{Samples, Volume};
use crate::CliError;

/// Side of the default volume, voxels.
pub const SIDE: usize = 64;

/// Builds the default volume (f32 densities in [0, 1]).
pub fn default_volume() -> Volume {
    volume(SIDE).expect("the 64³ scene (1 MiB) fits in memory")
}

/// The field sampled on an `n`³ grid (n ≥ 2) over the default volume's box, divided by the
/// default grid's peak (so another grid's peak may differ slightly from 1). An `n`³ grid takes
/// 4n³ bytes: memory refusing them is an error (`--scene-size 512` needs 512 MiB), not an abort.
pub fn volume(n: usize) -> Result<Volume, CliError> {
    let (data, spacing) = sample(n)?;
    let peak = if n == SIDE {
        data.iter().copied().fold(0.0f32, f32::max)
    } else {
        sample(SIDE)?.0.into_iter().fold(0.0f32, f32::max)
    };
    let data: Vec<f32> = data.into_iter().map(|v| v / peak).collect();
    Ok(Volume::new([n; 3], [spacing; 3], Samples::F32(data.into())))
}

/// The unnormalised field on an `n`³ grid, and the grid's spacing (world units).
fn sample(n: usize) -> Result<(Vec<f32>, f32), CliError> {
    let c = (n as f32 - 1.0) / 2.0;
    // Grid spans ±18 Bohr radii.
    let s = 18.0 / c;
    let (ca, sa) = (30f32.to_radians().cos(), 30f32.to_radians().sin());
    let (cb, sb) = (20f32.to_radians().cos(), 20f32.to_radians().sin());
    let len = n
        .checked_pow(3)
        .ok_or_else(|| CliError::input(format!("--scene-size {n}: n³ samples overflow")))?;
    let mut data =
        crate::io::try_vec(len, &format!("the built-in scene at {n}³")).map_err(CliError::input)?;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let (x0, y0, z0) = ((i as f32 - c) * s, (j as f32 - c) * s, (k as f32 - c) * s);
                // Orbital frame: tilt about x, then about y.
                let (y1, z1) = (ca * y0 - sa * z0, sa * y0 + ca * z0);
                let (x, z) = (cb * x0 + sb * z1, -sb * x0 + cb * z1);
                let y = y1;
                let r = (x * x + y * y + z * z).sqrt();
                // 3d_xy: ψ ∝ x y e^(−r/3), peak density at r = 6. 2p_z: ψ ∝ z e^(−r/2), peak at r = 2.
                let d = (x * y).powi(2) * (-2.0 * r / 3.0).exp();
                let p = z * z * (-r).exp();
                data.push(d / 6.8 + 0.45 * p / 0.54);
            }
        }
    }
    Ok((data, (SIDE as f32 - 1.0) / (n as f32 - 1.0)))
}
