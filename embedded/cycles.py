#!/usr/bin/env python3
"""Estimated cycles per frame of a firmware run on QEMU, counted by instruction class.

  cycles.py CORE ELF LOG [--selftest]

CORE is m0 (the micro:bit's nRF51822), m3 or m4 (Cortex-M4F). LOG is QEMU's
`-d in_asm,exec,nochain` log of the run (a file or a FIFO, read once, as it is written): every
translated block's instructions (in_asm) and every execution of a block (exec; `nochain` logs
each one), so the log is the exact instruction stream. A block ends at a branch: whether that
branch was taken is read from the next block executed (taken unless it starts at the
fall-through address).

Each executed instruction is put in a class and charged that class's cycles from ARM's
documented timings (Cortex-M0 TRM, r0p0, section 3.3 "Instruction set summary": the nRF51's
single-cycle multiplier; Cortex-M3 TRM r2p1 and Cortex-M4 TRM r0p1, table 3-1 "Processor
instruction timings" and, for the M4F's FPU, table 7-1). Where ARM gives a range the upper end
is taken, so the figure is an upper bound on the core's own cycles: loads and stores 2 (ARM: 1
when neighbouring loads/stores pipeline), a pipeline refill P = 3 on the M3/M4 (ARM: 1-3), long
multiplies 5/7 and divides 12 on the M3. Memory is charged no wait states: the micro:bit's
nRF51822 runs from flash at 16 MHz with none (code and data), the MPS2 boards from SSRAM with
none, the STM32F100 at 24 MHz needs none (FLASH_ACR latency 0); a 168 MHz STM32F4 needs 5,
which its ART accelerator's prefetch and 1 KiB instruction cache hide for loops that fit it
(the splat and compositing loops are a few hundred bytes), so the M4F figure assumes that.

Measured regions: every call of `spin` (the SysTick calibration), `setup` (the view-independent
set-up) and `render` (one orbit frame each), from the function's first block to the next block
in `main`. Frame figures leave out `emit` (printing frame 0's image over semihosting), from its
entry to its return, as the firmware's SysTick figure does. Prints one line per region:

  region NAME instructions N cycles C loads L stores S multi N multi_regs R branches_taken T
         branches_not_taken F calls K mul M div D fpu V other O

(all counts of executed instructions; `multi` are LDM/STM/PUSH/POP, `multi_regs` their
registers), and with --selftest checks the count on the calibration function `spin(2^20)`
against a hand count of its instructions (listed in `main`): its loop is n `subs` (1 cycle
each), n - 1 taken `bne` and one not taken, around it a push and a pop to the pc.
"""
import os
import re
import subprocess
import sys

TOOLS = os.path.join(
    subprocess.run(["rustc", "--print", "sysroot"], capture_output=True, text=True, check=True).stdout.strip(),
    "lib", "rustlib", "x86_64-unknown-linux-gnu", "bin")

INSN = re.compile(r"^0x([0-9a-f]{8}):\s+([0-9a-f]{4}(?: [0-9a-f]{4})?)\s+(\S+)\s*(.*)$")
COND = "(eq|ne|cs|hs|cc|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le)"
BRANCH = re.compile(r"^b" + COND + r"?$")
LIBRARY = re.compile(r"^__|compiler_builtins|libm|^fmaxf|^fminf|^memc|^mems")
CLASSES = ("loads", "stores", "multi", "multi_regs", "branches_taken", "branches_not_taken",
           "calls", "mul", "div", "fpu", "other")


def registers(ops):
    """Registers named in a {list} (ranges expanded)."""
    m = re.search(r"\{([^}]*)\}", ops)
    if not m:
        return 1
    n = 0
    for part in m.group(1).split(","):
        part = part.strip()
        r = re.fullmatch(r"[rsd](\d+)\s*-\s*[rsd](\d+)", part)
        n += int(r.group(2)) - int(r.group(1)) + 1 if r else 1
    return n


