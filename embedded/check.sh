#!/usr/bin/env bash
# Everything the embedded demo must show, in one run (CI calls it; it works locally too):
#  0. every board runs the compact fixed path (footprint::fixed::compact) on an orbit of 4
#     frames: per frame its checksum (equal to the host's, bit for bit) and instructions; the
#     first frame's image, RAM, stack and flash, and its PSNR against the host's float render;
#     boards: mps2-an385 (M3) and mps2-an386 (M4F) at 64², micro:bit (M0, 16 KiB) at 48²,
#     stm32vldiscovery (STM32F100, M3, 8 KiB) at 32²;
#  1. the host renders the scene (debug, and release on 4 threads) to one Q24 fixed-point
#     checksum and one compact checksum, the ones pinned in expected-checksum.txt; the Q24 path
#     still runs on the M3 (`--features q24`) to the same bits;
#  2. the firmware renders it on QEMU mps2-an385 (Cortex-M3, no FPU) and mps2-an386 (Cortex-M4F)
#     and prints the same checksum, its painted-stack high-water mark, static RAM and flash, and
#     its image, which the host checks (CRC) and compares with its float render (PSNR);
#  2a. each firmware sends its bands as RGB565 rows through the core's embedded-graphics adaptor
#     into a framebuffer-less display that keeps their CRC, equal to the host's for the same rows;
#  2b. on QEMU microbit (Cortex-M0, nRF51822 memory map: 256 KiB flash, 16 KiB RAM) and
#     stm32vldiscovery (8 KiB RAM) it renders 48×48 and 32×32 in bands, with the host's
#     checksums for those sizes, within each board's RAM: statics + stack;
#  3. the fixed paths' splat and compositing contain no float (object-code audit on every
#     board's build), and the audit catches a planted float multiply;
#  4. the worst-case stack from the compiler's stack sizes fits STACK_BUDGET and bounds what the
#     painted stack measured;
#  5. the float build's figures, and every build's instructions per frame under -icount, for the
#     README's cost table;
#  6. every compact board's estimated cycles per orbit frame, by instruction class, from QEMU's log
#     of the blocks it executes (cycles.py: ARM's documented timings; its instruction count must
#     equal the SysTick figure, and its count of the calibration loop a hand count), frames per
#     second at the board's clock, and CI fails past each board's cycle ceiling (below); the
#     M4F also renders 128×128 (`--features side128`, its own summary line `M4F 128x128`).
# Needs: qemu-system-arm, rustup targets thumbv6m-none-eabi, thumbv7m-none-eabi,
# thumbv7em-none-eabihf, and the llvm-tools component.
set -euo pipefail
cd "$(dirname "$0")"

# The compact path's per-view stencil set-up keeps one box of float weights on the stack (9×9 at
# the M4F's 128², which has 4 MiB of RAM: its budget is larger).
STACK_BUDGET=4608
STACK_BUDGET_LARGE=6144
# -icount shift=0: the virtual clock advances 1 ns per instruction, so the firmware's SysTick
# count (calibrated against a loop of known length) is an instruction count, the same every run.
QEMU_FLAGS=(-nographic -icount shift=0 -semihosting-config enable=on,target=native)
LINK=(-C link-arg=-Tlink.x)
fail() { echo "embedded: FAIL: $*" >&2; exit 1; }

echo "== host"
# (Not `tee /dev/stderr`: reopening stderr truncates it when it is a log file.)
out=$(cargo run -q -p footprint-scene-host)
echo "$out"
host_debug=$(grep -E '^(fixed|compact) checksum' <<<"$out" | sed 's/ (.*//')
out=$(cargo run -q --release -p footprint-scene-host -- --threads 4)
echo "$out"
host_release=$(grep -E '^(fixed|compact) checksum' <<<"$out" | sed 's/ (.*//')
[ "$host_debug" = "$host_release" ] || fail "host debug ($host_debug) and release ($host_release) differ"
# The checksums are pinned: a change to either fixed path's output is a reviewed decision (update
# expected-checksum.txt in the same commit), never an accident.
expected=$(cat expected-checksum.txt)
[ "$host_debug" = "$expected" ] || fail "host '$host_debug', expected-checksum.txt '$expected'"
echo "host checksums equal expected-checksum.txt"
host_q24=$(grep '^fixed checksum' <<<"$out")
host_q24_rgb565=$(sed -n 's/^rgb565 crc \(0x[0-9a-f]*\) .*/\1/p' <<<"$out")
# host_value PREFIX KEY, host_orbit PREFIX: the host's value of "PREFIXKEY 0x…" ("", "microbit ", "stm32 ").
host_out=$out
host_value() { sed -n "s/^$1$2 \(0x[0-9a-f]*\).*/\1/p" <<<"$host_out"; }
host_orbit() { sed -n "s/^$1orbit checksums //p" <<<"$host_out"; }

