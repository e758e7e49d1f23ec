// spanwise.js — span-wise mode shapes in the page (DESIGN.md 8.3).
//
// The daemon writes them from a stored spatial result with mode shapes
// (GET /v1/analyses/{id}/result?format=spanwise|bmodes; 409 for any other
// result), so the page only offers them where the result has
// `model.members`.  For a blade (members in one straight chain from the root
// to the tip: the blade form, or BModes' own mesh) the selected mode's flap,
// edge and twist are plotted against the span fraction, read from that CSV.

const NS = 'http://www.w3.org/2000/svg';

/**
 * Can the daemon give span-wise shapes for this result?  {ok: true} or
 * {ok: false, why} (the tooltip of the disabled downloads).
 */
export function spanwiseAvailability(id, result) {
  const md = (result && result.model) || {};
  if (md.spatial !== true) {
    return {ok: false, why: 'A planar result has no span-wise shapes: flap, edge and twist need a spatial model ' +
      '(the daemon answers 409 here).'};
  }
  if (!Array.isArray(md.members) || md.members.length === 0) {
    return {ok: false, why: 'This result has no mode shapes: turn "mode shapes" on and solve again ' +
      '(the daemon answers 409 here).'};
  }
  if (!id || /^file/.test(id)) {
    return {ok: false, why: 'Opened from a file, not a job of this daemon: solve it (or Reopen the job) to download these.'};
  }
  return {ok: true, why: ''};
}

/** One CSV line into fields ("…" quoted fields with "" inside). */
function csvFields(line) {
  const out = [];
  let i = 0;
  while (i <= line.length) {
    if (line[i] === '"') {
      let v = '';
      i++;
      while (i < line.length) {
        if (line[i] === '"' && line[i + 1] === '"') {
          v += '"';
          i += 2;
        } else if (line[i] === '"') {
          i++;
          break;
        } else v += line[i++];
      }
      out.push(v);
      i++; // the comma
    } else {
      const j = line.indexOf(',', i);
      const e = j < 0 ? line.length : j;
      out.push(line.slice(i, e));
      i = e + 1;
    }
  }
  return out;
}

/** The daemon's span-wise CSV as rows {omega, rpm, mode, …, member_id (text), s, r_m, flap, …} (numbers). */
export function parseSpanwise(text) {
  const lines = text.split(/\r?\n/).filter((l) => l !== '');
  if (!lines.length) return [];
  const head = csvFields(lines[0]);
  return lines.slice(1).map((l) => {
    const f = csvFields(l);
    const r = {};
    head.forEach((h, k) => {
      r[h] = h === 'member_id' ? f[k] : Number(f[k]);
    });
    return r;
  });
}

/**
 * The members of model.members as one straight chain root → tip (a blade):
 * [{member, offset, length}] with offsets along the chain, and the total
 * length; null for any other structure (branches, corners, loose members).
 */
export function bladeChain(members) {
  if (!Array.isArray(members) || !members.length) return null;
  const first = (m) => m.nodes[0], last = (m) => m.nodes[m.nodes.length - 1];
  if (!members.every((m) => Array.isArray(m.nodes) && m.nodes.length >= 2 && Array.isArray(m.axes) &&
      m.axes.length === 9 && typeof m.length === 'number' && m.length > 0)) return null;
  const ends = new Set(members.map(last));
  const roots = members.filter((m) => !ends.has(first(m)));
  if (roots.length !== 1) return null;
  const byStart = new Map();
  for (const m of members) {
    if (byStart.has(first(m))) return null; // a branch
    byStart.set(first(m), m);
  }
  const e1 = roots[0].axes.slice(0, 3);
  const out = [];
  let m = roots[0], offset = 0;
  while (m && out.length < members.length) {
    const a = m.axes;
    if (Math.abs(a[0] * e1[0] + a[1] * e1[1] + a[2] * e1[2] - 1) > 1e-6) return null; // a corner
    out.push({member: m.member, offset, length: m.length});
    offset += m.length;
    m = byStart.get(last(m));
  }
  return out.length === members.length ? {parts: out, length: offset} : null;
}

/**
 * The points of one mode at one speed along the chain: [{x (span fraction),
 * flap, edge, twist}], root to tip, a shared joint once.
 */
export function spanPoints(rows, chain, omega, mode) {
  const tol = 1e-9 * Math.max(1, Math.abs(omega));
  const at = new Map(chain.parts.map((p) => [p.member, p]));
  const pts = [];
  for (const r of rows) {
    if (r.mode !== mode || Math.abs(r.omega - omega) > tol) continue;
    const p = at.get(r.member);
    if (!p) continue;
    pts.push({x: (p.offset + r.s * p.length) / chain.length, flap: r.flap, edge: r.edge, twist: r.twist});
  }
  pts.sort((a, b) => a.x - b.x);
  return pts.filter((p, i) => i === 0 || p.x - pts[i - 1].x > 1e-12);
}

function el(name, attrs, parent) {
  const e = document.createElementNS(NS, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  if (parent) parent.append(e);
  return e;
}

function text(parent, x, y, t, cls, anchor = 'middle') {
  const e = el('text', {x, y, class: cls, 'text-anchor': anchor}, parent);
  e.textContent = t;
  return e;
}

/** Round tick values over [lo, hi] (about n of them). */
function ticks(lo, hi, n = 4) {
  const span = hi - lo;
  const raw = span / n;
  const p = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((k) => k * p).find((s) => s >= raw) || raw;
  const out = [];
  for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step) out.push(Math.abs(v) < 1e-12 * step ? 0 : v);
  return out;
}

