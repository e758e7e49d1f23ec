// campbell.js — the Campbell diagram (natural frequencies against speed) with
// engine-order lines kP (ω = k·Ω) and their crossings, drawn with uPlot, in
// the speed unit (rad/s | rpm) and frequency unit (rad/s | Hz | per rev) the
// page shows.
//
// uPlot wants one shared, sorted x array: it is the union of the solved
// speeds and the crossing speeds.  A mode's value is `undefined` at a
// crossing-only x (joined over) and `null` at a speed without trusted modes
// (a gap); the crossing series has values only at the crossings and no line.
//
// A speed whose case is not "solved" or carries warnings (its equilibrium is
// outside what the model describes) is "flagged": its modes are drawn as
// hollow grey circles (a draw hook), are not part of the mode lines and are
// never used for crossings.  The lines are the result's tracked modes
// (tracked_index, DESIGN.md 9.1), named by their labels; the result's
// crossing / veering flags, the daemon's critical speeds and error bars
// (error_estimate) are drawn by the hook.  Engine-order lines are grey, each with its own
// dash, and labelled where they leave the plot: the labels are elements of .u-over
// placed so that none overlaps another (placeLabels; export.js places the SVG's the
// same way).  When the modes reach far above the engine orders (blades: 4P at 1 Hz,
// modes at 8 Hz), the y range is fitted to the modes the orders cross and the next
// one above (yFocus); "show all modes" (allModes) goes back to every mode.  Dense
// sweeps (more than MARKER_MAX_SPEEDS speeds) are drawn as lines without point
// markers, and no series is rounded to whole pixels (pxAlign 0: no staircase).
// One speed is no diagram: the frequencies are a table with bars (singleSpeed).
// Drag selects a zoom box (x, y or both); double click resets.  A reference result (another design) can
// be overlaid: its modes are thin dashed lines.
//
// Divergence speeds (the result's divergence_speeds, present only when the
// sweep crossed one): where the steady state loses (onset) or regains
// (recovery) static stability, the lowest eigenvalue of K* passing through
// zero.  Each is a translucent red vertical band with a label ("divergence 1st
// torsion"), the statically unstable range (an onset to the next recovery or
// the end of the sweep) is shaded lightly.  Both are elements under uPlot's
// canvas (.u-under, so the lines stay on top; the labels are in .u-over),
// placed by the draw hook from the x scale, so they follow zoom and resize;
// divergenceSvg adds them to the exported SVG.

import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import {SPEED_UNITS, FREQ_UNITS} from './request.js';

const TWO_PI = 2 * Math.PI;
// Okabe–Ito and Tol colours: told apart by colour-blind readers, none of them black or grey
// (black rings mark crossings, grey is engine orders and flagged speeds)
export const COLORS = ['#0072b2', '#d55e00', '#009e73', '#cc79a7', '#e69f00', '#56b4e9', '#882255', '#117733',
  '#aa4499', '#999933'];
const EO_DASH = [[6, 4], [2, 3], [10, 3, 2, 3], [12, 6], [4, 2, 1, 2], [1, 2]];
const CROSS_STROKE = '#111111';
/** Above this many speeds the mode lines are drawn without point markers. */
export const MARKER_MAX_SPEEDS = 60;
const FLAG_STROKE = '#9ca3af';

/** Is a case flagged (not solved, or with warnings)? */
export function flaggedCase(c) {
  return c.status !== 'solved' || (Array.isArray(c.warnings) && c.warnings.length > 0);
}

/** A mode's Campbell line: its tracked_index (DESIGN.md 9.1), else its sorted index (a result without tracking). */
export function lineOf(md, k) {
  return md && Number.isInteger(md.tracked_index) ? md.tracked_index : k;
}

/**
 * Cases sorted by speed and the Campbell lines (tracked modes):
 * {rows: [{omega, rpm, status, flagged, modes, byLine: Map(line -> mode)}],
 *  lines: [{id, label, name}], nModes}.  A line is named by the label of its
 * mode at the first speed where it appears ("1st flap"); a name taken twice
 * gets " (2)"; a line without labels is "mode k".
 */
export function campbellData(result) {
  const cases = (result && Array.isArray(result.cases) ? result.cases : [])
    .filter((c) => typeof c.omega === 'number')
    .slice()
    .sort((a, b) => a.omega - b.omega);
  const nModes = cases.reduce((m, c) => Math.max(m, Array.isArray(c.modes) ? c.modes.length : 0), 0);
  const first = new Map(); // line -> label at its first speed
  const rows = cases.map((c) => {
    const modes = Array.isArray(c.modes) ? c.modes : [];
    const byLine = new Map();
    modes.forEach((md, k) => {
      if (!md || typeof md.frequency_rad_s !== 'number') return;
      const l = lineOf(md, k);
      byLine.set(l, md);
      if (!first.has(l)) first.set(l, typeof md.label === 'string' ? md.label : null);
    });
    return {omega: c.omega, rpm: typeof c.rpm === 'number' ? c.rpm : c.omega * 60 / TWO_PI, status: c.status,
      flagged: flaggedCase(c), modes, byLine};
  });
  const used = new Map();
  const lines = Array.from(first.keys()).sort((a, b) => a - b).map((id) => {
    const label = first.get(id);
    const base = label || `mode ${id + 1}`;
    const n = (used.get(base) || 0) + 1;
    used.set(base, n);
    return {id, label, name: n === 1 ? base : `${base} (${n})`};
  });
  return {rows, lines, nModes};
}

/**
 * Crossings of the Campbell lines with the engine-order lines ω = k·Ω, k in
 * orders: a sign change of ω_line(Ω) − k·Ω between two consecutive speeds that
 * are both unflagged and both hold the line, interpolated linearly (rad/s).
 * [{line, name, order, omega, freq (rad/s)}].
 */
export function crossings(rows, lines, orders) {
  const out = [];
  for (const ln of lines) {
    for (const k of orders) {
      for (let i = 0; i + 1 < rows.length; i++) {
        const a = rows[i], b = rows[i + 1];
        if (a.flagged || b.flagged) continue;
        const ma = a.byLine.get(ln.id), mb = b.byLine.get(ln.id);
        if (!ma || !mb) continue;
        const da = ma.frequency_rad_s - k * a.omega, db = mb.frequency_rad_s - k * b.omega;
        if (da === 0 && i > 0 && !rows[i - 1].flagged && rows[i - 1].byLine.has(ln.id)) continue; // the previous interval's end
        if (da === 0 || db === 0 || (da < 0) !== (db < 0)) {
          const t = da === db ? 0 : da / (da - db);
          const om = a.omega + t * (b.omega - a.omega);
          out.push({line: ln.id, name: ln.name, order: k, omega: om, freq: k * om});
        }
      }
    }
  }
  return out.sort((p, q) => p.omega - q.omega || p.line - q.line);
}

