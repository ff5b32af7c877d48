#!/usr/bin/env python3
"""Object-code checks on a firmware ELF, using LLVM's objdump/readobj (rustup's llvm-tools).

  elf_check.py float-audit ELF
      Fails if a function of the fixed path's splat or compositing (footprint::fixed::splat,
      footprint::fixed::composite) calls a soft-float routine (__aeabi_f*/__aeabi_d*, __addsf3 …)
      or executes a VFP instruction (v*.f32/f64, vmov to or from s/d registers).

  elf_check.py stack-bound ELF CHAIN BUDGET
      Worst-case stack of the last function in CHAIN ("a>b>c", names or name fragments: the
      callers from the reset handler down, then the function bounded), from the compiler's per-function
      stack sizes (-Z emit-stack-sizes; functions built without it, such as compiler-builtins, are
      sized from their prologue) over the direct call graph. Fails on recursion, on an indirect
      call outside panic paths, or if the bound exceeds BUDGET bytes. Panic paths (symbols with
      `panic`) are followed but their indirect calls (formatting) are listed, not bounded: a panic
      ends the program.
"""
import os
import re
import subprocess
import sys

TOOLS = os.path.join(
    subprocess.run(["rustc", "--print", "sysroot"], capture_output=True, text=True, check=True).stdout.strip(),
    "lib", "rustlib", "x86_64-unknown-linux-gnu", "bin")

FIXED_PATH = ("5fixed5splat5splat", "5fixed9composite", "7compact15CompactStencils5splat", "7compact13composite_row")
SOFT_FLOAT = re.compile(r"__aeabi_[fd]|__(add|sub|mul|div|neg)[sdt]f3|__(eq|ne|lt|le|gt|ge|unord|cmp)[sdt]f2"
                        r"|__(extend|trunc)[sdt]f|__fix(uns)?[sdt]f|__float(un)?[sdt]i[sdt]f|__powi[sdt]f2")
VFP = re.compile(r"^v\S*\.(f32|f64)|^vmov\b.*\b[sd]\d+|^vldr|^vstr|^vpush|^vpop|^vcvt")
HEADER = re.compile(r"^([0-9a-f]+) <(.+)>:$")
INSN = re.compile(r"^\s+([0-9a-f]+):\s+(\S+)\s*(.*)$")
TARGET = re.compile(r"<([^>+]+)(\+0x[0-9a-f]+)?>")


def tool(name, *args):
    return subprocess.run([os.path.join(TOOLS, name), *args], capture_output=True, text=True, check=True).stdout


def functions(elf):
    """{symbol: [(mnemonic, operands)]} from the disassembly."""
    funcs, current = {}, None
    for line in tool("llvm-objdump", "-d", "--no-show-raw-insn", elf).splitlines():
        m = HEADER.match(line)
        if m:
            current = m.group(2)
            funcs[current] = []
            continue
        m = INSN.match(line)
        if m and current is not None:
            funcs[current].append((m.group(2), m.group(3)))
    return funcs


def callees(name, insns):
    """Direct callees (calls and branches into other functions) and whether there is an indirect call."""
    out, indirect = set(), False
    for mnem, ops in insns:
        if not mnem.startswith("b") or mnem.startswith("bic") or mnem.startswith("bfc") or mnem.startswith("bfi"):
            continue
        t = TARGET.search(ops)
        if t:
            if t.group(1) != name and t.group(2) is None:
                out.add(t.group(1))
        elif mnem in ("blx", "bx") and not ops.strip().startswith("lr"):
            indirect = True
    return out, indirect


def float_audit(elf):
    funcs = functions(elf)
    audited = [n for n in funcs if any(k in n for k in FIXED_PATH)]
    if not audited:
        sys.exit(f"float-audit: no fixed-path function found in {elf} (inlined away or renamed?)")
    bad = []
    for name in audited:
        for mnem, ops in funcs[name]:
            t = TARGET.search(ops)
            if mnem.startswith("b") and t and SOFT_FLOAT.search(t.group(1)):
                bad.append(f"{name}: calls {t.group(1)}")
            if VFP.search(f"{mnem} {ops}"):
                bad.append(f"{name}: {mnem} {ops}")
    print(f"float-audit: {len(audited)} fixed-path functions checked:")
    for n in sorted(audited):
        print(f"  {n} ({len(funcs[n])} instructions)")
    if bad:
        print("float-audit: FAILED, floating point in the fixed path:")
        for b in bad:
            print(f"  {b}")
        sys.exit(1)
    print("float-audit: no soft-float call and no FPU instruction")