class Timing:
    """One core's cycle table: `cost(mnemonic, operands)` -> (class, cycles if it falls through /
    is not taken, cycles if it branches)."""

    def __init__(self, core):
        if core not in ("m0", "m3", "m4"):
            raise SystemExit(f"cycles.py: unknown core {core!r} (m0, m3, m4)")
        self.core = core
        # Pipeline refill after a taken branch: the M0's taken branch is 3 cycles in all; the
        # M3/M4's is 1 + P, P in 1..3 (upper end taken).
        self.p = 3

    def cost(self, mnem, ops):
        # Thumb-2 conditional execution inside an IT block (`addeq`, `ldreq`, ...) is charged as the
        # instruction itself (a failed condition costs its issue cycle at least: an upper bound).
        m = mnem.split(".")[0]
        m0 = self.core == "m0"
        pc = re.search(r"\bpc\b", ops) is not None
        if BRANCH.match(m):
            taken = 3 if m0 else 1 + self.p
            return ("branch" if m == "b" else "cond_branch", 1, taken)
        if m in ("cbz", "cbnz"):
            return ("cond_branch", 1, 1 + self.p)
        if m == "bl":
            return ("call", 4 if m0 else 1 + self.p, 4 if m0 else 1 + self.p)
        if m in ("bx", "blx"):
            return ("call" if m == "blx" else "branch", 3 if m0 else 1 + self.p, 3 if m0 else 1 + self.p)
        if m in ("tbb", "tbh"):
            return ("branch", 2 + self.p, 2 + self.p)
        if re.match(r"^(push|pop|ldm|stm)", m):
            n = registers(ops)
            c = 1 + n
            if m.startswith(("pop", "ldm")) and pc:
                c += 3 if m0 else self.p
                return ("multi_pc", c, c, n)
            return ("multi", c, c, n)
        if re.match(r"^v(push|pop|ldm|stm)", m):
            n = registers(ops)
            return ("fpu_multi", 1 + n, 1 + n, n)
        if m.startswith("v"):
            if re.match(r"^v(div|sqrt)", m):
                c = 14
            elif re.match(r"^v(n?ml[as]|f?n?fm[as])", m):
                c = 3
            elif re.match(r"^v(ldr|str)", m):
                c = 2
            else:
                c = 1
            return ("fpu", c, c)
        if re.match(r"^ldrd|^strd", m):
            return ("load2" if m.startswith("ldr") else "store2", 3, 3)
        if re.match(r"^ldr", m):
            if ops.startswith("pc"):
                return ("load_pc", 2 + (3 if m0 else self.p), 2 + (3 if m0 else self.p))
            return ("load", 2, 2)
        if re.match(r"^str", m):
            return ("store", 2, 2)
        if m in ("mul", "muls"):
            return ("mul", 1, 1)
        if m in ("mla", "mls"):
            return ("mul", 2 if self.core == "m3" else 1, 2 if self.core == "m3" else 1)
        if re.match(r"^(u|s)(mull|mlal)", m):
            c = 1 if self.core == "m4" else (5 if "mull" in m else 7)
            return ("mul", c, c)
        if re.match(r"^(smla|smul|smlal|smua|smus|smmul|smmla)", m):
            return ("mul", 1, 1)
        if m in ("sdiv", "udiv"):
            return ("div", 12, 12)
        if m in ("dmb", "dsb", "isb", "mrs", "msr"):
            return ("other", 4 if m0 else 1 + (m in ("dmb", "dsb", "isb")) * 2,
                    4 if m0 else 1 + (m in ("dmb", "dsb", "isb")) * 2)
        if m in ("wfi", "wfe"):
            return ("other", 2, 2)
        if m in ("bkpt", "svc", "udf", "cpsid", "cpsie", "nop", "sev", "yield"):
            return ("other", 1, 1)
        if (m.startswith(("mov", "add")) and ops.startswith("pc")):
            c = 3 if m0 else 1 + self.p
            return ("branch", c, c)
        return ("alu", 1, 1)


class Block:
    __slots__ = ("call_last", "symbol", "costs", "start", "n", "cycles", "taken_extra", "fall", "classes", "cond_last")

    def __init__(self, insns, timing):
        self.n = len(insns)
        self.start = insns[0][0]
        self.costs = []
        self.call_last = False
        self.cycles = 0
        self.classes = dict.fromkeys(CLASSES, 0)
        self.taken_extra = 0
        self.cond_last = False
        last = len(insns) - 1
        for i, (addr, size, mnem, ops) in enumerate(insns):
            cls = timing.cost(mnem, ops)
            kind, fall, taken = cls[0], cls[1], cls[2]
            self.fall = addr + size
            control = kind in ("branch", "cond_branch", "call", "multi_pc", "load_pc")
            if kind in ("multi", "multi_pc"):
                self.classes["multi"] += 1
                self.classes["multi_regs"] += cls[3]
            elif kind == "fpu_multi":
                self.classes["fpu"] += 1
            elif kind in ("load", "load2", "load_pc"):
                self.classes["loads"] += 1
            elif kind in ("store", "store2"):
                self.classes["stores"] += 1
            elif kind in ("mul", "div", "fpu", "other"):
                self.classes[kind] += 1
            elif kind == "call":
                self.classes["calls"] += 1
            self.costs.append((addr, taken if control else fall))
            self.call_last = i == last and kind == "call"
            if i == last and kind == "cond_branch":
                # Charged as not taken here; the taken case adds the refill when the next
                # block shows it.
                self.cond_last = True
                self.cycles += fall
                self.taken_extra = taken - fall
            else:
                self.cycles += taken if control else fall


