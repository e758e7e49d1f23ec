#!/usr/bin/env bash
# tests/bench/device_run.sh — the issue 27 benchmarks in one call on the 16-core device machine
# (no network, none of our Debian packages: no jansson, gfortran, OpenBLAS, PostgreSQL or
# libmicrohttpd; python3 present; root), from a copy of the repository's working tree and one
# carried folder (CARRY, e.g. devcarry/, listed in .git/info/exclude).  A benchmark, never a test:
# it prints tables into files under $OUT (default /tmp/devout), as they come (tee), and checks
# nothing.  Every step is guarded: one that fails or runs out of time does not stop the others.
#   bash tests/bench/device_run.sh CARRY              (on the device, in the repository root)
#   bash tests/bench/device_run.sh --prepare CARRY    (here: fill CARRY, see below)
#   bash tests/bench/device_run.sh --rehearse CARRY   (here: the run as the device sees it)
# Files under $OUT, in the order they are written (env first: it costs a second):
#   env.txt       nproc, lscpu, uname, the devpack's COMMIT, CARRY/MANIFEST, --version of NEW and
#                 BASE, ldd of every binary with the pack's libraries (a "not found" is named)
#   sweeps.txt    bench_sweeps.sh BASE NEW 5           (speed sweeps, BASE vs NEW --threads 1..16)
#   small.txt     bench_small.sh NEW BASE 30           (whole-process time of small solves)
#   faults.txt    bench_faults.sh BASE 15 (the cost of a page fault; small solves with the heap
#                 faulted in up front, or in huge pages)
#   bmodes.txt    BMODES_BIN=CARRY/bmodes bench_bmodes.sh NEW 3 at 12 48 96 elements and the
#                 16-speed sweep; then, after the throughput tables and only when the time left
#                 allows it (estimated from the 96-element row: 3 BModes runs of ~25x its time),
#                 the 192-element row as a second table
#   replicas.txt  the devpack's run.sh --workers 1,8,16 --replicas 1,4,8 --workers-per-replica 2
#                 --jobs 40 (bench_replicas.py: one daemon on SQLite, replicas on one PostgreSQL)
#   steps.txt     each step's exit status and elapsed seconds (also printed on stdout)
# NEW is HEAD's spinmodal from the devpack, BASE the carried release build of 93b3ea5 (the base
# of the earlier device measurements, DESIGN.md 2.1).  LD_LIBRARY_PATH is the devpack's lib/ for every
# binary, OPENBLAS_NUM_THREADS=1 as the benches set it.
# The whole run stops starting steps at DEVRUN_DEADLINE seconds (default 360) and cuts a running
# step there (SIGINT, so bench_replicas.py stops its daemons and PostgreSQL; KILL 20 s later).
# Expected on the 16-core device, from the earlier device timings (DESIGN.md 2.1): env 5 s,
# sweeps ~50 s, small ~20 s, bmodes ~60 s, replicas ~60 s: ~3.5 minutes; the 192-element BModes
# row (~3 x 110 s there) is then skipped for want of time, with a line saying so.  On 2 cores
# here (faster per core, 2 cores): 158 s without the 192-element row.
# Shorter runs (a 2-core rehearsal) with these variables (the defaults shown):
#   DEVRUN_SWEEPS_N=5 DEVRUN_SMALL_N=30 DEVRUN_BMODES_N=3 DEVRUN_BMODES_ELEMENTS="12 48 96"
#   DEVRUN_BMODES_SWEEP=1 DEVRUN_BMODES_LATE=192 (empty: no 192-element row)
#   DEVRUN_REPLICAS="--workers 1,8,16 --replicas 1,4,8 --workers-per-replica 2 --jobs 40"
#   DEVRUN_STEPS="env sweeps small bmodes replicas bmodes-late" (a subset, in this order)
# CARRY holds (about 35 MB; made by --prepare, which runs the commands below):
#   devpack.tar.xz   `bash tests/bench/pack_device.sh devpack` (HEAD as committed; its lib/ also
#                    holds what the three programs below need, PACK_EXTRA_ELFS), copied; after
#                    new commits --prepare again (only the pack is rebuilt)
#   spinmodal-base   the CLI at 93b3ea5, release, stripped: git archive 93b3ea5 into
#                    /tmp/src-base, meson setup /tmp/build-base --buildtype=release, ninja
#                    server/spinmodal (no git worktree)
#   bmodes           BModes v3.00 built by bench_bmodes.sh (BMODES_KEEP), gfortran -O2, stripped
#   time             GNU time (/usr/bin/time, bench_bmodes.sh's peak memory): copied to
#                    /usr/bin/time for the run when the device lacks it, and removed after
#   fault_probe, prefault.so  bench_faults.sh's probe and LD_PRELOAD (gcc -O2, glibc only)
#   MANIFEST         what was built from what, when
# Run on the device (its output files come back from $OUT):
#   bash tests/bench/device_run.sh devcarry          (the carry list names devcarry)
# --rehearse CARRY: here, a copy of the working tree (tracked and untracked files that git does
# not ignore, as the device gets it) in /tmp/devrehearse with CARRY beside it, run in a mount
# namespace where the system's copies of the packed libraries (those python3 and the shell tools
# do not use), OpenBLAS, PostgreSQL, gfortran, xz and /usr/bin/time are hidden, under
# `env -i PATH=/usr/bin:/bin` (DEVRUN_* and OUT passed on; OUT default /tmp/devout-rehearse).
set -u
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BASE_COMMIT=93b3ea5

