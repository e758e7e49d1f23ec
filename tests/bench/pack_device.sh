#!/bin/bash
# Pack the throughput benchmark (tests/bench/bench_replicas.py, issue 27 goal 4) for a machine
# without our Debian packages and without network (the 16-core device machine: gVisor, Python 3,
# root): a release build of spinmodald and spinmodal, every shared library they and the
# PostgreSQL server need that glibc does not provide, PostgreSQL's server tree (bin, lib, share,
# laid out as Debian installs it so that postgres finds its share and lib folders relative to
# its own path), the benchmark with the harness it imports, and run.sh.
#
# usage: bash tests/bench/pack_device.sh [--worktree] OUTDIR [BUILD_DIR]
#   --worktree build the working tree as it is (uncommitted edits included); by default the
#              committed HEAD is built from `git archive HEAD` (OUTDIR/COMMIT names it)
#   OUTDIR     the tree (emptied first), e.g. devpack/ (listed in .git/info/exclude); it also
#              gets OUTDIR/devpack.tar.xz, the same tree as one file (what a device run carries)
#   BUILD_DIR  default build-devpack (meson setup -Dbuildtype=release when absent)
#   PACK_EXTRA_ELFS  more programs (space-separated paths) whose libraries lib/ must hold too,
#              though they travel beside the tree (device_run.sh: the base CLI, BModes, GNU time)
# On the device machine (the tree lands under the repository copy, which `nobody` may not be
# able to reach; run.sh copies it to /tmp when run as root for that reason):
#   python3 -c "import tarfile; tarfile.open('devpack/devpack.tar.xz').extractall('/tmp/dp')"
#   bash /tmp/dp/devpack/run.sh [bench_replicas.py options]
# Check here, from the tree alone: env -i PATH=/usr/bin:/bin bash devpack/run.sh --workers 1,2 ...
set -euo pipefail
WORKTREE=0
[ "${1:-}" = --worktree ] && { WORKTREE=1; shift; }
[ $# -ge 1 ] || { echo "usage: $0 [--worktree] OUTDIR [BUILD_DIR]" >&2; exit 2; }
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
OUT=$(mkdir -p "$1" && cd "$1" && pwd)
BUILD=${2:-$ROOT/build-devpack}
PGVER=${PGVER:-15}
PGLIB=/usr/lib/postgresql/$PGVER
PGSHARE=/usr/share/postgresql/$PGVER
[ -x "$PGLIB/bin/postgres" ] || { echo "no PostgreSQL $PGVER server under $PGLIB" >&2; exit 1; }
case "$OUT" in "$ROOT"|/|"$HOME") echo "refusing to empty $OUT" >&2; exit 2 ;; esac

SRC=$ROOT
if [ $WORKTREE = 0 ]; then
    # HEAD as committed, unpacked beside the build folder (only files that changed are rebuilt)
    # (a file whose bytes did not change keeps its time, so ninja rebuilds only what changed)
    SRC=$BUILD-src
    new=$(mktemp -d)
    git -C "$ROOT" archive --format=tar HEAD | tar -C "$new" -xf -
    mkdir -p "$SRC"
    (cd "$new" && find . -type f) | while read -r f; do
        cmp -s "$new/$f" "$SRC/$f" || { mkdir -p "$(dirname "$SRC/$f")"; cp -p "$new/$f" "$SRC/$f"; }
    done
    rm -rf "$new"
    BUILD=$BUILD-head
fi
if [ ! -f "$BUILD/build.ninja" ]; then
    meson setup "$BUILD" "$SRC" -Dbuildtype=release
fi
ninja -C "$BUILD" server/spinmodald server/spinmodal

find "$OUT" -mindepth 1 -delete
name=$(basename "$OUT")
mkdir -p "$OUT"/{bin,lib,bench} "$OUT/pg/lib/postgresql/$PGVER/bin" "$OUT/pg/lib/postgresql/$PGVER/lib" \
    "$OUT/pg/share/postgresql"
cp "$BUILD/server/spinmodald" "$BUILD/server/spinmodal" "$OUT/bin/"

# PostgreSQL: the programs the harness runs (replicas_test.Postgres: initdb, pg_ctl, createdb;
# initdb runs postgres), the server's modules without JIT (llvmjit would need libLLVM; without
# it the server runs with jit unavailable), and the share folder (postgres.bki, timezonesets,
# tsearch_data, plpgsql's extension files)
for p in postgres initdb pg_ctl createdb psql pg_isready; do
    cp "$PGLIB/bin/$p" "$OUT/pg/lib/postgresql/$PGVER/bin/"
