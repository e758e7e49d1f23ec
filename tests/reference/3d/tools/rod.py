"""Independent discrete rod for spinning space frames (issue 22): written apart from spinmodal's
core to check its out-of-plane linearization where CalculiX cannot (a sharp corner out of the
plane, where ccx's knot is wrong under load: ../OOP.md).

Model: each element is a rigid segment of length l with its own absolute orientation R_s (3
coordinates: a hub-frame rotation increment, R_s <- exp(phi) R_s); positions follow from the
orientations exactly (inextensible, unshearable: Euler-Bernoulli in the limit).  Bending and
torsion live in rotational springs between consecutive segments: the relative rotation
log(E_a' R_a' R_b E_a) in the body axes of the parent, with the compliance of half of each
segment (l/2 D^-1, D = diag(GJ, EI_edge, EI_flap) in the section axes of DESIGN.md 7.1); a clamp
spring of half the first segment.  Mass lumped at the segment ends (mu l / 2 each side), rotary
inertia of the sections per segment.  Potential: springs - 1/2 Omega^2 sum m |P x|^2 - 1/2
Omega^2 e_z' X e_z; its gradient and Hessian are analytic for the centrifugal part (dx_i/dphi_s =
-skew(v_s) for the segments s on the path to i; the second derivative gives the block
1/2 (F v' + v F') - (F.v) I with F the centrifugal pull carried by s), by finite differences of
each 6-coordinate spring energy for the elastic part.  Newton from the previous speed, 8
load steps.  Convergence O(l^2): at 24 and 48 segments per member R2's frequencies differ by
<= 0.1 % (modes 1-4).  A chain (no branches: a branch node would share the parent's half
compliance between its children)."""
import numpy as np, scipy.linalg as sl

def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

def expm3(p):
    t = np.linalg.norm(p)
    K = skew(p)
    if t < 1e-8:
        return np.eye(3) + K + 0.5 * K @ K
    return np.eye(3) + np.sin(t) / t * K + (1 - np.cos(t)) / t ** 2 * K @ K

def logm3(R):
    c = (np.trace(R) - 1) / 2
    c = min(1.0, max(-1.0, c))
    t = np.arccos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if t < 1e-8:
        return 0.5 * w
    return t / (2 * np.sin(t)) * w

def unit(v):
    v = np.asarray(v, float); return v / np.linalg.norm(v)

def axes(e1, flap=None, mid=None):
    ez = np.array([0, 0, 1.0])
    if flap is not None:
        f = np.asarray(flap, float)
        e3 = unit(f - f.dot(e1) * e1)
    else:
        f = ez - ez.dot(e1) * e1
        if np.linalg.norm(f) < 1e-9:
            f = np.array([mid[0], mid[1], 0.0])
            f = f - f.dot(e1) * e1
        e3 = unit(f)
    e2 = np.cross(e3, e1)
    return np.column_stack([e1, e2, e3])

