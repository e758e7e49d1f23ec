#!/usr/bin/env bash
# tests/bench/bench_large.sh — issue 27, beyond its goals' cases: whole-process time of the models
# with one large frame (the classical floating-frame setup, sweep_cases.large_frames): the angled
# beam with 125 and 166 elements a member in one frame (500 and 664 coordinates, planar, 2 speeds)
# and the precone blade with 60 elements in one frame (360 coordinates, spatial, 2 speeds).
# `spinmodal solve --threads 1 FILE`, OPENBLAS_NUM_THREADS=1, the median of N runs of each binary,
# alternating run by run, and the ratio OTHER / NEW.  Then whether both give the same document
# (timing_ms and the solver version removed).  A benchmark, never a test: it prints.
#   bash tests/bench/bench_large.sh NEW [OTHER] [N]      (N default 3)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
new=${1:?usage: bench_large.sh NEW [OTHER] [N]}
other=${2:-}
n=${3:-3}
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 - "$tmp" <<'PY'
import json, os, sys
sys.path.insert(0, "tests/bench")
from sweep_cases import large_frames
for name, r in large_frames("."):
    json.dump(r, open(os.path.join(sys.argv[1], name + ".json"), "w"))
PY
python3 - "$n" "$new" "$other" "$tmp" <<'PY'
import glob, json, os, statistics, subprocess, sys, time

n, new, other, tmp = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
bins = [b for b in (new, other) if b]

def once(exe, path):
    t0 = time.perf_counter()
    p = subprocess.run([exe, "solve", "--threads", "1", path], capture_output=True, text=True)
    if p.returncode:
        sys.exit("%s solve %s failed: %s" % (exe, path, p.stderr))
    return (time.perf_counter() - t0) * 1e3, p.stdout

def strip(text):
    r = json.loads(text)
    r.pop("timing_ms", None)
    r["solver"].pop("version", None)
    return json.dumps(r, sort_keys=True)

print("median wall ms of %d runs, alternating; NEW = %s%s" % (n, new, ", OTHER = " + other if other else ""))
print("%-22s %10s%s" % ("case", "new", " %10s %8s %s" % ("other", "x", "same") if other else ""))
for path in sorted(glob.glob(os.path.join(tmp, "*.json"))):
    t = {b: [] for b in bins}
    out = {}
    for _ in range(n):
        for b in bins:
            ms, text = once(b, path)
            t[b].append(ms)
            out[b] = text
    line = "%-22s %10.1f" % (os.path.basename(path)[:-5], statistics.median(t[new]))
    if other:
        mo = statistics.median(t[other])
        line += " %10.1f %8.2f %s" % (mo, mo / statistics.median(t[new]),
                                      "yes" if strip(out[new]) == strip(out[other]) else "NO")
    print(line)
PY