def prologue_size(insns):
    size = 0
    for mnem, ops in insns[:12]:
        regs = re.search(r"\{([^}]*)\}", ops)
        count = 0
        if regs:
            for part in regs.group(1).split(","):
                part = part.strip()
                r = re.match(r"([rsd])(\d+)-[rsd](\d+)", part)
                count += (int(r.group(3)) - int(r.group(2)) + 1) if r else 1
        if mnem in ("push", "push.w") or (mnem.startswith("stmdb") and ops.startswith("sp!")):
            size += 4 * count
        elif mnem == "vpush":
            size += (8 if "d" in regs.group(1) else 4) * count
        else:
            m = re.match(r"sub(\.w|s)?$", mnem)
            imm = re.search(r"sp,\s*(sp,\s*)?#(0x[0-9a-f]+|\d+)", ops)
            if m and imm and ops.startswith("sp"):
                size += int(imm.group(2), 0)
    return size


def stack_bound(elf, chain, budget):
    """Worst-case stack of the last function of `chain` (">"-separated names or name fragments),
    plus the frames of the functions before it (its callers down from the reset handler)."""
    funcs = functions(elf)
    sizes = {}
    text = tool("llvm-readobj", "--stack-sizes", elf)
    for m in re.finditer(r"Functions: \[([^\]]*)\]\s*Size: (0x[0-9a-fA-F]+|\d+)", text):
        for f in m.group(1).split(","):
            sizes[f.strip()] = int(m.group(2), 0)

    def find(fragment):
        # Exact, else the one name ending with it (a function, not the closures and generic
        # instances named after it), else the one containing it.
        found = (
            [n for n in funcs if n == fragment]
            or [n for n in funcs if n.endswith(fragment)]
            or [n for n in funcs if fragment in n]
        )
        if len(found) != 1:
            sys.exit(f"stack-bound: {len(found)} functions match '{fragment}': {found[:5]}")
        return found[0]

    names = [find(f) for f in chain.split(">")]
    estimated, indirect_panic, on_path, memo = set(), set(), [], {}

    def frame(name):
        if name in sizes:
            return sizes[name]
        estimated.add(name)
        return prologue_size(funcs.get(name, []))

    def cost(name, panicking):
        # Keyed by whether a panic function is on the path, so the result does not depend on
        # the order the graph is walked in.
        panicking = panicking or "panic" in name
        key = (name, panicking)
        if key in memo:
            return memo[key]
        if name in on_path:
            sys.exit(f"stack-bound: recursion through {name}: unbounded")
        on_path.append(name)
        calls, indirect = callees(name, funcs.get(name, []))
        if indirect:
            if panicking:
                indirect_panic.add(name)
            else:
                sys.exit(f"stack-bound: indirect call in {name} (path {' > '.join(on_path)}): unbounded")
        best, via = 0, None
        for c in sorted(calls):
            if c in funcs:
                v = cost(c, panicking)[0]
                if v > best:
                    best, via = v, c
        on_path.pop()
        memo[key] = (frame(name) + best, via, frame(name), panicking)
        return memo[key]

    callers = sum(frame(n) for n in names[:-1])
    total = callers + cost(names[-1], False)[0]
    print(f"stack-bound: worst case from {' > '.join(names)}: {total} bytes (budget {budget})")
    print("  frame  function (callers, then the worst path)")
    for n in names[:-1]:
        print(f"  {frame(n):>6}  {n}{' (prologue)' if n in estimated else ''}")
    n, panicking = names[-1], False
    while n:
        panicking = panicking or "panic" in n
        entry = memo[(n, panicking)]
        print(f"  {entry[2]:>6}  {n}{' (prologue)' if n in estimated else ''}")
        n = entry[1]
    print(f"  {len(memo)} (function, panicking) pairs reached; {len(estimated)} sized from their prologue; "
          f"{len(indirect_panic)} with indirect calls on panic paths (not followed)")
    if total > budget:
        sys.exit(f"stack-bound: {total} bytes exceeds the budget of {budget}")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "float-audit":
        float_audit(sys.argv[2])
    elif len(sys.argv) == 5 and sys.argv[1] == "stack-bound":
        stack_bound(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    else:
        sys.exit(__doc__)
