#!/usr/bin/env python3
"""spinmodal_client — a small client for the spinmodald HTTP JSON API (Python 3.11, stdlib only).

The contract is server/DAEMON.md.  Library use::

    from spinmodal_client import Client, SpinmodalError

    c = Client("http://127.0.0.1:8080", token=None)
    st = c.submit("examples/angled-beam-90.json", wait=30)   # status document
    st = c.wait(st["id"])                                    # until done/failed/canceled
    res = c.result(st["id"])                                 # result document (dict)
    print(res["cases"][0]["modes"][0]["frequency_rad_s"])
    rows = c.campbell("examples/angled-beam-90-sweep.json", speeds=[0, 5, 10, 15, 20])

Transport: http.client (stdlib); HTTP proxies from the environment are not used.

Command line (also ``python3 -m spinmodal_client --help``)::

    python3 -m spinmodal_client solve request.json [--csv] [--url URL] [--token T] [--timeout S]
    python3 -m spinmodal_client validate request.json
    python3 -m spinmodal_client status ID
    python3 -m spinmodal_client cancel ID
    python3 -m spinmodal_client list [--state S] [--limit N]
    python3 -m spinmodal_client campbell request.json --speeds 0:20:21 [--hz]   (or --rpm 0:15:16)

Exit codes: 0 ok, 1 the job failed or was canceled, 2 invalid request (HTTP 400, 413, 415,
422), 3 connection error, server error or any other HTTP error (401, 404, 409, 429, 503 ...),
64 usage error.  --url and --token default to $SPINMODAL_URL and $SPINMODAL_TOKEN.
"""

import argparse
import copy
import csv as _csv
import io
import json
import os
import sys
import http.client
import socket
import time
import urllib.parse

__all__ = ["Client", "SpinmodalError", "SpinmodalConnectionError", "SpinmodalJobError",
           "parse_speeds", "parse_csv", "FINAL_STATES", "DEFAULT_URL"]

DEFAULT_URL = "http://127.0.0.1:8080"
FINAL_STATES = ("done", "failed", "canceled")
MAX_WAIT = 60.0          # the daemon accepts ?wait=S with 0 <= S <= 60
_USER_AGENT = "spinmodal-python-client/0.1"


class SpinmodalError(Exception):
    """An error answer of the daemon (an RFC 9457 problem document) or a failure to reach it.

    Attributes (None when the answer did not carry them):
      status       HTTP status code (None for connection errors)
      type         problem type URI ("about:blank" or "https://spinmodal.dev/problems/...")
      title        short summary
      detail       explanation of this occurrence
      errors       list of {"pointer", "message"} (validation errors, 400/422); [] if none
      retry_after  seconds from the Retry-After header (429, 503), as a float
      body         the raw response text
    """

    def __init__(self, message, status=None, type=None, title=None, detail=None,
                 errors=None, retry_after=None, body=None):
        super().__init__(message)
        self.status = status
        self.type = type
        self.title = title
        self.detail = detail
        self.errors = list(errors or [])
        self.retry_after = retry_after
        self.body = body

    @property
    def invalid_request(self):
        """True for the answers that mean "your request is wrong" (400, 413, 415, 422)."""
        return self.status in (400, 413, 415, 422)

    def __str__(self):
        text = super().__str__()
        for e in self.errors:
            if isinstance(e, dict):
                text += "\n  %s: %s" % (e.get("pointer", "?") or '""', e.get("message", ""))
        return text


class SpinmodalConnectionError(SpinmodalError):
    """The daemon could not be reached (refused, unknown host, timeout, connection reset)."""


class SpinmodalJobError(SpinmodalError):
    """A job ended `failed` or `canceled` where a result was needed.

    ``job`` is the final status document; ``type``/``title``/``detail`` come from its
    ``error`` object (``type`` "canceled" for a canceled job); ``status`` is None.
    """

    def __init__(self, message, job, **kw):
        super().__init__(message, **kw)
        self.job = job


def _retry_after(headers):
    value = headers.get("Retry-After") if headers is not None else None
    if value is None:
        return None
    try:
        return max(0.0, float(value))
    except ValueError:
        pass
    try:  # an HTTP date
        from email.utils import parsedate_to_datetime
        return max(0.0, parsedate_to_datetime(value).timestamp() - time.time())
    except (TypeError, ValueError, IndexError):
        return None


def _fmt_seconds(s):
    """Format a ?wait value: integral values without a fraction, others with milliseconds."""
    s = min(MAX_WAIT, max(0.0, float(s)))
    if s == int(s):
        return str(int(s))
    return ("%.3f" % s).rstrip("0").rstrip(".")


