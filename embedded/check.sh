#!/usr/bin/env bash
# Everything the embedded demo must show, in one run (CI calls it; it works locally too):
#  1. the host renders the scene (debug, and release on 4 threads) to one fixed-point checksum,
#     the one pinned in expected-checksum.txt;
#  2. the firmware renders it on QEMU mps2-an385 (Cortex-M3, no FPU) and mps2-an386 (Cortex-M4F)
#     and prints the same checksum, its painted-stack high-water mark, static RAM and flash, and
#     its image, which the host checks (CRC) and compares with its float render (PSNR);
#  2a. each firmware sends its bands as RGB565 rows through the core's embedded-graphics adaptor
#     into a framebuffer-less display that keeps their CRC, equal to the host's for the same rows;
#  2b. on QEMU microbit (Cortex-M0, nRF51822 memory map: 256 KiB flash, 16 KiB RAM) it renders
#     48×48 in bands, with the host's checksum for that size, in 16 KiB: statics + stack;
#  3. the fixed path's splat and compositing contain no float (object-code audit on M3, M4F and
#     the micro:bit's M0), and the audit catches a planted float multiply;
#  4. the worst-case stack from the compiler's stack sizes fits STACK_BUDGET and bounds what the
#     painted stack measured;
#  5. the float build's figures, and every build's instructions per frame under -icount, for the
#     README's cost table.
# Needs: qemu-system-arm, rustup targets thumbv6m-none-eabi, thumbv7m-none-eabi,
# thumbv7em-none-eabihf, and the llvm-tools component.
set -euo pipefail
cd "$(dirname "$0")"

STACK_BUDGET=4096
# -icount shift=0: the virtual clock advances 1 ns per instruction, so the firmware's SysTick
# count (calibrated against a loop of known length) is an instruction count, the same every run.
QEMU_FLAGS=(-nographic -icount shift=0 -semihosting-config enable=on,target=native)
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
host_microbit=$(sed -n 's/^microbit fixed checksum //p' <<<"$out")
[ -n "$host_microbit" ] || fail "the host printed no micro:bit checksum"
# The rows a display is sent (RGB565 through the core's embedded-graphics adaptor), per size.
host_rgb565=$(sed -n 's/^rgb565 crc \(0x[0-9a-f]*\) .*/\1/p' <<<"$out")
host_rgb565_microbit=$(sed -n 's/^microbit rgb565 crc \(0x[0-9a-f]*\) .*/\1/p' <<<"$out")
[ -n "$host_rgb565" ] && [ -n "$host_rgb565_microbit" ] || fail "the host printed no rgb565 CRC"
[ "$host_debug" = "$host_release" ] || fail "host debug ($host_debug) and release ($host_release) differ"
# The checksum is pinned: a change to the fixed path's output is a reviewed decision (update
# expected-checksum.txt in the same commit), never an accident.
expected=$(cat expected-checksum.txt)
[ "$host_debug" = "$expected" ] || fail "host '$host_debug', expected-checksum.txt '$expected'"
echo "host fixed checksum equals expected-checksum.txt"

# run MACHINE CPU ELF: prints the firmware's output, fails on a non-zero exit or a timeout
# (CPU "-": the machine's own).
run() {
  local cpu=(-cpu "$2")
  [ "$2" = - ] && cpu=()
  timeout 300 qemu-system-arm -machine "$1" "${cpu[@]}" "${QEMU_FLAGS[@]}" -kernel "$3" \
    || fail "$3 on $1 exited with $?"
}
images=target/embedded-images
mkdir -p "$images"
# compare NAME LOG: the host checks the printed image's CRC and measures it against its float
# render; prints the host's line and leaves $images/NAME/{microbit,host-float}.png.
compare() {
  cargo run -q --release -p footprint-scene-host -- compare "$2" "$images/$1" \
    || fail "$1: the printed image does not match the host's"
}

# field NAME OUTPUT: the N of a firmware's "NAME N bytes" line; instr OUTPUT: its instructions
# per frame.
field() { sed -n "s/^$1 \([0-9]*\) bytes/\1/p" <<<"$2"; }
instr() { sed -n 's/^frame instructions \([0-9]*\).*/\1/p' <<<"$1"; }

