#!/usr/bin/env bash
# tests/bench/bench_sweeps.sh — issue 27 goals 2 and 3: whole-process time of speed sweeps
# (`spinmodal solve FILE`, stdout to /dev/null, OPENBLAS_NUM_THREADS=1), the median of N runs of
# BASE (as it is: a CLI without --threads solves on one thread) and of NEW with --threads
# 1, 2, 4, 8, 16, alternating run by run in one run.  Then whether NEW gives the same result
# document (timings and version removed) on 1 and 16 threads (the threads must not change a
# bit), and whether BASE's is the same.  A benchmark, never a test: it prints, it checks nothing.
#   bash tests/bench/bench_sweeps.sh BASE NEW [N]      (N default 5)
# Cases: the angled beam (examples/angled-beam-90.json, planar, 48 elements, 143 coordinates)
# at 101 speeds 0..20 rad/s; the R3-style precone blade of bench_spatial.c (spatial, hub radius
# 1 m, 10 m at 10 deg, 48 elements, 288 coordinates, the tree path) at 21 speeds 0..20 and 101
# speeds 0..20 rad/s; 3 modes, shapes on, default options.  Measured on the 16-core device (see
# DESIGN.md 2.1) and on 2 shared cores.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
base=${1:?usage: bench_sweeps.sh BASE NEW [N]}
new=${2:?usage: bench_sweeps.sh BASE NEW [N]}
n=${3:-5}
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 tests/bench/sweep_cases.py "$tmp"   # planar101, blade21, blade101 .json
ms() {
  local s e
  s=$(date +%s%N)
  "$@" >/dev/null
  e=$(date +%s%N)
  echo $(((e - s) / 1000000))
}
med() { sort -n | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}'; }
strip() {
  python3 -c "import json,sys; r=json.load(sys.stdin); r.pop('timing_ms'); r['solver'].pop('version'); print(json.dumps(r, sort_keys=True))"
}
echo "$(nproc --all) cores, load $(cut -d' ' -f1-3 /proc/loadavg); median ms of $n runs, alternating"
printf "%-10s %8s" case base
for t in 1 2 4 8 16; do printf " %8s" "new t$t"; done
printf " %10s\n" "base/best"
for f in planar101 blade21 blade101; do
  : >"$tmp/t_base"
  for t in 1 2 4 8 16; do : >"$tmp/t_$t"; done
  for _ in $(seq "$n"); do
    ms "$base" solve "$tmp/$f.json" >>"$tmp/t_base"
    for t in 1 2 4 8 16; do ms "$new" solve --threads "$t" "$tmp/$f.json" >>"$tmp/t_$t"; done
  done
  b=$(med <"$tmp/t_base")
  best=$b
  printf "%-10s %8s" "$f" "$b"
  for t in 1 2 4 8 16; do
    v=$(med <"$tmp/t_$t")
    [ "$v" -lt "$best" ] && best=$v
    printf " %8s" "$v"
  done
  printf " %10s\n" "$(awk -v a="$b" -v c="$best" 'BEGIN{printf "%.2f", a / (c > 0 ? c : 1)}')"
  "$new" solve --threads 1 "$tmp/$f.json" | strip >"$tmp/a"
  "$new" solve --threads 16 "$tmp/$f.json" | strip >"$tmp/b"
  cmp -s "$tmp/a" "$tmp/b" && echo "  $f: new --threads 1 and --threads 16 give the same document" ||
    echo "  $f: the documents DIFFER between --threads 1 and 16"
  "$base" solve "$tmp/$f.json" | strip >"$tmp/a"
  cmp -s "$tmp/a" "$tmp/b" && echo "  $f: base gives the same document" ||
    echo "  $f: base gives another document (tests/bench/compare_outputs.py BASE NEW says by how much)"
done
