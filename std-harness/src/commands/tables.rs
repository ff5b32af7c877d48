//! `footprint tables`: precompute a generic table and save it in the core's byte format.

use crate::io::{self, table::table_bytes};
use crate::CliError;
use clap::Args;
use footprint::Kernel;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct TablesArgs {
    /// Kernel spec, e.g. gaussian:spread=1.6,sigmas=2.5.
    #[arg(long, default_value = "gaussian:spread=1.6,sigmas=2.5")]
    pub kernel: String,
    /// Table size N (N×N samples over [-1,1]²).
    #[arg(long, default_value_t = 129)]
    pub size: usize,
    /// Output file.
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(args: &TablesArgs) -> Result<(), CliError> {
    let kernel = Kernel::parse(&args.kernel)
        .map_err(|e| CliError::input(format!("--kernel '{}': {e}", args.kernel)))?;
    io::outputs::check(&[io::outputs::Planned {
        flag: "--out",
        path: &args.out,
        extensions: &[],
    }])?;
    let start = std::time::Instant::now();
    let bytes = table_bytes(&kernel, args.size)?;
    io::write_atomic(&args.out, &bytes)?;
    crate::say!(
        "wrote {} ({}x{} table, kernel {kernel}, {} bytes, crc32 {:08x}) in {:.1} ms",
        args.out.display(),
        args.size,
        args.size,
        bytes.len(),
        u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().expect("4 bytes")),
        start.elapsed().as_secs_f64() * 1e3
    );
    Ok(())
}
