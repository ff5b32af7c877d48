//! `footprint compare`: how far apart two PFM images are, greyscale (`splat`'s) or colour
//! (`render --out x.pfm`'s; every channel of every pixel compared).

use crate::io::{self, image::decode_pfm_any};
use crate::metrics::{max_rel_diff, psnr};
use crate::CliError;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Image under test (PFM, greyscale or colour).
    pub a: PathBuf,
    /// Reference image (PFM, of the same kind).
    pub b: PathBuf,
    /// Fail (exit 1) if max |A − B| / peak(B) exceeds this.
    #[arg(long, value_parser = crate::args::parse_finite_f64, allow_hyphen_values = true)]
    pub max_diff: Option<f64>,
    /// Fail (exit 1) if the PSNR of A against B, 10·log₁₀(1 / MSE) over every value (peak 1, the
    /// convention of `verify`), is below this many dB.
    #[arg(long, value_name = "DB", value_parser = crate::args::parse_finite_f64, allow_hyphen_values = true)]
    pub min_psnr: Option<f64>,
}

/// Exit 1 (a failed check) when the difference exceeds `--max-diff` or either image holds a
/// non-finite value (NaN or infinity: no comparison with it means anything), whether or not
/// `--max-diff` is given.
pub fn run(args: &CompareArgs) -> Result<(), CliError> {
    if let Some(limit) = args.max_diff {
        if !(limit.is_finite() && limit >= 0.0) {
            return Err(CliError::input(format!(
                "--max-diff {limit}: expected a finite number >= 0"
            )));
        }
    }
    let load = |p: &PathBuf| decode_pfm_any(&io::read_file(p)?, &p.display().to_string());
    let ((a, ca), (b, cb)) = (load(&args.a)?, load(&args.b)?);
    if ca != cb {
        let kind = |c: usize| if c == 3 { "colour (RGB)" } else { "greyscale" };
        return Err(CliError::input(format!(
            "{} is a {} PFM, {} a {} one: compare two of a kind",
            args.a.display(),
            kind(ca),
            args.b.display(),
            kind(cb)
        )));
    }
    for (name, img) in [(&args.a, &a), (&args.b, &b)] {
        let bad = img.data.iter().filter(|v| !v.is_finite()).count();
        if bad > 0 {
            return Err(CliError::check(format!(
                "{}: {bad} non-finite value(s) (NaN or infinity)",
                name.display()
            )));
        }
    }
    let d = max_rel_diff(&a, &b)?;
    let psnr = psnr(&a, &b);
    crate::say!(
        "max |A-B| / peak(B) = {d:.6} ({:.4} %); PSNR {psnr:.2} dB (peak 1)",
        d * 100.0
    );
    match (args.max_diff, args.min_psnr) {
        (Some(limit), _) if !(d <= limit) => Err(CliError::check(format!(
            "difference {d:.6} exceeds --max-diff {limit}"
        ))),
        (_, Some(db)) if !(psnr >= db) => Err(CliError::check(format!(
            "PSNR {psnr:.2} dB is below --min-psnr {db}"
        ))),
        _ => Ok(()),
    }
}
