#!/usr/bin/env bash
# Writes the real-writer fixtures fresh with the current releases of VTK, SimpleITK, nibabel and
# pynrrd (in a venv under target/), then runs tests/real_writers.rs on them; then checks --view
# against VTK's camera (tests/writers/vtk_camera.py; offscreen rendering needs libegl-mesa0).
#   tests/writers/run.sh            (from the repository root)
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/writers-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install -q --disable-pip-version-check vtk SimpleITK nibabel pynrrd numpy
out=$(mktemp -d)
"$venv/bin/python" tests/writers/make_fixtures.py "$out"
FOOTPRINT_WRITER_FIXTURES="$out" cargo test -q --test suite real_writers:: -- --nocapture 2>&1 | grep -E "matched|test result|panicked|FAILED"
rm -rf "$out"

# VTK's camera: silhouettes of VTK's renders and Footprint's agree for the same --view.
cargo build -q --release -p footprint-harness
cam=$(mktemp -d)
"$venv/bin/python" tests/writers/vtk_camera.py "$PWD/target/release/footprint" "$cam"
rm -rf "$cam"
