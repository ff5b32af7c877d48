//! The command line's top: the subcommands and the dispatch to them. Nothing imports this module
//! back; the argument structs commands share live in [`crate::args`].

use crate::args::SplatArgs;
use crate::commands;
use crate::io::stream::InMemory;
use clap::{Parser, Subcommand};
use std::ffi::OsString;

/// Footprint: Westover footprint-evaluation splatting.
#[derive(Parser, Debug)]
#[command(name = "footprint", version, about, arg_required_else_help = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a volume (or, with no volume, the built-in scene) to a PNG.
    #[command(allow_negative_numbers = true, after_help = RENDER_EXAMPLES)]
    Render(commands::render::RenderCommandArgs),
    /// Render one voxel (value 1) and write its raw footprint weights (px⁻²).
    #[command(allow_negative_numbers = true)]
    Splat(SplatArgs),
    /// Render with the core and with the f64 reference (no tables) and report PSNR, RMSE and max
    /// error; exit 1 below --min-psnr.
    #[command(allow_negative_numbers = true)]
    Verify(commands::verify::VerifyArgs),
    /// Precompute a generic footprint table and save it (the paper's preprocessor).
    #[command(allow_negative_numbers = true)]
    Tables(commands::tables::TablesArgs),
    /// Compare two PFM images (greyscale, or colour as `render --out x.pfm` writes): max |A − B|
    /// relative to B's peak.
    #[command(allow_negative_numbers = true)]
    Compare(commands::compare::CompareArgs),
    /// Sweep table size, lookup, method and accumulation on one scene: frame time against error
    /// (tradeoff.csv/.svg/.png with the Pareto frontier) and stability (stability.svg/.png).
    #[command(allow_negative_numbers = true)]
    Chart(commands::chart::ChartArgs),
    /// What a volume file holds: dimensions, spacing, type, orientation, value range,
    /// percentiles and the window `render` would use (--json writes them).
    #[command(allow_negative_numbers = true)]
    Info(commands::info::InfoArgs),
    /// Frame times of one volume loaded once: frame 1 fresh, later frames turned by --orbit and
    /// reusing cached state (first_ms, median_ms, phases_ms; --json).
    #[command(allow_negative_numbers = true)]
    Bench(commands::bench::BenchArgs),
    /// Where the ray through one pixel (--at X,Y) first reaches an accumulated opacity of 0.5 in
    /// the frame's continuous model: its depth (world units, 0 at the volume's centre, growing
    /// away from the viewer), its world point and the volume's value there (--json).
    #[command(allow_negative_numbers = true)]
    Probe(commands::probe::ProbeArgs),
    /// Print a shell completion script: `footprint completions bash > ~/.local/share/bash-completion/completions/footprint`
    /// (zsh: into a folder on $fpath as `_footprint`; fish: ~/.config/fish/completions/footprint.fish).
    Completions {
        /// bash, zsh, fish, elvish or powershell.
        shell: clap_complete::Shell,
    },
}

const RENDER_EXAMPLES: &str = "Examples:
  footprint render                                   the built-in scene to footprint.png
  footprint info head.nrrd                           dims, spacing, range and the window render picks
  footprint render head.nrrd --tf ct-bone-skin --shading phong -o head.png
  footprint render head.nrrd -s 256x256 --view 30,20,0 --window 1200,2400 -o head.png
  footprint render head.nrrd --orbit 36 --colorbar -o orbit.png   (an animated PNG)
  footprint render head.nrrd -o head.pfm             linear float RGB, for footprint compare";

