# Sourced by the benches' scripts (benches/real_size.sh, benches/post_reconstruction.sh): works
# from the repository root ($root), reads `--reps N` ($reps, default 3) and the binary ($fp: the
# first argument left, else the release build, built if missing).
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
reps=3
if [ "${1:-}" = --reps ]; then reps=$2; shift 2; fi
fp=${1:-$root/target/release/footprint}
[ -x "$fp" ] || cargo build -q --release -p footprint-harness