function fmt(v) {
  return Number(v.toPrecision(3)).toString();
}

/** The smallest span of the axes: displacement (m; modes are scaled to 1 m) and twist (rad, about 0.6°). */
export const MIN_SPAN = {displacement: 0.1, twist: 0.01};

/**
 * A range [lo, hi] holding 0 and every value, a little wider; at least
 * minSpan wide (a mode without twist does not stretch its axis to ±1 rad:
 * a flat line in a small range), centred on the values where widened.
 */
function range(vals, minSpan) {
  let lo = Math.min(0, ...vals), hi = Math.max(0, ...vals);
  if (hi - lo < minSpan) {
    const mid = (lo + hi) / 2;
    lo = Math.min(lo, mid - minSpan / 2);
    hi = Math.max(hi, mid + minSpan / 2);
  }
  const pad = 0.06 * (hi - lo);
  return [lo - pad, hi + pad];
}

/**
 * The twist range: the values' own (range), or where they are smaller than
 * the minimum span, the displacement range d scaled to that span (0 at the
 * same height, so the zero lines agree without widening either axis).
 */
function twistRange(vals, d) {
  const lo = Math.min(0, ...vals), hi = Math.max(0, ...vals);
  if (hi - lo >= MIN_SPAN.twist) return range(vals, MIN_SPAN.twist);
  const k = MIN_SPAN.twist / (d[1] - d[0]);
  const r = [d[0] * k, d[1] * k];
  return lo >= r[0] && hi <= r[1] ? r : range(vals, MIN_SPAN.twist);
}

/** Widen the ranges so that 0 is at the same height on both axes (one zero line). */
function alignZero(a, b) {
  const below = (r) => -r[0] / (r[1] - r[0]);
  const p = Math.max(below(a), below(b));
  const q = Math.max(1 - below(a), 1 - below(b)); // the share above 0
  const fit = (r) => {
    const unit = Math.max(-r[0] / p, r[1] / q); // axis length per unit share
    return [-p * unit, q * unit];
  };
  return [fit(a), fit(b)];
}

export const SPAN_SERIES = [
  {key: 'flap', label: 'flap (m)', cls: 'sw-flap'},
  {key: 'edge', label: 'edge (m)', cls: 'sw-edge'},
  {key: 'twist', label: 'twist (rad, right axis)', cls: 'sw-twist'},
];

/**
 * Draw flap and edge (left axis, m: the mode scaled to 1 m at its largest)
 * and twist (right axis, rad) against the span fraction; labels renames
 * the legend's series ({flap: 'fore-aft (m)', …} for a tower).
 */
export function drawSpanwise(svg, pts, labels = {}) {
  svg.textContent = '';
  const W = 600, H = 200, L = 52, R = 56, T = 26, B = 34;
  const X = (x) => L + x * (W - L - R);
  const d0 = range(pts.flatMap((p) => [p.flap, p.edge]), MIN_SPAN.displacement);
  const [dr, tr] = alignZero(d0, twistRange(pts.map((p) => p.twist), d0));
  const Y = (v, r) => T + (r[1] - v) / (r[1] - r[0]) * (H - T - B);
  const g = el('g', {class: 'sw-axes'}, svg);
  el('rect', {x: L, y: T, width: W - L - R, height: H - T - B, class: 'sw-frame'}, g);
  for (const x of [0, 0.25, 0.5, 0.75, 1]) {
    el('line', {x1: X(x), x2: X(x), y1: T, y2: H - B, class: 'sw-grid'}, g);
    text(g, X(x), H - B + 14, fmt(x), 'sw-tick');
  }
  text(g, (L + W - R) / 2, H - 4, 'span fraction (root 0 → tip 1)', 'sw-title');
  for (const v of ticks(dr[0], dr[1])) {
    el('line', {x1: L, x2: W - R, y1: Y(v, dr), y2: Y(v, dr), class: v === 0 ? 'sw-zero' : 'sw-grid'}, g);
    text(g, L - 5, Y(v, dr) + 4, fmt(v), 'sw-tick', 'end');
  }
  for (const v of ticks(tr[0], tr[1])) text(g, W - R + 5, Y(v, tr) + 4, fmt(v), 'sw-tick sw-twist-tick', 'start');
  text(g, L - 5, T - 8, 'm', 'sw-title', 'end');
  text(g, W - R + 5, T - 8, 'rad', 'sw-title sw-twist-tick', 'start');
  let lx = L;
  for (const s of SPAN_SERIES) {
    const r = s.key === 'twist' ? tr : dr;
    el('polyline', {class: 'sw-line ' + s.cls, 'data-series': s.key,
      points: pts.map((p) => `${X(p.x).toFixed(2)},${Y(p[s.key], r).toFixed(2)}`).join(' ')}, svg);
    el('line', {x1: lx, x2: lx + 22, y1: 12, y2: 12, class: 'sw-line ' + s.cls}, svg);
    const label = labels[s.key] || s.label;
    const t = text(svg, lx + 27, 16, label, 'sw-legend', 'start');
    lx += 40 + label.length * 6.2;
    t.dataset.series = s.key;
  }
  return {displacement: dr, twist: tr};
}
