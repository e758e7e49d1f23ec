// view3d.js — the spatial view (DESIGN.md 7): the structure, its steady state
// and an animated mode shape in 3D, drawn in SVG with an orthographic
// projection the user turns by dragging (or with the arrow keys).
//
// Camera: azimuth az and elevation el (degrees) of the viewing direction, the
// hub axis z always up on the screen (el = 90: seen from above, the planar
// view; el = 0: seen from the side, where flap motion is vertical).  Screen
// axes: right = (−sin az, cos az, 0), up = (−sin el cos az, −sin el sin az,
// cos el).  The scale fits the drawing at the home camera and only shrinks
// when a turned view would not fit, so turning never makes it jump.
//
// Rows of a result: a spatial node or shape row is [x, y, z, rx, ry, rz] /
// [dx, dy, dz, rx, ry, rz]; a planar one [x, y, φ] / [dx, dy, dφ] has no z
// (drawn at z = 0).  Rotations are not drawn.

import {el, clear, defs, r2, elemPath} from './drawing.js';
import {xyz} from './mesh.js';

const W = 600, H = 360, PAD = 30;
const RAD = Math.PI / 180;

/** Views the user can pick; home is where Reset goes. */
export const PRESETS = {
  home: {az: -60, el: 25, label: '3D (oblique)'},
  top: {az: -90, el: 90, label: 'top: x-y (hub plane)'},
  front: {az: -90, el: 0, label: 'front: x-z'},
  side: {az: 0, el: 0, label: 'side: y-z'},
};

export function homeCamera() {
  return {az: PRESETS.home.az, el: PRESETS.home.el};
}

/** Screen axes of a camera (unit vectors in hub coordinates). */
export function screenAxes(cam) {
  const a = cam.az * RAD, e = cam.el * RAD;
  const ca = Math.cos(a), sa = Math.sin(a), ce = Math.cos(e), se = Math.sin(e);
  return {right: [-sa, ca, 0], up: [-se * ca, -se * sa, ce], toward: [ce * ca, ce * sa, se]};
}

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

/**
 * World (m) to SVG (px) for the points given: pivot at the centre of their
 * bounding box, scale = min(fit at the home camera, fit at this camera).
 */
function projector(points, cam) {
  const lo = [0, 0, 0], hi = [0, 0, 0];
  for (const p of points) {
    for (let i = 0; i < 3; i++) {
      if (!Number.isFinite(p[i])) continue;
      lo[i] = Math.min(lo[i], p[i]);
      hi[i] = Math.max(hi[i], p[i]);
    }
  }
  const c = [0, 1, 2].map((i) => (lo[i] + hi[i]) / 2);
  const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-9);
  const fit = (k) => {
    const ax = screenAxes(k);
    let hx = 0.05 * size, hy = 0.05 * size;
    for (const p of points) {
      const d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
      if (!d.every(Number.isFinite)) continue;
      hx = Math.max(hx, Math.abs(dot(d, ax.right)));
      hy = Math.max(hy, Math.abs(dot(d, ax.up)));
    }
    return Math.min((W / 2 - PAD) / hx, (H / 2 - PAD) / hy);
  };
  const s = Math.min(fit(PRESETS.home), fit(cam));
  const ax = screenAxes(cam);
  const f = (p) => {
    const d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
    return [W / 2 + s * dot(d, ax.right), H / 2 - s * dot(d, ax.up)];
  };
  f.scale = s;
  f.size = size;
  f.axes = ax;
  return f;
}

/** The largest side of the bounding box of the points and the origin (the planar view's size). */
function extent(points) {
  const lo = [0, 0, 0], hi = [0, 0, 0];
  for (const p of points) {
    for (let i = 0; i < 3; i++) {
      if (!Number.isFinite(p[i])) continue;
      lo[i] = Math.min(lo[i], p[i]);
      hi[i] = Math.max(hi[i], p[i]);
    }
  }
  return Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-9);
}

/** "x y" pairs of a polyline. */
function pts2(list) {
  return list.map((p) => `${r2(p[0])},${r2(p[1])}`).join(' ');
}