def symbols(elf):
    """{name fragment: (start, end)} of the functions the regions need."""
    out = subprocess.run([os.path.join(TOOLS, "llvm-nm"), "-S", "--defined-only", "-C", elf],
                         capture_output=True, text=True, check=True).stdout
    found = {}
    for line in out.splitlines():
        parts = line.split(None, 3)
        if len(parts) < 4 or parts[2].lower() != "t":
            continue
        name = parts[3]
        for key, pattern in (("main", r"footprint_firmware::__cortex_m_rt_main::"),
                             ("spin", r"footprint_firmware::spin::"),
                             ("setup", r"footprint_firmware::setup::"),
                             ("render", r"footprint_firmware::render::h"),
                             ("emit", r"footprint_firmware::emit::h")):
            if re.match(pattern, name):
                start = int(parts[0], 16) & ~1
                found[key] = (start, start + int(parts[1], 16))
    for key in ("main", "spin", "setup", "render"):
        if key not in found:
            raise SystemExit(f"cycles.py: no symbol for {key} in {elf}")
    return found


def main(argv):
    if len(argv) < 4:
        raise SystemExit(__doc__)
    timing, elf, log = Timing(argv[1]), argv[2], argv[3]
    selftest = "--selftest" in argv[4:]
    sym = symbols(elf)
    main_lo, main_hi = sym["main"]
    entries = {sym[k][0]: k for k in ("spin", "setup", "render")}
    emit_entry = sym.get("emit", (None, None))[0]
    blocks = {}
    pending = []
    regions = []
    # {block's host address: [executions, times its last branch was taken]} of the open region
    current = None
    prev, prev_entry = None, None
    symbol = ""
    # CYCLES_INCLUSIVE=N: each function's cycles with its callees, over region N (0 = spin, 1 =
    # set-up, 2 = frame 0), from a shadow call stack (debugging aid; the figures above are exact).
    inclusive = {}
    inclusive_after = int(os.environ.get("CYCLES_INCLUSIVE", "-1"))
    profiling, stack, sites = None, [], {}
    current_partial = [0, 0]  # instructions and cycles of blocks cut short by an I/O access
    muted, emit_ret = False, None
    with open(log, "r", errors="replace") as f:
        for line in f:
            c = line[0]
            if c == "0":
                m = INSN.match(line)
                if m:
                    addr = int(m.group(1), 16)
                    pending.append((addr, 2 if len(m.group(2)) == 4 else 4, m.group(3), m.group(4)))
                continue
            if c == "S" and line.startswith("Stopped execution"):
                # The block logged last never ran (-icount's budget ran out before it).
                if prev_entry is not None:
                    prev_entry[0] -= 1
                prev_entry = None
                continue
            if c == "c" and line.startswith("cpu_io_recompile: rewound"):
                # The block logged last ran up to (not including) an I/O access, then was
                # retranslated to start there: count only the part that ran.
                if prev_entry is not None:
                    prev_entry[0] -= 1
                    upto = int(line.rsplit(" ", 1)[1], 16)
                    done = [c for a, c in blocks[prev].costs if a < upto]
                    current_partial[0] += len(done)
                    current_partial[1] += sum(done)
                prev_entry = None
                continue
            if c == "I" and line.startswith("IN:"):
                symbol = line[3:].strip()
                continue
            if c != "T":
                continue
            # "Trace 0: HOST [flags/PC/...] symbol": a translated block is named by where its
            # host code is (QEMU may translate one PC twice: under -icount a block is cut short
            # at an I/O access and retranslated).
            host = line.split(" ", 3)[2]
            if pending:
                blocks[host] = Block(pending, timing)
                blocks[host].symbol = symbol
                pending = []
            pc = int(line.split("/", 2)[1], 16)
            # Close the previous block's branch: taken unless this block is its fall-through.
            if prev_entry is not None:
                b = blocks[prev]
                if b.cond_last and pc != b.fall:
                    prev_entry[1] += 1
            if current is None:
                if pc in entries:
                    current, current_partial = {}, [0, 0]
                    regions.append((entries[pc], current, current_partial))
                    if len(regions) == 1 + inclusive_after:
                        profiling, stack = inclusive, []
            elif main_lo <= pc < main_hi:
                current = None
            if current is not None:
                if pc == emit_entry and not muted:
                    # Returns to the fall-through of the block that called it.
                    muted, emit_ret = True, blocks[prev].fall
                elif muted and pc == emit_ret:
                    muted = False
            prev_entry = None
            if current is not None and not muted:
                prev_entry = current.get(host)
                if prev_entry is None:
                    current[host] = prev_entry = [0, 0]
                prev_entry[0] += 1
            if profiling is not None and current is not None and not muted:
                b = blocks[host]
                while stack and stack[-1][1] == pc:
                    stack.pop()
                if prev is not None and blocks[prev].call_last and (not stack or stack[-1][1] != pc):
                    p = blocks[prev]
                    stack.append((b.symbol, p.fall, p.costs[-1][0], p.symbol))
                for sym_name in {f[0] for f in stack} | {b.symbol}:
                    profiling[sym_name] = profiling.get(sym_name, 0) + b.cycles
                # Library code (soft float, 64-bit and division helpers, libm) charged to the call
                # site in our code that entered it.
                for f in reversed(stack):
                    if not LIBRARY.search(f[3]):
                        if LIBRARY.search(f[0]):
                            sites[(f[2], f[3])] = sites.get((f[2], f[3]), 0) + b.cycles
                        break
                if len(regions) > 1 + inclusive_after:
                    profiling = None
            prev = host
    if sites:
        for (addr, caller), c in sorted(sites.items(), key=lambda kv: -kv[1])[:25]:
            print(f"  library call at {addr:#x} in {caller}: {c} cycles", file=sys.stderr)
    if inclusive:
        total = max(inclusive.values())
        for sym_name, c in sorted(inclusive.items(), key=lambda kv: -kv[1])[:40]:
            print(f"  inclusive {c:>10} cycles {100 * c / total:5.1f} %  {sym_name}", file=sys.stderr)
    frames = []
    dumped = False
    for name, counts, partial in regions:
        total = dict.fromkeys(("instructions", "cycles") + CLASSES, 0)
        total["instructions"], total["cycles"] = partial
        if os.environ.get("CYCLES_DUMP") == name and not dumped:
            dumped = True
            by_symbol = {}
            for host, (n, taken) in counts.items():
                b = blocks[host]
                print(f"  block {b.start:#x} x{n} taken {taken}: {b.n} insns {b.cycles} cycles", file=sys.stderr)
                k = by_symbol.setdefault(b.symbol, [0, 0])
                k[0] += n * b.n
                k[1] += n * b.cycles + taken * b.taken_extra
            for sym_name, (i, c) in sorted(by_symbol.items(), key=lambda kv: -kv[1][1])[:25]:
                print(f"  {c:>10} cycles {i:>10} instructions  {sym_name}", file=sys.stderr)
        for host, (n, taken) in counts.items():
            b = blocks[host]
            total["instructions"] += n * b.n
            total["cycles"] += n * b.cycles + taken * b.taken_extra
            for k, v in b.classes.items():
                total[k] += n * v
            if b.cond_last:
                total["branches_taken"] += taken
                total["branches_not_taken"] += n - taken
        frames.append((name, total))
        print(f"region {name} " + " ".join(f"{k} {v}" for k, v in total.items()))
    if selftest:
        spins = [t for n, t in frames if n == "spin"]
        if not spins:
            raise SystemExit("cycles.py: selftest: no spin region")
        t = spins[0]
        # Hand count of the whole function as rustc builds it (llvm-objdump -d):
        #   M0: push {r7, lr} (1 + 2); add r7, sp, #0 (1); movs r0, #1 (1); lsls r0, r0, #20 (1);
        #       loop: subs r0, #1 (1); bne loop (3 taken, 1 not); pop {r7, pc} (4 + 2)
        #   M3/M4: push {r7, lr} (1 + 2); mov r7, sp (1); mov.w r0, #0x100000 (1);
        #       loop: subs (1); bne (1 + P taken, 1 not); pop {r7, pc} (1 + 2 + P), P = 3
        n = 1 << 20
        if timing.core == "m0":
            hand = 3 + 1 + 1 + 1 + n * 1 + (n - 1) * 3 + 1 + 6
        else:
            hand = 3 + 1 + 1 + n * 1 + (n - 1) * (1 + timing.p) + 1 + (3 + timing.p)
        ok = t["cycles"] == hand and t["instructions"] == 2 * n + (5 if timing.core == "m0" else 4)
        print(f"selftest: spin({n}) hand count {hand} cycles, counted {t['cycles']} "
              f"({t['instructions']} instructions) {'ok' if ok else 'FAILED'}")
        if not ok:
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