/**
 * The result's tracking flags as markers: one per flagged pair of lines at a
 * speed (DESIGN.md 9.1).  When the pair swapped order since the previous
 * speed holding both, the marker is where their straight segments meet;
 * otherwise (a veering at its closest approach) at the flagged speed, midway.
 * Flagged speeds (warnings, unsolved) give none.  [{kind, lines: [a, b], names, omega, freq}].
 */
export function trackingMarks(rows, lines) {
  const name = new Map(lines.map((l) => [l.id, l.name]));
  const out = [];
  const seen = new Set();
  rows.forEach((r, i) => {
    if (r.flagged) return;
    for (const [a, md] of r.byLine) {
      const b = md.tracking_partner;
      if ((md.tracking_flag !== 'crossing' && md.tracking_flag !== 'veering') || !Number.isInteger(b) || !r.byLine.has(b)) continue;
      const key = `${i}:${Math.min(a, b)}:${Math.max(a, b)}`;
      if (seen.has(key)) continue;
      seen.add(key);
      const fa = md.frequency_rad_s, fb = r.byLine.get(b).frequency_rad_s;
      let omega = r.omega, freq = (fa + fb) / 2;
      let j = i - 1;
      while (j >= 0 && !(rows[j].byLine.has(a) && rows[j].byLine.has(b))) j--;
      if (j >= 0) {
        const p = rows[j];
        const da = p.byLine.get(a).frequency_rad_s - p.byLine.get(b).frequency_rad_s, db = fa - fb;
        if ((da < 0) !== (db < 0) && da !== db) {
          const t = da / (da - db);
          omega = p.omega + t * (r.omega - p.omega);
          freq = p.byLine.get(a).frequency_rad_s + t * (fa - p.byLine.get(a).frequency_rad_s);
        }
      }
      const pair = [Math.min(a, b), Math.max(a, b)];
      out.push({kind: md.tracking_flag, lines: pair, names: pair.map((l) => name.get(l) || `mode ${l + 1}`),
        omega, freq, at: r.omega});
    }
  });
  return out;
}

/** A mode's frequency in unit fu at a case (the result's own per_rev / Hz when it has them). */
export function freqIn(fu, md, omega) {
  if (!md || typeof md.frequency_rad_s !== 'number') return null;
  if (fu === 'hz' && typeof md.frequency_hz === 'number') return md.frequency_hz;
  if (fu === 'rev' && 'per_rev' in md) return typeof md.per_rev === 'number' ? md.per_rev : null;
  return FREQ_UNITS[fu].of(md.frequency_rad_s, omega);
}

/** A mode's error_estimate (rad/s) in unit fu at speed omega, or null (none, or per rev at rest). */
export function errIn(fu, md, omega) {
  if (!md || typeof md.error_estimate !== 'number') return null;
  return FREQ_UNITS[fu].of(md.error_estimate, omega);
}

/** A case's speed in unit su (the result's own rpm when it has it). */
export function speedIn(su, row) {
  return su === 'rpm' ? row.rpm : row.omega;
}

/**
 * The result's divergence speeds (divergence_speeds; [] without them), sorted
 * by speed: [{omega (rad/s), rpm, mode, kind ('onset' | 'recovery'), bracket
 * ([lo, hi] rad/s or null), negative ([before, after] or null), refined,
 * refineSolves, omegaInterpolated}].
 */
export function divergenceSpeeds(result) {
  const ds = result && Array.isArray(result.divergence_speeds) ? result.divergence_speeds : [];
  const num = (v) => typeof v === 'number' && Number.isFinite(v);
  return ds.filter((d) => d && num(d.omega_rad_s)).map((d) => ({
    omega: d.omega_rad_s,
    rpm: num(d.rpm) ? d.rpm : d.omega_rad_s * 60 / TWO_PI,
    mode: typeof d.mode === 'string' && d.mode ? d.mode : null,
    kind: d.kind === 'recovery' ? 'recovery' : 'onset',
    bracket: Array.isArray(d.bracket) && d.bracket.length === 2 && d.bracket.every(num) ? d.bracket.slice() : null,
    negative: Array.isArray(d.negative_eigenvalues) && d.negative_eigenvalues.length === 2 &&
      d.negative_eigenvalues.every(Number.isInteger) ? d.negative_eigenvalues.slice() : null,
    refined: d.refined === true,
    refineSolves: Number.isInteger(d.refine_solves) ? d.refine_solves : null,
    omegaInterpolated: num(d.omega_interpolated) ? d.omega_interpolated : null,
  })).sort((a, b) => a.omega - b.omega);
}

/** A divergence speed's label on the diagram: "divergence 1st torsion" ("… ends" at a recovery). */
export function divergenceLabel(d) {
  return `divergence ${d.mode || 'mode'}${d.kind === 'recovery' ? ' ends' : ''}`;
}

/**
 * The speed ranges (rad/s) where the steady state is statically unstable (K*
 * has negative eigenvalues): from an onset to the next recovery, or to the end
 * of the sweep; before a first recovery, from the start of the sweep.  The
 * count of negative eigenvalues is each entry's negative_eigenvalues, else
 * counted by kind.  [{from, to}] within [rows' first, last speed].
 */
export function unstableRanges(divs, rows) {
  if (!divs.length || !rows.length) return [];
  const lo = rows[0].omega, hi = rows[rows.length - 1].omega;
  let count = divs[0].negative ? divs[0].negative[0] : divs[0].kind === 'recovery' ? 1 : 0;
  let start = count > 0 ? lo : null;
  const out = [];
  for (const d of divs) {
    const after = d.negative ? d.negative[1] : Math.max(0, count + (d.kind === 'onset' ? 1 : -1));
    if (start === null && after > 0) start = d.omega;
    else if (start !== null && after <= 0) {
      out.push({from: start, to: d.omega});
      start = null;
    }
    count = after;
  }
  if (start !== null && hi > start) out.push({from: start, to: hi});
  return out.filter((r) => r.to > r.from);
}

/**
 * The aligned uPlot data for rows, lines, orders, units {speed, freq}, the
 * daemon's critical speeds {orders (covered), points} and an optional
 * reference {rows, lines}: [x, lines…, orders…, crossings, critical, tracking
 * marks, ref lines…], with meta[i] = {kind, line?} for each column.  The
 * divergence speeds (divergenceSpeeds) are no column: div [{…, x, label}] and
 * unstable [{from, to, x0, x1}] (x in the speed unit) are drawn by the hook.
 */