def _load_request(request):
    """A request as JSON bytes: a dict/list is encoded, bytes are sent verbatim, a str or
    os.PathLike names a file ('-' is stdin) whose bytes are sent verbatim."""
    if isinstance(request, (dict, list)):
        return json.dumps(request).encode("utf-8")
    if isinstance(request, (bytes, bytearray)):
        return bytes(request)
    if isinstance(request, (str, os.PathLike)):
        if str(request) == "-":
            return sys.stdin.buffer.read()
        with open(request, "rb") as f:
            return f.read()
    raise TypeError("request must be a dict, a path or JSON bytes, not %s" % type(request).__name__)


def _request_dict(request):
    """A request as a dict (a deep copy), for the edits campbell() makes."""
    if isinstance(request, dict):
        return copy.deepcopy(request)
    return json.loads(_load_request(request).decode("utf-8"))


def parse_speeds(text):
    """Speeds from 'START:STOP:COUNT' (COUNT evenly spaced values, both ends included, like
    numpy.linspace: '0:15:16' is 0, 1, ... 15), one number or a comma-separated list '0,5,10'.
    Returns a list of floats.  COUNT 1 needs START = STOP ('0:15:1' would silently be 0 alone:
    ValueError), the same rule as `spinmodal import --rpm` and clients/curl/campbell.sh."""
    text = text.strip()
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise ValueError("speeds must be START:STOP:COUNT, got %r" % text)
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
        if count < 1:
            raise ValueError("COUNT must be >= 1, got %d" % count)
        if count == 1 and stop != start:
            raise ValueError("%s would be %g alone: COUNT is the number of speeds, both ends "
                             "included (e.g. %g:%g:%d)" % (text, start, start, stop,
                                                           int(abs(stop - start)) + 1))
        if count == 1:
            return [start]
        step = (stop - start) / (count - 1)
        out = [start + i * step for i in range(count)]
        out[-1] = stop
        return [round(x, 12) + 0.0 for x in out]
    values = [float(v) for v in text.split(",") if v.strip()]
    if not values:
        raise ValueError("no speeds in %r" % text)
    return values


def _num(text, kind=float):
    return kind(text) if text not in ("", None) else None


