"""Time budgets of the end-to-end tests, scaled to the machine they run on.

Python 3 standard library only.  Used by tests/e2e, tests/clients, tests/cli and
tests/docs; tests/web/web.test.mjs follows the same rules (and reads the same
constants from timescale.json).

Every wait of these tests polls for a condition and gives up after

    budget(base) = base * factor()       (seconds)

where `base` is what an unloaded developer machine needs, with a wide margin, and

    factor() = max(SPINMODAL_TEST_TIME_FACTOR, calibration)     (never below 1)

- SPINMODAL_TEST_TIME_FACTOR (default 1): the slowdown the caller announces.
  .ci/run sets it to the --timeout-multiplier it gives `meson test` (4 for the
  sanitizer build), so the waits grow with meson's timeouts.
- calibration: measured when the test starts: the median wall time of 3 reference
  solves by the CLI (`spinmodal solve -`, the beta = 90 deg angled beam of
  examples/angled-beam-90.json, one BLAS thread) divided by nominal_solve_s of
  timescale.json, the time that solve takes on an unloaded machine
  (debugoptimized build).  A loaded machine, a sanitizer build or a slow CPU
  makes it larger.  The CLI is SPINMODAL_TEST_CLI (meson.build sets it), else
  the `spinmodal` next to the daemon given to calibrate(); without one the
  calibration is 1 (and says so).

A check on an elapsed time ("canceled within 5 s") uses scaled(5): the same
check, on the same scale.  Lower bounds ("?wait=0.5 blocked at least 0.45 s") are
not scaled: a slow machine cannot make an answer come early.

The meson timeout of a test is SPINMODAL_TEST_TIMEOUT (meson.build passes the
same number as `timeout:`); meson kills the test after that many seconds times
its --timeout-multiplier (= SPINMODAL_TEST_TIME_FACTOR in .ci/run).  No wait
goes past that point: budget() is cut to the time left before it, minus a
margin, so a test that runs out of time fails with a FAIL line naming what it
waited for, not with a bare meson TIMEOUT.
"""
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
_START = time.monotonic()

with open(os.path.join(HERE, "timescale.json")) as _f:
    CONSTANTS = json.load(_f)
NOMINAL_SOLVE_S = float(CONSTANTS["nominal_solve_s"])
MAX_FACTOR = float(CONSTANTS["max_factor"])
REFERENCE_REQUEST = CONSTANTS["reference_request"]

_factor = None
_info = ""


def env_factor():
    """SPINMODAL_TEST_TIME_FACTOR as a number >= 1 (1 when unset or malformed)."""
    try:
        v = float(os.environ.get("SPINMODAL_TEST_TIME_FACTOR", "1") or 1)
    except ValueError:
        v = 1.0
    return max(1.0, v) if v == v else 1.0


def _find_cli(daemon_exe):
    exe = os.environ.get("SPINMODAL_TEST_CLI")
    if not exe and daemon_exe:
        exe = os.path.join(os.path.dirname(os.path.abspath(daemon_exe)), "spinmodal")
    return exe if exe and os.access(exe, os.X_OK) else None


def reference_solve_seconds(cli, runs=3):
    """Median wall time of `runs` reference solves by the CLI (None when one fails)."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    body = json.dumps(REFERENCE_REQUEST).encode()
    times = []
    for _ in range(runs):
        t0 = time.monotonic()
        try:
            p = subprocess.run([cli, "solve", "-"], input=body, capture_output=True, env=env,
                               timeout=60 * MAX_FACTOR)
        except (OSError, subprocess.TimeoutExpired):
            return None
        if p.returncode != 0:
            return None
        times.append(time.monotonic() - t0)
    return statistics.median(times)


def calibrate(daemon_exe=None, cli=None, quiet=False):
    """Measure the machine once (later calls return the same factor)."""
    global _factor, _info
    if _factor is not None:
        return _factor
    fe = env_factor()
    cli = cli or _find_cli(daemon_exe)
    t = reference_solve_seconds(cli) if cli else None
    if t is None:
        cal = 1.0
        how = "no calibration (%s)" % ("no spinmodal CLI found" if not cli else "reference solve failed")
    else:
        cal = max(1.0, t / NOMINAL_SOLVE_S)
        how = "reference solve %.3f s (nominal %.3f s) -> %.2f" % (t, NOMINAL_SOLVE_S, cal)
    _factor = min(MAX_FACTOR, max(fe, cal))
    _info = "timescale: %s; SPINMODAL_TEST_TIME_FACTOR %g; factor %.2f" % (how, fe, _factor)
    hard = hard_limit()
    if hard is not None:
        _info += "; meson kills this test %.0f s after its start" % hard
    if not quiet:
        print(_info, flush=True)
    return _factor


def factor():
    """The time factor (calibrates on first use)."""
    return calibrate() if _factor is None else _factor


def info():
    return _info


def hard_limit():
    """Seconds after the start of this process at which meson kills it (None: unknown)."""
    try:
        t = float(os.environ.get("SPINMODAL_TEST_TIMEOUT", "") or "nan")
    except ValueError:
        return None
    if not t > 0:
        return None
    return t * env_factor()


def remaining():
    """Seconds left before meson's kill, minus a margin for reporting (None: unknown)."""
    hard = hard_limit()
    if hard is None:
        return None
    margin = min(30.0, max(3.0, 0.1 * hard))
    return hard - margin - (time.monotonic() - _START)


def scaled(base):
    """base seconds on this machine's scale (for checks on an elapsed time)."""
    return base * factor()


def budget(base, floor=0.5):
    """Upper bound of a wait whose unloaded need is well below `base` seconds: base
    times factor(), cut to the time left before meson's kill (at least `floor`)."""
    b = base * factor()
    left = remaining()
    if left is not None and left < b:
        b = max(floor, left)
    return b


def wait_param(base, daemon_max=60.0):
    """A ?wait= value (seconds) for the daemon: budget(base), at most the daemon's
    maximum (DAEMON.md: 60 s)."""
    return round(min(daemon_max, budget(base)), 3)


def wait_until(cond, base, interval=0.02):
    """Poll cond() until it returns a true value or budget(base) runs out; the last value."""
    end = time.monotonic() + budget(base)
    while True:
        v = cond()
        if v or time.monotonic() >= end:
            return v
        time.sleep(interval)


if __name__ == "__main__":   # python3 timescale.py [CLI]: print the factor
    calibrate(cli=sys.argv[1] if len(sys.argv) > 1 else None)