/** A circle of radius r in the plane z = z0 about the hub axis, as screen points. */
function circle(f, r, z0 = 0, a0 = 0, a1 = 2 * Math.PI, n = 64) {
  const out = [];
  for (let i = 0; i <= n; i++) {
    const a = a0 + ((a1 - a0) * i) / n;
    out.push(f([r * Math.cos(a), r * Math.sin(a), z0]));
  }
  return out;
}

/** Points the drawing of the hub axis needs in view (its ends: see hub()). */
function axisPoints(size) {
  return [[0, 0, -0.35 * 0.3 * size], [0, 0, 0.3 * size]];
}

/**
 * The hub axis (z) with the spin arrow, the hub circle, and the plane of
 * rotation swept by the structure (a faint floor: it is not fitted into the
 * view, so it may run off its edges).
 */
function hub(g, f, hubR, discR, size) {
  if (discR > 0) el('polygon', {points: pts2(circle(f, discR)), class: 'disc'}, g);
  if (hubR > 0) el('polyline', {points: pts2(circle(f, hubR)), class: 'hub'}, g);
  const h = 0.3 * size;
  const [x0, y0] = f([0, 0, -0.35 * h]), [x1, y1] = f([0, 0, h]);
  el('line', {x1: r2(x0), y1: r2(y0), x2: r2(x1), y2: r2(y1), class: 'axis-line', 'marker-end': 'url(#arrow)'}, g);
  // Ω positive about z: an arc turning counter-clockwise seen from +z
  const r = Math.max(0.06 * size, 14 / f.scale);
  el('polyline', {points: pts2(circle(f, r, 0.7 * h, -2.4, 1.6, 24)), class: 'spin', 'marker-end': 'url(#arrow)'}, g);
  const t = el('text', {x: r2(x1 + 6), y: r2(y1 + 4), class: 'label axis-label'}, g);
  t.textContent = 'Ω, z';
}

/** The x, y, z triad in the lower left corner (z = spin axis). */
function triad(g, cam) {
  const ax = screenAxes(cam);
  const ox = 34, oy = H - 30, L = 22;
  const grp = el('g', {class: 'triad'}, g);
  [['x', [1, 0, 0]], ['y', [0, 1, 0]], ['z', [0, 0, 1]]].forEach(([name, v]) => {
    const dx = L * dot(v, ax.right), dy = -L * dot(v, ax.up);
    el('line', {x1: ox, y1: oy, x2: r2(ox + dx), y2: r2(oy + dy), class: `triad-${name}`}, grp);
    const len = Math.hypot(dx, dy);
    const k = len > 1e-6 ? (len + 8) / len : 0;
    const t = el('text', {x: r2(ox + dx * k - 3), y: r2(oy + dy * k + 4), class: `label triad-label triad-${name}`}, grp);
    t.textContent = name;
  });
}

/** The clamp: a hatched square plate normal to the first member. */
function clampPlate(g, f, at, dir) {
  const n = Math.hypot(...dir) || 1;
  const e = dir.map((c) => c / n);
  // two unit vectors normal to e
  const ref = Math.abs(e[2]) < 0.9 ? [0, 0, 1] : [1, 0, 0];
  let u = [e[1] * ref[2] - e[2] * ref[1], e[2] * ref[0] - e[0] * ref[2], e[0] * ref[1] - e[1] * ref[0]];
  const un = Math.hypot(...u);
  u = u.map((c) => c / un);
  const v = [e[1] * u[2] - e[2] * u[1], e[2] * u[0] - e[0] * u[2], e[0] * u[1] - e[1] * u[0]];
  const h = 13 / f.scale;
  const corner = (a, b) => f([at[0] + h * (a * u[0] + b * v[0]), at[1] + h * (a * u[1] + b * v[1]),
    at[2] + h * (a * u[2] + b * v[2])]);
  const grp = el('g', {class: 'clamp'}, g);
  const poly = [corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1)];
  el('polygon', {points: pts2(poly), fill: 'url(#hatch)', class: 'clamp-fill'}, grp);
  el('polygon', {points: pts2(poly), class: 'clamp-wall'}, grp);
}

