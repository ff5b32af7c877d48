//! `footprint compare`: how far apart two single-channel PFM images are.

use crate::io::{self, image::decode_pfm, image::GreyImage};
use crate::CliError;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Image under test (PFM).
    pub a: PathBuf,
    /// Reference image (PFM).
    pub b: PathBuf,
    /// Fail (exit 1) if max |A − B| / peak(B) exceeds this.
    #[arg(long)]
    pub max_diff: Option<f64>,
}

/// max |a − b| / max(b), the "normalised footprint" difference used throughout the tests.
pub fn max_rel_diff(a: &GreyImage, b: &GreyImage) -> Result<f64, CliError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(CliError::input(format!(
            "images differ in size: {}x{} vs {}x{}",
            a.width, a.height, b.width, b.height
        )));
    }
    let peak = f64::from(b.peak());
    if peak <= 0.0 {
        return Err(CliError::input("reference image has no positive value"));
    }
    let worst = a
        .data
        .iter()
        .zip(&b.data)
        .map(|(x, y)| f64::from(x - y).abs())
        .fold(0.0, f64::max);
    Ok(worst / peak)
}

pub fn run(args: &CompareArgs) -> Result<(), CliError> {
    let load = |p: &PathBuf| decode_pfm(&io::read_file(p)?, &p.display().to_string());
    let (a, b) = (load(&args.a)?, load(&args.b)?);
    let d = max_rel_diff(&a, &b)?;
    crate::say!("max |A-B| / peak(B) = {d:.6} ({:.4} %)", d * 100.0);
    match args.max_diff {
        Some(limit) if d.is_nan() || d > limit => Err(CliError::check(format!(
            "difference {d:.6} exceeds --max-diff {limit}"
        ))),
        _ => Ok(()),
    }
}