export function plotData(rows, lines, orders, units, ref = null, critical = null, divergence = []) {
  const su = units.speed, fu = units.freq;
  const covered = new Set(critical ? critical.orders : []);
  const cross = crossings(rows, lines, orders.filter((k) => !covered.has(k)));
  const crit = (critical ? critical.points : []).filter((c) => orders.includes(c.order));
  const marks = trackingMarks(rows, lines);
  const xOf = (omega) => SPEED_UNITS[su].of(omega);
  const yOf = (w, omega, order) => (fu === 'rev' && order !== undefined ? order : FREQ_UNITS[fu].of(w, omega));
  const pts = new Map(); // x -> omega (rad/s)
  for (const r of rows) pts.set(speedIn(su, r), r.omega);
  for (const c of cross) pts.set(xOf(c.omega), c.omega);
  for (const c of crit) pts.set(su === 'rpm' && typeof c.rpm === 'number' ? c.rpm : xOf(c.omega), c.omega);
  for (const m of marks) pts.set(xOf(m.omega), m.omega);
  const refRows = ref ? ref.rows : [];
  for (const r of refRows) pts.set(speedIn(su, r), r.omega);
  const xs = Array.from(pts.keys()).sort((a, b) => a - b);
  const at = new Map(rows.map((r) => [speedIn(su, r), r]));
  const data = [xs];
  const meta = [{kind: 'x'}];
  const errbars = [];
  for (const ln of lines) {
    data.push(xs.map((x) => {
      const r = at.get(x);
      if (!r) return undefined;
      if (r.flagged) return null;
      const md = r.byLine.get(ln.id);
      if (!md) return null; // the line is not in the window here: a gap
      const y = freqIn(fu, md, r.omega);
      const e = errIn(fu, md, r.omega);
      if (y !== null && e !== null) errbars.push({x, y, e, line: ln.id, name: ln.name});
      return y;
    }));
    meta.push({kind: 'mode', line: ln.id, name: ln.name});
  }
  for (const k of orders) {
    data.push(xs.map((x) => (fu === 'rev' ? k : FREQ_UNITS[fu].of(k * pts.get(x), pts.get(x)))));
    meta.push({kind: 'eo', order: k});
  }
  const column = (items, xf, yf) => {
    const m = new Map(items.map((c) => [xf(c), yf(c)]));
    return xs.map((x) => (m.has(x) ? m.get(x) : undefined));
  };
  data.push(column(cross, (c) => xOf(c.omega), (c) => yOf(c.freq, c.omega, c.order)));
  meta.push({kind: 'crossings'});
  const critX = (c) => (su === 'rpm' && typeof c.rpm === 'number' ? c.rpm : xOf(c.omega));
  data.push(column(crit, critX, (c) => yOf(c.freq, c.omega, c.order)));
  meta.push({kind: 'critical'});
  data.push(column(marks, (m) => xOf(m.omega), (m) => yOf(m.freq, m.omega)));
  meta.push({kind: 'tracking'});
  if (ref) {
    const rat = new Map(refRows.map((r) => [speedIn(su, r), r]));
    for (const ln of ref.lines) {
      data.push(xs.map((x) => {
        const r = rat.get(x);
        if (!r) return undefined;
        if (r.flagged) return null;
        return freqIn(fu, r.byLine.get(ln.id), r.omega);
      }));
      meta.push({kind: 'ref', line: ln.id, name: ln.name});
    }
  }
  // the flagged speeds' modes, drawn hollow by the hook
  const flagged = [];
  for (const r of rows) {
    if (!r.flagged) continue;
    for (const [l, md] of r.byLine) {
      const v = freqIn(fu, md, r.omega);
      if (v !== null) flagged.push({x: speedIn(su, r), y: v, line: l, status: r.status});
    }
  }
  const critPts = crit.map((c) => ({...c, x: critX(c), y: yOf(c.freq, c.omega, c.order)}));
  const markPts = marks.map((m) => ({...m, x: xOf(m.omega), y: yOf(m.freq, m.omega)}));
  const crossPts = cross.map((c) => ({...c, x: xOf(c.omega), y: yOf(c.freq, c.omega, c.order)}));
  const divX = (d) => (su === 'rpm' ? d.rpm : xOf(d.omega));
  const div = divergence.map((d) => ({...d, x: divX(d), label: divergenceLabel(d)}));
  const unstable = unstableRanges(divergence, rows).map((r) => ({...r, x0: xOf(r.from), x1: xOf(r.to)}));
  // the ends of the range in rpm: the result's own rpm where the end is a case or a divergence speed
  for (const r of unstable) {
    if (su !== 'rpm') continue;
    const at = (om) => div.find((d) => d.omega === om) || rows.find((q) => q.omega === om);
    if (at(r.from)) r.x0 = at(r.from).rpm;
    if (at(r.to)) r.x1 = at(r.to).rpm;
  }
  return {data, meta, cross: crossPts, crit: critPts, marks: markPts, flagged, errbars, div, unstable};
}

/**
 * The y range that keeps the engine orders readable.  top is where the
 * highest order line ends (at the highest speed shown); when it lies far below
 * the highest mode (blades: 4P at 1 Hz, modes up to 8 Hz) the range is fitted
 * to the lines that come below top somewhere (the orders cross them), the
 * lowest line above them (the margin to the next mode) and top itself.
 * Returns null when every mode fits (the fitted range would be more than 60 %
 * of the whole), else {top (the fitted maximum), hidden (lines reaching above
 * it), max (the highest mode)}.  Not for per rev (its own range).
 */
export function yFocus(data, meta, ymaxAll) {
  let eoTop = -Infinity;
  const modes = [];
  meta.forEach((m, i) => {
    const vals = data[i].filter((v) => typeof v === 'number' && Number.isFinite(v));
    if (!vals.length) return;
    if (m.kind === 'eo') eoTop = Math.max(eoTop, ...vals);
    if (m.kind === 'mode') modes.push({lo: Math.min(...vals), hi: Math.max(...vals)});
  });
  if (!(eoTop > 0) || !modes.length || !(ymaxAll > 0)) return null;
  let top = eoTop;
  for (const m of modes) if (m.lo <= eoTop) top = Math.max(top, m.hi);
  const above = modes.filter((m) => m.lo > eoTop).sort((a, b) => a.lo - b.lo)[0];
  if (above) top = Math.max(top, above.hi);
  if (top >= 0.6 * ymaxAll) return null;
  return {top, hidden: modes.filter((m) => m.hi > top * 1.0000001).length, max: ymaxAll};
}

/**
 * Where each engine-order line leaves the plot (the last point inside the
 * scales, interpolated to the top edge): [{order, x, y}] in data units.
 * xs: the x column; cols[i]: the values of orders[i].
 */
export function orderExits(xs, cols, orders, sc) {
  const out = [];
  orders.forEach((k, i) => {
    const ys = cols[i];
    let xi = -1;
    for (let j = 0; j < xs.length; j++) {
      if (xs[j] >= sc.xMin && xs[j] <= sc.xMax && typeof ys[j] === 'number' && ys[j] <= sc.yMax && ys[j] >= sc.yMin) xi = j;
    }
    if (xi < 0) return;
    let x = xs[xi], y = ys[xi];
    if (xi + 1 < xs.length && ys[xi + 1] > sc.yMax && ys[xi + 1] !== ys[xi]) { // interpolate to the top edge
      const t = (sc.yMax - ys[xi]) / (ys[xi + 1] - ys[xi]);
      x = xs[xi] + t * (xs[xi + 1] - xs[xi]);
      y = sc.yMax;
    }
    out.push({order: k, x: Math.min(x, sc.xMax), y});
  });
  return out;
}