class Client:
    """A client of one spinmodald.

    url      base URL of the daemon (no trailing /v1)
    token    bearer token sent as ``Authorization: Bearer`` (needed for POST/DELETE when the
             daemon runs with --token-file); None sends none
    timeout  seconds for one HTTP exchange (a ?wait=S long poll gets S more)
    """

    def __init__(self, url=DEFAULT_URL, token=None, timeout=30):
        self.url = (url or DEFAULT_URL).rstrip("/")
        self.token = token or None
        self.timeout = timeout
        u = urllib.parse.urlsplit(self.url if "://" in self.url else "http://" + self.url)
        if u.scheme not in ("http", "https"):
            raise ValueError("spinmodald URL must be http:// or https://, got %r" % url)
        self._scheme = u.scheme
        self._host = u.hostname or "127.0.0.1"
        try:
            self._port = u.port
        except ValueError:
            raise ValueError("bad port in spinmodald URL %r" % url) from None
        self._prefix = u.path.rstrip("/")      # a reverse proxy may serve the API under a path

    def __repr__(self):
        return "Client(%r)" % self.url

    # ------------------------------------------------------------------ plumbing

    def _call(self, method, path, body=None, query=None, wait=0.0, expect_json=True):
        """One HTTP exchange.  Returns (status, headers, decoded body) or raises SpinmodalError.

        http.client rather than urllib.request: when the daemon refuses a body early (413,
        answered without reading the rest) the send fails with EPIPE/ECONNRESET, and the answer
        it already sent must still be read.  Proxies ($http_proxy) are not used.
        """
        if query:
            q = urllib.parse.urlencode({k: v for k, v in query.items() if v is not None})
            if q:
                path += ("&" if "?" in path else "?") + q
        headers = {"Accept": "application/json, application/problem+json;q=0.9, */*;q=0.5",
                   "User-Agent": _USER_AGENT}
        if body is not None:
            headers["Content-Type"] = "application/json"
        if self.token:
            headers["Authorization"] = "Bearer " + self.token
        what = "%s %s" % (method, path)
        timeout = self.timeout + wait
        try:
            cls = http.client.HTTPSConnection if self._scheme == "https" else http.client.HTTPConnection
            conn = cls(self._host, self._port, timeout=timeout)
        except (ValueError, http.client.InvalidURL) as e:
            raise SpinmodalConnectionError("bad spinmodald URL %r: %s" % (self.url, e)) from None
        try:
            send_error = None
            try:
                conn.request(method, self._prefix + path, body=body, headers=headers)
            except (BrokenPipeError, ConnectionResetError) as e:
                if body is None:
                    raise
                send_error = e      # the daemon may have answered early (413) and closed
            try:
                resp = conn.getresponse()
                status, hdrs, raw = resp.status, resp.headers, resp.read()
            except (http.client.HTTPException, OSError):
                if send_error is not None:
                    raise send_error from None
                raise
        except TimeoutError as e:
            raise SpinmodalConnectionError("spinmodald at %s did not answer %s within %g s"
                                           % (self.url, what, timeout)) from e
        except (ConnectionRefusedError, socket.gaierror) as e:
            raise SpinmodalConnectionError("cannot reach spinmodald at %s (%s): %s"
                                           % (self.url, what, e)) from e
        except (http.client.HTTPException, OSError) as e:   # reset, broken pipe, bad answer ...
            raise SpinmodalConnectionError("connection to spinmodald at %s failed (%s): %s"
                                           % (self.url, what, e or type(e).__name__)) from e
        finally:
            conn.close()
        if status >= 400:
            raise self._problem(method, path, status, hdrs, raw)
        text = raw.decode("utf-8", "replace")
        if not expect_json:
            return status, hdrs, text
        try:
            return status, hdrs, json.loads(text) if text else None
        except ValueError as e:
            raise SpinmodalError("%s: the answer (HTTP %d) is not JSON: %s: %.200s"
                                 % (what, status, e, text), status=status, body=text) from None

    @staticmethod
    def _problem(method, path, status, headers, raw):
        text = raw.decode("utf-8", "replace")
        doc = None
        try:
            doc = json.loads(text) if text else None
        except ValueError:
            pass
        if not isinstance(doc, dict):
            doc = {}
        title = doc.get("title")
        detail = doc.get("detail")
        errors = doc.get("errors") if isinstance(doc.get("errors"), list) else []
        msg = "HTTP %d" % status
        if title:
            msg += " %s" % title
        if detail:
            msg += ": %s" % detail
        if not title and not detail and text and not doc:
            msg += ": %.200s" % text.strip()
        msg += " (%s %s)" % (method, path)
        return SpinmodalError(msg, status=status, type=doc.get("type"), title=title, detail=detail,
                              errors=errors, retry_after=_retry_after(headers), body=text)

    @staticmethod
    def _check_id(id):
        if not isinstance(id, str) or not id or "/" in id or "?" in id:
            raise ValueError("a job id is a string of 64 hex digits, got %r" % (id,))
        return urllib.parse.quote(id, safe="")

    # ------------------------------------------------------------------ API

    def submit(self, request, wait=None, retry=False, retries=5):
        """POST /v1/analyses.  request: a dict, a file path ('-' = stdin) or JSON bytes.

        wait: seconds the daemon may hold the answer until the job finishes (0...60; larger
        values are clamped to 60 — use wait() for longer).  Returns the status document
        (with ``result`` when the job is done).  retry=True: on 429 (queue full) or 503
        (stopping, database busy) sleep for Retry-After (1 s if absent, at most 60 s) and try
        again, up to ``retries`` times, then raise the last SpinmodalError.
        """
        body = _load_request(request)
        query = {"wait": _fmt_seconds(wait)} if wait is not None else None
        wait_s = float(query["wait"]) if query else 0.0
        attempt = 0
        while True:
            try:
                _, _, doc = self._call("POST", "/v1/analyses", body=body, query=query, wait=wait_s)
                return doc
            except SpinmodalError as e:
                if not retry or e.status not in (429, 503) or attempt >= retries:
                    raise
                attempt += 1
                time.sleep(min(60.0, e.retry_after if e.retry_after is not None else 1.0))

    def validate(self, request):
        """POST /v1/validate: check a request without storing or queueing it.  Returns
        {"valid": true, "id", "request_sha256", "canonical"}; an invalid request raises
        SpinmodalError (400/413/415/422, as submit() would).  Needs no token."""
        return self._call("POST", "/v1/validate", body=_load_request(request))[2]

    def get(self, id, wait=None):
        """GET /v1/analyses/{id}: the status document (``wait``: long poll up to S <= 60 s)."""
        query = {"wait": _fmt_seconds(wait)} if wait is not None else None
        wait_s = float(query["wait"]) if query else 0.0
        return self._call("GET", "/v1/analyses/" + self._check_id(id), query=query, wait=wait_s)[2]

    def wait(self, id, timeout=None, poll=0.5):
        """Wait until job id is done, failed or canceled and return its final status document.

        Uses the daemon's long polls (GET ?wait=S, S <= 60); ``poll`` is the pause between
        requests when the daemon answers early without a final state.  Raises TimeoutError
        after ``timeout`` seconds (None: wait for ever).
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            left = MAX_WAIT if deadline is None else deadline - time.monotonic()
            t0 = time.monotonic()
            doc = self.get(id, wait=max(0.0, min(MAX_WAIT, left)))
            if doc.get("state") in FINAL_STATES:
                return doc
            if deadline is not None and time.monotonic() >= deadline:
                raise TimeoutError("job %s still %s after %g s" % (id, doc.get("state"), timeout))
            if time.monotonic() - t0 < min(left, MAX_WAIT) - 0.05:
                # answered early without a final state: do not hammer the daemon
                pause = poll if deadline is None else min(poll, max(0.0, deadline - time.monotonic()))
                time.sleep(pause)

    def result(self, id):
        """GET /v1/analyses/{id}/result: the result document (SpinmodalError 409 when none)."""
        return self._call("GET", "/v1/analyses/%s/result" % self._check_id(id))[2]

    def csv(self, id):
        """GET /v1/analyses/{id}/result?format=csv: the frequency table as CSV text."""
        return self._call("GET", "/v1/analyses/%s/result" % self._check_id(id),
                          query={"format": "csv"}, expect_json=False)[2]

    def spanwise(self, id, bmodes=False):
        """GET /v1/analyses/{id}/result?format=spanwise (CSV) or format=bmodes (BModes-style
        text): the span-wise mode shapes of a spatial result with mode shapes (409 otherwise)."""
        return self._call("GET", "/v1/analyses/%s/result" % self._check_id(id),
                          query={"format": "bmodes" if bmodes else "spanwise"},
                          expect_json=False)[2]

    def import_file(self, format, main, sec_props=None, name=None, tip_radius=None,
                    hub_radius=None, rpm=None, bmodes_mesh=None):
        """POST /v1/import/{format}: a blade file's text (``main``; BModes also the text of its
        section-properties file, ``sec_props``) -> the import document {request,
        input_warnings, warnings, source}.  ``rpm`` (rev/min, replaces the file's speed): a
        number, a list of numbers, or the text of a range 'START:STOP:COUNT' (COUNT speeds,
        both ends included) or list '0,5,10' as `spinmodal import --rpm` takes it.

        ``input_warnings`` is [{"pointer", "message"}], the shape of a result's input_warnings
        (pointer: the field of the request the warning is about); ``warnings`` holds the same
        messages as plain strings (the older shape; a daemon before 0.8 sends only these, and
        they come back here as input_warnings with pointer "").  SpinmodalError 422 names the
        file, line and field of a refused file."""
        body = {"main": main}
        if sec_props is not None:
            body["sec_props"] = sec_props
        if name:
            body["name"] = name
        if isinstance(rpm, (list, tuple)):
            rpm = ",".join(repr(float(v)) for v in rpm)
        doc = self._call("POST", "/v1/import/" + urllib.parse.quote(format, safe=""),
                         body=json.dumps(body).encode("utf-8"),
                         query={"tip_radius": tip_radius, "hub_radius": hub_radius,
                                "rpm": rpm, "bmodes_mesh": bmodes_mesh})[2]
        if isinstance(doc, dict) and "input_warnings" not in doc:
            doc["input_warnings"] = [{"pointer": "", "message": str(w)}
                                     for w in doc.get("warnings") or []]
        return doc

    def cancel(self, id):
        """DELETE /v1/analyses/{id}: the status document (``canceled`` for a queued job,
        ``cancel_requested`` for a running one); SpinmodalError 409 when already finished."""
        return self._call("DELETE", "/v1/analyses/" + self._check_id(id))[2]

    def list(self, state=None, limit=20):
        """Iterate over every job (status documents without result), newest first, following
        the ``next`` links page by page (``limit`` jobs per request, 1...100)."""
        query = {"limit": str(int(limit))}
        if state is not None:
            query["state"] = state
        _, _, doc = self._call("GET", "/v1/analyses", query=query)
        while True:
            for item in doc.get("items") or []:
                yield item
            nxt = doc.get("next")
            if not nxt:
                return
            path = urllib.parse.urlsplit(nxt)
            target = path.path + ("?" + path.query if path.query else "")
            if self._prefix and target.startswith(self._prefix + "/"):
                target = target[len(self._prefix):]
            if state is not None and "state" not in urllib.parse.parse_qs(path.query):
                target += ("&" if path.query else "?") + urllib.parse.urlencode({"state": state})
            _, _, doc = self._call("GET", target)

    def campbell(self, request, speeds=None, timeout=None, retry=True, rpm=None):
        """Run a sweep and return its frequency table as a list of rows, one per speed and
        mode in request order: dicts with omega, mode, frequency_rad_s, frequency_hz, status
        and mac_to_previous (mode and the numbers are None for a speed without modes, e.g.
        no_equilibrium).  ``speeds`` (a list of rad/s) or ``rpm`` (a list of rev/min, not
        both) replaces the request's speeds, whichever key it used (analysis.omega or
        analysis.rpm: the importers write rpm); mode shapes are switched off.  A job that
        ends failed with a stored result (no equilibrium at some speeds) still returns its
        rows; otherwise SpinmodalJobError."""
        if speeds is not None and rpm is not None:
            raise ValueError("campbell(): give speeds (rad/s) or rpm (rev/min), not both")
        req = _request_dict(request)
        analysis = req.setdefault("analysis", {})
        if speeds is not None:
            analysis.pop("rpm", None)
            analysis["omega"] = [float(s) for s in speeds]
        elif rpm is not None:
            analysis.pop("omega", None)
            analysis["rpm"] = [float(s) for s in rpm]
        analysis["mode_shapes"] = False
        st = self.submit(req, wait=MAX_WAIT if timeout is None else min(MAX_WAIT, timeout), retry=retry)
        if st.get("state") not in FINAL_STATES:
            st = self.wait(st["id"], timeout=timeout)
        if st.get("state") not in ("done", "failed") or (
                st.get("state") == "failed" and "result" not in st):
            raise _job_error(st)
        return parse_csv(self.csv(st["id"]))

    def health(self):
        """GET /readyz: {"status": "ready", "checks": {...}}; SpinmodalError 503 when not ready."""
        return self._call("GET", "/readyz")[2]

    def live(self):
        """GET /livez: {"status": "ok"} while the process serves."""
        return self._call("GET", "/livez")[2]


def parse_csv(text):
    """Rows of the daemon's frequency CSV as dicts (omega, mode, frequency_rad_s, frequency_hz,
    status, mac_to_previous, per_rev, rpm, label, label_confidence, tracked_index, tracking_flag,
    error_estimate); numbers as float/int, empty fields as None (per_rev at omega = 0,
    error_estimate without "error_estimate": true, or from a daemon before these columns)."""
    rows = []
    for r in _csv.DictReader(io.StringIO(text)):
        rows.append({
            "omega": _num(r.get("omega")),
            "mode": _num(r.get("mode"), int),
            "frequency_rad_s": _num(r.get("frequency_rad_s")),
            "frequency_hz": _num(r.get("frequency_hz")),
            "status": r.get("status"),
            "mac_to_previous": _num(r.get("mac_to_previous")),
            "per_rev": _num(r.get("per_rev")),
            "rpm": _num(r.get("rpm")),
            # DESIGN.md 9.1 (None from a daemon before these columns)
            "label": r.get("label") or None,
            "label_confidence": _num(r.get("label_confidence")),
            "tracked_index": _num(r.get("tracked_index"), int),
            "tracking_flag": r.get("tracking_flag") or None,
            "error_estimate": _num(r.get("error_estimate_rad_s")),
        })
    return rows


# Columns of format_table: key in a row, header, decimals (None: an integer or text).
TABLE_COLUMNS = (("omega", "omega_rad_s", 4), ("rpm", "rpm", 2), ("mode", "mode", None),
                 ("frequency_rad_s", "freq_rad_s", 6), ("frequency_hz", "freq_hz", 6),
                 ("per_rev", "per_rev", 4), ("status", "status", None), ("label", "label", None))


def table_rows(result):
    """The rows of a result document (DESIGN.md 4): one dict per speed and mode with omega, rpm,
    mode, frequency_rad_s, frequency_hz, per_rev, status and label (mode, frequencies and label
    None for a speed without modes; per_rev None at rest), and error_estimate (None without one)."""
    rows = []
    for c in result.get("cases", []):
        base = {"omega": c.get("omega"), "rpm": c.get("rpm"), "status": c.get("status")}
        for k, m in enumerate(c.get("modes") or [None]):
            m = m or {}
            rows.append(dict(base, mode=k + 1 if m else None, frequency_rad_s=m.get("frequency_rad_s"),
                             frequency_hz=m.get("frequency_hz"), per_rev=m.get("per_rev"),
                             label=m.get("label"), error_estimate=m.get("error_estimate")))
    return rows


def _estimate_cell(row, key):
    """" +/- e" after the frequency in rad/s when the row has an error estimate (DESIGN.md 9)."""
    e = row.get("error_estimate")
    return " +/- %.1e" % e if key == "frequency_rad_s" and e is not None else ""


def format_table(rows):
    """rows (table_rows or parse_csv) as an aligned text table: speed in rad/s and rpm, mode, the
    frequency in rad/s (with " +/- e" when the row has an error estimate), Hz and per
    revolution, status, the mode label; every number of a column with the same
    decimals, right-aligned; "-" for a missing value (the spinmodal CLI's --table)."""
    def cell(v, dec):
        if v is None:
            return "-"
        return "%.*f" % (dec, v) if dec is not None else str(v)
    cells = [[cell(r.get(k), dec) + _estimate_cell(r, k) for k, _, dec in TABLE_COLUMNS]
             for r in rows]
    heads = [h for _, h, _ in TABLE_COLUMNS]
    width = [max([len(h)] + [len(c[j]) for c in cells]) for j, h in enumerate(heads)]
    lines = []
    for row in [heads] + cells:
        lines.append("  ".join(v.rjust(width[j]) if j < len(row) - 1 else v.ljust(width[j])
                               for j, v in enumerate(row)))
    return "\n".join(lines) + "\n"


def _job_error(st):
    err = st.get("error") or {}
    state = st.get("state")
    if state == "canceled":
        return SpinmodalJobError("job %s was canceled" % st.get("id"), st, type="canceled",
                                 title="canceled", detail=err.get("detail"))
    msg = "job %s %s" % (st.get("id"), state)
    if err.get("title") or err.get("type"):
        msg += ": %s" % (err.get("title") or err.get("type"))
    if err.get("detail"):
        msg += " (%s)" % err["detail"]
    return SpinmodalJobError(msg, st, type=err.get("type"), title=err.get("title"),
                             detail=err.get("detail"))


# ====================================================================== command line

EXIT_OK, EXIT_FAILED, EXIT_INVALID, EXIT_ERROR, EXIT_USAGE = 0, 1, 2, 3, 64


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, "%s: error: %s\n" % (self.prog, message))