report=target/embedded-report.txt
mkdir -p target
: > "$report"
for spec in "thumbv7m-none-eabi mps2-an385 cortex-m3 M3" "thumbv7em-none-eabihf mps2-an386 cortex-m4 M4F"; do
  read -r target machine cpu name <<<"$spec"
  echo "== $name fixed ($target on $machine)"
  cargo build -q --release -p footprint-firmware --target "$target"
  elf=target/$target/release/footprint-firmware
  out=$(run "$machine" "$cpu" "$elf")
  grep -v '^row ' <<<"$out"
  sum=$(grep '^fixed checksum' <<<"$out") || fail "$name printed no checksum"
  [ "$sum" = "$host_debug" ] || fail "$name: '$sum', host: '$host_debug'"
  echo "$name fixed: $sum (= host)"
  shown=$(sed -n 's/^rgb565 crc \(0x[0-9a-f]*\) .*/\1/p' <<<"$out")
  [ "$shown" = "$host_rgb565" ] || fail "$name: the display was sent rgb565 crc '$shown', host: '$host_rgb565'"
  echo "$name display rows: rgb565 crc $shown (= host)"
  printf '%s\n' "$out" > "target/$name.log"
  compare "$name" "target/$name.log"
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
  grep -v '^row ' <<<"$fout"
  echo "$name fixed: stack $used (bound $bound), static RAM $(field 'static RAM' "$out"), flash $(field flash "$out"), instructions/frame $(instr "$out")" >>"$report"
  echo "$name float: stack $(field 'stack high-water' "$fout"), static RAM $(field 'static RAM' "$fout"), flash $(field flash "$fout"), instructions/frame $(instr "$fout")" >>"$report"
done

echo "== micro:bit fixed (thumbv6m-none-eabi on microbit: Cortex-M0, 16 KiB RAM)"
cargo build -q --release -p footprint-firmware --target thumbv6m-none-eabi
elf=target/thumbv6m-none-eabi/release/footprint-firmware
out=$(run microbit - "$elf")
grep -v '^row ' <<<"$out"
printf '%s\n' "$out" > target/microbit.log
sum=$(sed -n 's/^fixed checksum //p' <<<"$out")
[ "$sum" = "$host_microbit" ] || fail "micro:bit: checksum '$sum', host: '$host_microbit'"
shown=$(sed -n 's/^rgb565 crc \(0x[0-9a-f]*\) .*/\1/p' <<<"$out")
[ "$shown" = "$host_rgb565_microbit" ] \
  || fail "micro:bit: the display was sent rgb565 crc '$shown', host: '$host_rgb565_microbit'"
ram=$(field 'static RAM' "$out"); stack=$(field 'stack high-water' "$out"); flash=$(field flash "$out")
read -r w h < <(sed -n 's/^image \([0-9]*\) \([0-9]*\)$/\1 \2/p' <<<"$out")
[ -n "$ram" ] && [ -n "$stack" ] && [ -n "$flash" ] && [ -n "$w" ] || fail "micro:bit: missing figures"
cmp_out=$(compare microbit target/microbit.log)
psnr=$(sed -n 's/.*psnr_vs_float \([0-9.]*\) dB.*/\1/p' <<<"$cmp_out")
echo "microbit: image ${w}x${h}, ram $ram B, stack $stack B, flash $flash B, checksum $sum, psnr_vs_float $psnr dB"
[ "$w" -ge 48 ] && [ "$h" -ge 48 ] || fail "micro:bit: image ${w}x${h} is smaller than 48x48"
[ $((ram + stack)) -le 16384 ] || fail "micro:bit: static RAM $ram + stack $stack > 16384"
python3 -c "import sys; sys.exit(0 if float('$psnr') >= 35 else 1)" || fail "micro:bit: PSNR $psnr dB < 35"
# The README's pictures are these two: a change is a reviewed decision (copy them to docs/images).
for f in microbit host-float; do
  cmp -s "$images/microbit/$f.png" "../docs/images/microbit-$f.png" \
    || fail "docs/images/microbit-$f.png differs from $images/microbit/$f.png (copy it if intended)"
done
python3 elf_check.py float-audit "$elf"
echo "== micro:bit stack bound"
RUSTC_BOOTSTRAP=1 RUSTFLAGS="-Z emit-stack-sizes ${LINK[*]}" \
  cargo build -q --release -p footprint-firmware --target thumbv6m-none-eabi --target-dir target/stack
bound_out=$(python3 elf_check.py stack-bound "target/stack/thumbv6m-none-eabi/release/footprint-firmware" \
  "__stext>main>___cortex_m_rt_main>footprint_firmware6render" "$STACK_BUDGET")
echo "$bound_out"
bound=$(sed -n 's/^stack-bound: worst case from [^:]*: \([0-9]*\) bytes.*/\1/p' <<<"$bound_out")
[ -n "$bound" ] && [ "$stack" -le "$bound" ] || fail "micro:bit: painted stack $stack exceeds the computed bound $bound"
echo "micro:bit fixed: stack $stack (bound $bound), static RAM $ram, flash $flash, instructions/frame $(instr "$out")" >>"$report"
echo "== micro:bit float"
cargo build -q --release -p footprint-firmware --features float --target thumbv6m-none-eabi --target-dir target/float
fout=$(run microbit - "target/float/thumbv6m-none-eabi/release/footprint-firmware")
grep -v '^row ' <<<"$fout"
echo "micro:bit float: stack $(field 'stack high-water' "$fout"), static RAM $(field 'static RAM' "$fout"), flash $(field flash "$fout"), instructions/frame $(instr "$fout")" >>"$report"

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
