#!/usr/bin/env python3
"""How the CLI starts (issue 27, DESIGN.md 2.1): OpenBLAS from its archive, on one thread.

Usage: startup_test.py SPINMODAL LINK REQUEST...
LINK: "static-pie" when meson linked the whole CLI static-pie (-Dstatic_cli, found), "static"
when it linked it with OpenBLAS's archive (-Dstatic_openblas, found), "shared" otherwise.

  - static-pie: every check of "static", and the CLI has no program interpreter (PT_INTERP) and
    needs no shared library at all (no dynamic loader at its start: 0.3-0.5 ms of a small solve
    in a virtual machine), and is position independent (ELF type DYN: its addresses are still
    randomised);

  - static: the CLI needs none of libopenblas.so.0, libblas.so.3, liblapack.so.3 (ELF NEEDED,
    readelf -d), nor libgfortran.so.5 (server/fortran_rt.c defines the one routine OpenBLAS's
    LAPACK takes from it; its libraries' constructors cost 0.3-0.5 ms of each start in a virtual
    machine), and prints its version without the environment variables OpenBLAS reads;
    shared: it needs libopenblas.so.0 (so that the configuration says what was built);
  - each REQUEST solved without OPENBLAS_NUM_THREADS, OMP_NUM_THREADS and GOTO_NUM_THREADS
    (the CLI then asks OpenBLAS for one thread before OpenBLAS starts), with
    OPENBLAS_NUM_THREADS=1 and with OMP_NUM_THREADS=1 gives the same document, byte for byte
    (timing_ms removed), with one sweep thread and with three.
"""
import os
import re
import subprocess
import sys

FAILURES = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILURES.append(what)
    return cond


def needed(path):
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True, check=True).stdout
    return set(re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out))


def program_headers(path):
    """readelf -lW: (ELF file type line, the program headers' types)."""
    out = subprocess.run(["readelf", "-lW", path], capture_output=True, text=True,
                         check=True).stdout
    kind = re.search(r"Elf file type is (\S+)", out)
    return (kind.group(1) if kind else "?"), set(re.findall(r"^\s+([A-Z_]+)\s+0x", out, re.M))


def env_without_blas(**extra):
    env = {k: v for k, v in os.environ.items()
           if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "GOTO_NUM_THREADS")}
    env.update(extra)
    return env


def solve(cli, req, env, threads):
    p = subprocess.run([cli, "solve", "--threads", str(threads), req], capture_output=True,
                       text=True, env=env, timeout=600)
    if p.returncode != 0:
        return "exit %d: %s" % (p.returncode, p.stderr.strip())
    return re.sub(r'"timing_ms":\{[^}]*\}', "", p.stdout)


def main():
    cli, link, reqs = sys.argv[1], sys.argv[2], sys.argv[3:]
    libs = needed(cli)
    blas = sorted(libs & {"libopenblas.so.0", "libblas.so.3", "liblapack.so.3"})
    if link == "static-pie":
        kind, headers = program_headers(cli)
        check(not libs, "static-pie: the CLI needs no shared library (NEEDED: %s)" % sorted(libs))
        check("INTERP" not in headers and "LOAD" in headers,
              "static-pie: no program interpreter (program headers: %s)" % sorted(headers))
        check(kind == "DYN", "static-pie: position independent (ELF type %s)" % kind)
    if link in ("static", "static-pie"):
        check(not blas, "static: the CLI needs no shared BLAS/LAPACK (NEEDED: %s)" % sorted(libs))
        imports = subprocess.run(["nm", "-D", "--undefined-only", cli], capture_output=True,
                                 text=True).stdout  # a static-pie program has none: "no symbols"
        check("libgfortran.so.5" not in libs,
              "static: the CLI needs no libgfortran (NEEDED: %s; its imports from it: %s)"
              % (sorted(libs), sorted(set(re.findall(r"_gfortran_\w+", imports)))))
        p = subprocess.run([cli, "--version"], capture_output=True, text=True,
                           env=env_without_blas(), timeout=60)
        check(p.returncode == 0 and p.stdout.startswith("spinmodal "),
              "static: --version without OpenBLAS's variables: %r" % p.stdout.strip())
    else:
        check("libopenblas.so.0" in libs or "libblas.so.3" in libs,
              "shared: the CLI needs the shared BLAS (NEEDED: %s)" % sorted(libs))
    for req in reqs:
        name = os.path.basename(req)
        ref = solve(cli, req, env_without_blas(OPENBLAS_NUM_THREADS="1"), 1)
        check(ref.startswith("{"), "%s solves with OPENBLAS_NUM_THREADS=1 (%s)" % (name, ref[:80]))
        for label, env in (("no BLAS variables", env_without_blas()),
                           ("OMP_NUM_THREADS=1", env_without_blas(OMP_NUM_THREADS="1"))):
            for threads in (1, 3):
                check(solve(cli, req, env, threads) == ref,
                      "%s, %s, %d sweep thread(s): the same bytes" % (name, label, threads))
    if FAILURES:
        print("%d check(s) failed" % len(FAILURES))
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()