# ---------------------------------------------------------------- --prepare CARRY (this machine)
if [ "${1:-}" = --prepare ]; then
    set -eo pipefail
    carry=$(mkdir -p "${2:?usage: device_run.sh --prepare CARRY}" && cd "$2" && pwd)
    pack=${DEVRUN_PACK:-$ROOT/devpack}
    want=$(git -C "$ROOT" rev-parse "$BASE_COMMIT")
    if [ ! -x "$carry/spinmodal-base" ] || [ "$(cat "$carry/spinmodal-base.commit" 2>/dev/null)" != "$want" ]; then
        rm -rf /tmp/src-base /tmp/build-base
        mkdir -p /tmp/src-base && git -C "$ROOT" archive "$BASE_COMMIT" | tar -x -C /tmp/src-base
        meson setup /tmp/build-base /tmp/src-base --buildtype=release >/dev/null
        ninja -C /tmp/build-base server/spinmodal
        cp /tmp/build-base/server/spinmodal "$carry/spinmodal-base"
        strip --strip-unneeded "$carry/spinmodal-base"
        echo "$want" > "$carry/spinmodal-base.commit"
    fi
    if [ ! -x "$carry/bmodes" ]; then
        BMODES_KEEP="$carry/bmodes" BMODES_ELEMENTS=12 BMODES_SWEEP=0 \
            bash "$ROOT/tests/bench/bench_bmodes.sh" "$carry/spinmodal-base" 1
        strip --strip-unneeded "$carry/bmodes"
    fi
    [ -x "$carry/time" ] || cp /usr/bin/time "$carry/time"
    # bench_faults.sh's probe and preload (glibc only)
    gcc -O2 -Wall -o "$carry/fault_probe" "$ROOT/tests/bench/fault_probe.c"
    gcc -O2 -Wall -shared -fPIC -o "$carry/prefault.so" "$ROOT/tests/bench/prefault.c"
    # the pack, its lib/ holding what BASE, bmodes and time need too (pack_device.sh's collection)
    PACK_EXTRA_ELFS="$carry/spinmodal-base $carry/bmodes $carry/time" \
        bash "$ROOT/tests/bench/pack_device.sh" "$pack"
    cp "$pack/devpack.tar.xz" "$carry/devpack.tar.xz"
    {
        echo "prepared $(date -u +%FT%TZ) on $(uname -n) by tests/bench/device_run.sh --prepare"
        echo "devpack.tar.xz: $(head -1 "$pack/COMMIT" | cut -c1-100)"
        echo "spinmodal-base: $(git -C "$ROOT" log -1 --format='%H %s' "$BASE_COMMIT" | cut -c1-100) (release, stripped)"
        echo "bmodes: BModes v3.00, $(git --git-dir=/work/.mirror/old-NWTC+BModes/repo rev-parse --short HEAD 2>/dev/null || echo '?'), gfortran -O2, NMAX 4000, stripped"
        echo "time: $(/usr/bin/time --version 2>&1 | head -1)"
    } > "$carry/MANIFEST"
    cat "$carry/MANIFEST"
    du -sh "$carry"
    exit 0
fi

