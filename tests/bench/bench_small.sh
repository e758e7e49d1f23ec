#!/usr/bin/env bash
# tests/bench/bench_small.sh — issue 27 goal 1: whole-process time of small solves
# (`spinmodal solve FILE`, stdout to /dev/null, OPENBLAS_NUM_THREADS=1), the median of N runs,
# and with a second binary its median and the ratio OTHER / NEW, both measured in one run,
# alternating run by run.  A benchmark, never a test: it prints, it checks nothing.
#   bash tests/bench/bench_small.sh NEW [OTHER] [N]      (N default 40)
# NEW, OTHER: spinmodal binaries (e.g. build-perf/server/spinmodal and a copy of an older one).
# Cases: examples/angled-beam-90.json (planar, 48 elements, 1 speed) and the BModes CertTest
# blade Test01 imported by NEW (`spinmodal import bmodes`): with --bmodes-mesh 1, 2, 4, 8
# (12, 24, 48, 96 elements, BModes' own model) and without it (48 elements, interpolated).
# The first row, /bin/true, is what any process costs here (the same program in both columns);
# the second, `--version`, the CLI's own floor: loading, start-up and exit without a request.
# Columns: wall ms (median), cpu ms (user + system of the child, median: steadier than wall on
# a shared machine), faults (the child's minor page faults, median: on a machine where a fault is
# dear, e.g. under gVisor, they are much of a small solve's wall time), then wall and cpu for
# OTHER and the two ratios.  Environment variables reach the solves, so
# `GLIBC_TUNABLES=glibc.malloc.hugetlb=1 bash tests/bench/bench_small.sh NEW` measures a malloc
# setting.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
new=${1:?usage: bench_small.sh NEW [OTHER] [N]}
other=${2:-}
n=${3:-40}
# SMALL_USER_ENV=1: without OPENBLAS_NUM_THREADS and OMP_NUM_THREADS, as a user runs the CLI
# (a shared OpenBLAS then starts a thread per core before main).
if [ "${SMALL_USER_ENV:-0}" = 1 ]; then
  unset OPENBLAS_NUM_THREADS OMP_NUM_THREADS GOTO_NUM_THREADS
else
  export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
bmi=tests/reference/blades/bmodes_certtest/Test01_nonunif_blade.bmi
cases=("any-process=/bin/true" "floor--version=--version" "beam48-planar=examples/angled-beam-90.json")
for k in 1 2 4 8; do
  "$new" import bmodes "$bmi" --bmodes-mesh "$k" >"$tmp/t01_m$k.json" 2>/dev/null
  cases+=("blade$((12 * k))-bmodes-mesh=$tmp/t01_m$k.json")
done
"$new" import bmodes "$bmi" >"$tmp/t01.json" 2>/dev/null
cases+=("blade48-interpolated=$tmp/t01.json")

python3 - "$n" "$new" "$other" "${cases[@]}" <<'PY'
import os, statistics, sys, time

n, new, other = int(sys.argv[1]), sys.argv[2], sys.argv[3]
cases = [c.split("=", 1) for c in sys.argv[4:]]
bins = [b for b in (new, other) if b]
null = os.open(os.devnull, os.O_WRONLY)

def once(exe, path):
    """Wall ms, child CPU ms and minor faults of one whole-process solve (posix_spawn: no shell,
    no fork copy); path "--version" runs `exe --version` (the process floor), path /bin/true
    runs /bin/true instead of exe (any process's floor)."""
    fa = [(os.POSIX_SPAWN_DUP2, null, 1), (os.POSIX_SPAWN_DUP2, null, 2)]
    if path == "/bin/true":
        exe = path
    argv = [exe, path] if path == "--version" else [exe] if path == "/bin/true" else [exe, "solve", path]
    t0 = time.perf_counter_ns()
    pid = os.posix_spawn(exe, argv, os.environ, file_actions=fa)
    _, status, ru = os.wait4(pid, 0)
    wall = (time.perf_counter_ns() - t0) / 1e6
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit("%s solve %s failed" % (exe, path))
    return wall, (ru.ru_utime + ru.ru_stime) * 1e3, ru.ru_minflt

head = "%-24s %9s %9s %7s" % ("case", "wall ms", "cpu ms", "faults")
if other:
    head += " %9s %9s %8s %8s" % ("oth wall", "oth cpu", "wall x", "cpu x")
print("N = %d runs each, median; NEW = %s%s" % (n, new, ", OTHER = " + other if other else ""))
print(head)
for name, path in cases:
    for b in bins:  # warm the page cache
        once(b, path)
    runs = {b: [] for b in bins}
    for _ in range(n):
        for b in bins:
            runs[b].append(once(b, path))
    med = {b: tuple(statistics.median(r[k] for r in runs[b]) for k in range(3)) for b in bins}
    line = "%-24s %9.2f %9.2f %7d" % (name, med[new][0], med[new][1], med[new][2])
    if other:
        o = med[other]
        line += " %9.2f %9.2f %8.2f %8.2f" % (o[0], o[1], o[0] / med[new][0],
                                             o[1] / max(med[new][1], 1e-9))
    print(line)
PY
