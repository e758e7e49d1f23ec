#!/usr/bin/env bash
# tests/bench/bench_ab.sh — two builds side by side where threads share one process (issue 27
# goals 3 and 4): a benchmark, never a test; it prints and checks nothing.
#   bash tests/bench/bench_ab.sh A_DIR B_DIR [REPS] [THREADS] [WORKERS]
# A_DIR and B_DIR each hold spinmodal and spinmodald (a build folder's server/, or a devpack's
# bin/).  Defaults: REPS 2, THREADS "1 8 16", WORKERS "1,16".
#   1. CLI sweeps (the 101-speed planar and spatial sweeps of bench_sweeps.sh) with --threads T
#      for each T in THREADS: median wall and CPU ms of 5 runs, A and B alternating.
#   2. bench_replicas.py --sqlite-only --workers WORKERS --jobs 40 on A, then B, REPS times
#      (alternating, so a drift of the machine shows in both): jobs/s, solve and CPU ms a job.
# Written for the comparison of blas_buffers.c (OpenBLAS's work buffers kept per thread) with
# the build before it on the 16-core device (DESIGN.md 2.1), where one daemon's 16 workers or
# one sweep's 16 threads share OpenBLAS's buffer table; on 2 cores the two builds should tie.
set -u
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
A=$(cd "${1:?usage: bench_ab.sh A_DIR B_DIR [REPS] [THREADS] [WORKERS]}" && pwd)
B=$(cd "${2:?usage: bench_ab.sh A_DIR B_DIR [REPS] [THREADS] [WORKERS]}" && pwd)
reps=${3:-2}
threads=${4:-1 8 16}
workers=${5:-1,16}
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 LC_ALL=C
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "A = $A ($("$A/spinmodal" --version 2>&1))"
echo "B = $B ($("$B/spinmodal" --version 2>&1))"
echo "$(nproc --all) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
python3 tests/bench/sweep_cases.py "$tmp"   # planar101, blade21, blade101 .json
echo "== 1. CLI sweeps, median of 5 alternating runs (wall ms / CPU ms)"
python3 - "$A/spinmodal" "$B/spinmodal" "$tmp" "$threads" <<'PY'
import resource, statistics, subprocess, sys, time
a_exe, b_exe, d, threads = sys.argv[1], sys.argv[2], sys.argv[3], [int(t) for t in sys.argv[4].split()]
def run(exe, case, t):
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    s = time.perf_counter()
    subprocess.run([exe, "solve", "--threads", str(t), d + "/" + case + ".json"],
                   stdout=subprocess.DEVNULL, check=True)
    e = time.perf_counter()
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (e - s) * 1e3, (r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime) * 1e3
print("%-10s %4s  %17s  %17s  %s" % ("case", "thr", "A wall / CPU", "B wall / CPU", "A/B wall"))
for case in ("planar101", "blade101"):
    for t in threads:
        a, b = [], []
        for _ in range(5):
            a.append(run(a_exe, case, t))
            b.append(run(b_exe, case, t))
        med = lambda xs, k: statistics.median(x[k] for x in xs)
        print("%-10s %4d  %7.1f / %7.1f  %7.1f / %7.1f  %.2f" % (case, t, med(a, 0), med(a, 1),
              med(b, 0), med(b, 1), med(a, 0) / med(b, 0)), flush=True)
PY
echo "== 2. one daemon on SQLite, workers $workers, 40 jobs a worker (11-speed planar sweeps)"
echo "W     jobs   jobs/s  ratio   eff  busy solve ms  cpu ms   pg ms  faults wall j/s  submit   span"
for rep in $(seq "$reps"); do
    for side in A B; do
        dir=$A; [ $side = B ] && dir=$B
        echo "-- $side, round $rep"
        python3 -u tests/bench/bench_replicas.py "$dir" --sqlite-only --workers "$workers" \
            --jobs 40 2>&1 | grep -E '^[0-9]+ +[0-9]+ '
    done
done