/** [x, y, z] of an equilibrium row (planar rows [x, y, φ] have z = 0). */
export function rowXYZ(row) {
  return [row[0], row[1], row.length >= 6 ? row[2] : 0];
}

/** [dx, dy, dz] of a shape row (planar rows [dx, dy, dφ] have dz = 0). */
function rowD(row) {
  if (!row) return [0, 0, 0];
  return [row[0] ?? 0, row[1] ?? 0, row.length >= 6 ? row[2] ?? 0 : 0];
}

/**
 * Draw the structure in 3D into svg (the arguments of drawing.js drawStructure,
 * plus the camera).  Sets data-view="3d", data-az, data-el and data-scale.
 */
export function drawStructure3d(svg, st, mesh, cam, opts = {}) {
  clear(svg);
  defs(svg);
  svg.dataset.view = '3d';
  svg.dataset.az = String(cam.az);
  svg.dataset.el = String(cam.el);
  const P = (v) => xyz(v);
  const eq = opts.equilibrium && mesh.ok && opts.equilibrium.length === mesh.nodes.length ? opts.equilibrium : null;
  const pts = Object.values(mesh.joints).map(P);
  if (eq) for (const n of eq) pts.push(rowXYZ(n));
  const clampAt = mesh.joints[st && st.clamp] ? P(mesh.joints[st.clamp]) : null;
  const hubR = clampAt ? Math.hypot(clampAt[0], clampAt[1]) : 0;
  let discR = hubR;
  for (const p of pts) discR = Math.max(discR, Math.hypot(p[0], p[1]));
  if (hubR > 0) pts.push([hubR, 0, 0], [-hubR, 0, 0], [0, hubR, 0], [0, -hubR, 0]);
  const size = extent(pts);
  pts.push(...axisPoints(size));
  const f = projector(pts, cam);
  svg.dataset.scale = String(f.scale);

  const g = el('g', {}, svg);
  hub(g, f, hubR, discR, size);

  // out of the hub plane: the members' shadows on it and drop lines from the joints
  const sh = el('g', {class: 'shadows'}, g);
  for (const [a, b] of mesh.lines) {
    const A = P(a), B = P(b);
    if (A[2] === 0 && B[2] === 0) continue;
    const [x1, y1] = f([A[0], A[1], 0]), [x2, y2] = f([B[0], B[1], 0]);
    el('line', {x1: r2(x1), y1: r2(y1), x2: r2(x2), y2: r2(y2), class: 'shadow'}, sh);
  }
  for (const xy of Object.values(mesh.joints)) {
    const p = P(xy);
    if (p[2] === 0) continue;
    const [x1, y1] = f(p), [x2, y2] = f([p[0], p[1], 0]);
    el('line', {x1: r2(x1), y1: r2(y1), x2: r2(x2), y2: r2(y2), class: 'drop'}, sh);
  }

  for (const [a, b, i] of mesh.lines) {
    const [x1, y1] = f(P(a)), [x2, y2] = f(P(b));
    const ln = el('line', {x1: r2(x1), y1: r2(y1), x2: r2(x2), y2: r2(y2), class: eq ? 'member faded' : 'member'}, g);
    const m = st.members[i];
    const t = el('title', {}, ln);
    t.textContent = `member ${m.id ?? i}: ${m.from} → ${m.to}, ${m.elements} elements`;
  }
  if (mesh.ok && opts.nodes) {
    for (const n of mesh.nodes) {
      const [x, y] = f([n.x, n.y, n.z]);
      el('circle', {cx: r2(x), cy: r2(y), r: 1.8, class: 'node'}, g);
    }
  }
  if (mesh.ok && opts.frames) {
    // each frame's section axes at its origin: e1 along the member, e3 the flap normal
    const L = Math.max(8, Math.min(20, 0.3 * (f.scale * f.size) / Math.max(4, Math.sqrt(mesh.frames.length) * 2))) / f.scale;
    const fg = el('g', {class: 'frames'}, g);
    for (const fr of mesh.frames) {
      if (!fr.axes) continue;
      const n = mesh.nodes[fr.node];
      const o = [n.x, n.y, n.z];
      const [x, y] = f(o);
      for (const [key, cls] of [['e1', 'frame-x'], ['e3', 'frame-z']]) {
        const e = fr.axes[key];
        const [x2, y2] = f([o[0] + L * e[0], o[1] + L * e[1], o[2] + L * e[2]]);
        el('line', {x1: r2(x), y1: r2(y), x2: r2(x2), y2: r2(y2), class: cls}, fg);
      }
    }
  }
  if (eq) {
    const d = elemPath(mesh.elems, (k) => f(rowXYZ(eq[k])));
    el('path', {d, class: 'equilibrium', id: 'equilibrium-path'}, g);
  }
  if (clampAt) {
    let dir = [1, 0, 0];
    const m0 = (st.members || []).find((m) => m && (m.from === st.clamp || m.to === st.clamp) &&
      mesh.joints[m.from] && mesh.joints[m.to]);
    if (m0) {
      const other = P(mesh.joints[m0.from === st.clamp ? m0.to : m0.from]);
      dir = [other[0] - clampAt[0], other[1] - clampAt[1], other[2] - clampAt[2]];
    }
    clampPlate(g, f, clampAt, dir);
  }
  for (const p of Array.isArray(st && st.point_masses) ? st.point_masses : []) {
    const at = p && mesh.joints[p.joint];
    if (!at) continue;
    const [x, y] = f(P(at));
    el('rect', {x: r2(x - 6), y: r2(y - 6), width: 12, height: 12, class: 'mass'}, g);
    const t = el('text', {x: r2(x + 9), y: r2(y + 16), class: 'label mass-label'}, g);
    t.textContent = `${p.mass} kg`;
  }
  for (const [name, xy] of Object.entries(mesh.joints)) {
    const [x, y] = f(P(xy));
    el('circle', {cx: r2(x), cy: r2(y), r: 4, class: 'joint'}, g);
    const t = el('text', {x: r2(x + 7), y: r2(y - 7), class: 'label'}, g);
    t.textContent = name;
  }
  triad(g, cam);
  if (eq && opts.eqLabel) {
    const t = el('text', {x: W - 8, y: H - 8, class: 'label legend-eq', 'text-anchor': 'end'}, g);
    t.textContent = opts.eqLabel;
  }
  if (!mesh.ok && mesh.reason) {
    const t = el('text', {x: 8, y: 16, class: 'label warn'}, g);
    t.textContent = `cannot mesh: ${mesh.reason}`;
  }
}