def _dump(doc, pretty):
    json.dump(doc, sys.stdout, indent=2 if pretty else None)
    sys.stdout.write("\n")


def _print_job_error(st):
    err = st.get("error")
    what = "job %s %s" % (st.get("id"), st.get("state"))
    if err:
        what += ": %s" % json.dumps(err)
    print(what, file=sys.stderr)


def _read_request(path):
    try:
        return _load_request(path)
    except OSError as e:
        raise _RequestFileError("cannot read the request file %s: %s" % (path, e.strerror or e)) from None


class _RequestFileError(Exception):
    pass


def _cmd_solve(c, a):
    st = c.submit(_read_request(a.request), wait=MAX_WAIT if a.timeout is None else min(MAX_WAIT, a.timeout),
                  retry=True)
    if st.get("state") not in FINAL_STATES:
        st = c.wait(st["id"], timeout=a.timeout)
    has_result = st.get("state") == "done" or "result" in st
    if has_result:
        if a.csv:
            sys.stdout.write(c.csv(st["id"]))
        elif a.spanwise or a.bmodes:
            sys.stdout.write(c.spanwise(st["id"], bmodes=a.bmodes))
        elif a.table:
            res = st["result"] if "result" in st else c.result(st["id"])
            sys.stdout.write(format_table(table_rows(res)))
            for w in res.get("input_warnings", []):
                print("warning: %s: %s" % (w.get("pointer"), w.get("message")))
        else:
            _dump(st["result"] if "result" in st else c.result(st["id"]), a.pretty)
    if st.get("state") != "done":
        _print_job_error(st)
        return EXIT_FAILED
    return EXIT_OK