# ---------------------------------------------------------------- --rehearse CARRY (this machine)
if [ "${1:-}" = --rehearse ]; then
    carry=$(cd "${2:?usage: device_run.sh --rehearse CARRY}" && pwd) || exit 2
    dst=/tmp/devrehearse
    rm -rf "$dst"; mkdir -p "$dst"
    (cd "$ROOT" && git ls-files -z -co --exclude-standard |
        tar --null --ignore-failed-read --no-recursion -T - -cf - 2>/dev/null) | tar -C "$dst" -xf -
    cp -r "$carry" "$dst/devcarry"
    pass=(OUT="${OUT:-/tmp/devout-rehearse}")
    while IFS= read -r kv; do pass+=("$kv"); done < <(env | grep '^DEVRUN_')
    rm -rf "${OUT:-/tmp/devout-rehearse}" /tmp/devrehearse-overlay
    # the libraries the pack holds (to hide the system's copies), read from the carried tarball
    python3 - "$carry/devpack.tar.xz" > /tmp/devrehearse-libs <<'PY'
import sys, tarfile
for m in tarfile.open(sys.argv[1]):
    p = m.name.split("/")
    if len(p) == 3 and p[1] == "lib":
        print(p[2])
PY
    cd "$dst" && exec unshare -m bash "$dst/tests/bench/device_run.sh" --hidden /tmp/devrehearse-libs "${pass[@]}"
