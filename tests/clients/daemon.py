"""Start and stop a spinmodald for the client tests (self-contained; no tests/e2e import).

    with Daemon(exe, workers=1, token="s3cret") as d:
        d.url            # http://127.0.0.1:PORT
        d.log()          # stderr so far

The daemon listens on a free loopback port (--listen 127.0.0.1:0; the port is read from the
`event=listening addr=...` log line), keeps its database in a temporary directory and is
stopped with SIGTERM (SIGKILL after a grace period).  Its waits are base budgets scaled to
the machine by tests/e2e/timescale.py (the one module shared with tests/e2e).
"""
import os
import re
import shutil
import signal
import subprocess
import tempfile
import sys
import threading

sys.path.append(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "e2e"))
import timescale as ts  # noqa: E402

_LISTENING = re.compile(r"event=listening\b.*\baddr=(\S+)")


class DaemonError(Exception):
    pass


class Daemon:
    def __init__(self, exe, workers=2, token=None, extra=(), start_timeout=None):
        self.exe = exe
        self.workers = workers
        self.token = token
        self.extra = list(extra)
        self.start_timeout = start_timeout or ts.budget(20.0)
        self.tmp = None
        self.proc = None
        self.url = None
        self.addr = None
        self.returncode = None
        self._lines = []
        self._lock = threading.Lock()
        self._reader = None

    # --------------------------------------------------------------- lifecycle

    def start(self):
        self.tmp = tempfile.mkdtemp(prefix="spinmodal-clients-")
        args = [self.exe, "--listen", "127.0.0.1:0", "--db", os.path.join(self.tmp, "jobs.db"),
                "--workers", str(self.workers), "--shutdown-grace", "2"]
        if self.token is not None:
            path = os.path.join(self.tmp, "token")
            with open(path, "w") as f:
                f.write(self.token + "\n")
            os.chmod(path, 0o600)
            args += ["--token-file", path]
        args += self.extra
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
        for k in list(env):   # no configuration leaking in from the environment
            if k.startswith("SPINMODAL_"):
                del env[k]
        self.proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.PIPE, env=env, cwd=self.tmp)
        found = threading.Event()

        def read():
            for raw in self.proc.stderr:
                line = raw.decode("utf-8", "replace").rstrip("\n")
                with self._lock:
                    self._lines.append(line)
                m = _LISTENING.search(line)
                if m and self.addr is None:
                    self.addr = m.group(1)
                    found.set()
            found.set()   # EOF: the daemon exited

        self._reader = threading.Thread(target=read, daemon=True)
        self._reader.start()
        if not found.wait(self.start_timeout) or self.addr is None:
            self.stop()
            raise DaemonError("spinmodald did not log event=listening within %g s (exit %s); log:\n%s"
                              % (self.start_timeout, self.returncode, self.log()))
        self.url = "http://" + self.addr
        return self

    def stop(self, grace=15.0):
        """SIGTERM, wait (budget(grace)), SIGKILL; returns the exit status (None if it never started)."""
        if self.proc is not None and self.returncode is None:
            if self.proc.poll() is None:
                self.proc.send_signal(signal.SIGTERM)
                try:
                    self.proc.wait(ts.budget(grace))
                except subprocess.TimeoutExpired:
                    self.proc.kill()
                    self.proc.wait()
            self.returncode = self.proc.returncode
            if self._reader is not None:
                self._reader.join(ts.budget(5))
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
            self.tmp = None
        return self.returncode

    def log(self):
        with self._lock:
            return "\n".join(self._lines)

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
        return False


def free_port():
    """A loopback port nothing listens on (for connection-refused checks)."""
    import socket
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port
