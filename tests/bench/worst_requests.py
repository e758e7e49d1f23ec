#!/usr/bin/env python3
"""worst_requests.py SPINMODALD -- the heaviest requests the daemon's default flags allow (issue 23,
DESIGN F: no request above 30 s of worker time or 500 MB): starts SPINMODALD on a scratch SQLite
file (port 18777, one worker), submits each request, and prints its outcome, how long its job ran
(finished_at - started_at) and the daemon's peak RSS (VmHWM).  A measurement, not a test:
OPENBLAS_NUM_THREADS=1 python3 tests/bench/worst_requests.py build/server/spinmodald"""
import datetime
import json
import os
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

exe = sys.argv[1]; port = 18777
tmp = tempfile.mkdtemp(prefix="spinmodal-worst-")
d = subprocess.Popen([exe, "--db", os.path.join(tmp, "w.db"), "--listen", "127.0.0.1:%d" % port, "--workers", "1"],
                     stdout=open(os.path.join(tmp, "log"), "w"), stderr=subprocess.STDOUT)
time.sleep(1.5)
def hwm():
    for l in open("/proc/%d/status" % d.pid):
        if l.startswith("VmHWM"): return int(l.split()[1]) / 1024
def blade(ne, modes, omega, **a):
    an = {"omega": omega, "modes": modes, "mode_shapes": False}; an.update(a)
    return {"blade": {"length": 10.0, "hub_radius": 0.5, "elements": ne,
                      "section": {"EA": 2.8e7, "EI_flap": 1.4e4, "EI_edge": 5.6e4, "GJ": 1.3e4, "mass_per_length": 1.2}},
            "analysis": an}
def planar(ne, omega):
    return {"structure": {"joints": {"O": [0, 0], "T": [10, 0]}, "sections": {"s": {"E": 7e10, "A": 4e-4, "I": 2e-7, "mass_per_length": 1.2}},
            "members": [{"id": "m", "from": "O", "to": "T", "section": "s", "elements": ne}], "clamp": "O"},
            "analysis": {"omega": omega, "mode_shapes": False}}
cases = [
 ("dense path at its cap: 166-element blade, 70 modes, 16 speeds", blade(166, 70, [0.5 * i for i in range(16)])),
 ("dense path at its cap, 17 speeds (estimate past 30 s)", blade(166, 70, [0.5 * i for i in range(17)])),
 ("tree path: 2000-element blade, 64 modes, 10 speeds", blade(2000, 64, [1.0 * i for i in range(10)])),
 ("planar 2000 elements, 1001 speeds", planar(2000, [0.02 * i for i in range(1001)])),
 ("error estimate: 500-element blade, 6 modes, 40 speeds", blade(500, 6, [0.5 * i for i in range(40)], error_estimate=True)),
 ("largest result under 50 MB: 1000 elements, 20 modes, 7 speeds, shapes", blade(1000, 20, [1.0 * i for i in range(7)], mode_shapes=True)),
]
def ts(x): return datetime.datetime.strptime(x, "%Y-%m-%dT%H:%M:%S.%fZ").timestamp()
for name, req in cases:
    h0 = hwm(); t0 = time.monotonic()
    try:
        r = urllib.request.urlopen(urllib.request.Request("http://127.0.0.1:%d/v1/analyses" % port, data=json.dumps(req).encode(),
                                   headers={"Content-Type": "application/json"}))
        j = json.loads(r.read())
    except urllib.error.HTTPError as e:
        b = json.loads(e.read()); print("%-70s %d %s" % (name, e.code, b.get("errors", [{}])[0].get("message", "")[:160])); continue
    while True:
        s = json.loads(urllib.request.urlopen("http://127.0.0.1:%d/v1/analyses/%s" % (port, j["id"])).read())
        if s["state"] in ("done", "failed", "canceled"): break
        time.sleep(0.5)
    ran = ts(s["finished_at"]) - ts(s["started_at"])
    err = (s.get("error") or {}).get("type")
    print("%-70s %s%s ran %.1f s, speeds %s, daemon peak %.0f MB (before %.0f)" % (name, s["state"], "/" + err if err else "", ran,
          "%d/%d" % (s["progress"]["done"], s["progress"]["total"]), hwm(), h0), flush=True)
d.terminate(); d.wait()