/** Do boxes a and b ({x, y, w, h}) overlap, with gap px between them? */
export function boxesOverlap(a, b, gap = 1) {
  return a.x < b.x + b.w + gap && b.x < a.x + a.w + gap && a.y < b.y + b.h + gap && b.y < a.y + a.h + gap;
}

/**
 * Place labels in a W × H box so that none overlaps another or the boxes
 * taken: each item {w, h, x, y} wants its left edge at x and its middle at
 * y; it takes the nearest free place on a grid of shifts (up and down by its
 * height, to the left by its width), kept inside the box.  Returns one box
 * {x, y, w, h} per item (top-left corner), or null where no place is free.
 */
export function placeLabels(items, W, H, taken = []) {
  const placed = [];
  const shifts = [];
  for (let i = 0; i <= 8; i++) for (let j = -8; j <= 8; j++) shifts.push([i, j]);
  shifts.sort((a, b) => (a[0] + Math.abs(a[1])) - (b[0] + Math.abs(b[1])) || Math.abs(a[1]) - Math.abs(b[1]) || a[1] - b[1]);
  return items.map((it) => {
    for (const [i, j] of shifts) {
      const b = {x: Math.max(0, Math.min(W - it.w, it.x - i * (it.w + 3))),
        y: Math.max(0, Math.min(H - it.h, it.y - it.h / 2 + j * (it.h + 1))), w: it.w, h: it.h};
      if (!taken.some((o) => boxesOverlap(b, o)) && !placed.some((o) => boxesOverlap(b, o))) {
        placed.push(b);
        return b;
      }
    }
    return null;
  });
}

/**
 * The engine-order labels ("2P") of a drawn diagram laid out without
 * overlaps: data/meta/orders as plotData gives them, sc the scales
 * {xMin, xMax, yMin, yMax}, X/Y data → px in a W × H box, measure(text) the
 * text's width in px, h its height.  [{order, text, box ({x, y, w, h} or null)}].
 */
export function orderLabelLayout(data, meta, orders, sc, X, Y, W, H, measure, h, taken = []) {
  const cols = orders.map((k) => data[meta.findIndex((m) => m.kind === 'eo' && m.order === k)] || []);
  const exits = orderExits(data[0], cols, orders, sc);
  const items = exits.map((e) => {
    const text = `${e.order}P`;
    return {order: e.order, text, w: measure(text) + 4, h, x: X(e.x) + 3, y: Y(e.y) - h / 2 - 1};
  });
  const boxes = placeLabels(items, W, H, taken);
  return items.map((it, i) => ({order: it.order, text: it.text, box: boxes[i]}));
}

/** "1, 2, 4-6" -> [1, 2, 4, 5, 6] (whole orders 1…50, sorted, unique); anything else is ignored. */
export function parseOrders(text) {
  const out = new Set();
  for (const part of String(text).split(/[\s,;]+/)) {
    const m = /^(\d+)(?:(?:-|…|\.\.)(\d+))?P?$/i.exec(part);
    if (!m) continue;
    const a = Number(m[1]), b = m[2] ? Number(m[2]) : a;
    for (let k = Math.max(1, a); k <= Math.min(50, b); k++) out.add(k);
  }
  return Array.from(out).sort((a, b) => a - b);
}

/** The marker series' legend names (their shapes are drawn by the hook; black, apart from the mode colours). */
export const MARK_NAMES = {crossings: '○ kP crossings', critical: '◉ critical speeds', tracking: '✕ modes cross / ◇ veer'};

function seriesFor(last, units) {
  const {lines, orders, ref, meta} = last;
  const fu = FREQ_UNITS[units.freq].label, su = SPEED_UNITS[units.speed].label;
  const fmt = (v) => (v === null || v === undefined ? '–' : Number(v.toPrecision(6)) + ' ' + fu);
  // a marker's legend value under the cursor: which lines (and orders) it joins
  const markAt = (list, idx, text) => {
    const x = last.data[0][idx];
    const hit = list.filter((m) => m.x === x);
    return hit.length ? hit.map(text).join('; ') : '–';
  };
  const s = [{label: `Ω (${su})`, value: (self, v) => (v === null || v === undefined ? '–' : Number(v.toPrecision(6)))}];
  // point markers only where the speeds are few enough to tell apart; no rounding to whole pixels
  lines.forEach((ln) => {
    s.push({label: ln.name, stroke: COLORS[ln.id % COLORS.length], width: 2, value: (self, v) => fmt(v),
      points: {show: last.markers, size: 5}, pxAlign: 0});
  });
  orders.forEach((k, i) => {
    s.push({label: `${k}P`, stroke: '#6b7280', width: 1, dash: EO_DASH[i % EO_DASH.length], value: (self, v) => fmt(v),
      points: {show: false}, pxAlign: 0});
  });
  s.push({label: MARK_NAMES.crossings, stroke: CROSS_STROKE, fill: '#ffffff', width: 0, paths: () => null,
    value: (self, v, si, idx) => (v === undefined || v === null ? '–' : markAt(last.cross, idx, (c) => `${c.name} × ${c.order}P`)),
    points: {show: true, size: 10, stroke: CROSS_STROKE, fill: '#ffffff', width: 2}});
  s.push({label: MARK_NAMES.critical, stroke: CROSS_STROKE, fill: CROSS_STROKE, width: 0, paths: () => null,
    value: (self, v, si, idx) => (v === undefined || v === null ? '–'
      : markAt(last.crit, idx, (c) => `${c.label || 'line ' + c.line} × ${c.order}P${c.refined ? '' : ' (not refined)'}`)),
    points: {show: false}});
  s.push({label: MARK_NAMES.tracking, stroke: CROSS_STROKE, fill: '#ffffff', width: 0, paths: () => null,
    value: (self, v, si, idx) => (v === undefined || v === null ? '–'
      : markAt(last.marks, idx, (m) => `${m.names.join(m.kind === 'crossing' ? ' ✕ ' : ' ◇ ')} (${m.kind})`)),
    points: {show: false}});
  if (ref) {
    ref.lines.forEach((ln) => {
      s.push({label: `ref ${ln.name}`, stroke: COLORS[ln.id % COLORS.length] + '99', width: 1.5, dash: [3, 3],
        value: (self, v) => fmt(v), points: {show: false}, pxAlign: 0});
    });
  }
  if (s.length !== meta.length) throw new Error('campbell: series and data columns differ');
  return s;
}

/** Smallest half-length (CSS px) of an error bar worth drawing: it must reach past the point marker (radius 2.5 px). */
export const ERRBAR_MIN_PX = 3;