/**
 * The animated mode shape in 3D (drawing.js modeView, plus the camera).
 * u(θ) = Re((re + i·im)·e^{iθ}) = re·cos θ − im·sin θ on the translations
 * (dx, dy, dz), scaled by amp·size as in the planar view.  frame(θ) redraws
 * it; last() is what the last frame drew: {theta, amp (m per unit of the
 * shape), world: [[x, y, z]…] per node, screen: [[X, Y]…] per node (the
 * points of #mode-path)}.  The shadow of the mode on the hub plane makes flap
 * (z) motion readable in any view.
 */
export function modeView3d(svg, mesh, eq, shape, amp, cam) {
  clear(svg);
  defs(svg);
  svg.dataset.view = '3d';
  svg.dataset.az = String(cam.az);
  svg.dataset.el = String(cam.el);
  const n = mesh.nodes.length;
  const re = shape && Array.isArray(shape.re) ? shape.re : null;
  const im = shape && Array.isArray(shape.im) ? shape.im : null;
  const base = eq && eq.length === n ? eq.map(rowXYZ) : mesh.nodes.map((p) => [p.x, p.y, p.z]);
  const und = mesh.nodes.map((p) => [p.x, p.y, p.z]);
  const size = extent(base);
  const A = amp * size;
  const pts = base.concat(und, axisPoints(size));
  for (const p of base) {
    for (let i = 0; i < 3; i++) {
      const q = p.slice(), r = p.slice();
      q[i] -= A;
      r[i] += A;
      pts.push(q, r);
    }
  }
  const f = projector(pts, cam);
  svg.dataset.scale = String(f.scale);
  const g = el('g', {}, svg);
  let discR = 0;
  for (const p of base) discR = Math.max(discR, Math.hypot(p[0], p[1]));
  hub(g, f, 0, discR, size);
  el('path', {d: elemPath(mesh.elems, (k) => f(und[k])), class: 'member ghost'}, g);
  el('path', {d: elemPath(mesh.elems, (k) => f(base[k])), class: 'equilibrium thin'}, g);
  const shadow = el('path', {d: '', class: 'mode-shadow', id: 'mode-shadow'}, g);
  const modePath = el('path', {d: '', class: 'mode', id: 'mode-path'}, g);
  triad(g, cam);
  const ok = !!(re && re.length === n);
  let last = null;
  function frame(theta) {
    if (!ok) return;
    const c = Math.cos(theta), s = Math.sin(theta);
    const world = base.map((b, k) => {
      const r = rowD(re[k]), i = rowD(im && im[k]);
      return [0, 1, 2].map((j) => b[j] + A * (r[j] * c - i[j] * s));
    });
    const screen = world.map(f);
    modePath.setAttribute('d', elemPath(mesh.elems, (k) => screen[k]));
    shadow.setAttribute('d', elemPath(mesh.elems, (k) => f([world[k][0], world[k][1], 0])));
    last = {theta, amp: A, world, screen};
  }
  frame(0);
  return {frame, ok, last: () => last};
}

