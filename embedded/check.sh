#!/usr/bin/env bash
# Everything the embedded demo must show, in one run (CI calls it; it works locally too):
#  1. the host renders the scene (debug, and release on 4 threads) to one fixed-point checksum,
#     the one pinned in expected-checksum.txt;
#  2. the firmware renders it on QEMU mps2-an385 (Cortex-M3, no FPU) and mps2-an386 (Cortex-M4F)
#     and prints the same checksum, its painted-stack high-water mark, static RAM and flash;
#  3. the fixed path's splat and compositing contain no float (object-code audit on M3, M4F and
#     M0+), and the audit catches a planted float multiply;
#  4. the worst-case stack from the compiler's stack sizes fits STACK_BUDGET and bounds what the
#     painted stack measured;
#  5. the float build's figures, for the README's cost table.
# Needs: qemu-system-arm, rustup targets thumbv6m-none-eabi, thumbv7m-none-eabi,
# thumbv7em-none-eabihf, and the llvm-tools component.
set -euo pipefail
cd "$(dirname "$0")"

STACK_BUDGET=4096
QEMU_FLAGS=(-nographic -semihosting-config enable=on,target=native)
LINK=(-C link-arg=-Tlink.x)
fail() { echo "embedded: FAIL: $*" >&2; exit 1; }

echo "== host"
# (Not `tee /dev/stderr`: reopening stderr truncates it when it is a log file.)
out=$(cargo run -q -p footprint-scene-host)
echo "$out"
host_debug=$(grep '^fixed checksum' <<<"$out")
out=$(cargo run -q --release -p footprint-scene-host -- --threads 4)
echo "$out"
host_release=$(grep '^fixed checksum' <<<"$out")
[ "$host_debug" = "$host_release" ] || fail "host debug ($host_debug) and release ($host_release) differ"
# The checksum is pinned: a change to the fixed path's output is a reviewed decision (update
# expected-checksum.txt in the same commit), never an accident.
expected=$(cat expected-checksum.txt)
[ "$host_debug" = "$expected" ] || fail "host '$host_debug', expected-checksum.txt '$expected'"
echo "host fixed checksum equals expected-checksum.txt"

# run MACHINE CPU ELF: prints the firmware's output, fails on a non-zero exit or a timeout.
run() {
  timeout 300 qemu-system-arm -machine "$1" -cpu "$2" "${QEMU_FLAGS[@]}" -kernel "$3" \
    || fail "$3 on $1 exited with $?"
}

report=target/embedded-report.txt
mkdir -p target
: > "$report"
for spec in "thumbv7m-none-eabi mps2-an385 cortex-m3 M3" "thumbv7em-none-eabihf mps2-an386 cortex-m4 M4F"; do
  read -r target machine cpu name <<<"$spec"
  echo "== $name fixed ($target on $machine)"
  cargo build -q --release -p footprint-firmware --target "$target"
  elf=target/$target/release/footprint-firmware
  out=$(run "$machine" "$cpu" "$elf")
  echo "$out"
  sum=$(grep '^fixed checksum' <<<"$out") || fail "$name printed no checksum"
  [ "$sum" = "$host_debug" ] || fail "$name: '$sum', host: '$host_debug'"
  echo "$name fixed: $sum (= host)"
  python3 elf_check.py float-audit "$elf"

  echo "== $name stack bound"
  RUSTC_BOOTSTRAP=1 RUSTFLAGS="-Z emit-stack-sizes ${LINK[*]}" \
    cargo build -q --release -p footprint-firmware --target "$target" --target-dir target/stack
  # The render's worst case plus the frames of its callers from the reset handler (main's own
  # printing goes through core::fmt's indirect calls and is not bounded; it runs after the
  # high-water mark is taken).
  bound_out=$(python3 elf_check.py stack-bound "target/stack/$target/release/footprint-firmware" \
    "__stext>main>___cortex_m_rt_main>footprint_firmware6render" "$STACK_BUDGET")
  echo "$bound_out"
  bound=$(sed -n 's/^stack-bound: worst case from [^:]*: \([0-9]*\) bytes.*/\1/p' <<<"$bound_out")
  used=$(sed -n 's/^stack high-water \([0-9]*\) bytes/\1/p' <<<"$out")
  [ -n "$bound" ] && [ -n "$used" ] || fail "$name: no stack figures"
  [ "$used" -le "$bound" ] || fail "$name: painted stack $used exceeds the computed bound $bound"

  echo "== $name float"
  cargo build -q --release -p footprint-firmware --features float --target "$target" --target-dir target/float
  fout=$(run "$machine" "$cpu" "target/float/$target/release/footprint-firmware")
  echo "$fout"
  field() { sed -n "s/^$1 \([0-9]*\) bytes/\1/p" <<<"$2"; }
  echo "$name fixed: stack $used (bound $bound), static RAM $(field 'static RAM' "$out"), flash $(field flash "$out")" >>"$report"
  echo "$name float: stack $(field 'stack high-water' "$fout"), static RAM $(field 'static RAM' "$fout"), flash $(field flash "$fout")" >>"$report"
done

echo "== M0+ (thumbv6m-none-eabi: built and audited; QEMU's mps2 boards have no M0 image)"
cargo build -q --release -p footprint-firmware --target thumbv6m-none-eabi
python3 elf_check.py float-audit target/thumbv6m-none-eabi/release/footprint-firmware

echo "== the audit catches a planted float (--cfg footprint_audit_plant)"
RUSTFLAGS="--cfg footprint_audit_plant ${LINK[*]}" \
  cargo build -q --release -p footprint-firmware --target thumbv7m-none-eabi --target-dir target/plant
if python3 elf_check.py float-audit target/plant/thumbv7m-none-eabi/release/footprint-firmware; then
  fail "the audit missed the planted float"
fi
echo "planted float caught"

echo "== summary"
cat "$report"
echo "embedded: all checks passed"