# run MACHINE CPU ELF [CORE CYCLES]: prints the firmware's output, fails on a non-zero exit or a
# timeout (CPU "-": the machine's own). With CORE (m0, m3, m4), QEMU also logs every block it
# executes into a FIFO that cycles.py reads as it is written, and each measured region's
# instructions and estimated cycles by instruction class go to the file CYCLES.
run() {
  local cpu=(-cpu "$2") log=() fifo="" pid="" limit=300
  [ "$2" = - ] && cpu=()
  if [ $# -ge 5 ]; then
    fifo=$(mktemp -u "${TMPDIR:-/tmp}/footprint-exec.XXXXXX")
    mkfifo "$fifo"
    timeout 1200 python3 cycles.py "$4" "$3" "$fifo" --selftest >"$5" 2>&1 &
    pid=$!
    log=(-d in_asm,exec,nochain -D "$fifo")
    limit=1200
  fi
  timeout "$limit" qemu-system-arm -machine "$1" "${cpu[@]}" "${QEMU_FLAGS[@]}" "${log[@]}" -kernel "$3" \
    || { [ -z "$pid" ] || kill "$pid" 2>/dev/null; fail "$3 on $1 exited with $?"; }
  if [ -n "$pid" ]; then
    wait "$pid" || fail "cycles.py on $3: $(cat "$5")"
    rm -f "$fifo"
  fi
}
images=target/embedded-images
mkdir -p "$images"
# compare NAME LOG: the host checks the printed image's CRC and measures it against its float
# render; prints the host's line and leaves $images/NAME/{microbit,host-float}.png.
compare() {
  cargo run -q --release -p footprint-scene-host -- compare "$2" "$images/$1" \
    || fail "$1: the printed image does not match the host's"
}

# field NAME OUTPUT: the N of a firmware's "NAME N bytes" line; instr OUTPUT: its first frame's
# instructions; frames OUTPUT: each frame's checksum, and instructions.
field() { sed -n "s/^$1 \([0-9]*\) bytes/\1/p" <<<"$2"; }
instr() { sed -n 's/^frame instructions \([0-9]*\).*/\1/p' <<<"$1"; }
frame_sums() { sed -n 's/^frame [0-9]* checksum \(0x[0-9a-f]*\) .*/\1/p' <<<"$1" | paste -sd' '; }
frame_instr() { sed -n 's/^frame [0-9]* checksum 0x[0-9a-f]* instructions \([0-9]*\)/\1/p' <<<"$1" | paste -sd' '; }
# stack_bound TARGET DIR FEATURES [BUDGET]: the worst-case stack of the render chain (the compiler's stack
# sizes), printed; the bound in $bound.
stack_bound() {
  RUSTC_BOOTSTRAP=1 RUSTFLAGS="-Z emit-stack-sizes ${LINK[*]}" \
    cargo build -q --release -p footprint-firmware --target "$1" --target-dir "$2" $3
  # The render's worst case plus the frames of its callers from the reset handler (main's own
  # printing goes through core::fmt's indirect calls and is not bounded; it runs after the
  # high-water mark is taken).
  local b
  b=$(python3 elf_check.py stack-bound "$2/$1/release/footprint-firmware" \
    "__stext>main>___cortex_m_rt_main>footprint_firmware6render" "${4:-$STACK_BUDGET}")
  echo "$b"
  bound=$(sed -n 's/^stack-bound: worst case from [^:]*: \([0-9]*\) bytes.*/\1/p' <<<"$b")
}

report=target/embedded-report.txt
mkdir -p target
: > "$report"
# Each board's worst orbit frame, estimated cycles (cycles.py: ARM's documented timings, upper
# ends of ranges, no wait states). TARGET is the budget issue 78 set: the micro:bit a frame a
# second at 16 MHz, the M4F's 128² ten frames a second at 168 MHz. CI fails past CEILING: the
# TARGET where a board meets it, otherwise the worst frame measured when the ceiling was last set
# plus 2 % (so a regression stops CI while the gap to the target is printed on every run).
declare -A TARGET=([microbit]=16000000 [M4F-128]=16800000)
declare -A CEILING=([microbit]=30240000 [M4F-128]=44690000 [M4F]=16920000 [M3]=22680000 [STM32F100]=23180000)
# The clock each board's frames per second are given at, MHz: the micro:bit's nRF51822 16,
# QEMU's MPS2 FPGA images 25 (the M3's), the STM32F100 24; the M4F's 168, a 168 MHz STM32F4-class
# part, as the issue's budget (QEMU's mps2-an386 models its core, not a clock).
declare -A CLOCK=([microbit]=16 [M4F-128]=168 [M4F]=168 [M3]=25 [STM32F100]=24)

# board NAME TARGET MACHINE CPU CORE RAM PREFIX LABEL PSNR FEATURES: the compact firmware on one
# board (LABEL starts its summary line; PSNR the least dB against float it must reach).
board() {
  local name=$1 target=$2 machine=$3 cpu=$4 core=$5 ram=$6 prefix=$7 label=$8 least=$9 features=${10}
  local dir=target/board-$name
  echo "== $label compact ($target on $machine)"
  cargo build -q --release -p footprint-firmware --target "$target" --target-dir "$dir" $features
  local elf=$dir/$target/release/footprint-firmware
  local out
  out=$(run "$machine" "$cpu" "$elf" "$core" "target/$name.cycles")
  grep -v '^row ' <<<"$out"
  printf '%s\n' "$out" > "target/$name.log"
  local sum shown sums want
  sum=$(sed -n 's/^compact checksum //p' <<<"$out")
  [ -n "$sum" ] && [ "$sum" = "$(host_value "$prefix" 'compact checksum')" ] \
    || fail "$name: compact checksum '$sum', host: '$(host_value "$prefix" 'compact checksum')'"
  sums=$(frame_sums "$out"); want=$(host_orbit "$prefix")
  [ -n "$sums" ] && [ "$sums" = "$want" ] || fail "$name: orbit checksums '$sums', host: '$want'"
  shown=$(sed -n 's/^rgb565 crc \(0x[0-9a-f]*\) .*/\1/p' <<<"$out")
  [ "$shown" = "$(host_value "$prefix" 'compact rgb565 crc')" ] \
    || fail "$name: the display was sent rgb565 crc '$shown', host: '$(host_value "$prefix" 'compact rgb565 crc')'"
  local cmp_out psnr
  cmp_out=$(compare "$name" "target/$name.log")
  echo "$cmp_out"
  psnr=$(sed -n 's/.*psnr_vs_float \([0-9.]*\) dB.*/\1/p' <<<"$cmp_out")
  python3 -c "import sys; sys.exit(0 if float('$psnr') >= $least else 1)" || fail "$name: PSNR $psnr dB < $least"
  python3 elf_check.py float-audit "$elf"
  local statics stack flash
  statics=$(field 'static RAM' "$out"); stack=$(field 'stack high-water' "$out"); flash=$(field flash "$out")
  [ -n "$statics" ] && [ -n "$stack" ] && [ -n "$flash" ] || fail "$name: missing figures"
  [ $((statics + stack)) -le "$ram" ] || fail "$name: static RAM $statics + stack $stack > $ram"
  echo "== $label stack bound"
  local budget=$STACK_BUDGET
  [ "$name" = M4F-128 ] && budget=$STACK_BUDGET_LARGE
  stack_bound "$target" "target/stack-$name" "$features" "$budget"
  [ -n "$bound" ] && [ "$stack" -le "$bound" ] || fail "$name: painted stack $stack exceeds the computed bound $bound"
  local ins setup
  ins=$(frame_instr "$out")
  setup=$(sed -n 's/^setup instructions \([0-9]*\).*/\1/p' <<<"$out")
  # Cycles: the exec log's count of each frame's instructions must be the SysTick figure (within
  # 0.1 %: the two differ only by where the timer is read); the calibration loop's cycles were
  # held to their hand count when `run` waited for cycles.py --selftest.
  local cyc
  cyc=$(python3 - "target/$name.cycles" "$ins" "${CLOCK[$name]}" "${TARGET[$name]:-0}" "${CEILING[$name]}" <<'PY'
import sys
path, ins, clock, target, ceiling = sys.argv[1:]
regions = [l.split() for l in open(path) if l.startswith("region ")]
get = lambda r: dict(zip(r[2::2], map(int, r[3::2])))
frames = [get(r) for r in regions if r[1] == "render"]
setups = [get(r) for r in regions if r[1] == "setup"]
ins = [int(x) for x in ins.split()]
if len(frames) != len(ins) or not setups:
    sys.exit(f"cycles.py saw {len(frames)} frames, the firmware printed {len(ins)}")
for f, n in zip(frames, ins):
    if abs(f["instructions"] - n) > n / 1000:
        sys.exit(f"exec log counted {f['instructions']} instructions, SysTick {n}")
cycles = [f["cycles"] for f in frames]
worst = max(cycles)
f0 = frames[0]
mix = ", ".join(f"{k} {f0[k]}" for k in ("loads", "stores", "multi", "multi_regs", "branches_taken",
                                           "branches_not_taken", "calls", "mul", "div", "fpu"))
target, ceiling = int(target), int(ceiling)
if target:
    budget = (f"budget {target / 1e6:g} M cycles met" if worst <= target else
              f"budget {target / 1e6:g} M cycles NOT met ({worst / target:.2f}x; CI ceiling {ceiling / 1e6:g} M)")
else:
    budget = f"no cycle budget (CI ceiling {ceiling / 1e6:g} M)"
print(f"estimated cycles/frame {' '.join(map(str, cycles))} (set-up once: {setups[0]['cycles']}); "
      f"{int(clock) * 1e6 / worst:.2f} frames/s at {clock} MHz (worst frame); {budget}")
print(f"frame 0 mix: {f0['instructions']} instructions: {mix}", file=sys.stderr)
sys.exit(3 if worst > ceiling else 0)
PY
) || fail "$name: cycles: $cyc (ceiling ${CEILING[$name]})"
  echo "$label cycles: $cyc"
  echo "$label compact: orbit instructions/frame $ins (set-up once: $setup); $cyc; static RAM $statics + stack $stack (bound $bound) of $ram B; flash $flash B; checksum $sum; psnr_vs_float $psnr dB" >>"$report"
}

board M3 thumbv7m-none-eabi mps2-an385 cortex-m3 m3 4194304 "" M3 40 ""
board M4F thumbv7em-none-eabihf mps2-an386 cortex-m4 m4 4194304 "" M4F 40 ""
board M4F-128 thumbv7em-none-eabihf mps2-an386 cortex-m4 m4 4194304 "m4f128 " "M4F 128x128" 45 "--features side128"
board microbit thumbv6m-none-eabi microbit - m0 16384 "microbit " microbit 40 ""
board STM32F100 thumbv7m-none-eabi stm32vldiscovery - m3 8192 "stm32 " STM32F100 40 "--features stm32f100"
# The README's pictures are the micro:bit's: a change is a reviewed decision (copy them to
# docs/images).
for f in microbit host-float; do
  cmp -s "$images/microbit/$f.png" "../docs/images/microbit-$f.png" \
    || fail "docs/images/microbit-$f.png differs from $images/microbit/$f.png (copy it if intended)"
done

echo "== M3 Q24 fixed path (--features q24)"
cargo build -q --release -p footprint-firmware --features q24 --target thumbv7m-none-eabi --target-dir target/q24
out=$(run mps2-an385 cortex-m3 target/q24/thumbv7m-none-eabi/release/footprint-firmware)
grep -v '^row ' <<<"$out"
sum=$(grep '^fixed checksum' <<<"$out") || fail "Q24 printed no checksum"
[ "$sum" = "$host_q24" ] || fail "Q24 on M3: '$sum', host: '$host_q24'"
shown=$(sed -n 's/^rgb565 crc \(0x[0-9a-f]*\) .*/\1/p' <<<"$out")
[ "$shown" = "$host_q24_rgb565" ] || fail "Q24 on M3: rgb565 crc '$shown', host: '$host_q24_rgb565'"
printf '%s\n' "$out" > target/M3-q24.log
compare M3-q24 target/M3-q24.log
python3 elf_check.py float-audit target/q24/thumbv7m-none-eabi/release/footprint-firmware
echo "M3 Q24 fixed: $sum (= host); static RAM $(field 'static RAM' "$out"), stack $(field 'stack high-water' "$out"), instructions/frame $(instr "$out")" >>"$report"

for spec in "thumbv7m-none-eabi mps2-an385 cortex-m3 M3" "thumbv7em-none-eabihf mps2-an386 cortex-m4 M4F" "thumbv6m-none-eabi microbit - micro:bit"; do
  read -r target machine cpu name <<<"$spec"
  echo "== $name float"
  cargo build -q --release -p footprint-firmware --features float --target "$target" --target-dir target/float
  fout=$(run "$machine" "$cpu" "target/float/$target/release/footprint-firmware")
  grep -v '^row ' <<<"$fout"
  echo "$name float: stack $(field 'stack high-water' "$fout"), static RAM $(field 'static RAM' "$fout"), flash $(field flash "$fout"), instructions/frame $(instr "$fout")" >>"$report"
done

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