/**
 * Turn the view of svg by dragging (pointer), with the arrow keys (5° a
 * press) and Home / double click (back to the home view).  Only while the svg
 * shows the 3D view (data-view="3d").  getCam() is the shared camera,
 * changed(how) is called after it changed ('drag', 'key', 'reset').
 */
export function attachOrbit(svg, getCam, changed) {
  let drag = null;
  const active = () => svg.dataset.view === '3d';
  const clampEl = (v) => Math.max(-90, Math.min(90, v));
  const wrap = (v) => ((((v + 180) % 360) + 360) % 360) - 180;
  svg.addEventListener('pointerdown', (ev) => {
    if (!active() || ev.button !== 0) return;
    drag = {x: ev.clientX, y: ev.clientY, id: ev.pointerId};
    svg.setPointerCapture(ev.pointerId);
    svg.classList.add('dragging');
    ev.preventDefault();
  });
  svg.addEventListener('pointermove', (ev) => {
    if (!drag || ev.pointerId !== drag.id) return;
    const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
    if (dx === 0 && dy === 0) return;
    drag.x = ev.clientX;
    drag.y = ev.clientY;
    const cam = getCam();
    cam.az = wrap(cam.az - 0.5 * dx);
    cam.el = clampEl(cam.el + 0.5 * dy);
    changed('drag');
  });
  const end = (ev) => {
    if (!drag || ev.pointerId !== drag.id) return;
    drag = null;
    svg.classList.remove('dragging');
  };
  svg.addEventListener('pointerup', end);
  svg.addEventListener('pointercancel', end);
  svg.addEventListener('dblclick', () => {
    if (!active()) return;
    Object.assign(getCam(), homeCamera());
    changed('reset');
  });
  svg.addEventListener('keydown', (ev) => {
    if (!active()) return;
    const cam = getCam();
    const step = {ArrowLeft: [5, 0], ArrowRight: [-5, 0], ArrowUp: [0, -5], ArrowDown: [0, 5]}[ev.key];
    if (step) {
      cam.az = wrap(cam.az + step[0]);
      cam.el = clampEl(cam.el + step[1]);
      changed('key');
    } else if (ev.key === 'Home') {
      Object.assign(cam, homeCamera());
      changed('reset');
    } else {
      return;
    }
    ev.preventDefault();
  });
}