class Rod:
    def __init__(self, joints, sections, members, clamp, ne=None, masses=()):
        """members: list of dict(frm, to, section, elements, flap=None); sections: EA.. dicts."""
        self.segs = []      # dict(parent, l, E (3x3 body axes), D (3), mu, ip(3 body inertia per length), start, end)
        node_of_joint = {clamp: None}
        # build member by member in an order that follows the tree from the clamp
        pending = list(members)
        self.end_seg = {}   # joint name -> segment whose end is at that joint (or None for the clamp)
        self.end_seg[clamp] = -1
        while pending:
            prog = False
            for mb in list(pending):
                a, b = mb['from'], mb['to']
                if a not in self.end_seg and b in self.end_seg:
                    a, b = b, a
                if a not in self.end_seg:
                    continue
                pending.remove(mb); prog = True
                p0, p1 = np.array(joints[a], float), np.array(joints[b], float)
                n = ne or mb.get('elements', 24)
                e1 = unit(p1 - p0); E = axes(e1, mb.get('flap_direction'), (p0 + p1) / 2)
                S = sections[mb['section']]
                L = np.linalg.norm(p1 - p0); l = L / n
                D = np.array([S['GJ'], S['EI_edge'], S['EI_flap']])
                mu = S['mass_per_length']
                ife, iff = S.get('flap_inertia', 0.0), S.get('edge_inertia', 0.0)
                # body rotary inertia per length: about e1 = if+ie, about e2 (edge-normal) ... use DESIGN: flap_inertia pairs with flap bending
                ip = np.array([ife + iff, iff, ife])
                parent = self.end_seg[a]
                for k in range(n):
                    self.segs.append(dict(parent=parent, l=l, E=E, D=D, mu=mu, ip=ip,
                                          v0=E @ np.array([l, 0, 0])))
                    parent = len(self.segs) - 1
                self.end_seg[b] = parent
            if not prog:
                raise ValueError('disconnected')
        self.S = len(self.segs)
        self.root = np.array(joints[clamp], float)
        self.R = [np.eye(3) for _ in range(self.S)]
        self.children = [[] for _ in range(self.S)]
        for i, s in enumerate(self.segs):
            if s['parent'] >= 0:
                self.children[s['parent']].append(i)
        # point masses at segment ends: node i = end of segment i; mass
        self.m_end = np.array([s['mu'] * s['l'] / 2 for s in self.segs])
        self.m_root_extra = 0.0
        for i, s in enumerate(self.segs):
            if s['parent'] >= 0:
                self.m_end[s['parent']] += s['mu'] * s['l'] / 2
        for (j, mass) in masses:
            self.m_end[self.end_seg[j]] += mass
        # joint springs: (parent a or -1, child b, K (3x3 in a's body frame / b's for the clamp), Q0)
        self.springs = []
        for b, s in enumerate(self.segs):
            a = s['parent']
            Cb = s['l'] / 2 * np.diag(1 / s['D'])
            if a < 0:
                self.springs.append((a, b, np.linalg.inv(Cb), s['E']))
            else:
                sa = self.segs[a]
                Q0 = sa['E'].T @ s['E']
                # the parent's half length is shared among its children: give each child the
                # parent's half compliance (exact for a chain)
                C = sa['l'] / 2 * np.diag(1 / sa['D']) + Q0 @ Cb @ Q0.T
                self.springs.append((a, b, np.linalg.inv(C), sa['E']))

    # positions
    def ends(self, R=None):
        R = self.R if R is None else R
        x = np.zeros((self.S, 3)); st = np.zeros((self.S, 3))
        for i, s in enumerate(self.segs):
            st[i] = self.root if s['parent'] < 0 else x[s['parent']]
            x[i] = st[i] + R[i] @ s['v0']
        return st, x

    def spring_energy(self, a, b, K, Ea, Ra, Rb):
        Rel = Ea.T @ (Ra.T @ Rb) @ Ea if a >= 0 else Ea.T @ Rb @ Ea
        d = logm3(Rel)
        return 0.5 * d @ K @ d

    def elastic_grad_hess(self, h=1e-5):
        n = 3 * self.S
        g = np.zeros(n); H = np.zeros((n, n))
        for (a, b, K, Ea) in self.springs:
            idx = ([3 * a, 3 * a + 1, 3 * a + 2] if a >= 0 else []) + [3 * b, 3 * b + 1, 3 * b + 2]
            k = len(idx)
            Ra0 = self.R[a] if a >= 0 else np.eye(3); Rb0 = self.R[b]
            def f(p):
                Ra = expm3(p[:3]) @ Ra0 if a >= 0 else Ra0
                Rb = expm3(p[-3:]) @ Rb0
                return self.spring_energy(a, b, K, Ea, Ra, Rb)
            p0 = np.zeros(k)
            f0 = f(p0)
            gl = np.zeros(k); Hl = np.zeros((k, k))
            for i in range(k):
                e = np.zeros(k); e[i] = h
                fp, fm = f(e), f(-e)
                gl[i] = (fp - fm) / (2 * h)
                Hl[i, i] = (fp - 2 * f0 + fm) / h ** 2
                for j in range(i):
                    e2 = np.zeros(k); e2[j] = h
                    Hl[i, j] = Hl[j, i] = (f(e + e2) - f(e - e2) - f(-e + e2) + f(-e - e2)) / (4 * h * h)
            for i in range(k):
                g[idx[i]] += gl[i]
                for j in range(k):
                    H[idx[i], idx[j]] += Hl[i, j]
        return g, H

    def centrifugal(self, Om):
        """gradient and Hessian of -1/2 Om^2 sum m |P x|^2 (ends) - 1/2 Om^2 e_z X e_z (rotary)."""
        P = np.diag([1.0, 1.0, 0.0])
        st, x = self.ends()
        n = 3 * self.S
        # F_s = sum over ends downstream of s (incl. own end) of m P x
        F = np.zeros((self.S, 3))
        for i in reversed(range(self.S)):
            F[i] += self.m_end[i] * (P @ x[i])
            p = self.segs[i]['parent']
            if p >= 0:
                F[p] += F[i]
        # Jacobian of end positions: dx_i/dphi_s = -skew(v_s) for s on path
        J = np.zeros((self.S, 3, n))
        for i in range(self.S):
            s = i
            while s >= 0:
                v = self.R[s] @ self.segs[s]['v0']
                J[i][:, 3 * s:3 * s + 3] = -skew(v)
                s = self.segs[s]['parent']
        g = np.zeros(n); H = np.zeros((n, n))
        for s in range(self.S):
            v = self.R[s] @ self.segs[s]['v0']
            g[3 * s:3 * s + 3] = -Om ** 2 * np.cross(v, F[s])
            B = 0.5 * (np.outer(F[s], v) + np.outer(v, F[s])) - F[s].dot(v) * np.eye(3)
            H[3 * s:3 * s + 3, 3 * s:3 * s + 3] -= Om ** 2 * B
        for i in range(self.S):
            H -= Om ** 2 * self.m_end[i] * J[i].T @ P @ J[i]
        # rotary: -1/2 Om^2 ez' R Ib R' ez, R = exp(phi) R0: X = R Ib R'
        ez = np.array([0, 0, 1.0])
        for s, sg in enumerate(self.segs):
            X = self.R[s] @ sg['E'] @ np.diag(sg['mu'] * sg['l'] * sg['ip']) @ sg['E'].T @ self.R[s].T
            # d/dphi of ez' exp X exp' ez = 2 ez' skew(phi) X ez = 2 phi.(X ez x ez)
            a = X @ ez
            g[3 * s:3 * s + 3] += -0.5 * Om ** 2 * 2 * np.cross(a, ez)
            # second: ez'(K^2 X + 2 K X K' + X K^2') ez with K = skew(phi): Hessian of phi -> 2 [ (ez'K^2 X ez) + ez' K X K' ez ]
            Hs = np.zeros((3, 3))
            for i in range(3):
                for j in range(3):
                    Ki, Kj = skew(np.eye(3)[i]), skew(np.eye(3)[j])
                    Hs[i, j] = ez @ (0.5 * (Ki @ Kj + Kj @ Ki) @ X + X @ (0.5 * (Ki @ Kj + Kj @ Ki)).T + Ki @ X @ Kj.T + Kj @ X @ Ki.T) @ ez
            H[3 * s:3 * s + 3, 3 * s:3 * s + 3] += -0.5 * Om ** 2 * Hs
        self.J = J
        return g, H

    def mass(self):
        n = 3 * self.S
        self.centrifugal(0.0)
        M = np.zeros((n, n))
        for i in range(self.S):
            M += self.m_end[i] * self.J[i].T @ self.J[i]
        for s, sg in enumerate(self.segs):
            X = self.R[s] @ sg['E'] @ np.diag(sg['mu'] * sg['l'] * sg['ip']) @ sg['E'].T @ self.R[s].T
            # plus the segment's own inertia as a rigid rod beyond the lumped ends: none (lumped)
            M[3 * s:3 * s + 3, 3 * s:3 * s + 3] += X
        return M

    def gyro(self, Om):
        n = 3 * self.S
        S = skew([0, 0, 1.0])
        C = np.zeros((n, n))
        for i in range(self.S):
            C += 2 * Om * self.m_end[i] * self.J[i].T @ S @ self.J[i]
        return C

    def solve(self, Om, tol=1e-10, steps=8):
        for k in range(1, steps + 1):
            w = Om * np.sqrt(k / steps)
            for it in range(60):
                ge, He = self.elastic_grad_hess()
                gc, Hc = self.centrifugal(w)
                g = ge + gc; H = He + Hc
                dphi = -np.linalg.solve(H, g)
                for s in range(self.S):
                    self.R[s] = expm3(dphi[3 * s:3 * s + 3]) @ self.R[s]
                if np.linalg.norm(dphi) < tol:
                    break
            else:
                raise RuntimeError('no convergence at %g' % w)
        ge, He = self.elastic_grad_hess()
        gc, Hc = self.centrifugal(Om)
        self.K = He + Hc
        self.M = self.mass()
        return np.linalg.norm(ge + gc)

    def freqs(self, Om, coriolis=False, nm=6):
        lam = sl.eigh(self.K, self.M, eigvals_only=True)
        neg = int((lam < 0).sum())
        if not coriolis:
            w = np.sign(lam) * np.sqrt(np.abs(lam))
            return w[:nm], neg, lam[:nm]
        n = self.K.shape[0]
        C = self.gyro(Om)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-self.K, -C]])
        B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), self.M]])
        ev = sl.eigvals(A, B)
        ev = ev[np.imag(ev) > 1e-9]
        return np.sort(np.imag(ev))[:nm], neg, None

    def tip(self, joint):
        st, x = self.ends()
        return x[self.end_seg[joint]]
