// campbell-data.js — the Campbell diagram's data, from a result to what is
// plotted: the cases as rows and the tracked modes as lines (campbellData),
// the page's crossings with the engine orders, the result's tracking flags
// and divergence speeds, values in the units shown, the aligned uPlot columns
// (plotData) and the y range fitted to the engine orders (yFocus).  No DOM and
// no uPlot here: campbell.js draws what plotData gives.

import {SPEED_UNITS, FREQ_UNITS} from './request.js';

const TWO_PI = 2 * Math.PI;

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

/** A number as text to 6 significant digits, '–' when it is not a finite number. */
export function sig(v) {
  return typeof v === 'number' && Number.isFinite(v) ? String(Number(v.toPrecision(6))) : '–';
}