/** The marker shapes: ◉ critical speed (○ when not refined), ✕ crossing, ◇ veering; r in px. */
function markShape(ctx, kind, x, y, r) {
  ctx.beginPath();
  if (kind === 'crossing') {
    ctx.moveTo(x - r, y - r);
    ctx.lineTo(x + r, y + r);
    ctx.moveTo(x + r, y - r);
    ctx.lineTo(x - r, y + r);
    ctx.stroke();
  } else if (kind === 'veering') {
    ctx.moveTo(x, y - r * 1.3);
    ctx.lineTo(x + r, y);
    ctx.lineTo(x, y + r * 1.3);
    ctx.lineTo(x - r, y);
    ctx.closePath();
    ctx.fill();
    ctx.stroke();
  } else {
    ctx.arc(x, y, r, 0, 2 * Math.PI);
    ctx.fill();
    ctx.stroke();
    if (kind === 'critical') {
      ctx.beginPath();
      ctx.fillStyle = CROSS_STROKE;
      ctx.arc(x, y, r * 0.45, 0, 2 * Math.PI);
      ctx.fill();
      ctx.fillStyle = '#ffffff';
    }
  }
}

/**
 * The draw hook: error bars (where longer than the point marker), the flagged
 * speeds' modes as hollow grey circles, the tracking and critical-speed
 * markers, and the engine-order labels.  Reports what it drew to onDraw.
 */
function decorations(getLast, onDraw) {
  return (u) => {
    const L = getLast();
    if (!L) return;
    const ctx = u.ctx, px = uPlot.pxRatio || 1;
    const {left, top, width, height} = u.bbox;
    ctx.save();
    ctx.beginPath();
    ctx.rect(left, top, width, height);
    ctx.clip();
    // error bars: vertical segments y ± e in the line's colour, with caps
    let drawn = 0, hidden = 0, emax = 0;
    const xMin = u.scales.x.min, xMax = u.scales.x.max;
    ctx.lineWidth = 1.25 * px;
    for (const b of L.errbars) {
      emax = Math.max(emax, b.e);
      if (b.x < xMin || b.x > xMax) continue;
      const y0 = u.valToPos(b.y, 'y'), half = Math.abs(u.valToPos(b.y + b.e, 'y') - y0);
      if (half < ERRBAR_MIN_PX) {
        hidden++;
        continue;
      }
      drawn++;
      const X = u.valToPos(b.x, 'x', true), Y0 = u.valToPos(b.y - b.e, 'y', true), Y1 = u.valToPos(b.y + b.e, 'y', true);
      ctx.strokeStyle = COLORS[b.line % COLORS.length];
      ctx.beginPath();
      ctx.moveTo(X, Y0);
      ctx.lineTo(X, Y1);
      ctx.moveTo(X - 3 * px, Y0);
      ctx.lineTo(X + 3 * px, Y0);
      ctx.moveTo(X - 3 * px, Y1);
      ctx.lineTo(X + 3 * px, Y1);
      ctx.stroke();
    }
    ctx.lineWidth = 1.5 * px;
    ctx.strokeStyle = FLAG_STROKE;
    ctx.fillStyle = '#ffffff';
    for (const p of L.flagged) {
      const x = u.valToPos(p.x, 'x', true), y = u.valToPos(p.y, 'y', true);
      ctx.beginPath();
      ctx.arc(x, y, 4 * px, 0, 2 * Math.PI);
      ctx.fill();
      ctx.stroke();
    }
    // the daemon's critical speeds and the tracking flags: black shapes
    ctx.strokeStyle = CROSS_STROKE;
    ctx.fillStyle = '#ffffff';
    ctx.lineWidth = 2 * px;
    for (const c of L.crit) {
      markShape(ctx, c.refined ? 'critical' : 'ring', u.valToPos(c.x, 'x', true), u.valToPos(c.y, 'y', true), 5.5 * px);
    }
    for (const m of L.marks) markShape(ctx, m.kind, u.valToPos(m.x, 'x', true), u.valToPos(m.y, 'y', true), 5 * px);
    ctx.restore();
    orderLabels(u, L);
    L.errDrawn = {drawn, hidden, max: emax, total: L.errbars.length};
    if (onDraw) onDraw(L);
  };
}

/**
 * The engine-order labels as elements of .u-over (CSS px of the plot area),
 * where each line leaves the plot, moved so that none overlaps another or a
 * divergence label; L.labelBoxes keeps what was placed.
 */
function orderLabels(u, L) {
  for (const el of Array.from(u.over.querySelectorAll('.campbell-eo-label'))) el.remove();
  const px = uPlot.pxRatio || 1;
  const W = u.bbox.width / px, H = u.bbox.height / px;
  const taken = Array.from(u.over.querySelectorAll('.campbell-divergence-label'))
    .map((e) => ({x: e.offsetLeft, y: e.offsetTop, w: e.offsetWidth, h: e.offsetHeight}));
  const probe = document.createElement('span');
  probe.className = 'campbell-eo-label';
  probe.style.visibility = 'hidden';
  u.over.append(probe);
  const measure = (t) => {
    probe.textContent = t;
    return probe.offsetWidth || 7 * t.length;
  };
  const h = Math.max(14, probe.offsetHeight || 14);
  const sc = {xMin: u.scales.x.min, xMax: u.scales.x.max, yMin: u.scales.y.min, yMax: u.scales.y.max};
  const lay = orderLabelLayout(u.data, L.meta, L.orders, sc, (v) => u.valToPos(v, 'x'), (v) => u.valToPos(v, 'y'),
    W, H, (t) => measure(t) - 4, h, taken);
  probe.remove();
  L.labelBoxes = [];
  for (const l of lay) {
    if (!l.box) continue; // no free place: the legend names the line
    const e = document.createElement('span');
    e.className = 'campbell-eo-label';
    e.textContent = l.text;
    e.dataset.order = String(l.order);
    Object.assign(e.style, {left: `${l.box.x}px`, top: `${l.box.y}px`, width: `${l.box.w}px`, height: `${l.box.h}px`});
    u.over.append(e);
    L.labelBoxes.push({order: l.order, ...l.box});
  }
}

/** Half-width (CSS px) of a divergence speed's band, on the page and in the exported SVG. */
export const DIV_BAND_PX = 4;

/**
 * The draw hook of the divergence speeds: the unstable ranges (light) and the
 * bands (translucent red, a line at the speed) as elements of .u-under (under
 * the canvas, whose lines stay on top), the labels in .u-over; placed from
 * the x scale at every draw (zoom, resize).  Nothing without divergence speeds.
 */