def bmodes_sec_props_name(bmi_text):
    """The section-properties file a BModes .bmi names (the quoted value on its
    sec_props_file line), or None."""
    for line in bmi_text.splitlines():
        if "sec_props_file" in line:
            v = line.strip().split()[0] if line.strip() else ""
            return v.strip("'\"") or None
    return None


def _cmd_import(c, a):
    if a.rpm is not None:
        try:
            parse_speeds(a.rpm)     # the daemon parses it again (400 for what this misses)
        except ValueError as e:
            print("import: --rpm: %s" % e, file=sys.stderr)
            return EXIT_USAGE
    try:
        with open(a.file, encoding="utf-8", errors="replace", newline="") as f:
            main = f.read()
        sec = None
        if a.format == "bmodes":
            sec_path = a.sec_props or bmodes_sec_props_name(main)
            if not sec_path:
                raise _RequestFileError("%s: no sec_props_file line; give --sec-props" % a.file)
            if not os.path.isabs(sec_path) and not a.sec_props:
                sec_path = os.path.join(os.path.dirname(os.path.abspath(a.file)), sec_path)
            with open(sec_path, encoding="utf-8", errors="replace", newline="") as f:
                sec = f.read()
    except OSError as e:
        raise _RequestFileError("%s: %s" % (e.filename, e.strerror)) from None
    doc = c.import_file(a.format, main, sec_props=sec, name=os.path.basename(a.file),
                        tip_radius=a.tip_radius, hub_radius=a.hub_radius, rpm=a.rpm,
                        bmodes_mesh=a.bmodes_mesh)
    for w in doc.get("input_warnings", []):
        print("warning: %s: %s" % (w.get("pointer"), w.get("message")), file=sys.stderr)
    _dump(doc if a.full else doc.get("request"), a.pretty)
    return EXIT_OK