/// Runs the command line `args` (program name first); returns the process exit code: 0 success,
/// 1 a check failed, 2 bad input or I/O error. Errors are printed to stderr as one line.
/// SIGINT, SIGTERM and SIGHUP remove the command's temporaries before the process ends
/// ([`crate::io::temporaries::remove_on_signals`]).
pub fn run<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    crate::io::outputs::ignore_file_size_signal();
    crate::io::temporaries::remove_on_signals();
    crate::io::forget_inputs();
    // A failure left from an earlier command of this process (tests run many) is not this one's.
    let _ = crate::stdout_failure();
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e)
            if !e.use_stderr()
                || e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand =>
        {
            // --help, --version, and a bare `footprint`: the help, on stdout.
            use clap::CommandFactory as _;
            if e.use_stderr() {
                crate::say!("{}", Cli::command().render_help());
            } else {
                let _ = e.print();
            }
            return 0;
        }
        Err(e) => {
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr().lock(), "footprint: {}", clap_line(&e));
            return 2;
        }
    };
    // A report that could not be written is a failure, not a success (`info > /dev/full`).
    let result = dispatch(cli.command).and_then(|()| match crate::stdout_failure() {
        None => Ok(()),
        Some(e) => Err(crate::CliError::input(format!(
            "standard output: cannot write: {e}"
        ))),
    });
    match result {
        Ok(()) => 0,
        Err(e) => {
            if !e.said {
                use std::io::Write as _;
                let _ = writeln!(std::io::stderr().lock(), "footprint: {e}");
            }
            e.code
        }
    }
}

fn dispatch(command: Command) -> Result<(), crate::CliError> {
    match command {
        Command::Render(a) => commands::render::run(&a),
        Command::Splat(a) => commands::splat::run(&a),
        Command::Verify(a) => commands::verify::run(&a),
        Command::Tables(a) => commands::tables::run(&a),
        Command::Compare(a) => commands::compare::run(&a),
        Command::Chart(a) => commands::chart::run(&a),
        Command::Bench(a) => commands::bench::run(&a),
        Command::Info(a) => commands::info::run(&a),
        Command::Probe(a) => commands::probe::run(&a),
        Command::Completions { shell } => {
            let out = completion_script(&shell.to_string())?;
            use std::io::Write as _;
            std::io::stdout()
                .lock()
                .write_all(&out)
                .map_err(|e| crate::CliError::input(format!("standard output: {e}")))
        }
    }
}

/// The completion script of `footprint` for `shell` (bash, zsh, fish, elvish, powershell): what
/// `footprint completions SHELL` prints.
pub fn completion_script(shell: &str) -> Result<Vec<u8>, crate::CliError> {
    use clap::CommandFactory as _;
    let shell: clap_complete::Shell = shell.parse().map_err(|_| {
        crate::CliError::input(format!(
            "no completions for '{shell}': bash, zsh, fish, elvish or powershell"
        ))
    })?;
    let mut out = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), "footprint", &mut out);
    Ok(out)
}

/// Runs the command line `args` (program name first) as [`run`] does, for a program that calls
/// the harness (the Python package): `memory`, a volume it holds, is what `render`, `verify` or
/// `bench` renders in place of VOLUME, and the error comes back instead of being printed
/// (`--help` is an error here too). The process's signal dispositions are left as they are.
pub fn run_with<I, T>(args: I, memory: Option<InMemory>) -> Result<(), crate::CliError>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = Cli::try_parse_from(args).map_err(|e| crate::CliError::input(clap_line(&e)))?;
    run_command(cli.command, memory)
}

/// Runs `command`, built by flags or by keywords (`crate::args::keywords`), on `memory` if given
/// (a volume in memory, for `render`, `verify` and `bench` only).
pub fn run_command(mut command: Command, memory: Option<InMemory>) -> Result<(), crate::CliError> {
    crate::io::forget_inputs();
    if let Some(m) = memory {
        let render = match &mut command {
            Command::Render(a) => &mut a.render,
            Command::Verify(a) => &mut a.render,
            Command::Bench(a) => &mut a.render,
            Command::Probe(a) => &mut a.render,
            _ => {
                return Err(crate::CliError::input(
                    "only render, verify, bench and probe take a volume in memory",
                ))
            }
        };
        render.memory = Some(m);
    }
    dispatch(command)
}

/// A parse error as one line, as every other error: clap's first line without its "error: "
/// prefix, with its suggestion kept where it has one ("tip: a similar argument exists: '--out'";
/// the usage that follows is what --help prints).
fn clap_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let first = text.lines().next().unwrap_or("bad arguments");
    let first = first.strip_prefix("error: ").unwrap_or(first);
    let tips: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("tip:"))
        .collect();
    // "a similar argument exists" before clap's other tips.
    let tip = tips.iter().find(|t| t.contains("similar")).or(tips.first());
    match tip {
        Some(tip) => format!("{first} ({tip}; see --help)"),
        None => format!("{first} (see --help)"),
    }
}
