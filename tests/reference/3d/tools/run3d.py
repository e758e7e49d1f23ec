#!/usr/bin/python3
"""CalculiX (ccx 2.20, Debian calculix-ccx) reference cases for a 3D (flap / lead-lag /
torsion / axial) rotating-beam modal code.

Per run one deck with three steps (same approach as ../calculix/run_study.py):
  1 *STATIC, NLGEOM + *DLOAD CENTRIF (Omega^2, axis = global Z through the origin)
  2 *FREQUENCY, STORAGE=YES, PERTURBATION (prestress + spin softening)
  3 *COMPLEX FREQUENCY, CORIOLIS, PERTURBATION (modal basis = modes of step 2; Omega>0 only)
Beams are B32R, expanded by ccx into one C3D20R brick through the section.

Usage (from this folder):
  /usr/bin/python3 run3d.py run GROUP [GROUP ...]   # groups: see GROUPS below
  /usr/bin/python3 run3d.py one CASE OMEGA [NE] [TAG]
  /usr/bin/python3 run3d.py parse                   # re-parse runs/ -> results/*.csv
Writes decks/<run>.inp, runs/<run>/ (small .dat extract, .sta, log, json), results/*.csv.
"""
import os, re, sys, csv, json, time, math, subprocess
from concurrent.futures import ThreadPoolExecutor
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DECKS = os.path.join(HERE, 'decks')
RUNS = os.path.join(HERE, 'runs')
RES = os.path.join(HERE, 'results')
CCX = '/usr/bin/ccx'

E = 7.0e10
NU = 0.3
G = E / (2 * (1 + NU))
EZ = np.array([0.0, 0.0, 1.0])

# ------------------------------------------------------------------ sections
def rect_J(b, h):
    """St Venant torsion constant of a b x h rectangle (series, b >= h)"""
    if b < h: b, h = h, b
    s = 0.0
    for n in range(1, 60, 2):
        s += math.tanh(n * math.pi * b / (2 * h)) / n ** 5
    return b * h ** 3 / 3.0 * (1 - 192.0 / math.pi ** 5 * h / b * s)

def section(name):
    """returns dict: kind (RECT/CIRC), t1 (thickness along local 1 = flap direction),
    t2 (along local 2 = in-plane/edge direction), E, rho, A, I1 (bending about local 2,
    i.e. flap bending, = t2*t1^3/12), I2 (edge bending), J (exact St Venant), Ip, m"""
    if name == 'circR0':          # R0: EI = 1e8, m = 100 kg/m
        r = (4 * 1e8 / (math.pi * E)) ** 0.25
        A = math.pi * r * r; I = math.pi * r ** 4 / 4
        return dict(kind='CIRC', t1=2 * r, t2=2 * r, E=E, rho=100.0 / A, A=A, I1=I, I2=I, J=2 * I, Ip=2 * I, m=100.0, r=r)
    if name == 'circR0s':         # R0 slender equivalent: L/r = 250, m = EI/L^4 (so sqrt(EI/mL^4) = 1)
        L = 31.623; r = L / 250.0
        A = math.pi * r * r; I = math.pi * r ** 4 / 4
        m = E * I / L ** 4
        return dict(kind='CIRC', t1=2 * r, t2=2 * r, E=E, rho=m / A, A=A, I1=I, I2=I, J=2 * I, Ip=2 * I, m=m, r=r)
    if name == 'sqR0':            # R0 check: square with the same EI = 1e8 and m = 100 kg/m as the circle
        a = (12 * 1e8 / E) ** 0.25
        A = a * a; I = a ** 4 / 12
        return dict(kind='RECT', t1=a, t2=a, E=E, rho=100.0 / A, A=A, I1=I, I2=I, J=rect_J(a, a), Ip=2 * I, m=100.0, r=a / 2)
    if name == 'sq':              # R1/R2: square, E = 7e10, EI = 14000 both ways, m = 1.2 kg/m
        a = (12 * 2e-7) ** 0.25
        A = a * a; I = a ** 4 / 12
        return dict(kind='RECT', t1=a, t2=a, E=E, rho=1.2 / A, A=A, I1=I, I2=I, J=rect_J(a, a), Ip=2 * I, m=1.2)
    if name.startswith('sqE'):       # square with E scaled (mass per length kept)
        f = float(name[3:]); S = section('sq'); S['E'] = E * f; return S
    if name == 'sqKY':            # earlier planar study's 'square' (E' = E*b/h, keeps EA = 2.8e7)
        h = (12 * 2e-7 / 4e-4) ** 0.5; b = 4e-4 / h
        Em = E * b / h; A = h * h; I = h ** 4 / 12
        return dict(kind='RECT', t1=h, t2=h, E=Em, rho=1.2 / A, A=A, I1=I, I2=I, J=rect_J(h, h), Ip=2 * I, m=1.2)
    if name == 'rect':            # R3: 0.06 (edge, in-plane) x 0.02 (flap), m = 3 kg/m
        b, h = 0.06, 0.02
        A = b * h
        return dict(kind='RECT', t1=h, t2=b, E=E, rho=3.0 / A, A=A, I1=b * h ** 3 / 12, I2=h * b ** 3 / 12,
                    J=rect_J(b, h), Ip=(b * h ** 3 + h * b ** 3) / 12, m=3.0)
    if name == 'rectA':           # PB arm: the 'rect' geometry (so no knot at the arm/blade joint) with
        S = section('rect')       # E x 5 (EI_flap = 14000 as 'sq') and 1.2 kg/m
        S['E'] = 5 * E; S['m'] = 1.2; S['rho'] = 1.2 / S['A']; return S
    raise ValueError(name)

# ------------------------------------------------------------------ cases
def unit(v):
    v = np.asarray(v, float); return v / np.linalg.norm(v)

def flapdir(t):
    """local 1 (flap) direction: projection of global Z normal to t; for members parallel to Z: global Y"""
    f = EZ - np.dot(EZ, t) * t
    if np.linalg.norm(f) < 0.3:
        f = np.array([0.0, 1.0, 0.0]) - np.dot([0.0, 1.0, 0.0], t) * t
    return unit(f)

def member_n1(m, t):
    """flap axis (local 1) of an element with tangent t: the member's explicit 'n1' (made normal to t)
    if given, else the default flapdir(t). An explicit, continuous n1 along a filleted path avoids the
    knot ccx generates where the local axes of consecutive elements jump (e.g. the default switching
    to global Y near a member parallel to Z)."""
    if m.get('n1') is None:
        return flapdir(t)
    n = np.asarray(m['n1'], float)
    return unit(n - np.dot(n, t) * t)

def fillet_path(pts, rf, secs, ne, narc, n1s=None):
    """members along the polyline pts with a circular fillet of radius rf at every interior corner.
    secs: section per straight segment (an arc takes the section of the segment before it);
    n1s: explicit flap axis per segment (None = default); an arc uses the normal of its plane
    (= d1 x d2) when both adjoining segments use it, else the segment's own n1 / default."""
    pts = [np.array(p, float) for p in pts]
    nseg = len(pts) - 1
    n1s = n1s or [None] * nseg
    starts = [pts[0]]; ends = []; arcs = []
    for k in range(1, nseg):
        d1 = unit(pts[k] - pts[k - 1]); d2 = unit(pts[k + 1] - pts[k])
        th = math.acos(max(-1.0, min(1.0, float(np.dot(d1, d2)))))
        tl = rf * math.tan(th / 2)
        a = pts[k] - tl * d1; b = pts[k] + tl * d2
        nvec = unit(d2 - np.dot(d1, d2) * d1)
        c = a + rf * nvec
        u, v = -nvec, d1
        q = c + rf * (math.cos(th) * u + math.sin(th) * v)
        assert np.allclose(q, b, atol=1e-9), (q, b)
        ends.append(a); starts.append(b)
        arcs.append(dict(arc=(tuple(c), rf, 0.0, th), plane=(tuple(u), tuple(v)), sec=secs[k - 1], ne=narc,
                         n1=n1s[k - 1] if n1s[k - 1] is not None else None))
    ends.append(pts[-1])
    mem = []
    for k in range(nseg):
        mem.append(dict(p0=tuple(starts[k]), p1=tuple(ends[k]), sec=secs[k], ne=ne, n1=n1s[k]))
        if k < nseg - 1: mem.append(arcs[k])
    return mem

