//! `footprint compare`: how far apart two single-channel PFM images are.

use crate::io::{self, image::decode_pfm};
use crate::metrics::max_rel_diff;
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