function divergenceBands(getLast) {
  return (u) => {
    for (const el of Array.from(u.root.querySelectorAll('.div-el'))) el.remove();
    const L = getLast();
    if (!L || !L.div || !L.div.length) return;
    const W = u.bbox.width / (uPlot.pxRatio || 1);
    const X = (v) => u.valToPos(v, 'x');
    const su = SPEED_UNITS[L.units.speed].label;
    // the ranges' words under the bands' labels (which stack from the top)
    const wordsTop = 4 + 18 * L.div.length;
    for (const r of L.unstable) {
      const a = Math.max(-2, X(r.x0)), b = Math.min(W + 2, X(r.x1));
      if (!(b > a)) continue;
      const el = document.createElement('div');
      el.className = 'div-el campbell-unstable';
      el.style.left = `${a}px`;
      el.style.width = `${b - a}px`;
      el.dataset.x0 = String(r.x0);
      el.dataset.x1 = String(r.x1);
      const t = document.createElement('span');
      t.textContent = 'statically unstable';
      t.style.top = `${wordsTop}px`;
      el.append(t);
      u.under.append(el);
    }
    L.div.forEach((d, i) => {
      const x = X(d.x);
      if (!(x >= -DIV_BAND_PX && x <= W + DIV_BAND_PX)) return; // zoomed out of view
      const band = document.createElement('div');
      band.className = `div-el campbell-divergence ${d.kind}`;
      band.style.left = `${x - DIV_BAND_PX}px`;
      band.style.width = `${2 * DIV_BAND_PX}px`;
      Object.assign(band.dataset, {x: String(d.x), omega: String(d.omega), mode: d.mode || '', kind: d.kind});
      u.under.append(band);
      const lab = document.createElement('div');
      lab.className = `div-el campbell-divergence-label ${d.kind}`;
      lab.textContent = d.label;
      lab.dataset.x = String(d.x);
      lab.style.top = `${4 + 18 * i}px`;
      lab.style.left = `${x + DIV_BAND_PX + 2}px`;
      lab.title = `${d.label} at Ω = ${sig(d.x)} ${su}`;
      u.over.append(lab);
      if (x + DIV_BAND_PX + 2 + lab.offsetWidth > W) lab.style.left = `${Math.max(0, x - DIV_BAND_PX - 2 - lab.offsetWidth)}px`;
    });
  };
}

/** A divergence speed in words (the tooltip and the SVG's titles). */
function divergenceText(d, su) {
  const n = (v) => String(Number(v.toPrecision(5)));
  const u = SPEED_UNITS[su];
  return `Divergence speed (${d.kind}) of ${d.mode || 'a mode'} at Ω = ${n(d.x)} ${u.label}: the steady state ` +
    `${d.kind === 'onset' ? 'loses' : 'regains'} static stability (the lowest eigenvalue of K* passes through zero)` +
    (d.bracket ? `; between the speeds ${n(u.of(d.bracket[0]))} and ${n(u.of(d.bracket[1]))} ${u.label}` : '') +
    (d.refined ? `, refined${d.refineSolves !== null ? ` by ${d.refineSolves} solves` : ''}` : ', not refined (interpolated)');
}

/**
 * The exported Campbell SVG (export.js campbellSvg's text, drawn from u and
 * last) with the divergence speeds: the unstable ranges and the bands under
 * the lines, the labels above them, inside its plot's clip.  The text as it
 * was without divergence speeds.
 */
export function divergenceSvg(text, u, last) {
  if (!text || !u || !last || !last.div || !last.div.length) return text;
  const m = /<clipPath id="plot"><rect x="([-\d.]+)" y="([-\d.]+)" width="([-\d.]+)" height="([-\d.]+)"\/><\/clipPath><g clip-path="url\(#plot\)">/
    .exec(text);
  if (!m) return text;
  const [L, T, pw, ph] = m.slice(1, 5).map(Number);
  const xs = u.scales.x;
  const X = (v) => L + ((v - xs.min) / (xs.max - xs.min || 1)) * pw;
  const r2 = (v) => Math.round(v * 100) / 100;
  const esc = (t) => String(t).replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;').replace(/"/g, '&quot;');
  const under = [], over = [];
  for (const r of last.unstable) {
    const a = Math.max(L - 2, X(r.x0)), b = Math.min(L + pw + 2, X(r.x1));
    if (!(b > a)) continue;
    under.push(`<rect class="unstable-range" x="${r2(a)}" y="${T}" width="${r2(b - a)}" height="${ph}" fill="#dc2626" ` +
      'fill-opacity="0.07"><title>statically unstable</title></rect>');
    over.push(`<text class="unstable-label" x="${r2(Math.max(a, L) + 6)}" y="${r2(T + 15 + 18 * last.div.length)}" ` +
      'fill="#b91c1c" fill-opacity="0.8" font-size="10.5">statically unstable</text>');
  }
  last.div.forEach((d, i) => {
    const x = X(d.x);
    if (!(x >= L - DIV_BAND_PX && x <= L + pw + DIV_BAND_PX)) return;
    const title = `<title>${esc(divergenceText(d, last.units.speed))}</title>`;
    under.push(`<rect class="divergence-band" x="${r2(x - DIV_BAND_PX)}" y="${T}" width="${2 * DIV_BAND_PX}" height="${ph}" ` +
      `fill="#dc2626" fill-opacity="0.28">${title}</rect>`);
    under.push(`<line class="divergence-line" x1="${r2(x)}" y1="${T}" x2="${r2(x)}" y2="${T + ph}" stroke="#b91c1c" ` +
      'stroke-width="1.5"/>');
    const w = 6.1 * d.label.length, y = T + 15 + 18 * i;
    const right = x + DIV_BAND_PX + 3 + w > L + pw;
    const lx = right ? x - DIV_BAND_PX - 3 : x + DIV_BAND_PX + 3;
    over.push(`<rect x="${r2(right ? lx - w - 2 : lx - 2)}" y="${r2(y - 11)}" width="${r2(w + 4)}" height="15" fill="#ffffff" ` +
      'fill-opacity="0.85"/>');
    over.push(`<text class="divergence-label" x="${r2(lx)}" y="${r2(y)}"${right ? ' text-anchor="end"' : ''} fill="#991b1b" ` +
      `font-size="11" font-weight="600">${esc(d.label)}</text>`);
  });
  const start = m.index + m[0].length;
  const close = text.indexOf('</g>', start);
  if (close < 0) return text;
  // two rows under the legend's last (export.js: rows 17 px apart, the text 26 px right of the marker)
  const legend = [];
  const rowsL = Array.from(text.slice(close).matchAll(/<text x="([\d.]+)" y="([\d.]+)" fill="#1b1f24">/g));
  if (rowsL.length) {
    const lx = Number(rowsL[rowsL.length - 1][1]) - 26, ly0 = Number(rowsL[rowsL.length - 1][2]) - 4 + 17;
    [['divergence speed', 0.28], ['statically unstable', 0.07]].forEach(([t, op], k) => {
      const ly = ly0 + 17 * k;
      if (k === 1 && !last.unstable.length) return;
      legend.push(`<rect x="${r2(lx + 10 - (k ? 10 : DIV_BAND_PX))}" y="${r2(ly - 6)}" width="${k ? 20 : 2 * DIV_BAND_PX}" ` +
        `height="12" fill="#dc2626" fill-opacity="${op}"/>` +
        (k ? '' : `<line x1="${r2(lx + 10)}" y1="${r2(ly - 6)}" x2="${r2(lx + 10)}" y2="${r2(ly + 6)}" stroke="#b91c1c" ` +
          'stroke-width="1.5"/>') +
        `<text x="${r2(lx + 26)}" y="${r2(ly + 4)}" fill="#1b1f24">${t}</text>`);
    });
  }
  const end = text.lastIndexOf('</svg>');
  return text.slice(0, start) + '\n' + under.join('\n') + text.slice(start, close) + over.join('\n') + '\n' +
    (legend.length && end > close ? text.slice(close, end) + legend.join('\n') + '\n' + text.slice(end) : text.slice(close));
}