# new out-of-plane cases (group 'oop'): knot-free filleted paths, see ../OOP.md
OOP = {
    # name: (polyline, fillet radius, sections per segment, explicit n1 per segment, speeds)
    'R2F': ([(0.5, 0, 0), (3.5, 0, 0), (3.5, 0, 2)], 0.4, ['sq', 'sq'], [(0, 1, 0)] * 2, [0, 10, 15, 20]),
    'HM': ([(0.5, 0, 0), (3.0, 0, 0), (3.0, 0, -2.5)], 0.4, ['sq', 'sq'], [(0, 1, 0)] * 2, [0, 8, 12, 16]),
    'SK': ([(0.5, 0, 0), (3.0, 0, 0), (3.0, 1.2, 1.6)], 0.4, ['sq', 'sq'], [(0, -0.8, 0.6)] * 2, [0, 12, 16, 20]),
    'PB': ([(0.5, 0, 0), (2.5, 0, 0), (2.5 + 8 * math.cos(math.radians(15)), 0, 8 * math.sin(math.radians(15)))],
           0.4, ['rectA', 'rect'], [None, None], [0, 1, 2, 4]),
    # PBK: PB with the square arm: the section change sq -> rect makes ccx generate a knot at the
    # arm/blade joint (not a reference; run to show the knot's effect)
    'PBK': ([(0.5, 0, 0), (2.5, 0, 0), (2.5 + 8 * math.cos(math.radians(15)), 0, 8 * math.sin(math.radians(15)))],
           0.4, ['sq', 'rect'], [None, None], [0, 1, 2, 4]),
    'MA': ([(0, 0, 0), (0, 0, 2), (3, 0, 2)], 0.4, ['sq', 'sq'], [(0, 1, 0)] * 2, [0, 15, 20, 25]),
}

# spinmodal sections (DESIGN.md spatial form); GJ = the effective GJ of ../README.md
SPIN_SECTIONS = {
    'sq': dict(EA=1.08444e8, EI_flap=14000.0, EI_edge=14000.0, GJ=10758.0, mass_per_length=1.2,
               flap_inertia=1.549e-4, edge_inertia=1.549e-4),
    'rect': dict(EA=8.4e7, EI_flap=2800.0, EI_edge=25200.0, GJ=3883.0, mass_per_length=3.0,
                 flap_inertia=1e-4, edge_inertia=9e-4),
    'rectA': dict(EA=4.2e8, EI_flap=14000.0, EI_edge=126000.0, GJ=5 * 3883.0, mass_per_length=1.2,
                  flap_inertia=4e-5, edge_inertia=3.6e-4),
}

def spin_request(case, ne=24, arcmode='ends', omegas=None, coriolis=True):
    """the spinmodal request for an OOP case: straight members with ne elements; every ccx arc
    element becomes one straight member joining its end points (arcmode 'ends') or two joining its
    three nodes ('nodes'), one element each; flap_direction = the ccx element's local 1 axis."""
    d = build_case(case, ne)
    nodes, index, elems = mesh(d)
    joints = {}; names = {}
    def jname(p):
        k = tuple(round(float(x), 9) for x in p)
        if k not in names:
            names[k] = 'J%d' % len(names)
            joints[names[k]] = [round(float(x), 12) + 0.0 for x in p]
        return names[k]
    members = []; secs = {}
    for im, m in enumerate(d['members']):
        secs[m['sec']] = SPIN_SECTIONS[m['sec']]
        if 'arc' in m:
            for eid, jm, (a, b, c), t, n1 in elems:
                if jm != im: continue
                pp = [nodes[a - 1], nodes[c - 1]] if arcmode == 'ends' else [nodes[a - 1], nodes[b - 1], nodes[c - 1]]
                for p0, p1 in zip(pp[:-1], pp[1:]):
                    members.append({'id': 'm%d' % (len(members) + 1), 'from': jname(p0), 'to': jname(p1), 'section': m['sec'],
                                    'elements': 1, 'flap_direction': [round(float(x), 12) for x in member_n1(m, unit(p1 - p0))]})
        else:
            p0, p1 = np.array(m['p0'], float), np.array(m['p1'], float)
            members.append({'id': 'm%d' % (len(members) + 1), 'from': jname(p0), 'to': jname(p1), 'section': m['sec'],
                            'elements': m['ne'], 'flap_direction': [round(float(x), 12) for x in member_n1(m, unit(p1 - p0))]})
    tip = jname(d['tip'])
    req = {'structure': {'joints': joints, 'sections': secs, 'members': members, 'clamp': jname(d['clamp'])},
           'frames': 'per_element',
           'analysis': {'omega': [float(w) for w in (omegas if omegas is not None else d['omegas'])], 'modes': 10,
                        'coriolis': coriolis}}
    return req, tip