fi
if [ "${1:-}" = --hidden ]; then  # inside the namespace of --rehearse: hide, then run
    packlibs=$2; shift 2
    export PATH=/usr/bin:/bin:/usr/sbin:/sbin
    keep=$( (for t in bash python3 cp mkdir rm chmod date ls sed awk grep tar stat sort cut tr readlink \
        lscpu nproc uname timeout tee cmp seq realpath mktemp head tail cat env id dirname useradd; do
        p=$(command -v "$t") && ldd "$(readlink -f "$p")"; done
        ldd "$(python3 -c 'import sysconfig; print(sysconfig.get_path("platstdlib"))')"/lib-dynload/*.so
        ) 2>/dev/null | awk '$2 == "=>" {print $1}' | sort -u)
    hidden=
    for so in $(cat "$packlibs"); do
        echo "$keep" | grep -qx "$so" && continue
        for d in /usr/lib/x86_64-linux-gnu /lib/x86_64-linux-gnu; do
            [ -e "$d/$so" ] && mount --bind /dev/null "$(readlink -f "$d/$so")" && hidden="$hidden $so" && break
        done
    done
    for d in /usr/lib/x86_64-linux-gnu/openblas-pthread /usr/lib/postgresql; do
        [ -d "$d" ] && mount -t tmpfs none "$d"
    done
    [ -e /usr/bin/gfortran ] && mount --bind /dev/null "$(readlink -f /usr/bin/gfortran)"
    ov=/tmp/devrehearse-overlay
    mkdir -p "$ov/u" "$ov/w"
    mount -t overlay overlay -o "lowerdir=/usr/bin,upperdir=$ov/u,workdir=$ov/w" /usr/bin &&
        rm -f /usr/bin/time /usr/bin/xz /usr/bin/pg_config
    echo "rehearsal: hidden$hidden, OpenBLAS, PostgreSQL, gfortran, /usr/bin/time, xz"
    exec env -i PATH=/usr/bin:/bin "$@" bash tests/bench/device_run.sh devcarry
fi

# ---------------------------------------------------------------- the run (the device machine)
CARRY=$(cd "${1:?usage: device_run.sh CARRY | --prepare CARRY | --rehearse CARRY}" && pwd) || exit 2
cd "$ROOT" || exit 2
OUT=${OUT:-/tmp/devout}
mkdir -p "$OUT"
T0=$(date +%s)
DEADLINE=${DEVRUN_DEADLINE:-360}
STEPS=${DEVRUN_STEPS:-env sweeps small faults bmodes replicas bmodes-late}
WORK=/tmp/spinmodal-devrun
: > "$OUT/steps.txt"
log() { echo "$*" | tee -a "$OUT/steps.txt"; }
elapsed() { echo $(( $(date +%s) - T0 )); }

# the devpack, unpacked with Python (no xz binary assumed), before LD_LIBRARY_PATH points at it
rm -rf "$WORK"; mkdir -p "$WORK/bin"; chmod 755 "$WORK"
python3 - "$CARRY/devpack.tar.xz" "$WORK" <<'PY' || log "devpack: unpacking FAILED (the steps below will fail)"
import sys, tarfile
with tarfile.open(sys.argv[1]) as t:
    if hasattr(tarfile, "fully_trusted_filter"):  # Python >= 3.12: no filter warning
        t.extractall(sys.argv[2], filter="fully_trusted")
    else:
        t.extractall(sys.argv[2])
PY
DP=$WORK/devpack
NEW=$DP/bin/spinmodal
cp "$CARRY/spinmodal-base" "$CARRY/bmodes" "$WORK/bin/" && chmod 755 "$WORK/bin/"*
BASE=$WORK/bin/spinmodal-base
BMODES=$WORK/bin/bmodes
log "devpack unpacked to $DP: $(elapsed) s"

LIBS=$DP/lib
export LD_LIBRARY_PATH=$LIBS OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 LC_ALL=C PYTHONUNBUFFERED=1
# GNU time for bench_bmodes.sh's peak memory column (it runs /usr/bin/time); put back afterwards
TIME_ADDED=
if [ ! -x /usr/bin/time ] && [ -x "$CARRY/time" ] && [ -w /usr/bin ]; then
    cp "$CARRY/time" /usr/bin/time && chmod 755 /usr/bin/time && TIME_ADDED=1
fi

have_timeout=0
command -v timeout >/dev/null && have_timeout=1
# step NAME FILE LIMIT COMMAND...: run it (stdout and stderr teed into $OUT/FILE) for at most
# LIMIT seconds and never past DEADLINE; SIGINT first (Python's finally blocks run), KILL 20 s on
step() {
    local name=$1 file=$2 limit=$3 s left rc
    shift 3
    s=$(date +%s)
    left=$(( DEADLINE - (s - T0) ))
    if [ "$left" -lt 15 ]; then
        log "== $name: skipped, $left s left of $DEADLINE" | tee -a "$OUT/$file"; return
    fi
    [ "$limit" -gt "$left" ] && limit=$left
    echo "== $name: $* (at most $limit s; started at $(( s - T0 )) s)" | tee -a "$OUT/$file"
    if [ $have_timeout = 1 ] && [ "$(type -t "$1")" != function ]; then
        timeout -s INT -k 20 "$limit" "$@" 2>&1 | tee -a "$OUT/$file"
    else
        "$@" 2>&1 | tee -a "$OUT/$file"
    fi
    rc=${PIPESTATUS[0]}
    [ "$rc" = 124 ] && rc="124 (cut at $limit s)"
    log "== $name: exit $rc, $(( $(date +%s) - s )) s (total $(elapsed) s)" | tee -a "$OUT/$file"
}
want() { case " $STEPS " in *" $1 "*) return 0 ;; esac; return 1; }

envinfo() {
    echo "nproc $(env -u OMP_NUM_THREADS nproc) (all $(nproc --all)); load $(cat /proc/loadavg); $(uname -a)"
    head -2 /etc/os-release 2>/dev/null
    lscpu 2>/dev/null | grep -E '^(Architecture|CPU\(s\)|On-line|Thread|Core|Socket|Model name|CPU MHz|CPU max MHz|L1d|L2|L3|NUMA node\(s\)|Hypervisor)'
    grep -E '^(MemTotal|MemAvailable)' /proc/meminfo
    echo "python3: $(python3 --version 2>&1); /usr/bin/time: $([ -x /usr/bin/time ] && echo "${TIME_ADDED:+carried, }present" || echo absent)"
    echo "LD_LIBRARY_PATH=$LD_LIBRARY_PATH"
    echo "--- devpack COMMIT"; cat "$DP/COMMIT"
    echo "--- $CARRY/MANIFEST"; cat "$CARRY/MANIFEST" 2>/dev/null
    echo "--- versions"
    echo "NEW  $NEW: $("$NEW" --version 2>&1)"
    echo "BASE $BASE: $("$BASE" --version 2>&1)"
    echo "spinmodald: $("$DP/bin/spinmodald" --version 2>&1 | head -1)"
    echo "--- libraries (with LD_LIBRARY_PATH): how many from $LIBS, and any from elsewhere"
    for b in "$NEW" "$BASE" "$BMODES" "$DP/bin/spinmodald" "$DP"/pg/lib/postgresql/*/bin/postgres; do
        ldd "$b" 2>&1 | awk -v b="$(basename "$b")" -v w="$WORK/" '
            $2 == "=>" { if (index($3, w) == 1) n++; else o = o " " $1 " " ($3 ~ /^\// ? $3 : "NOT FOUND") }
            END { printf "%-15s %2d packed;%s\n", b ":", n, o == "" ? " nothing else" : o }'
    done
    if ldd "$NEW" "$BASE" "$BMODES" "$DP/bin/spinmodald" 2>&1 | grep -q 'not found'; then
        echo "MISSING LIBRARIES:"; ldd "$NEW" "$BASE" "$BMODES" "$DP/bin/spinmodald" 2>&1 | grep 'not found'
    else
        echo "every library resolved"
    fi
    # what the benches import (hashlib, ssl, lzma and sqlite3 are not used: a newer python3 may
    # not load the pack's older libcrypto or libsqlite3, and need not)
    python3 -c 'import json, http.client, socket, select, concurrent.futures, statistics, pwd, glob, random
print("python3 under LD_LIBRARY_PATH: the modules the benches use load")' 2>&1
}

want env && step env env.txt 30 envinfo
want sweeps && step sweeps sweeps.txt 150 \
    bash tests/bench/bench_sweeps.sh "$BASE" "$NEW" "${DEVRUN_SWEEPS_N:-5}"
want small && step small small.txt 75 \
    bash tests/bench/bench_small.sh "$NEW" "$BASE" "${DEVRUN_SMALL_N:-30}"
# what a page fault costs on the device, and small solves with their heap faulted in up front or
# in huge pages (bench_faults.sh; its probe and preload come from CARRY)
# (on BASE: HEAD's CLI is static-pie, which LD_PRELOAD cannot reach and bench_faults.sh refuses)
want faults && step faults faults.txt 60 \
    bash tests/bench/bench_faults.sh "$BASE" "${DEVRUN_FAULTS_N:-15}" "$CARRY/fault_probe" "$CARRY/prefault.so"
want bmodes && step bmodes bmodes.txt 120 \
    env BMODES_BIN="$BMODES" BMODES_ELEMENTS="${DEVRUN_BMODES_ELEMENTS-12 48 96}" \
    BMODES_SWEEP="${DEVRUN_BMODES_SWEEP:-1}" bash tests/bench/bench_bmodes.sh "$NEW" "${DEVRUN_BMODES_N:-3}"
want replicas && step replicas replicas.txt 150 \
    bash "$DP/run.sh" ${DEVRUN_REPLICAS:---workers 1,8,16 --replicas 1,4,8 --workers-per-replica 2 --jobs 40}
late=${DEVRUN_BMODES_LATE-192}
if want bmodes-late && [ -n "$late" ]; then
    # BModes' time grows faster than elements^3: a 192-element run took 25x a 96-element one
    # here (98.7 s against 4.0 s, 162 MiB); the row costs 3 BModes runs (the first, 1 timed,
    # the peak memory one) when one run is over 5 s: skipped unless that fits the time left
    t96=$(awk '/^Test01, 96 el\./ {print $7}' "$OUT/bmodes.txt" 2>/dev/null | tail -1)
    need=$(awk -v t="${t96:-0}" 'BEGIN {printf "%d", (t > 0 ? 3 * 25 * t / 1000 + 15 : 0)}')
    left=$(( DEADLINE - $(elapsed) ))
    if [ "$need" -gt 0 ] && [ "$need" -gt "$left" ]; then
        log "== bmodes-late: skipped, the $late-element row needs ~$need s (96 el.: $t96 ms a BModes run), $left s left" |
            tee -a "$OUT/bmodes.txt"
    else
        step bmodes-late bmodes.txt "$left" env BMODES_BIN="$BMODES" BMODES_ELEMENTS="$late" BMODES_SWEEP=0 \
            bash tests/bench/bench_bmodes.sh "$NEW" "${DEVRUN_BMODES_N:-3}"
    fi
fi

# leftovers: any process still running a binary of the unpacked pack (a daemon or PostgreSQL of
# a cut step), by its pid; then the carried /usr/bin/time
for p in /proc/[0-9]*; do
    exe=$(readlink "$p/exe" 2>/dev/null) || continue
    case "$exe" in "$WORK"/*|/tmp/spinmodal-devpack/*)
        log "left running, killed: ${p#/proc/} $exe"; kill -9 "${p#/proc/}" 2>/dev/null ;;
    esac
done
[ -n "$TIME_ADDED" ] && rm -f /usr/bin/time
log "device_run: done in $(elapsed) s; files: $(cd "$OUT" && ls | tr '\n' ' ')"
exit 0