/** What lies under the cursor (CSS px in the plot area): the nearest marker or point within 8 px, as text. */
function hoverText(u, L, cx, cy) {
  const fu = FREQ_UNITS[L.units.freq].label, su = SPEED_UNITS[L.units.speed].label;
  const n = (v) => String(Number(v.toPrecision(5)));
  let best = null;
  const consider = (x, y, pri, text) => {
    const d = Math.hypot(u.valToPos(x, 'x') - cx, u.valToPos(y, 'y') - cy) - pri;
    if (d <= 8 && (!best || d < best.d)) best = {d, text};
  };
  for (const m of L.marks) {
    consider(m.x, m.y, 3, `${m.kind === 'crossing' ? 'Modes cross' : 'Veering'}: ${m.names.join(' and ')} ` +
      `(flagged at Ω = ${n(SPEED_UNITS[L.units.speed].of(m.at))} ${su})`);
  }
  for (const c of L.crit) {
    consider(c.x, c.y, 3, `Critical speed: ${c.label || 'line ' + c.line} meets ${c.order}P at Ω = ${n(c.x)} ${su}, ` +
      `${n(c.y)} ${fu}${c.refined ? ' (refined by the daemon)' : ' (interpolated, not refined)'}`);
  }
  for (const c of L.cross) {
    consider(c.x, c.y, 2, `${c.name} meets ${c.order}P at Ω = ${n(c.x)} ${su}, ${n(c.y)} ${fu} (interpolated between ` +
      'the speeds solved; tick "find critical speeds" and solve again to have it refined)');
  }
  // a divergence band: anywhere along it, after the markers and points close by
  for (const d of L.div || []) {
    const dist = Math.abs(u.valToPos(d.x, 'x') - cx) + 2;
    if (dist <= 8 && (!best || dist < best.d)) best = {d: dist, text: divergenceText(d, L.units.speed)};
  }
  const eb = new Map(L.errbars.map((b) => [`${b.line}:${b.x}`, b]));
  L.meta.forEach((m, i) => {
    if (m.kind !== 'mode') return;
    const col = L.data[i];
    for (let j = 0; j < col.length; j++) {
      if (typeof col[j] !== 'number') continue;
      const b = eb.get(`${m.line}:${L.data[0][j]}`);
      let t = `${m.name}: ${n(col[j])}`;
      if (b) {
        const half = Math.abs(u.valToPos(b.y + b.e, 'y') - u.valToPos(b.y, 'y'));
        t += ` ± ${n(b.e)}`;
        if (half < ERRBAR_MIN_PX) t += ' (error bar too small to see at this scale)';
      }
      consider(L.data[0][j], col[j], 0, `${t} ${fu} at Ω = ${n(L.data[0][j])} ${su}`);
    }
  });
  return best ? best.text : '';
}