def _cmd_validate(c, a):
    _dump(c.validate(_read_request(a.request)), a.pretty)
    return EXIT_OK


def _cmd_status(c, a):
    st = c.get(a.id)
    _dump(st, a.pretty)
    return EXIT_FAILED if st.get("state") in ("failed", "canceled") else EXIT_OK


def _cmd_cancel(c, a):
    _dump(c.cancel(a.id), a.pretty)
    return EXIT_OK


def _cmd_list(c, a):
    n = 0
    for item in c.list(state=a.state, limit=a.limit):
        if a.json:
            _dump(item, False)
        else:
            p = item.get("progress") or {}
            print("%s  %-8s  %5s/%-5s  %s" % (item.get("id"), item.get("state"), p.get("done", ""),
                                              p.get("total", ""), item.get("created_at") or ""))
        n += 1
        if a.max is not None and n >= a.max:
            break
    return EXIT_OK


def _cmd_campbell(c, a):
    try:
        speeds = parse_speeds(a.speeds) if a.speeds else None
        rpm = parse_speeds(a.rpm) if a.rpm else None
    except ValueError as e:
        print("campbell: --%s: %s" % ("speeds" if a.speeds else "rpm", e), file=sys.stderr)
        return EXIT_USAGE
    if speeds is not None and rpm is not None:
        print("campbell: give --speeds (rad/s) or --rpm (rev/min), not both", file=sys.stderr)
        return EXIT_USAGE
    body = _read_request(a.request)
    try:
        request = json.loads(body.decode("utf-8"))
    except ValueError as e:
        print("spinmodal: %s is not JSON: %s" % (a.request, e), file=sys.stderr)
        return EXIT_INVALID
    rows = c.campbell(request, speeds=speeds, rpm=rpm, timeout=a.timeout)
    key = "frequency_hz" if a.hz else "frequency_rad_s"
    if a.csv:
        w = _csv.writer(sys.stdout, lineterminator="\n")
        w.writerow(["omega", "mode", "frequency_rad_s", "frequency_hz", "status"])
        for r in rows:
            w.writerow(["" if r[k] is None else repr(r[k]) if isinstance(r[k], float) else r[k]
                        for k in ("omega", "mode", "frequency_rad_s", "frequency_hz", "status")])
        return EXIT_OK if all(r["status"] != "no_equilibrium" for r in rows) else EXIT_FAILED
    # one line per speed, one column per mode
    by_speed, order = {}, []
    for r in rows:
        if r["omega"] not in by_speed:
            order.append(r["omega"])
            by_speed[r["omega"]] = {"status": r["status"], "f": {}}
        if r["mode"] is not None:
            by_speed[r["omega"]]["f"][r["mode"]] = r[key]
    nmodes = max([m for s in by_speed.values() for m in s["f"]] or [0])
    unit = "Hz" if a.hz else "rad/s"
    print("%10s  %-14s" % ("omega", "status") + "".join("%14s" % ("mode %d" % m) for m in range(1, nmodes + 1))
          + "   (frequencies in %s)" % unit)
    for om in order:
        s = by_speed[om]
        cells = "".join("%14s" % ("" if s["f"].get(m) is None else "%.6g" % s["f"][m])
                        for m in range(1, nmodes + 1))
        print("%10.4g  %-14s" % (om, s["status"]) + cells)
    return EXIT_OK if all(s["status"] != "no_equilibrium" for s in by_speed.values()) else EXIT_FAILED