def oop_case(case, ne):
    pts, rf, secs, n1s, oms = OOP[case]
    narc = max(12, ne // 2)
    d = dict(case=case, masses=[], twist=None, members=fillet_path(pts, rf, secs, ne, narc, n1s),
             clamp=tuple(pts[0]), tip=tuple(pts[-1]), omegas=oms, fillet=rf, path=pts)
    return d

def build_case(case, ne=24, variant=''):
    if case in OOP:
        d = oop_case(case, ne)
        for m in d['members']:
            m.setdefault('ne', ne); m.setdefault('twist', None)
        return d
    m_f = re.search(r'_fil(\d+)', variant)
    if case in ('R1', 'R1KY') and m_f:
        rf = int(m_f.group(1)) / 1000.0; s = 'sq' if case == 'R1' else 'sqKY'
        nf = max(4, int(round(ne / 4)))
        d = dict(case=case, masses=[], twist=None)
        d['members'] = [dict(p0=(0, 0, 0), p1=(5 - rf, 0, 0), sec=s),
                        dict(arc=((5 - rf, rf, 0), rf, -math.pi / 2, 0.0), sec=s, ne=nf),
                        dict(p0=(5, rf, 0), p1=(5, 5, 0), sec=s)]
        d['clamp'] = (0, 0, 0); d['tip'] = (5, 5, 0); d['omegas'] = [0, 10, 20]; d['fillet'] = rf
        for m in d['members']:
            m.setdefault('ne', ne); m.setdefault('twist', None)
        return d
    """members: list of dict(p0, p1, ne, sec, twist0_deg, twist1_deg); masses: [(point, kg)];
    clamp point; tip point(s)"""
    d = dict(case=case, masses=[], twist=None)
    if case in ('R0', 'R0s', 'R0q'):
        d['members'] = [dict(p0=(0, 0, 0), p1=(31.623, 0, 0), sec={'R0': 'circR0', 'R0s': 'circR0s', 'R0q': 'sqR0'}[case])]
        d['clamp'] = (0, 0, 0); d['tip'] = (31.623, 0, 0); d['omegas'] = [0, 4, 8, 12]
    elif case in ('R1', 'R1KY'):
        s = 'sq' if case == 'R1' else 'sqKY'
        d['members'] = [dict(p0=(0, 0, 0), p1=(5, 0, 0), sec=s), dict(p0=(5, 0, 0), p1=(5, 5, 0), sec=s)]
        d['clamp'] = (0, 0, 0); d['tip'] = (5, 5, 0); d['omegas'] = [0, 10, 20]
    elif case == 'T0':            # calibration: straight square cantilever (torsion constant)
        d['members'] = [dict(p0=(0, 0, 0), p1=(5, 0, 0), sec='sq')]
        d['clamp'] = (0, 0, 0); d['tip'] = (5, 0, 0); d['omegas'] = [0]
    elif case == 'R2':
        d['members'] = [dict(p0=(0.5, 0, 0), p1=(3.5, 0, 0), sec='sq'), dict(p0=(3.5, 0, 0), p1=(3.5, 0, 2), sec='sq')]
        d['clamp'] = (0.5, 0, 0); d['tip'] = (3.5, 0, 2); d['omegas'] = [0, 5, 10, 15, 20]
    elif case == 'M1':
        d['members'] = [dict(p0=(3.5, 0, 0), p1=(3.5, 0, 2), sec='sq')]
        d['clamp'] = (3.5, 0, 0); d['tip'] = (3.5, 0, 2); d['omegas'] = [0, 10, 15, 20]
    elif case == 'M2':
        d['members'] = [dict(p0=(3.5, 0, 0), p1=(3.5, 0, 5), sec='sq')]
        d['clamp'] = (3.5, 0, 0); d['tip'] = (3.5, 0, 5); d['omegas'] = [0, 5, 10, 15]
    elif case.startswith('R2a') or case.startswith('R2b'):   # R2 with member 1 (a) or the mast (b) stiffened
        f = case[3:]
        s1, s2 = ('sqE' + f, 'sq') if case[2] == 'a' else ('sq', 'sqE' + f)
        d['members'] = [dict(p0=(0.5, 0, 0), p1=(3.5, 0, 0), sec=s1), dict(p0=(3.5, 0, 0), p1=(3.5, 0, 2), sec=s2)]
        d['clamp'] = (0.5, 0, 0); d['tip'] = (3.5, 0, 2); d['omegas'] = [0, 5, 10, 15, 20]
    elif case.startswith('R2f'):   # R2 with a fillet of radius rf mm at C in the X-Z plane
        rf = int(case[3:]) / 1000.0; nf = max(4, int(round(ne / 4))) if rf < 0.3 else max(8, int(round(ne / 2)))
        d['members'] = [dict(p0=(0.5, 0, 0), p1=(3.5 - rf, 0, 0), sec='sq'),
                        dict(arc=((3.5 - rf, 0, rf), rf, -math.pi / 2, 0.0), plane=((1, 0, 0), (0, 0, 1)), sec='sq', ne=nf),
                        dict(p0=(3.5, 0, rf), p1=(3.5, 0, 2), sec='sq')]
        d['clamp'] = (0.5, 0, 0); d['tip'] = (3.5, 0, 2); d['omegas'] = [0, 5, 10, 15, 20]
    elif case == 'R3':
        c, s = math.cos(math.radians(10)), math.sin(math.radians(10))
        d['members'] = [dict(p0=(1, 0, 0), p1=(1 + 10 * c, 0, 10 * s), sec='rect')]
        d['clamp'] = (1, 0, 0); d['tip'] = (1 + 10 * c, 0, 10 * s); d['omegas'] = [0, 5, 10, 15]
    else:
        raise ValueError(case)
    for m in d['members']:
        m.setdefault('ne', ne); m.setdefault('twist', None)
    return d

CTRL_A = '50,60,61,300,100,8,12,20,400,10'
FIELD_TIGHT = '1e-4,1e-4,0.01,,1e-4,1e-5,1e-3,1e-8'

def mesh(d):
    nodes = []; index = {}
    def node(p):
        key = tuple(round(float(x), 9) for x in p)
        if key not in index:
            nodes.append(np.array(p, float)); index[key] = len(nodes)
        return index[key]
    elems = []   # (eid, member, (n0, nm, n1), t, n1dir)
    for im, m in enumerate(d['members']):
        if 'arc' in m:   # circular fillet in the X-Y plane: centre c, radius R, angles a0 -> a1 (rad)
            c, R, a0, a1 = m['arc']; ne = m['ne']
            au, av = np.array(m.get('plane', ((1, 0, 0), (0, 1, 0)))[0], float), np.array(m.get('plane', ((1, 0, 0), (0, 1, 0)))[1], float)
            pts = [np.array(c, float) + R * (math.cos(a0 + (a1 - a0) * k / (2 * ne)) * au + math.sin(a0 + (a1 - a0) * k / (2 * ne)) * av)
                   for k in range(2 * ne + 1)]
            ids = [node(q) for q in pts]
            for e in range(ne):
                t = unit(pts[2 * e + 2] - pts[2 * e])
                elems.append((len(elems) + 1, im, (ids[2 * e], ids[2 * e + 1], ids[2 * e + 2]), t, member_n1(m, t)))
            continue
        p0 = np.array(m['p0'], float); p1 = np.array(m['p1'], float); ne = m['ne']
        t = unit(p1 - p0)
        f0 = member_n1(m, t)
        ids = [node(p0 + (p1 - p0) * k / (2 * ne)) for k in range(2 * ne + 1)]
        for e in range(ne):
            if m['twist']:
                th = math.radians(m['twist'][0] + (m['twist'][1] - m['twist'][0]) * (e + 0.5) / ne)
                # right-handed rotation of the flap axis about the member tangent t
                n1 = f0 * math.cos(th) + np.cross(t, f0) * math.sin(th)
            else:
                n1 = f0
            elems.append((len(elems) + 1, im, (ids[2 * e], ids[2 * e + 1], ids[2 * e + 2]), t, n1))
    return nodes, index, elems

def make_deck(d, Om, nmodes, ncmodes, title='', symdof=None, etype='B32R', n1ip=False, inplane_only=False):
    nodes, index, elems = mesh(d)
    if n1ip:   # variant: local 1 = in-plane normal (flap thickness then lies along local 2)
        elems = [(eid, im, ns, t, unit(np.cross(t, n1))) for eid, im, ns, t, n1 in elems]
    key = lambda p: index[tuple(round(float(x), 9) for x in p)]
    o = ['*HEADING', '%s Omega=%g rad/s %s' % (d['case'], Om, title),
         '** units SI (m, kg, s, N, Pa); rotation axis = global Z through the origin; generated by run3d.py',
         '*NODE, NSET=NALL']
    for k, p in enumerate(nodes):
        o.append('%d, %.12g, %.12g, %.12g' % (k + 1, p[0], p[1], p[2]))
    secs = {}
    for eid, im, (a, b, c), t, n1 in elems:
        o.append('*ELEMENT, TYPE=%s, ELSET=E%04d\n%d, %d, %d, %d' % (etype, eid, eid, a, b, c))
    o.append('*ELSET, ELSET=EBEAM')
    o += ['E%04d,' % e[0] for e in elems]
    mats = []
    for eid, im, _, t, n1 in elems:
        sname = d['members'][im]['sec']; S = section(sname)
        if sname not in mats:
            mats.append(sname)
            o.append('*MATERIAL, NAME=M_%s\n*ELASTIC\n%.10g, %g\n*DENSITY\n%.10g' % (sname, S['E'], NU, S['rho']))
        t1, t2 = (S['t2'], S['t1']) if n1ip else (S['t1'], S['t2'])
        o.append('*BEAM SECTION, ELSET=E%04d, MATERIAL=M_%s, SECTION=%s\n%.10g, %.10g\n%.12g, %.12g, %.12g'
                 % (eid, sname, S['kind'], t1, t2, n1[0], n1[1], n1[2]))
    eall = ['EBEAM']
    for i, (p, mass) in enumerate(d['masses']):
        eid = 900001 + i
        o.append('*ELEMENT, TYPE=MASS, ELSET=EMASS%d\n%d, %d' % (i, eid, key(p)))
        o.append('*MASS, ELSET=EMASS%d\n%.10g' % (i, mass))
        eall.append('EMASS%d' % i)
    o.append('*ELSET, ELSET=EALL\n' + ', '.join(eall))
    o.append('*NSET, NSET=NROOT\n%d' % key(d['clamp']))
    o.append('*NSET, NSET=NTIP\n%d' % key(d['tip']))
    o.append('** clamp: all 6 dofs of the root beam node')
    o.append('*BOUNDARY\nNROOT, 1, 6')
    if inplane_only:
        o.append('** IN-PLANE-ONLY ANCHOR MODEL (as in ../calculix): dof 3 of every beam node fixed in all steps')
        o.append('*BOUNDARY\nNALL, 3, 3')
    if symdof:
        o.append('*NSET, NSET=NSYM')
        o += ['%d,' % k for k in range(1, len(nodes) + 1) if k != key(d['clamp'])]
    o.append('*STEP, NLGEOM, INC=10000')
    o.append('*STATIC\n%g, 1.0, 1e-7, %g' % (0.02, 0.25))
    o.append('*CONTROLS, PARAMETERS=TIME INCREMENTATION\n%s' % CTRL_A)
    o.append('*CONTROLS, PARAMETERS=FIELD\n%s' % FIELD_TIGHT)
    if Om > 0:
        o.append('*DLOAD\nEALL, CENTRIF, %.10g, 0., 0., 0., 0., 0., 1.' % (Om ** 2))
    if symdof:
        o.append('** static step only: mirror-symmetry constraint (dof %d of every beam node); the steady' % symdof)
        o.append('** state is exactly symmetric, so this carries ~zero reaction (checked via RF below)')
        o.append('*BOUNDARY\nNSYM, %d, %d' % (symdof, symdof))
        o.append('*NODE PRINT, NSET=NSYM\nRF')
    o.append('*NODE PRINT, NSET=NALL\nU')
    o.append('*NODE FILE\nU')
    o.append('*END STEP')
    o.append('*STEP, PERTURBATION')
    o.append('*FREQUENCY, STORAGE=YES\n%d' % nmodes)
    if symdof:
        o.append('** release the symmetry constraint: only the clamp remains')
        o.append('*BOUNDARY, OP=NEW\nNROOT, 1, 6')
    o.append('*NODE FILE\nU')
    o.append('*END STEP')
    if Om > 0 and ncmodes:
        o.append('*STEP, PERTURBATION')
        o.append('*COMPLEX FREQUENCY, CORIOLIS\n%d' % ncmodes)
        o.append('*NODE PRINT, NSET=NTIP\nU')
        o.append('*END STEP')
    return '\n'.join(o) + '\n', nodes, elems

# ------------------------------------------------------------------ parsing
FLT = r'[-+]?\d*\.\d+(?:[EeDd][-+]?\d+)?'

def ffloat(x):
    try:
        return float(x)
    except ValueError:
        m = re.match(r'^([-+]?\d*\.\d+)([-+]\d+)$', x.replace('D', 'E').replace('d', 'e'))
        if m: return float(m.group(1) + 'E' + m.group(2))
        raise

def parse_dat(path):
    if not os.path.exists(path) and os.path.exists(path + '.gz'):
        import gzip
        lines = gzip.open(path + '.gz', 'rt').read().splitlines()
    else:
        lines = open(path).read().splitlines()
    idx = [i for i, l in enumerate(lines) if 'E I G E N V A L U E   O U T P U T' in l]
    stat_end = idx[0] if idx else len(lines)
    out = {}
    last = None; i = 0
    while i < stat_end:
        m = re.search(r'displacements \(vx,vy,vz\) for set NALL and time\s+(' + FLT + ')', lines[i])
        if m:
            t = float(m.group(1)); dd = {}; j = i + 2
            while j < stat_end and lines[j].strip():
                p = lines[j].split(); dd[int(p[0])] = [ffloat(v) for v in p[1:4]]; j += 1
            last = (t, dd); i = j
        else:
            i += 1
    if last:
        out['static_time'], out['static_disp'] = last
    freq = []
    if idx:
        j = idx[0] + 1
        while j < len(lines) and 'P A R T I C' not in lines[j] and 'S T E P' not in lines[j]:
            p = lines[j].split()
            if len(p) == 5 and p[0].isdigit():
                ev, wr, fc, wi = map(ffloat, p[1:])
                freq.append(dict(mode=int(p[0]), eig=ev, w=wr if ev >= 0 else -wi))
            j += 1
    out['freq'] = freq
    rf = [i for i, l in enumerate(lines[:stat_end]) if 'forces (fx,fy,fz) for set NSYM' in l]
    if rf:
        k = rf[-1] + 2; mx = np.zeros(3)
        while k < stat_end and lines[k].strip():
            mx = np.maximum(mx, np.abs([ffloat(v) for v in lines[k].split()[1:4]])); k += 1
        out['nsym_total_rf'] = mx.tolist()
    cplx = []
    if len(idx) > 1:
        j = idx[1] + 1
        while j < len(lines) and 'P A R T I C' not in lines[j]:
            p = lines[j].split()
            if len(p) == 4 and p[0].isdigit():
                cplx.append(dict(mode=int(p[0]), w=ffloat(p[1]), imag=ffloat(p[3])))
            j += 1
        cur = None
        for j in range(idx[1], len(lines)):
            m = re.search(r'P A R T I C I P A T I O N   F A C T O R S   F O R   M O D E\s+(\d+)', lines[j])
            if m:
                cur = int(m.group(1)); pf = {}
                if cur - 1 < len(cplx): cplx[cur - 1]['pf'] = pf
                continue
            if cur is not None:
                p = lines[j].split()
                if len(p) == 4 and p[0].isdigit():
                    pf[int(p[0])] = complex(ffloat(p[2]), ffloat(p[3]))
    out['cplx'] = cplx
    return out

def parse_frd(path):
    """returns coords {node: xyz}, list of DISP blocks [(header, {node: u})]"""
    coords = {}; blocks = []; elnodes = set()
    with open(path) as fh:
        mode = None; cur = None; hdr = ''
        for line in fh:
            if line.startswith('    2C'):
                mode = 'coord'; continue
            if line.startswith('    3C'):
                mode = 'elem'; continue
            if mode == 'elem' and line.startswith(' -2'):
                elnodes.update(int(line[3 + 10 * i:13 + 10 * i]) for i in range((len(line.rstrip()) - 3) // 10))
                continue
            if line.startswith('  100CL'):
                hdr = line.rstrip(); continue
            if line.startswith(' -4  DISP'):
                mode = 'disp'; cur = {}; blocks.append((hdr, cur)); continue
            if line.startswith(' -3'):
                mode = None; continue
            if mode == 'coord' and line.startswith(' -1'):
                n = int(line[3:13]); coords[n] = np.array([ffloat(line[13:25]), ffloat(line[25:37]), ffloat(line[37:49])])
            elif mode == 'disp' and line.startswith(' -1'):
                n = int(line[3:13]); cur[n] = np.array([ffloat(line[13:25]), ffloat(line[25:37]), ffloat(line[37:49])])
    coords = {n: x for n, x in coords.items() if n in elnodes}
    return coords, blocks

# ------------------------------------------------------------------ post-processing
def section_groups(nodes, coords):
    """assign every expanded node (number > number of beam nodes) to the nearest beam node"""
    nb = len(nodes); B = np.array(nodes)
    groups = {k: [] for k in range(1, nb + 1)}
    for n, x in coords.items():
        if n <= nb: continue
        k = int(np.argmin(np.sum((B - x) ** 2, axis=1))) + 1
        groups[k].append(n)
    return groups

def rigid_fit(X, U):
    """least squares u_i = u0 + th x (X_i - Xc); returns u0 (at centroid), th"""
    Xc = X.mean(axis=0); R = X - Xc
    A = np.zeros((3 * len(X), 6)); b = U.reshape(-1)
    for i, r in enumerate(R):
        A[3 * i:3 * i + 3, :3] = np.eye(3)
        # th x r = -[r]x th
        A[3 * i:3 * i + 3, 3:] = -np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    sol = np.linalg.lstsq(A, b, rcond=None)[0]
    return sol[:3], sol[3:]

def kabsch(X, Y):
    """rotation R with Y - Yc ~ R (X - Xc); returns rotation vector (rad)"""
    Xc = X - X.mean(0); Yc = Y - Y.mean(0)
    H = Xc.T @ Yc; U, S, Vt = np.linalg.svd(H)
    dsign = np.sign(np.linalg.det(Vt.T @ U.T))
    R = Vt.T @ np.diag([1, 1, dsign]) @ U.T
    ang = math.acos(max(-1.0, min(1.0, (np.trace(R) - 1) / 2)))
    if ang < 1e-12: return np.zeros(3)
    ax = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / (2 * math.sin(ang))
    return ax * ang

def node_frames(d, nodes, elems, pos):
    """per beam node: tangent (from current positions pos), flap dir, lag dir, mass & polar inertia weights"""
    nb = len(nodes)
    w = np.zeros(nb + 1); wp = np.zeros(nb + 1); tan = np.zeros((nb + 1, 3)); cnt = np.zeros(nb + 1)
    for eid, im, (a, b, c), t, n1 in elems:
        S = section(d['members'][im]['sec'])
        le = np.linalg.norm(nodes[c - 1] - nodes[a - 1])
        for n, f in ((a, 1 / 6), (b, 4 / 6), (c, 1 / 6)):
            w[n] += S['m'] * le * f; wp[n] += S['rho'] * S['Ip'] * le * f
        tc = unit(pos[c] - pos[a])
        for n in (a, b, c):
            tan[n] += tc; cnt[n] += 1
    for p, mass in d['masses']:
        k = [i for i, q in enumerate(nodes) if np.allclose(q, p)][0] + 1
        w[k] += mass
    frames = {}
    for n in range(1, nb + 1):
        if cnt[n] == 0: continue
        t = tan[n] / cnt[n]
        if np.linalg.norm(t) < 0.5:     # knot with opposite/perpendicular members: use first
            t = tan[n]
        t = unit(t)
        f = flapdir(t); l = np.cross(t, f)
        frames[n] = (t, f, l)
    return w, wp, frames

def classify_mode(groups, Xref, U, w, wp, frames, multi_member_nodes):
    """kinetic-energy fractions of a mode, from a rigid-section fit at every beam node:
    flap  = translation out of the X-Y plane, transverse to the member (for members parallel to
            the spin axis Z: their whole z motion, which is out of plane);
    lag   = in-plane translation transverse to the member (members parallel to Z: x and y motion);
    axial = translation along the member (members not parallel to Z);
    torsion = rotation about the member axis (weight rho*Ip; knot nodes excluded)"""
    e = dict(axial=0.0, flap=0.0, lag=0.0, torsion=0.0); ez = 0.0
    for n, ns in groups.items():
        if n not in frames or len(ns) < 3: continue
        X = np.array([Xref[k] for k in ns]); u = np.array([U.get(k, np.zeros(3)) for k in ns])
        u0, th = rigid_fit(X, u)
        t, f, l = frames[n]
        uu = float(np.dot(u0, u0))
        if abs(t[2]) > 0.95:
            e['flap'] += w[n] * u0[2] ** 2
            e['lag'] += w[n] * (uu - u0[2] ** 2)
        else:
            ua = float(np.dot(u0, t)); up = u0 - ua * t; uf = float(np.dot(up, f))
            e['axial'] += w[n] * ua ** 2
            e['flap'] += w[n] * uf ** 2
            e['lag'] += w[n] * (float(np.dot(up, up)) - uf ** 2)
        ez += w[n] * u0[2] ** 2
        if n not in multi_member_nodes:
            e['torsion'] += wp[n] * np.dot(th, t) ** 2
    tot = sum(e.values())
    fr = {k: v / tot for k, v in e.items()} if tot > 0 else e
    fr['z_transl'] = ez / tot if tot > 0 else 0.0
    return fr

def kind_label(fr):
    cats = sorted(('axial', 'flap', 'lag', 'torsion'), key=lambda k: -fr[k])
    if fr[cats[0]] >= 0.8:
        return cats[0]
    parts = [c for c in cats if fr[c] >= 0.1]
    return 'coupled(' + '+'.join(parts) + ')'

# ------------------------------------------------------------------ running
def run_name(case, Om, ne, tag=''):
    return '%s_w%02d_n%03d%s' % (case, Om, ne, tag)

SYMDOF = {}

def run_case(case, Om, ne=24, tag='', nmodes=None, ncmodes=None, keep_big=False, sym=True):
    d = build_case(case, ne, tag)
    if nmodes is None:
        nmodes = 30 if Om == 0 else (10 if '_m10' in tag else 20)
    if ncmodes is None:
        ncmodes = nmodes
    name = run_name(case, Om, ne, tag)
    rdir = os.path.join(RUNS, name)
    os.makedirs(rdir, exist_ok=True); os.makedirs(DECKS, exist_ok=True)
    symdof = SYMDOF.get(case) if sym else None
    deck, nodes, elems = make_deck(d, Om, nmodes, ncmodes, title='ne=%d/member %s' % (ne, tag), symdof=symdof,
                                   etype='B32' if '_B32F' in tag else 'B32R', n1ip='_n1ip' in tag,
                                   inplane_only='_ip' in tag.replace('_n1ip', ''))
    open(os.path.join(DECKS, name + '.inp'), 'w').write(deck)
    open(os.path.join(rdir, name + '.inp'), 'w').write(deck)
    env = dict(os.environ, OMP_NUM_THREADS='1', OPENBLAS_NUM_THREADS='1')
    t0 = time.time()
    with open(os.path.join(rdir, 'ccx.log'), 'w') as lf:
        rc = subprocess.call([CCX, '-i', name], cwd=rdir, stdout=lf, stderr=subprocess.STDOUT, env=env)
    wall = time.time() - t0
    logtxt = open(os.path.join(rdir, 'ccx.log')).read()
    if os.path.exists(os.path.join(rdir, 'ccx.log.gz')): os.remove(os.path.join(rdir, 'ccx.log.gz'))
    ok = ('*ERROR' not in logtxt) and os.path.exists(os.path.join(rdir, name + '.dat'))
    info = dict(name=name, case=case, Om=Om, ne=ne, tag=tag, nmodes=nmodes, ncmodes=ncmodes, rc=rc, ok=ok, wall=wall,
                symdof=symdof)
    try:
        res = postprocess(d, name, rdir, nodes, elems, Om)
        info.update(res)
    except Exception as ex:
        info['ok'] = False; info['post_error'] = repr(ex)
    if not keep_big:
        for ext in ('.frd', '.eig', '.12d', '.cvg'):
            p = os.path.join(rdir, name + ext)
            if os.path.exists(p): os.remove(p)
        for f in ('spooles.out', name + '.inp'):
            p = os.path.join(rdir, f)
            if os.path.exists(p): os.remove(p)
        shrink_dat(os.path.join(rdir, name + '.dat'))
        subprocess.call(['gzip', '-f', os.path.join(rdir, 'ccx.log')])
        if os.path.exists(os.path.join(rdir, name + '.dat')):
            subprocess.call(['gzip', '-f', os.path.join(rdir, name + '.dat')])
    json.dump(info, open(os.path.join(rdir, 'result.json'), 'w'), indent=1, default=float)
    print('%-28s ok=%s wall=%.1fs' % (name, info['ok'], wall), flush=True)
    return info

def shrink_dat(p):
    """keep only the last static displacement (and NSYM reaction) block + eigenvalue / participation output"""
    if not os.path.exists(p): return
    lines = open(p).read().splitlines()
    ev = [i for i, l in enumerate(lines) if 'E I G E N V A L U E   O U T P U T' in l]
    end = ev[0] if ev else len(lines)
    keep = []
    for pat in ('forces (fx,fy,fz) for set NSYM', 'displacements (vx,vy,vz) for set NALL'):
        idx = [i for i, l in enumerate(lines[:end]) if pat in l]
        if not idx: continue
        k0 = idx[-1]; k1 = k0 + 2
        while k1 < end and lines[k1].strip(): k1 += 1
        keep += lines[k0:k1] + ['']
    keep += (lines[ev[0] - 2:] if ev else [])
    open(p, 'w').write('\n'.join(keep) + '\n')

def postprocess(d, name, rdir, nodes, elems, Om):
    res = {}
    datp = os.path.join(rdir, name + '.dat')
    dat = parse_dat(datp)
    sta = os.path.join(rdir, name + '.sta')
    if os.path.exists(sta):
        sl = [l for l in open(sta).read().splitlines()[2:] if l.strip()]
        st1 = [l for l in sl if l.split()[0] == '1']
        res['static_increments'] = len([l for l in st1 if 'U' not in l.split()[2]])
        res['static_cutbacks'] = len([l for l in st1 if 'U' in l.split()[2]])
        try:
            res['static_iterations'] = sum(int(l.split()[3]) for l in st1 if 'U' not in l.split()[2])
        except Exception:
            pass
    res['static_time'] = dat.get('static_time')
    res['nsym_total_rf'] = dat.get('nsym_total_rf')
    if 'static_disp' not in dat or abs((dat.get('static_time') or 0) - 1.0) > 1e-6:
        res['ok_static'] = False
        return res
    res['ok_static'] = True
    sd = dat['static_disp']
    nb = len(nodes)
    pos = {n: nodes[n - 1] + np.array(sd.get(n, [0, 0, 0])) for n in range(1, nb + 1)}
    key = lambda p: [i for i, q in enumerate(nodes) if np.allclose(q, p)][0] + 1
    coords, blocks = parse_frd(os.path.join(rdir, name + '.frd'))
    groups = section_groups(nodes, coords)
    ncorner = len({n for e in elems for n in (e[2][0], e[2][2])}); nmid = len(elems)
    res['n_expanded_nodes'] = len(coords)
    res['n_knots_est'] = (len(coords) - 8 * ncorner - 4 * nmid) / 8.0
    nfreq = len(dat['freq'])
    btype = [int(h.split()[4]) if len(h.split()) > 4 else -1 for h, _ in blocks]
    static_blk = [b for (h, b), ty in zip(blocks, btype) if ty == 0][-1]   # 100CL analysis type 0 = static
    mode_blks = [b for (h, b), ty in zip(blocks, btype) if ty == 2]         # 2 = frequency step (MODAL)
    assert len(mode_blks) == nfreq, (len(mode_blks), nfreq)
    Xdef = {n: coords[n] + static_blk.get(n, np.zeros(3)) for n in coords}
    for lab in ('tip', 'tip2'):
        if lab not in d: continue
        k = key(d[lab])
        ns = groups[k]
        X0 = np.array([coords[n] for n in ns]); X1 = np.array([Xdef[n] for n in ns])
        rv = kabsch(X0, X1)
        res[lab] = dict(node=k, x=pos[k].tolist(), u=list(sd[k]), rotvec_deg=np.degrees(rv).tolist(),
                        n_section_nodes=len(ns))
    # mode classification
    w, wp, frames = node_frames(d, nodes, elems, pos)
    cnt = {}
    for eid, im, (a, b, c), t, n1 in elems:
        for n in (a, c): cnt.setdefault(n, set()).add(im)
    multi = {n for n, s in cnt.items() if len(s) > 1}
    modes = []
    for f, U in zip(dat['freq'], mode_blks):
        fr = classify_mode(groups, Xdef, U, w, wp, frames, multi)
        modes.append(dict(mode=f['mode'], w=f['w'], eig=f['eig'], kind=kind_label(fr), **{k: round(v, 4) for k, v in fr.items()}))
    res['modes'] = modes
    res['craw'] = complex_roots(dat, modes)
    res['cmodes'] = group_roots(res['craw'])
    res['n_negative_eig'] = sum(1 for f in dat['freq'] if f['eig'] < 0)
    return res

def complex_roots(dat, modes):
    """raw *COMPLEX FREQUENCY roots with their participation-weighted energy fractions"""
    cm = []
    for c in dat['cplx']:
        pf = c.get('pf', {})
        if not pf: continue
        tot = sum(abs(v) ** 2 for v in pf.values())
        dom = max(pf.items(), key=lambda kv: abs(kv[1]))[0]
        mix = {k: 0.0 for k in ('axial', 'flap', 'lag', 'torsion', 'z_transl')}
        for kk, v in pf.items():
            if kk - 1 < len(modes):
                for k in mix: mix[k] += abs(v) ** 2 / tot * modes[kk - 1][k]
        cm.append(dict(w=c['w'], imag=c['imag'], dom=dom, domshare=abs(pf[dom]) ** 2 / tot, **mix))
    return cm

def group_roots(cm, tol=0.01):
    """ccx's coriolissolve can return scattered copies of one root (see ../calculix/README.md 4.4):
    roots with the same dominant real mode whose frequencies differ by < tol (relative) are one root;
    the copy with the smallest |imaginary part| is kept. Distinct roots sharing a dominant real mode
    (strong Coriolis mixing) are kept separately."""
    reps = []
    for c in sorted(cm, key=lambda c: c['w']):
        for r in reps:
            if r['dom'] == c['dom'] and abs(c['w'] - r['_w0']) <= tol * max(abs(r['_w0']), 1e-9) + 1e-6:
                r['_copies'].append(c); break
        else:
            reps.append(dict(c, _w0=c['w'], _copies=[c]))
    out = []
    for r in reps:
        best = min(r['_copies'], key=lambda c: abs(c['imag']))
        ws = [c['w'] for c in r['_copies']]
        b2 = dict(best); b2['ncopies'] = len(ws)
        b2['relspread'] = (max(ws) - min(ws)) / max(abs(best['w']), 1e-9)
        b2['kind'] = kind_label(b2)
        out.append(b2)
    return sorted(out, key=lambda c: c['w'])

def regroup():
    """recompute complex-root grouping of finished runs from their (kept) .dat files"""
    for name in sorted(os.listdir(RUNS)):
        p = os.path.join(RUNS, name, 'result.json')
        if not os.path.exists(p): continue
        r = json.load(open(p))
        datp = os.path.join(RUNS, name, name + '.dat')
        if not r.get('modes') or not (os.path.exists(datp) or os.path.exists(datp + '.gz')): continue
        dat = parse_dat(datp)
        r['craw'] = complex_roots(dat, r['modes'])
        r['cmodes'] = group_roots(r['craw'])
        sta = os.path.join(RUNS, name, name + '.sta')
        if os.path.exists(sta):
            st1 = [l for l in open(sta).read().splitlines()[2:] if l.strip() and l.split()[0] == '1']
            r['static_iterations'] = sum(int(l.split()[3]) for l in st1 if 'U' not in l.split()[2])
        json.dump(r, open(p, 'w'), indent=1, default=float)
        lg = os.path.join(RUNS, name, 'ccx.log')
        if os.path.exists(lg):
            subprocess.call(['gzip', '-f', lg])

def run_many(specs, jobs=2):
    with ThreadPoolExecutor(max_workers=jobs) as ex:
        return list(ex.map(lambda s: run_case(**s), specs))

GROUPS = {
    'R0': [dict(case='R0', Om=w) for w in (0, 4, 8, 12)],
    'R0s': [dict(case='R0s', Om=w) for w in (0, 4, 8, 12)],
    'T0': [dict(case='T0', Om=0)],
    'R1': [dict(case='R1', Om=w) for w in (0, 10, 20)],
    'R1fillet': [dict(case='R1', Om=w, tag='_fil%03d' % rf) for w in (20, 10, 0) for rf in (200, 100, 50)],
    'R2': [dict(case='R2', Om=w) for w in (0, 5, 10, 15, 16, 17, 18, 19, 20)],
    'R3': [dict(case='R3', Om=w) for w in (0, 5, 10, 15)],
    'oop': [dict(case=c, Om=w, ne=n) for c in ('R2F', 'HM', 'SK', 'PB', 'MA') for n in (24, 48)
            for w in OOP[c][4]] + [dict(case='PBK', Om=w) for w in OOP['PBK'][4]],
    'mesh': [dict(case='R1', Om=w, ne=48) for w in (0, 20)] + [dict(case='R3', Om=w, ne=48) for w in (0, 15)]
            + [dict(case='R2', Om=w, ne=48) for w in (15, 20)],
}

# ------------------------------------------------------------------ collection
def collect():
    os.makedirs(RES, exist_ok=True)
    rows = []; runs = []
    for name in sorted(os.listdir(RUNS)):
        p = os.path.join(RUNS, name, 'result.json')
        if not os.path.exists(p): continue
        r = json.load(open(p))
        tip = r.get('tip', {})
        runs.append(dict(run=name, case=r['case'], omega=r['Om'], ne_per_member=r['ne'], tag=r.get('tag', ''),
                         ok=r.get('ok') and r.get('ok_static', False), wall_s=round(r['wall'], 1),
                         static_increments=r.get('static_increments'), static_iterations=r.get('static_iterations'),
                         static_cutbacks=r.get('static_cutbacks'), n_negative_eig=r.get('n_negative_eig'),
                         tip_x=tip.get('x', [None] * 3)[0], tip_y=tip.get('x', [None] * 3)[1], tip_z=tip.get('x', [None] * 3)[2],
                         tip_rotvec_x_deg=tip.get('rotvec_deg', [None] * 3)[0], tip_rotvec_y_deg=tip.get('rotvec_deg', [None] * 3)[1],
                         tip_rotvec_z_deg=tip.get('rotvec_deg', [None] * 3)[2]))
        if not (r.get('ok') and r.get('ok_static')): continue
        base = dict(case=r['case'], omega=r['Om'], ne_per_member=r['ne'], tag=r.get('tag', ''))
        tx = tip.get('x', [float('nan')] * 3); tr = tip.get('rotvec_deg', [float('nan')] * 3)
        for cor in (False, True):
            lst = r['modes'] if (not cor or r['Om'] == 0) else r.get('cmodes', [])
            for i, m in enumerate(lst[:6] if cor else [mm for mm in lst if mm['eig'] > 0][:6]):
                rows.append(dict(base, coriolis=int(cor), mode=i + 1, frequency_rad_s='%.6g' % m['w'], kind=m['kind'],
                                 tip_x='%.6f' % tx[0], tip_y='%.6f' % tx[1], tip_z='%.6f' % tx[2],
                                 tip_rotvec_x_deg='%.4f' % tr[0], tip_rotvec_y_deg='%.4f' % tr[1], tip_rotvec_z_deg='%.4f' % tr[2],
                                 frac_axial=round(m['axial'], 3), frac_flap=round(m['flap'], 3), frac_lag=round(m['lag'], 3),
                                 frac_torsion=round(m['torsion'], 3), frac_z_transl=round(m['z_transl'], 3),
                                 cor_copies=m.get('ncopies', ''), cor_relspread=('%.2e' % m['relspread']) if 'relspread' in m else '',
                                 imag=('%.3e' % m['imag']) if 'imag' in m else ''))
    write_csv(rows, os.path.join(RES, 'modes_all.csv'))
    write_csv(runs, os.path.join(RES, 'runs.csv'))
    return rows, runs

def write_csv(rows, path):
    keys = []
    for r in rows:
        for k in r:
            if k not in keys: keys.append(k)
    with open(path, 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=keys); w.writeheader()
        for r in rows: w.writerow(r)

# ------------------------------------------------------------------ OOP deliverables
OOP_REFS = ('R2F', 'HM', 'SK', 'PB', 'MA')
OOP_NOTES = {
    'R2F': "R2 with a 0.4 m fillet at C in the X-Z plane (radial arm, then a mast along +z); section 'sq'; "
           "flap axis = global Y on every element (square: only the local axes of the ccx expansion change, "
           "and consistent axes keep ccx from generating a knot). Fillet as straight one-element members "
           "through the ccx arc nodes.",
    'HM': "hanging mast: radial arm O(0.5,0,0)->(3,0,0), 0.4 m fillet turning down, mast to (3,0,-2.5); 'sq'.",
    'SK': "skewed: radial arm (0.5,0,0)->(3,0,0), 0.4 m fillet, member rising and leaning tangentially along "
          "(0,0.6,0.8) to (3,1.2,1.6); 'sq'; no mirror symmetry, the steady state leaves the X-Z plane.",
    'PB': "precone blade on a flexible radial arm: arm (0.5,0,0)->(2.5,0,0) 'rectA' (the 0.06 x 0.02 rect "
          "geometry with E x 5 and 1.2 kg/m: EI_flap 14000 like 'sq'; a geometry change at a node makes ccx "
          "generate a knot, a material change does not), 0.4 m fillet, blade of 8 m at 15 deg precone, 'rect'.",
    'MA': "mast on the spin axis (0,0,0)->(0,0,2) (flap_direction global Y, as ccx), 0.4 m fillet, radial arm "
          "to (3,0,2); 'sq'; the lowest mode softens with speed.",
}

def oop_load(case, w, ne):
    p = os.path.join(RUNS, run_name(case, w, ne), 'result.json')
    r = json.load(open(p))
    assert r.get('ok') and r.get('ok_static'), p
    return r

def oop_lists(r, w):
    plain = [m for m in r['modes'] if m['eig'] > 0]
    cor = plain if w == 0 else r['cmodes']
    return plain, cor

def oop_write(outdir, arcmode='nodes'):
    """cases_oop.json and calculix_oop.csv from runs/ (group 'oop')"""
    out = {}
    for case in OOP_REFS:
        req, tip = spin_request(case, 24, arcmode)
        exp = []
        for w in OOP[case][4]:
            r = oop_load(case, w, 24)
            assert r['n_knots_est'] == 0 and r['n_negative_eig'] == 0, (case, w)
            plain, cor = oop_lists(r, w)
            exp.append(dict(omega=float(w), w_plain=[float('%.6g' % m['w']) for m in plain[:6]],
                            w_coriolis=[float('%.6g' % m['w']) for m in cor[:6]], kinds=[m['kind'] for m in plain[:6]],
                            tip=[round(x, 6) + 0.0 for x in r['tip']['x']]))
        out[case] = dict(request=req, tip_joint=tip, expected=exp, note=OOP_NOTES[case])
    json.dump(out, open(os.path.join(outdir, 'cases_oop.json'), 'w'), indent=1)
    rows = []
    for case in OOP_REFS + ('PBK',):
        for ne in (24, 48):
            for w in OOP[case][4]:
                try:
                    r = oop_load(case, w, ne)
                except (OSError, AssertionError):
                    continue
                tx, tr = r['tip']['x'], r['tip']['rotvec_deg']
                base = dict(case=case, omega=w, ne_per_member=ne, tag=r.get('tag', ''))
                plain, cor = oop_lists(r, w)
                for c, lst in ((0, plain), (1, cor)):
                    for i, m in enumerate(lst):
                        rows.append(dict(base, coriolis=c, mode=i + 1, frequency_rad_s='%.6g' % m['w'], kind=m['kind'],
                                         tip_x='%.6f' % tx[0], tip_y='%.6f' % tx[1], tip_z='%.6f' % tx[2],
                                         tip_rotvec_x_deg='%.4f' % tr[0], tip_rotvec_y_deg='%.4f' % tr[1], tip_rotvec_z_deg='%.4f' % tr[2],
                                         frac_axial=round(m['axial'], 3), frac_flap=round(m['flap'], 3), frac_lag=round(m['lag'], 3),
                                         frac_torsion=round(m['torsion'], 3), frac_z_transl=round(m['z_transl'], 3),
                                         cor_copies=m.get('ncopies', ''), cor_relspread=('%.2e' % m['relspread']) if 'relspread' in m else '',
                                         imag=('%.3e' % m['imag']) if 'imag' in m else '', n_knots_est=r['n_knots_est']))
    write_csv(rows, os.path.join(outdir, 'calculix_oop.csv'))

def oop_compare(spinmodal, arcmode='nodes', cases=OOP_REFS + ('PBK',)):
    """markdown tables: ccx 24, ccx 48, spinmodal 24 (lumped, per_element) and % differences"""
    lines = []; summary = []
    for case in cases:
        rest = np.array(OOP[case][0][-1], float)
        S = {}
        for cor in (False, True):
            req, tip = spin_request(case, 24, arcmode, coriolis=cor)
            fn = os.path.join(RES, 'spin_%s_%d.json' % (case, cor)); os.makedirs(RES, exist_ok=True)
            json.dump(req, open(fn, 'w'))
            o = json.loads(subprocess.run([spinmodal, 'solve', fn], capture_output=True, text=True).stdout)
            for c in o['cases']:
                S[(c['omega'], cor)] = c
        lines += ['', '### %s' % case, '', OOP_NOTES.get(case, 'PB with a square arm: ccx makes a knot at the '
                  'sq/rect joint: NOT a reference (knot present, not used as a reference).'), '',
                  '| Ω | Coriolis | mode | kind | ccx 24 | ccx 48 | spinmodal 24 | Δ vs 24 % | Δ vs 48 % |',
                  '|---|---|---|---|---|---|---|---|---|']
        tiplines = ['', '| Ω | ccx 24 tip | ccx 48 tip | spinmodal tip | displacement m | error vs 24 % | tip rotation deg (ccx) | knots (ccx est.) |',
                    '|---|---|---|---|---|---|---|---|']
        for w in OOP[case][4]:
            r24 = oop_load(case, w, 24)
            try:
                r48 = oop_load(case, w, 48)
            except (OSError, AssertionError):
                r48 = None
            for cor in (False, True):
                c = S[(float(w), cor)]
                ours = [m['frequency_rad_s'] for m in c['modes']]
                l24 = oop_lists(r24, w)[1 if cor else 0][:6]
                l48 = oop_lists(r48, w)[1 if cor else 0][:6] if r48 else []
                worst = 0.0
                for i, m in enumerate(l24):
                    o = min(ours, key=lambda x: abs(x - m['w']))
                    d24 = 100 * (o - m['w']) / m['w']
                    m48 = min(l48, key=lambda x: abs(x['w'] - m['w']))['w'] if l48 else float('nan')
                    d48 = 100 * (o - m48) / m48
                    worst = max(worst, abs(d24))
                    lines.append('| %g | %s | %d | %s | %.5g | %.5g | %.5g | %+.3f | %+.3f |' % (
                        w, 'yes' if cor else 'no', i + 1, m['kind'], m['w'], m48, o, d24, d48))
                tip = c['equilibrium']['joints'][spin_request(case, 24, arcmode)[1]][:3]
                moved = float(np.linalg.norm(np.array(r24['tip']['x']) - rest)); err = float(np.linalg.norm(np.array(tip) - np.array(r24['tip']['x'])))
                summary.append((case, w, cor, worst, 100 * err / moved if moved > 1e-9 else 0.0, c['status'], c.get('stability', {}).get('stable')))
                if not cor:
                    tiplines.append('| %g | (%.4f, %.4f, %.4f) | %s | (%.4f, %.4f, %.4f) | %.4f | %.3f | %.1f | %g |' % (
                        w, *r24['tip']['x'], '(%.4f, %.4f, %.4f)' % tuple(r48['tip']['x']) if r48 else '-', *tip, moved,
                        100 * err / moved if moved > 1e-9 else 0.0, float(np.linalg.norm(r24['tip']['rotvec_deg'])), r24['n_knots_est']))
        lines += tiplines
    head = ['| case | Ω | Coriolis | worst |Δ| of 6 modes vs ccx 24 % | tip error % of displacement | spinmodal status | stable |',
            '|---|---|---|---|---|---|---|']
    head += ['| %s | %g | %s | %.3f | %.3f | %s | %s |' % (c, w, 'yes' if cor else 'no', wd, te, st, sb) for c, w, cor, wd, te, st, sb in summary]
    return '\n'.join(head), '\n'.join(lines), summary

if __name__ == '__main__':
    what = sys.argv[1] if len(sys.argv) > 1 else 'parse'
    if what == 'run':
        specs = []
        for g in sys.argv[2:]: specs += GROUPS[g]
        run_many(specs, jobs=int(os.environ.get('JOBS', '2'))); collect()
    elif what == 'one':
        case, Om = sys.argv[2], float(sys.argv[3])
        ne = int(sys.argv[4]) if len(sys.argv) > 4 else 24
        tag = sys.argv[5] if len(sys.argv) > 5 else ''
        info = run_case(case, int(Om) if Om == int(Om) else Om, ne, tag, keep_big='keep' in tag, sym='nosym' not in tag)
        print(json.dumps({k: v for k, v in info.items() if k not in ('modes', 'cmodes')}, indent=1, default=str))
        for m in info.get('modes', [])[:10]: print(m)
        for m in info.get('cmodes', [])[:8]: print(m)
    elif what == 'request':     # run3d.py request CASE [NE] [ends|nodes] -> spinmodal request on stdout
        req, tip = spin_request(sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 24,
                                sys.argv[4] if len(sys.argv) > 4 else 'ends')
        print(json.dumps(dict(request=req, tip_joint=tip), indent=1))
    elif what == 'oopwrite':    # run3d.py oopwrite OUTDIR -> cases_oop.json, calculix_oop.csv
        oop_write(sys.argv[2])
    elif what == 'oopcompare':  # run3d.py oopcompare SPINMODAL -> results/oop_compare.md
        head, body, summ = oop_compare(sys.argv[2])
        open(os.path.join(RES, 'oop_compare.md'), 'w').write(head + '\n' + body + '\n')
        print(head)
    elif what == 'parse':
        collect()
    elif what == 'faildeck':
        deck, _, _ = make_deck(build_case('R1'), 20, 20, 20, title='sharp corner, out-of-plane free: static step stalls')
        open(os.path.join(DECKS, 'FAILS_R1_w20_n024_knot_free.inp'), 'w').write(deck)
    elif what == 'regroup':
        regroup(); collect()
