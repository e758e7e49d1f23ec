#!/usr/bin/env bash
# tests/bench/growth.sh — issue 14 growth table: planar beta = 90 deg beam, per-element frames,
# Omega = 20, Coriolis on, no mode shapes, one speed; whole-process wall time and peak memory
# (/usr/bin/time -v) of `bench_core --growth E SOLVER`, dense (today's path, forced) beside the
# automatic choice, measured in one run; ratio = dense / auto.  Release build in build-bench.
#   bash tests/bench/growth.sh [ELEMENTS...]     (default 48 96 192 384 768 1536)
#   bash tests/bench/growth.sh --spatial [ELEMENTS...]   the 3D precone blade of bench_spatial
#        (R3, W = 10, Coriolis, 6 modes, no shapes; default 48 96 192 400 768)
# DENSE_MAX (default 768; spatial 400) skips the dense path above that size (it takes minutes).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
if [ -d build-bench/meson-private ]; then
  meson configure build-bench -Dbuildtype=release >/dev/null
else
  meson setup build-bench -Dbuildtype=release >/dev/null
fi
spatial=0
if [ "${1:-}" = "--spatial" ]; then spatial=1; shift; fi
prog=bench_core
[ "$spatial" = 1 ] && prog=bench_spatial
ninja -C build-bench "tests/bench/$prog" >/dev/null
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
bin=build-bench/tests/bench/$prog
sizes=("$@")
if [ "${#sizes[@]}" -eq 0 ]; then
  if [ "$spatial" = 1 ]; then sizes=(48 96 192 400 768); else sizes=(48 96 192 384 768 1536); fi
fi
dense_max=${DENSE_MAX:-768}
[ "$spatial" = 1 ] && dense_max=${DENSE_MAX:-400}
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
# run E SOLVER: prints "wall_s peak_MB w1" (best wall of 3 runs for short ones, 1 for long ones)
run() {
  local best="" mem="" w1="" reps=3
  for ((k = 0; k < reps; k++)); do
    local t0 t1 wall rss
    t0=$(date +%s.%N)
    /usr/bin/time -v "$bin" --growth "$1" "$2" >"$tmp.out" 2>"$tmp"
    t1=$(date +%s.%N)
    wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN {print b - a}')   # includes starting /usr/bin/time (~1 ms)
    rss=$(awk -F': ' '/Maximum resident set size/ {printf "%.1f", $2 / 1024}' "$tmp")
    w1=$(awk '{print $4}' "$tmp.out")
    if [ -z "$best" ] || awk -v a="$wall" -v b="$best" 'BEGIN {exit !(a < b)}'; then best=$wall; mem=$rss; fi
    awk -v a="$wall" 'BEGIN {exit !(a > 2)}' && break
  done
  rm -f "$tmp.out"
  echo "$best $mem $w1"
}
printf '%-9s %6s | %9s %8s | %9s %8s | %8s %7s | %s\n' elements coords "dense s" "dense MB" "auto s" "auto MB" \
  "t ratio" "MB rat" "w1 dense / auto"
for e in "${sizes[@]}"; do
  read -r ta ma wa < <(run "$e" auto)
  coords=$(( 3 * e - 1 ))
  [ "$spatial" = 1 ] && coords=$(( 6 * e ))
  if [ "$e" -le "$dense_max" ]; then
    read -r td md wd < <(run "$e" dense)
    printf '%-9s %6s | %9.3f %8.1f | %9.3f %8.1f | %8.1f %7.1f | %s / %s\n' "$e" "$coords" "$td" "$md" "$ta" "$ma" \
      "$(awk -v a="$td" -v b="$ta" 'BEGIN {print a / b}')" "$(awk -v a="$md" -v b="$ma" 'BEGIN {print a / b}')" "$wd" "$wa"
  else
    printf '%-9s %6s | %9s %8s | %9.3f %8.1f | %8s %7s | - / %s\n' "$e" "$coords" "-" "-" "$ta" "$ma" "-" "-" "$wa"
  fi
done