done
find "$PGLIB/lib" -maxdepth 1 -name '*.so' ! -name 'llvmjit*' -exec cp {} "$OUT/pg/lib/postgresql/$PGVER/lib/" \;
cp -r "$PGSHARE" "$OUT/pg/share/postgresql/"

# shared libraries: everything ldd resolves outside glibc, under its soname
glibc='^(linux-vdso|libc|libm|libpthread|libdl|librt|libresolv|libutil|libanl|ld-linux[^ ]*)\.so'
elfs=("$OUT"/bin/* "$OUT"/pg/lib/postgresql/$PGVER/bin/* "$OUT"/pg/lib/postgresql/$PGVER/lib/*.so)
read -r -a extra <<< "${PACK_EXTRA_ELFS:-}"
elfs+=("${extra[@]}")
ldd "${elfs[@]}" 2>/dev/null | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}' | sort -u |
while read -r soname path; do
    if [[ ! $soname =~ $glibc ]] && [ ! -e "$OUT/lib/$soname" ]; then
        cp -L "$path" "$OUT/lib/$soname"
    fi
done
if ldd "${elfs[@]}" 2>/dev/null | grep -q 'not found'; then
    echo "unresolved libraries:" >&2; ldd "${elfs[@]}" | grep 'not found' >&2; exit 1
fi
chmod u+w "$OUT"/lib/* "$OUT"/bin/* "$OUT"/pg/lib/postgresql/$PGVER/bin/*
strip --strip-unneeded "$OUT"/bin/* "$OUT"/lib/* "$OUT"/pg/lib/postgresql/$PGVER/bin/* \
    "$OUT"/pg/lib/postgresql/$PGVER/lib/*.so 2>/dev/null || true

# the benchmark and what it imports (the harness finds daemon.py and the example beside it)
cp "$ROOT/tests/bench/bench_replicas.py" "$ROOT/tests/e2e/daemon.py" "$ROOT/tests/e2e/replicas_test.py" \
    "$ROOT/tests/e2e/timescale.py" "$ROOT/tests/e2e/timescale.json" "$ROOT/examples/angled-beam-90.json" \
    "$OUT/bench/"
git -C "$ROOT" log -1 --format='%H %s' > "$OUT/COMMIT"
if [ $WORKTREE = 1 ]; then
    echo "built from the working tree, with these uncommitted changes:" >> "$OUT/COMMIT"
    git -C "$ROOT" status --short -- server core >> "$OUT/COMMIT" || true
else
    echo "built from HEAD as committed (git archive)" >> "$OUT/COMMIT"
fi

cat > "$OUT/run.sh" <<'EOF'
#!/bin/bash
# Throughput scaling benchmark from this tree alone (packed by tests/bench/pack_device.sh).
# usage: bash run.sh [bench_replicas.py options]
#   without options: the issue 27 goal 4 run, twice (default malloc, then GLIBC_TUNABLES)
#   bash run.sh procs: the same solves by 1..16 separate CLI processes (the machine's ceiling)
set -u
HERE=$(cd "$(dirname "$0")" && pwd)
PGBIN=$HERE/pg/lib/postgresql/__PGVER__/bin
if [ "$(id -u)" = 0 ] && [ -z "${DEVPACK_COPIED:-}" ]; then
    # as root the PostgreSQL server runs as `nobody` (replicas_test.Postgres): it must exist and
    # reach this tree (every folder above it searchable), else work from a copy in /tmp
    python3 -c 'import pwd; pwd.getpwnam("nobody")' 2>/dev/null ||
        useradd -r -M -d /nonexistent -s /usr/sbin/nologin nobody ||
        echo "no user nobody and useradd failed: PostgreSQL will not start" >&2
    d=$HERE; reach=1
    while [ "$d" != / ]; do
        [ "$(( 0$(stat -c %a "$d") & 1 ))" = 1 ] || reach=0
        d=$(dirname "$d")
    done
    if [ $reach = 0 ]; then
        dst=/tmp/spinmodal-devpack
        rm -rf "$dst"; mkdir -p "$dst"
        tar -C "$HERE" --exclude=./devpack.tar.xz -cf - . | tar -C "$dst" -xf -
        chmod -R a+rX "$dst"; chmod 755 "$dst"
        DEVPACK_COPIED=1 exec bash "$dst/run.sh" "$@"
    fi
fi
export LD_LIBRARY_PATH=$HERE/lib OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 LC_ALL=C TZ=UTC
export PATH=$PGBIN:$PATH PG_BINDIR=$PGBIN
cd "$HERE"
echo "== device: nproc $(nproc --all) (affinity $(env -u OMP_NUM_THREADS nproc)), load $(cat /proc/loadavg), $(uname -r), $(python3 --version 2>&1)"
head -2 /etc/os-release 2>/dev/null
cat COMMIT
bad=$(ldd bin/spinmodald "$PGBIN/postgres" 2>&1 | grep -E 'not found' || true)
[ -z "$bad" ] || { echo "missing libraries: $bad"; exit 3; }
bin/spinmodal --version || { echo "spinmodal does not run"; ldd bin/spinmodal; exit 3; }
"$PGBIN/postgres" --version || { echo "postgres does not run"; ldd "$PGBIN/postgres"; exit 3; }
TUN=glibc.malloc.trim_threshold=268435456:glibc.malloc.mmap_threshold=268435456:glibc.malloc.top_pad=67108864
if [ "${1:-}" = procs ]; then
    # the machine's own ceiling: the same 11-speed solves by P separate `spinmodal solve`
    # processes (no daemon, no store, no shared process), default malloc and TUN
    lscpu 2>/dev/null | grep -E "^(CPU\(s\)|Thread|Core|Socket|Model name|L3)"
    python3 -c 'import json; r = json.load(open("bench/angled-beam-90.json")); r["analysis"]["omega"] = {"from": 1.0, "to": 11.0, "steps": 10}; r["analysis"]["mode_shapes"] = False; json.dump(r, open("/tmp/spinmodal-req11.json", "w"))'
    # --threads 1: a daemon worker solves on one thread (--solve-threads 1); the CLI would
    # otherwise take a thread per core for each of the P processes
    one() { for _ in $(seq "$1"); do bin/spinmodal solve --threads 1 /tmp/spinmodal-req11.json >/dev/null; done; }
    N=20
    for P in 1 2 4 8 12 16; do for t in "" "$TUN"; do
        s=$(date +%s%N)
        for _ in $(seq $P); do GLIBC_TUNABLES=$t one $N & done; wait
        e=$(date +%s%N)
        echo "procs $P${t:+ tunables}: $(( (e - s) / 1000000 / N )) ms a solve, $(python3 -c "print(round($P * $N / (($e - $s) / 1e9), 1))") solves/s"
    done; done
    exit 0
fi
if [ $# -gt 0 ]; then
    exec python3 -u bench/bench_replicas.py bin --pg-bin "$PGBIN" "$@"
fi
# the issue 27 goal 4 run: the tables as built, then again with glibc's heap kept by the
# workers (no trimming back to the kernel, no mmap for big blocks: the page faults of a job)
ARGS="--workers 1,2,4,8,16 --replicas 1,2,4,8 --workers-per-replica 2 --jobs 40"
echo "### pass 1: default malloc"
python3 -u bench/bench_replicas.py bin --pg-bin "$PGBIN" $ARGS
echo "### pass 2: daemons with GLIBC_TUNABLES=$TUN"
python3 -u bench/bench_replicas.py bin --pg-bin "$PGBIN" $ARGS --daemon-env GLIBC_TUNABLES=$TUN
EOF
sed -i "s/__PGVER__/$PGVER/" "$OUT/run.sh"
chmod 755 "$OUT/run.sh"
chmod -R a+rX "$OUT"

tar -C "$(dirname "$OUT")" --exclude="$name/devpack.tar.xz" -cf - "$name" | xz -T2 -6 > "$OUT/devpack.tar.xz.tmp"
mv "$OUT/devpack.tar.xz.tmp" "$OUT/devpack.tar.xz"
du -sh --exclude=devpack.tar.xz "$OUT" | sed 's/\t.*/ tree/'
ls -l "$OUT/devpack.tar.xz" | awk '{printf "%.1f MB devpack.tar.xz (top folder %s/)\n", $5 / 1e6, "'"$name"'"}'