/** A Campbell chart in container; update({result, orders, units, ref, critical}); destroy(). onDraw(last) after each draw. */
export function campbellChart(container, onDraw = null) {
  let plot = null;
  let last = null;
  const tip = document.createElement('div');
  tip.className = 'campbell-tip';
  tip.setAttribute('role', 'tooltip');
  tip.hidden = true;

  function width() {
    return Math.max(280, Math.floor(container.clientWidth || 560));
  }

  function update({result, orders, units, ref = null, critical = null, allModes = false}) {
    const {rows, lines, nModes} = campbellData(result);
    const refData = ref ? campbellData(ref) : null;
    const pd = plotData(rows, lines, orders, units, refData, critical, divergenceSpeeds(result));
    const {data, meta, flagged} = pd;
    last = {rows, lines, nModes, orders, units, ref: refData, ...pd, markers: rows.length <= MARKER_MAX_SPEEDS,
      focus: null, focused: false, labelBoxes: [], single: rows.length < 2};
    if (plot) plot.destroy();
    plot = null;
    for (const e of Array.from(container.querySelectorAll('.campbell-single'))) e.remove();
    container.dataset.view = last.single ? 'single' : 'diagram';
    container.dataset.cases = String(rows.length);
    container.dataset.crossings = String(pd.cross.length);
    container.dataset.divergence = String(pd.div.length);
    if (last.single) { // one speed: no diagram, the frequencies as bars
      container.append(singleSpeed(rows[0], lines, units));
      if (onDraw) onDraw(last);
      return last;
    }
    const fu = FREQ_UNITS[units.freq], su = SPEED_UNITS[units.speed];
    const yl = `frequency ${fu.sym} (${fu.label})`;
    let ymax = 0;
    meta.forEach((m, i) => {
      if (m.kind !== 'mode' && m.kind !== 'ref') return;
      for (const v of data[i]) if (typeof v === 'number') ymax = Math.max(ymax, v);
    });
    for (const p of flagged) ymax = Math.max(ymax, p.y);
    if (units.freq === 'rev') {
      // per rev explodes towards Ω = 0: show the band of the engine orders and the modes at the top
      // speed (the lower speeds' values stay in the table; zoom works inside this range)
      const top = meta.map((m, i) => [m, data[i]]).filter(([m]) => m.kind === 'mode').map(([, col]) => {
        for (let j = col.length - 1; j >= 0; j--) if (typeof col[j] === 'number') return col[j];
        return 0;
      });
      ymax = Math.min(ymax, Math.max(1.5 * (orders.length ? orders[orders.length - 1] : 1), ...top));
    } else {
      // modes far above the engine orders: fit the range to the modes the orders cross
      last.focus = yFocus(data, meta, ymax);
      last.focused = !!last.focus && !allModes;
      if (last.focused) ymax = last.focus.top;
    }
    plot = new uPlot({
      width: width(),
      height: 340,
      scales: {
        x: {time: false},
        // modes set the y range; engine-order lines are cut at the top
        y: {range: (self, min, max) => [0, (ymax > 0 ? ymax : max || 1) * 1.08]},
      },
      axes: [
        {label: `speed Ω (${su.label})`, stroke: '#333'},
        {label: yl, stroke: '#333', size: 60},
      ],
      legend: {live: true},
      // drag a box to zoom in x and y (a mostly horizontal or vertical drag zooms that axis only); double click resets
      cursor: {drag: {x: true, y: true, uni: 25}},
      hooks: {
        draw: [divergenceBands(() => last), decorations(() => last, onDraw)],
        setCursor: [(u) => {
          const {left, top} = u.cursor;
          const t = left >= 0 && top >= 0 && last ? hoverText(u, last, left, top) : '';
          tip.hidden = !t;
          tip.textContent = t;
          container.dataset.tip = t;
          if (t) {
            tip.style.left = `${Math.min(left + 12, u.bbox.width / (uPlot.pxRatio || 1) - 200)}px`;
            tip.style.top = `${Math.max(0, top - 34)}px`;
          }
        }],
      },
      series: seriesFor(last, units),
    }, data, container);
    plot.over.append(tip);
    tip.hidden = true;
    const cv = plot.root.querySelector('canvas');
    if (cv) {
      cv.setAttribute('role', 'img');
      cv.setAttribute('aria-label', rows.length
        ? `Campbell diagram: ${lines.length} tracked modes (${lines.map((l) => l.name).join(', ')}) at ${rows.length} ` +
          `speeds from ${sig(speedIn(units.speed, rows[0]))} to ` +
          `${sig(speedIn(units.speed, rows[rows.length - 1]))} ${su.label}, frequencies in ${fu.label}, engine orders ` +
          `${orders.join(', ') || 'none'}, ${pd.cross.length + pd.crit.length} crossings with them (listed below)` +
          (pd.marks.length ? `, ${pd.marks.length} mode crossings or veerings` : '') +
          (flagged.length ? `, ${new Set(flagged.map((p) => p.x)).size} speeds flagged (hollow grey)` : '') +
          (pd.div.length ? `, divergence speeds (red bands; listed below): ${pd.div.map((d) =>
            `${d.label} at ${sig(d.x)} ${su.label}`).join(', ')}` : '')
        : 'Campbell diagram: no speeds');
    }
    return last;
  }

  const ro = typeof ResizeObserver === 'function' ? new ResizeObserver(() => {
    if (plot) plot.setSize({width: width(), height: 340});
  }) : null;
  if (ro) ro.observe(container);

  return {
    update,
    /** What is plotted, from the uPlot instance itself (for tests and debugging). */
    plotted() {
      if (!plot || !last) return null;
      const over = plot.over.getBoundingClientRect();
      const labels = plot.series.map((s) => s.label);
      return {
        units: {...last.units},
        unit: last.units.freq,
        x: Array.from(plot.data[0]),
        series: labels.slice(1).map((label, i) => ({label, kind: last.meta[i + 1].kind, line: last.meta[i + 1].line,
          values: Array.from(plot.data[i + 1])})),
        lines: last.lines.map((l) => ({...l})),
        crossings: last.cross.map((c) => ({...c})),
        critical: last.crit.map((c) => ({...c})),
        marks: last.marks.map((m) => ({...m})),
        errbars: {list: last.errbars.map((b) => ({...b})), ...(last.errDrawn || {})},
        flagged: last.flagged.map((p) => ({...p})),
        divergence: last.div.map((d) => ({...d})),
        unstable: last.unstable.map((r) => ({...r})),
        scales: {x: [plot.scales.x.min, plot.scales.x.max], y: [plot.scales.y.min, plot.scales.y.max]},
        axisLabels: plot.axes.map((a) => a.label),
        // point markers and pixel rounding of each series, as uPlot holds them
        markers: last.markers,
        seriesStyle: plot.series.slice(1).map((s) => ({label: s.label, points: s.points.show(plot, 1) === true,
          pxAlign: s.pxAlign})),
        focus: last.focus ? {...last.focus, on: last.focused} : null,
        // the engine-order labels as laid out and as the page shows them (client rects)
        labelBoxes: last.labelBoxes.map((b) => ({...b})),
        labelRects: Array.from(plot.over.querySelectorAll('.campbell-eo-label, .campbell-divergence-label')).map((e) => {
          const r = e.getBoundingClientRect();
          return {text: e.textContent, x: r.left - over.left, y: r.top - over.top, w: r.width, h: r.height};
        }),
        xTicks: plot.axes[0]._values ? Array.from(plot.axes[0]._values) : [],
      };
    },
    /** The uPlot instance (export, zoom). */
    get plot() {
      return plot;
    },
    get last() {
      return last;
    },
    destroy() {
      if (ro) ro.disconnect();
      if (plot) plot.destroy();
      plot = null;
    },
  };
}

function sig(v) {
  return typeof v === 'number' && Number.isFinite(v) ? String(Number(v.toPrecision(6))) : '–';
}

/**
 * One speed: the modes' frequencies as a table with bars (a Campbell
 * diagram needs a sweep), in the units shown, each bar in its line's
 * colour, with its frequency per revolution (the nearest engine order).
 */
function singleSpeed(row, lines, units) {
  const fu = FREQ_UNITS[units.freq], su = SPEED_UNITS[units.speed];
  const wrap = document.createElement('div');
  wrap.className = 'campbell-single';
  const t = document.createElement('table');
  t.className = 'small campbell-single-table';
  const cap = t.createCaption();
  const x = row ? speedIn(units.speed, row) : null;
  cap.textContent = row ? `Frequencies at Ω = ${sig(x)} ${su.label} (one speed: a Campbell diagram needs a sweep)`
    : 'No speeds in this result';
  const hr = t.createTHead().insertRow();
  for (const h of ['mode', `${fu.sym} (${fu.label})`, '', 'engine order']) {
    const th = document.createElement('th');
    th.scope = 'col';
    th.textContent = h;
    hr.append(th);
  }
  const tb = t.createTBody();
  if (!row) return wrap;
  const items = lines.map((ln) => ({ln, md: row.byLine.get(ln.id)})).filter((o) => o.md)
    .map((o) => ({...o, v: freqIn(units.freq, o.md, row.omega)})).filter((o) => o.v !== null)
    .sort((a, b) => a.v - b.v);
  const vmax = Math.max(...items.map((o) => o.v), 0) || 1;
  for (const {ln, md, v} of items) {
    const tr = tb.insertRow();
    tr.dataset.line = String(ln.id);
    tr.insertCell().textContent = typeof md.label === 'string' ? md.label : ln.name;
    const c = tr.insertCell();
    c.textContent = sig(v);
    c.className = 'fq';
    const bc = tr.insertCell();
    bc.className = 'bar-cell';
    const bar = document.createElement('span');
    bar.className = 'bar';
    bar.style.width = `${(100 * v / vmax).toFixed(2)}%`;
    bar.style.background = COLORS[ln.id % COLORS.length];
    bc.append(bar);
    const pr = row.omega > 0 ? md.frequency_rad_s / row.omega : null;
    const k = pr === null ? null : Math.max(1, Math.round(pr));
    tr.insertCell().textContent = pr === null ? '– (Ω = 0)' : `${sig(Number(pr.toPrecision(3)))} per rev (near ${k}P)`;
  }
  wrap.append(t);
  return wrap;
}