def _parser():
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--url", default=os.environ.get("SPINMODAL_URL") or DEFAULT_URL,
                        help="daemon base URL (default $SPINMODAL_URL or %s)" % DEFAULT_URL)
    common.add_argument("--token", default=os.environ.get("SPINMODAL_TOKEN") or None,
                        help="bearer token for POST/DELETE (default $SPINMODAL_TOKEN)")
    common.add_argument("--pretty", action="store_true", help="indent JSON output")

    p = _Parser(prog="python3 -m spinmodal_client",
                description="Client of the spinmodald HTTP API (server/DAEMON.md).",
                epilog="exit codes: 0 ok, 1 job failed or canceled, 2 invalid request "
                       "(400/413/415/422), 3 connection, server or other HTTP error, 64 usage")
    sub = p.add_subparsers(dest="cmd", metavar="COMMAND", parser_class=_Parser)

    s = sub.add_parser("solve", parents=[common], help="submit a request, wait, print the result")
    s.add_argument("request", help="request JSON file ('-' for stdin)")
    fmt = s.add_mutually_exclusive_group()
    fmt.add_argument("--csv", action="store_true", help="print the frequency CSV instead of JSON")
    fmt.add_argument("--table", action="store_true",
                     help="print an aligned table: speed (rad/s, rpm), mode, frequency in rad/s, Hz "
                          "and per revolution, status")
    fmt.add_argument("--spanwise", action="store_true",
                     help="print the span-wise mode shapes (flap, edge, twist and slopes) as CSV "
                          "(spatial requests with mode_shapes)")
    fmt.add_argument("--bmodes", action="store_true",
                     help="print the span-wise mode shapes as a BModes-style table")
    s.add_argument("--timeout", type=float, default=None,
                   help="give up waiting after S seconds (exit 3; the job keeps running)")
    s.set_defaults(func=_cmd_solve)

    s = sub.add_parser("import", parents=[common],
                       help="turn a blade file into a request (POST /v1/import/FORMAT); print it")
    s.add_argument("format", choices=["bmodes", "elastodyn", "csv"])
    s.add_argument("file", help="the .bmi, ElastoDyn blade file or CSV")
    s.add_argument("--sec-props", help="BModes section-properties file (default: the one the "
                                       ".bmi names, next to it)")
    s.add_argument("--tip-radius", type=float, help="m from the spin axis (ElastoDyn, CSV)")
    s.add_argument("--hub-radius", type=float, help="m")
    s.add_argument("--rpm", metavar="SPEEDS",
                   help="rotor speeds, rev/min (override the file's): 12.1, a list 0,5,10 or "
                        "START:STOP:COUNT (COUNT speeds, both ends included: 0:15:16)")
    s.add_argument("--bmodes-mesh", type=int, metavar="K",
                   help="BModes: BModes' own model (its elements as uniform members with "
                        "midpoint properties), K FE elements each")
    s.add_argument("--full", action="store_true",
                   help="print the whole import document {request, warnings, input_warnings, "
                        "source}")
    s.set_defaults(func=_cmd_import)

    s = sub.add_parser("validate", parents=[common],
                       help="validate a request (nothing is stored); print the canonical form and id")
    s.add_argument("request", help="request JSON file ('-' for stdin)")
    s.set_defaults(func=_cmd_validate)

    s = sub.add_parser("status", parents=[common], help="print the status document of a job")
    s.add_argument("id")
    s.set_defaults(func=_cmd_status)

    s = sub.add_parser("cancel", parents=[common], help="cancel a queued or running job")
    s.add_argument("id")
    s.set_defaults(func=_cmd_cancel)

    s = sub.add_parser("list", parents=[common], help="list jobs, newest first")
    s.add_argument("--state", choices=["queued", "running", "done", "failed", "canceled"])
    s.add_argument("--limit", type=int, default=20, help="jobs per page (1...100, default 20)")
    s.add_argument("--max", type=int, default=None, help="stop after N jobs")
    s.add_argument("--json", action="store_true", help="one status document per line")
    s.set_defaults(func=_cmd_list)

    s = sub.add_parser("campbell", parents=[common],
                       help="sweep speeds and print the frequencies (a Campbell table)")
    s.add_argument("request", help="request JSON file ('-' for stdin)")
    s.add_argument("--speeds", help="rad/s: START:STOP:COUNT (e.g. 0:20:21) or a list 0,5,10; "
                                    "default: the request's own speeds")
    s.add_argument("--rpm", help="rev/min instead: START:STOP:COUNT (e.g. 0:15:16) or a list")
    s.add_argument("--hz", action="store_true", help="frequencies in Hz (default rad/s)")
    s.add_argument("--csv", action="store_true", help="CSV rows instead of a table")
    s.add_argument("--timeout", type=float, default=None, help="give up waiting after S seconds")
    s.set_defaults(func=_cmd_campbell)
    return p


def main(argv=None):
    p = _parser()
    a = p.parse_args(argv)
    if not getattr(a, "func", None):
        p.print_usage(sys.stderr)
        return EXIT_USAGE
    c = Client(a.url, token=a.token)
    try:
        return a.func(c, a)
    except SpinmodalJobError as e:
        print("spinmodal: %s" % e, file=sys.stderr)
        return EXIT_FAILED
    except SpinmodalError as e:
        print("spinmodal: %s" % e, file=sys.stderr)
        if e.body and e.status is not None and e.body.lstrip().startswith("{"):
            print(e.body.strip(), file=sys.stderr)
        return EXIT_INVALID if e.invalid_request else EXIT_ERROR
    except TimeoutError as e:
        print("spinmodal: %s" % e, file=sys.stderr)
        return EXIT_ERROR
    except _RequestFileError as e:
        print("spinmodal: %s" % e, file=sys.stderr)
        return EXIT_INVALID
    except BrokenPipeError:         # e.g. piped into head
        try:
            sys.stdout = open(os.devnull, "w")
        except OSError:
            pass
        return EXIT_OK
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
