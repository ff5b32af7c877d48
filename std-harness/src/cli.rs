//! Command-line parsing. Value formats: lists are comma-separated (`60,30,30`), sizes `WxH`,
//! angles in degrees, matrices nine numbers in row-major order.

use crate::commands;
use crate::CliError;
use clap::{Parser, Subcommand, ValueEnum};
use std::ffi::OsString;

/// Footprint: Westover footprint-evaluation splatting.
#[derive(Parser, Debug)]
#[command(name = "footprint", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a volume (or, with no volume, the built-in scene) to a PNG.
    Render(commands::render::RenderArgs),
    /// Render one voxel (value 1) and write its raw footprint weights (px⁻²).
    Splat(commands::splat::SplatArgs),
    /// Render with the core and with the f64 reference (no tables) and report PSNR, RMSE and max
    /// error; exit 1 below --min-psnr.
    Verify(commands::verify::VerifyArgs),
    /// Precompute a generic footprint table and save it (the paper's preprocessor).
    Tables(commands::tables::TablesArgs),
    /// Compare two single-channel PFM images: max |A − B| relative to B's peak.
    Compare(commands::compare::CompareArgs),
    /// Sweep table size, lookup, method and accumulation on one scene: frame time against error
    /// (tradeoff.csv/.svg/.png with the Pareto frontier) and stability (stability.svg/.png).
    Chart(commands::chart::ChartArgs),
}

/// Table lookup, as on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, ValueEnum)]
pub enum LookupArg {
    Nearest,
    Bilinear,
}

impl From<LookupArg> for footprint::Lookup {
    fn from(l: LookupArg) -> Self {
        match l {
            LookupArg::Nearest => footprint::Lookup::Nearest,
            LookupArg::Bilinear => footprint::Lookup::Bilinear,
        }
    }
}

/// How the footprint is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, ValueEnum)]
pub enum MethodArg {
    /// View table built through the Cholesky (or sheet-parallelogram) map: no singular angle.
    Robust,
    /// View table built through the paper's θ/Sx/Sy decomposition with its 0.01° cheat.
    Paper,
    /// No view table: each pixel is mapped straight into the generic table.
    Direct,
    /// f64, no tables: the exact line integral (the float reference).
    Reference,
}

/// How the sheet accumulator, the working image and compositing count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AccumArg {
    /// f32 throughout.
    Float,
    /// Integers only in the splat and compositing (see the core's `fixed` module): an integer
    /// table, an i64 accumulator, a Q24 image. Bit-exact on every target.
    Fixed,
}

/// The footprint flags `splat`, `render` and `verify` share.
#[derive(clap::Args, Debug, Clone)]
pub struct FootprintArgs {
    /// Kernel spec, e.g. gaussian:spread=1.6,sigmas=2.5 (also cone, sinc, bilinear).
    #[arg(long, default_value = "gaussian:spread=1.6,sigmas=2.5")]
    pub kernel: String,
    /// Generic and view table size N (N×N). The default, 129, is on the Pareto frontier of
    /// `footprint chart` for both charted scenes (README, "Speed against accuracy").
    #[arg(long, default_value_t = 129)]
    pub table: usize,
    /// Load the generic table from a file written by `footprint tables` (its N must equal --table).
    #[arg(long)]
    pub table_file: Option<std::path::PathBuf>,
    /// Lookup, both when building the view table and when sampling it (or the generic table).
    #[arg(long, value_enum, default_value_t = LookupArg::Bilinear)]
    pub lookup: LookupArg,
    /// Footprint method.
    #[arg(long, value_enum, default_value_t = MethodArg::Robust)]
    pub method: MethodArg,
    /// Smallest footprint semi-axis, pixels (sub-pixel footprints are widened to it).
    #[arg(long, default_value_t = footprint::geometry::DEFAULT_MIN_RADIUS_PX)]
    pub min_radius: f32,
    /// `--method paper` only: how close to 45° (degrees) the paper's rotation cheat nudges θ;
    /// 0 disables it, and the singular angle becomes a typed error.
    #[arg(long, default_value_t = 0.01)]
    pub paper_cheat: f32,
}

impl FootprintArgs {
    /// The ellipse-to-circle map `--method` and `--paper-cheat` ask for.
    pub fn mapping(&self) -> Result<footprint::geometry::Mapping, CliError> {
        if self.method != MethodArg::Paper {
            return Ok(footprint::geometry::Mapping::Robust);
        }
        if !(self.paper_cheat >= 0.0 && self.paper_cheat < 45.0) {
            return Err(CliError::input(format!(
                "--paper-cheat {}: expected degrees in [0, 45)",
                self.paper_cheat
            )));
        }
        Ok(footprint::geometry::Mapping::Paper {
            cheat_deg: self.paper_cheat,
        })
    }
}

impl FootprintArgs {
    /// The parsed `--kernel`.
    pub fn kernel(&self) -> Result<footprint::Kernel, CliError> {
        footprint::Kernel::parse(&self.kernel)
            .map_err(|e| CliError::input(format!("--kernel '{}': {e}", self.kernel)))
    }

    /// The generic table: loaded from `--table-file` (which must be for `kernel` and of size N), or
    /// built.
    pub fn generic_table<const N: usize>(
        &self,
        kernel: &footprint::Kernel,
    ) -> Result<Box<footprint::GenericTable<N>>, CliError> {
        let Some(path) = &self.table_file else {
            return Ok(Box::new(footprint::GenericTable::<N>::build(*kernel)));
        };
        let table = crate::commands::tables::load_table::<N>(path)?;
        if table.kernel() != kernel {
            return Err(CliError::input(format!(
                "{}: table is for kernel {}, but --kernel is {kernel}",
                path.display(),
                table.kernel()
            )));
        }
        Ok(table)
    }
}

/// Parses `a,b,c,…` into exactly `n` finite numbers.
pub fn parse_list<const N: usize>(s: &str) -> Result<[f32; N], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != N {
        return Err(format!(
            "expected {N} comma-separated numbers, got {}",
            parts.len()
        ));
    }
    let mut out = [0.0f32; N];
    for (o, p) in out.iter_mut().zip(parts) {
        *o = p
            .trim()
            .parse()
            .map_err(|_| format!("'{p}' is not a number"))?;
        if !o.is_finite() {
            return Err(format!("'{p}' is not finite"));
        }
    }
    Ok(out)
}

/// Parses `WxH` (each 1 … 16384).
pub fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WxH"))?;
    let parse = |v: &str| -> Result<usize, String> {
        let n: usize = v
            .parse()
            .map_err(|_| format!("'{v}' is not a whole number"))?;
        if !(1..=16384).contains(&n) {
            return Err(format!("image side {n} is outside 1..=16384"));
        }
        Ok(n)
    };
    Ok((parse(w)?, parse(h)?))
}

/// Runs the command line `args` (program name first); returns the process exit code: 0 success,
/// 1 a check failed, 2 bad input or I/O error. Errors are printed to stderr as one line.
pub fn run<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return code;
        }
    };
    let result = match cli.command {
        Command::Render(a) => commands::render::run(&a),
        Command::Splat(a) => commands::splat::run(&a),
        Command::Verify(a) => commands::verify::run(&a),
        Command::Tables(a) => commands::tables::run(&a),
        Command::Compare(a) => commands::compare::run(&a),
        Command::Chart(a) => commands::chart::run(&a),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr().lock(), "footprint: {e}");
            e.code
        }
    }
}
