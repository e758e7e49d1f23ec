#!/bin/bash
# tests/bench/compare_builds.sh BASE NEW — two builds of spinmodal side by side, alternating, in
# one run (the issue 24 "speed unchanged" check; issue 27's whole-process figures).  BASE and NEW
# are folders holding bench_core, bench_spatial and spinmodal of a release build each (e.g.
# build-a/tests/bench/bench_core ... copied into one folder).  Prints bench_core's case medians
# (3 rounds), bench_spatial (2 rounds) and the median of 40 whole-process `spinmodal solve` runs
# of the planar 48-element angled beam and the BModes Test01 blade (imported with NEW).  Ratios
# only mean something within one run on one machine; never a test.
set -u
[ $# -eq 2 ] || { echo "usage: $0 BASE_DIR NEW_DIR" >&2; exit 64; }
root=$(cd "$(dirname "$0")/../.." && pwd)
base=$(cd "$1" && pwd); new=$(cd "$2" && pwd)
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cp "$root/examples/angled-beam-90.json" "$tmp/planar48.json"
"$new/spinmodal" import bmodes "$root/tests/reference/blades/bmodes_certtest/Test01_nonunif_blade.bmi" \
    > "$tmp/test01.json" 2>/dev/null || { echo "import failed" >&2; exit 1; }
echo "nproc $(nproc); load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "### bench_core (median ms: a W=20 per-element, b RF16 paper, c 101-speed sweep)"
for r in 1 2 3; do for v in base new; do d=$base; [ $v = new ] && d=$new
    echo "$v r$r $("$d/bench_core" --seconds 3 | awk '/^\(/{printf "%s %s  ", $1, $(NF-6)}')"
done; done
echo "### bench_spatial (2 s per case)"
for r in 1 2; do for v in base new; do d=$base; [ $v = new ] && d=$new
    echo "== $v r$r"; "$d/bench_spatial" 2 | grep -E "^\(|blade [0-9]+ el" | sed 's/  */ /g' | cut -c1-150
done; done
echo "### whole-process solve, 40 runs each, alternating: median and minimum (us)"
for f in planar48 test01; do
    : > "$tmp/t_base"; : > "$tmp/t_new"
    for _ in $(seq 40); do for v in base new; do d=$base; [ $v = new ] && d=$new
        s=$(date +%s%N); "$d/spinmodal" solve "$tmp/$f.json" > /dev/null; e=$(date +%s%N)
        echo $(((e - s) / 1000)) >> "$tmp/t_$v"
    done; done
    for v in base new; do
        echo "$f $v median_us $(sort -n "$tmp/t_$v" | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}') min_us $(sort -n "$tmp/t_$v" | head -1)"
    done
done
