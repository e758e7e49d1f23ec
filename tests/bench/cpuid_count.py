#!/usr/bin/env python3
"""tests/bench/cpuid_count.py — how many CPUID instructions one run of a program executes, by the
function that executes them (issue 27 goal 1, DESIGN.md 2.1: a virtual machine traps each CPUID,
8 us on the 2-core machine here, `build/tests/bench/cpuid_cost`).  A benchmark, never a test.

    python3 tests/bench/cpuid_count.py EXE [ARGS...]
    e.g. OPENBLAS_NUM_THREADS=1 python3 tests/bench/cpuid_count.py build/server/spinmodal \
             solve examples/angled-beam-90.json

It finds EXE's CPUID sites with objdump, runs EXE under gdb with a breakpoint on each and prints
the hits by function, then the total.  Only EXE's own code is seen: meant for the static CLI
(meson's default where it links), which holds glibc's start-up, OpenBLAS and the codec; a
dynamically linked program's libraries (glibc's ld.so included) are not counted.  Needs gdb and
objdump (binutils).  The program's output goes to /dev/null.
"""
import os
import re
import subprocess
import sys
import tempfile

try:
    import gdb  # noqa: F401 (inside gdb: this file is also the gdb script)
except ImportError:
    gdb = None


def sites_of(exe):
    """[(address in the file's vaddr space, function)] of every cpuid, and the lowest LOAD vaddr."""
    dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", exe], capture_output=True,
                         text=True, check=True).stdout
    sites, fn = [], "?"
    for line in dis.splitlines():
        m = re.match(r"^([0-9a-f]+) <(.*)>:$", line)
        if m:
            fn = m.group(2)
        elif re.search(r"\tcpuid\b", line):
            sites.append((int(line.split(":")[0], 16), fn))
    heads = subprocess.run(["objdump", "-p", exe], capture_output=True, text=True, check=True).stdout
    loads = [int(m.group(1), 16) for m in re.finditer(r"LOAD\s+off\s+\S+\s+vaddr\s+(0x[0-9a-f]+)", heads)]
    return sites, min(loads) if loads else 0


def outer():
    if len(sys.argv) < 2:
        sys.exit("usage: cpuid_count.py EXE [ARGS...]")
    exe = os.path.realpath(sys.argv[1])
    sites, low = sites_of(exe)
    if not sites:
        print("%s: no cpuid instruction" % exe)
        return
    with tempfile.NamedTemporaryFile("w", suffix=".sites", delete=False) as f:
        for a, fn in sites:
            f.write("%x %s\n" % (a, fn))
        path = f.name
    env = dict(os.environ, CPUID_COUNT_SITES=path, CPUID_COUNT_LOW="%x" % low, CPUID_COUNT_EXE=exe)
    try:
        p = subprocess.run(["gdb", "-q", "-batch", "-nx", "-x", os.path.abspath(__file__), "--args", exe]
                           + sys.argv[2:], env=env, capture_output=True, text=True)
    finally:
        os.unlink(path)
    rows = [l[6:] for l in p.stdout.splitlines() if l.startswith("CPUID ")]
    if not rows:
        sys.exit("gdb gave no count:\n" + p.stdout[-2000:] + p.stderr[-2000:])
    print("%s: %d cpuid sites" % (exe, len(sites)))
    for r in rows:
        print(r)


def inner():
    exe, low = os.environ["CPUID_COUNT_EXE"], int(os.environ["CPUID_COUNT_LOW"], 16)
    gdb.execute("set pagination off")
    gdb.execute("set confirm off")
    gdb.execute("starti > /dev/null 2>&1")  # stopped at the first instruction, output dropped
    base = None
    for line in gdb.execute("info proc mappings", to_string=True).splitlines():
        f = line.split()
        if f and f[-1] == exe and f[0].startswith("0x"):
            base = int(f[0], 16) - low
            break
    if base is None:
        print("CPUID cannot find %s in the process's mappings" % exe)
        return
    fn_of = {}
    for line in open(os.environ["CPUID_COUNT_SITES"]):
        a, fn = line.split(None, 1)
        b = gdb.Breakpoint("*%d" % (base + int(a, 16)), internal=True)
        b.silent = True
        fn_of[b.number] = fn.strip()
    hits = {}
    while True:
        try:
            gdb.execute("continue", to_string=True)
        except gdb.error:
            break
        if not gdb.selected_inferior().pid:
            break
        try:
            frame = gdb.selected_frame()
        except gdb.error:
            break
        name = frame.name() or hex(int(gdb.parse_and_eval("$pc")))
        hits[name] = hits.get(name, 0) + 1
    for name, k in sorted(hits.items(), key=lambda x: -x[1]):
        print("CPUID %5d  %s" % (k, name))
    print("CPUID %5d  in all" % sum(hits.values()))


if __name__ == "__main__":
    if gdb is None:
        outer()
    else:
        inner()
