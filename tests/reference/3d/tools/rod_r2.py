#!/usr/bin/env python3
"""R2 of ../cases.json from the independent discrete rod (rod.py): the six lowest frequencies
without and with Coriolis (translational gyroscopic terms) and the steady tip P, per speed.

  /usr/bin/python3 rod_r2.py NE > r2_rod_NE.json      # NE segments per member (the table: 48)

Needs Debian's python3-numpy and python3-scipy.  About 10 minutes at 48 on one core."""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rod import Rod  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
case = json.load(open(os.path.join(here, "..", "cases.json")))["R2"]
ne = int(sys.argv[1]) if len(sys.argv) > 1 else 48
st = case["request"]["structure"]
rod = Rod(st["joints"], st["sections"], st["members"], st["clamp"], ne=ne)
out = []
for w in (0.0, 5.0, 10.0, 15.0, 20.0):
    res = rod.solve(w)
    fp, neg, _ = rod.freqs(w, False)
    fc = rod.freqs(w, True)[0] if w > 0 else fp
    out.append(dict(omega=w, w_plain=[float("%.6g" % x) for x in fp], w_coriolis=[float("%.6g" % x) for x in fc],
                    tip=[float("%.6f" % x) for x in rod.tip(case["tip_joint"])], negative_eigenvalues=neg,
                    residual=res))
    print(json.dumps(out[-1]), file=sys.stderr, flush=True)
json.dump(out, sys.stdout, indent=1)
