#!/usr/bin/env bash
# deploy/install-deps.sh — install every build and test dependency of
# spinmodal on Debian 12 (bookworm) with apt-get.
#
# Idempotent: packages already installed are left alone, and when nothing is
# missing apt is not touched at all (no network needed).  Otherwise runs
# `apt-get update` once and installs what is missing, noninteractively.
# Runs as root (CI, containers) or through sudo when not root.
#
# Usage: bash deploy/install-deps.sh
set -euo pipefail

# Required: compiler + build system, libraries of core/ and server/, the
# Python used by the schema tests, tools used by clients and CI.
required=(
  build-essential pkg-config meson ninja-build
  libjansson-dev libssl-dev                # codec, request SHA-256
  liblapacke-dev libopenblas-dev           # LAPACK(E) + BLAS for core/
  libgfortran-12-dev                       # the CLI links OpenBLAS's archive, which needs -lgfortran
  libmicrohttpd-dev libsqlite3-dev         # daemon (spinmodald)
  libpq-dev                                # daemon: the store's PostgreSQL backend (DESIGN.md §6)
  postgresql                               # tests: server binaries for the throwaway cluster (15 on Debian 12)
  python3 python3-jsonschema               # schema validation tests
  python3-yaml                             # tests/deploy: parses deploy/k8s and deploy/compose.yaml
  curl ca-certificates                     # clients, end-to-end tests
  nodejs npm chromium                      # web front end (clients/web) and its browser test (tests/web)
  clang libclang-rt-14-dev                 # CI fuzz step: libFuzzer (only Recommended by clang)
  clang-format                             # CI format step: .ci/format-check (clang-format 14, git-clang-format)
)
# Optional: nice to have, a failure to install them is only a warning.
# wrk: tests/bench/bench_http.sh; nginx: tests/deploy (deploy/nginx/spinmodal.conf in
# front of a real daemon; the test runs its own nginx, the package's service may be
# disabled); podman + debootstrap: tests/deploy (deploy-image) makes a Debian 12 base
# with debootstrap (no registry), builds deploy/Dockerfile with podman and runs its
# spinmodald from the image's file system (about 4 to 5 minutes on 2 cores, the
# network needed for apt-get and npm ci).  kubectl is used by tests/deploy when present
# but not installed here: Debian 12's kubernetes-client (1.20) conflicts with other
# kubectl installs.
optional=(valgrind wrk nginx podman debootstrap)

say() { printf 'install-deps: %s\n' "$*"; }

if [ "$(id -u)" -eq 0 ]; then
  SUDO=()
elif command -v sudo >/dev/null 2>&1; then
  SUDO=(sudo)
  say "not root: using sudo"
else
  say "error: must run as root, or with sudo available" >&2
  exit 1
fi

if ! command -v apt-get >/dev/null 2>&1; then
  say "error: apt-get not found; this script targets Debian 12" >&2
  exit 1
fi
if [ -r /etc/os-release ]; then
  # shellcheck disable=SC1091
  . /etc/os-release
  if [ "${ID:-}" != debian ] || [ "${VERSION_ID:-}" != 12 ]; then
    say "warning: tested on Debian 12, this is ${PRETTY_NAME:-unknown}"
  fi
fi

# missing PKG...: print the packages of the arguments that are not installed.
missing() {
  local p
  for p in "$@"; do
    # npm also comes inside other nodejs builds (NodeSource's provides and conflicts with it)
    if [ "$p" = npm ] && command -v npm >/dev/null 2>&1; then continue; fi
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
      printf '%s\n' "$p"
    fi
  done
}

mapfile -t need < <(missing "${required[@]}")
mapfile -t want < <(missing "${optional[@]}")

if [ "${#need[@]}" -eq 0 ] && [ "${#want[@]}" -eq 0 ]; then
  say "all ${#required[@]} required and ${#optional[@]} optional packages already installed"
  exit 0
fi

export DEBIAN_FRONTEND=noninteractive
apt_get=("${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get
         -y -q -o Dpkg::Options::=--force-confdef -o Dpkg::Options::=--force-confold)

say "running: apt-get update"
"${apt_get[@]}" update

if [ "${#need[@]}" -gt 0 ]; then
  say "installing required: ${need[*]}"
  "${apt_get[@]}" install --no-install-recommends "${need[@]}"
fi
if [ "${#want[@]}" -gt 0 ]; then
  say "installing optional: ${want[*]}"
  "${apt_get[@]}" install --no-install-recommends "${want[@]}" \
    || say "warning: optional packages not installed: ${want[*]}"
fi

mapfile -t still < <(missing "${required[@]}")
if [ "${#still[@]}" -gt 0 ]; then
  say "error: still missing: ${still[*]}" >&2
  exit 1
fi
say "done"
