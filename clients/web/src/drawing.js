// drawing.js — SVG drawings of the structure (joints, members, clamp, hub
// axis, frames, point masses, the steady deflected shape) and of an animated
// mode shape.  These are drawings, not charts: the Campbell diagram is uPlot.
// This is the planar view (the hub plane x-y, seen along the spin axis); a
// spatial structure is drawn by view3d.js, which shares the helpers below.

const NS = 'http://www.w3.org/2000/svg';
const W = 600, H = 360, PAD = 34;

export function el(name, attrs = {}, parent = null) {
  const e = document.createElementNS(NS, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  if (parent) parent.appendChild(e);
  return e;
}

export function clear(svg) {
  while (svg.firstChild) svg.removeChild(svg.firstChild);
}

/** World (m, y up) to SVG (px, y down) for the points given, origin included. */
function mapper(points) {
  let x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  for (const [x, y] of points) {
    if (!Number.isFinite(x) || !Number.isFinite(y)) continue;
    x0 = Math.min(x0, x); x1 = Math.max(x1, x);
    y0 = Math.min(y0, y); y1 = Math.max(y1, y);
  }
  let dx = x1 - x0, dy = y1 - y0;
  const size = Math.max(dx, dy, 1e-9);
  // keep some room around a degenerate (straight) structure
  if (dx < size * 0.15) { x0 -= size * 0.075; x1 += size * 0.075; dx = x1 - x0; }
  if (dy < size * 0.15) { y0 -= size * 0.075; y1 += size * 0.075; dy = y1 - y0; }
  const s = Math.min((W - 2 * PAD) / dx, (H - 2 * PAD) / dy);
  const ox = (W - s * dx) / 2, oy = (H - s * dy) / 2;
  const f = (x, y) => [ox + (x - x0) * s, H - oy - (y - y0) * s];
  f.scale = s;
  f.size = size;
  return f;
}

export function r2(v) {
  return Math.round(v * 100) / 100;
}

/** "M x y L x y ..." of the elements with node positions pos(k) -> [x, y] (px). */
export function elemPath(elems, pos) {
  let d = '';
  let last = -1;
  for (const e of elems) {
    const a = pos(e.n1), b = pos(e.n2);
    if (!a || !b) continue;
    if (e.n1 !== last) d += `M${r2(a[0])} ${r2(a[1])}`;
    d += `L${r2(b[0])} ${r2(b[1])}`;
    last = e.n2;
  }
  return d;
}

function hubAxis(g, f, hubRadius) {
  const [cx, cy] = f(0, 0);
  if (hubRadius > 0) {
    el('circle', {cx, cy, r: hubRadius * f.scale, class: 'hub'}, g);
  }
  el('circle', {cx, cy, r: 7, class: 'axis'}, g);
  el('circle', {cx, cy, r: 2, class: 'axis-dot'}, g);
  // counter-clockwise arrow: Ω positive about z (out of the page)
  const R = 15;
  const a0 = (200 * Math.PI) / 180, a1 = (340 * Math.PI) / 180;
  const p = (a) => [cx + R * Math.cos(a), cy - R * Math.sin(a)];
  const [sx, sy] = p(a0), [ex, ey] = p(a1);
  el('path', {d: `M${r2(sx)} ${r2(sy)} A${R} ${R} 0 0 0 ${r2(ex)} ${r2(ey)}`, class: 'spin', 'marker-end': 'url(#arrow)'}, g);
  const t = el('text', {x: cx - 24, y: cy + 24, class: 'label axis-label'}, g);
  t.textContent = 'Ω';
}

export function defs(svg) {
  const d = el('defs', {}, svg);
  const m = el('marker', {id: 'arrow', viewBox: '0 0 10 10', refX: 8, refY: 5, markerWidth: 6, markerHeight: 6,
    orient: 'auto-start-reverse'}, d);
  el('path', {d: 'M0 0 L10 5 L0 10 z', class: 'arrowhead'}, m);
  const p = el('pattern', {id: 'hatch', width: 6, height: 6, patternUnits: 'userSpaceOnUse',
    patternTransform: 'rotate(45)'}, d);
  el('line', {x1: 0, y1: 0, x2: 0, y2: 6, class: 'hatch-line'}, p);
}

/** The clamp: a wall perpendicular to the first member, hatched behind it. */
function clampSymbol(g, f, at, dir) {
  const [cx, cy] = f(at[0], at[1]);
  const ang = Math.atan2(-(dir[1]), dir[0]); // svg angle of the member
  const deg = (ang * 180) / Math.PI;
  const grp = el('g', {transform: `translate(${r2(cx)} ${r2(cy)}) rotate(${r2(deg)})`, class: 'clamp'}, g);
  el('rect', {x: -9, y: -14, width: 9, height: 28, fill: 'url(#hatch)', class: 'clamp-fill'}, grp);
  el('line', {x1: 0, y1: -14, x2: 0, y2: 14, class: 'clamp-wall'}, grp);
}

/**
 * Draw the structure into svg.
 * mesh: buildMesh() of the structure; st: the structure object (point masses);
 * opts: {frames, nodes, equilibrium: [[x, y, phi], ...] | null, eqLabel}.
 */
export function drawStructure(svg, st, mesh, opts = {}) {
  clear(svg);
  defs(svg);
  const pts = Object.values(mesh.joints);
  const eq = opts.equilibrium && mesh.ok && opts.equilibrium.length === mesh.nodes.length ? opts.equilibrium : null;
  if (eq) for (const n of eq) pts.push([n[0], n[1]]);
  const clampXY = mesh.joints[st && st.clamp];
  const hubR = clampXY ? Math.hypot(clampXY[0], clampXY[1]) : 0; // a joint may carry z (seen from above)
  if (clampXY) pts.push([-hubR, -hubR], [hubR, hubR]);
  const f = mapper(pts.length ? pts : [[1, 1]]);
  svg.dataset.scale = String(f.scale);
  svg.dataset.view = 'plane';

  const g = el('g', {}, svg);
  hubAxis(g, f, hubR);

  // members (undeformed)
  for (const [a, b, i] of mesh.lines) {
    const [x1, y1] = f(a[0], a[1]), [x2, y2] = f(b[0], b[1]);
    const ln = el('line', {x1: r2(x1), y1: r2(y1), x2: r2(x2), y2: r2(y2), class: eq ? 'member faded' : 'member'}, g);
    const m = st.members[i];
    const t = el('title', {}, ln);
    t.textContent = `member ${m.id ?? i}: ${m.from} → ${m.to}, ${m.elements} elements`;
  }
  if (mesh.ok && opts.nodes) {
    for (const n of mesh.nodes) {
      const [x, y] = f(n.x, n.y);
      el('circle', {cx: r2(x), cy: r2(y), r: 1.8, class: 'node'}, g);
    }
  }
  if (mesh.ok && opts.frames) {
    const L = Math.max(10, Math.min(22, 0.35 * (f.scale * f.size) / Math.max(4, Math.sqrt(mesh.frames.length) * 2)));
    const fg = el('g', {class: 'frames'}, g);
    for (const fr of mesh.frames) {
      const n = mesh.nodes[fr.node];
      const [x, y] = f(n.x, n.y);
      const c = Math.cos(fr.angle), s = Math.sin(fr.angle);
      el('line', {x1: r2(x), y1: r2(y), x2: r2(x + L * c), y2: r2(y - L * s), class: 'frame-x'}, fg);
      el('line', {x1: r2(x), y1: r2(y), x2: r2(x - L * s), y2: r2(y - L * c), class: 'frame-y'}, fg);
    }
  }
  // steady deflected shape
  if (eq) {
    const d = elemPath(mesh.elems, (k) => f(eq[k][0], eq[k][1]));
    el('path', {d, class: 'equilibrium', id: 'equilibrium-path'}, g);
  }
  // clamp
  if (clampXY) {
    let dir = [1, 0];
    const m0 = (st.members || []).find((m) => m && (m.from === st.clamp || m.to === st.clamp) &&
      mesh.joints[m.from] && mesh.joints[m.to]);
    if (m0) {
      const other = mesh.joints[m0.from === st.clamp ? m0.to : m0.from];
      dir = [other[0] - clampXY[0], other[1] - clampXY[1]];
    }
    clampSymbol(g, f, clampXY, dir);
  }
  // point masses
  for (const p of Array.isArray(st && st.point_masses) ? st.point_masses : []) {
    const at = p && mesh.joints[p.joint];
    if (!at) continue;
    const [x, y] = f(at[0], at[1]);
    el('rect', {x: r2(x - 6), y: r2(y - 6), width: 12, height: 12, class: 'mass'}, g);
    const t = el('text', {x: r2(x + 9), y: r2(y + 16), class: 'label mass-label'}, g);
    t.textContent = `${p.mass} kg`;
  }
  // joints
  for (const [name, xy] of Object.entries(mesh.joints)) {
    const [x, y] = f(xy[0], xy[1]);
    el('circle', {cx: r2(x), cy: r2(y), r: 4, class: 'joint'}, g);
    const t = el('text', {x: r2(x + 7), y: r2(y - 7), class: 'label'}, g);
    t.textContent = name;
  }
  if (eq && opts.eqLabel) {
    const t = el('text', {x: 8, y: H - 8, class: 'label legend-eq'}, g);
    t.textContent = opts.eqLabel;
  }
  if (!mesh.ok && mesh.reason) {
    const t = el('text', {x: 8, y: 16, class: 'label warn'}, g);
    t.textContent = `cannot mesh: ${mesh.reason}`;
  }
}

/**
 * An animated mode-shape view: create with the mesh, the steady nodes and the
 * complex shape; frame(phase) redraws the mode at phase θ:
 * u(θ) = Re((re + i·im)·e^{iθ}) = re·cos θ − im·sin θ, scaled by amp·size.
 */
export function modeView(svg, mesh, eq, shape, amp) {
  clear(svg);
  defs(svg);
  svg.dataset.view = 'plane';
  const n = mesh.nodes.length;
  const re = shape && Array.isArray(shape.re) ? shape.re : null;
  const im = shape && Array.isArray(shape.im) ? shape.im : null;
  const base = eq && eq.length === n ? eq.map((p) => [p[0], p[1]]) : mesh.nodes.map((p) => [p.x, p.y]);
  const pts = base.slice();
  const f0 = mapper(pts);
  const A = amp * f0.size;
  for (const p of base) pts.push([p[0] - A, p[1] - A], [p[0] + A, p[1] + A]);
  const f = mapper(pts);
  const g = el('g', {}, svg);
  hubAxis(g, f, 0);
  el('path', {d: elemPath(mesh.elems, (k) => f(mesh.nodes[k].x, mesh.nodes[k].y)), class: 'member ghost'}, g);
  el('path', {d: elemPath(mesh.elems, (k) => f(base[k][0], base[k][1])), class: 'equilibrium thin'}, g);
  const modePath = el('path', {d: '', class: 'mode', id: 'mode-path'}, g);
  const ok = re && re.length === n;
  function frame(theta) {
    if (!ok) return;
    const c = Math.cos(theta), s = Math.sin(theta);
    const pos = (k) => {
      const r = re[k], i = im && im[k] ? im[k] : [0, 0];
      return f(base[k][0] + A * ((r[0] ?? 0) * c - (i[0] ?? 0) * s), base[k][1] + A * ((r[1] ?? 0) * c - (i[1] ?? 0) * s));
    };
    modePath.setAttribute('d', elemPath(mesh.elems, pos));
  }
  frame(0);
  return {frame, ok};
}
