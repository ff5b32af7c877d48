#!/usr/bin/env bash
# The README's set-up figures: a fresh clone of this repository with an empty cargo home (so every
# crate is downloaded, as on a fresh machine), the README's two commands timed one after the
# other, target/'s size after each, and the test executables `cargo test --workspace` builds.
# Usage: benches/fresh_clone.sh [WORKDIR]   (default /tmp/footprint-fresh; it is replaced)
set -u
repo=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-/tmp/footprint-fresh}
rm -rf "$work"
mkdir -p "$work"
git clone -q "$repo" "$work/footprint"
export CARGO_HOME="$work/cargo-home"
cd "$work/footprint"
t0=$(date +%s)
cargo run --release -p footprint-harness -- render > "$work/run.log" 2>&1 || { tail "$work/run.log"; exit 1; }
t1=$(date +%s)
echo "main job (first picture): $((t1 - t0)) s, $(grep -c Downloaded "$work/run.log") crates downloaded, target/ $(du -sh target | cut -f1)"
cargo test --workspace > "$work/test.log" 2>&1 || { tail "$work/test.log"; exit 1; }
t2=$(date +%s)
echo "tests: $((t2 - t1)) s, target/ $(du -sh target | cut -f1)"
echo "test executables: $(cargo test --workspace --no-run 2>&1 | grep -c Executable)"
nproc | sed 's/^/cores: /'
