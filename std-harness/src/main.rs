//! The `footprint` command. See `footprint --help` and the README.

fn main() {
    std::process::exit(footprint_harness::run(std::env::args_os()));
}
