// campbell-draw.js — how the Campbell diagram's series look (colours, the
// engine orders' dashes, point markers, the marker series' legend), the draw
// hook that adds to uPlot's canvas what uPlot does not draw (error bars, the
// flagged speeds' hollow circles, critical-speed and tracking markers, then the
// engine-order labels) and the tooltip text of what lies under the cursor.

import uPlot from 'uplot';
import {SPEED_UNITS, FREQ_UNITS} from './request.js';
import {orderLabels} from './campbell-labels.js';
import {divergenceText} from './campbell-divergence.js';

// Okabe–Ito and Tol colours: told apart by colour-blind readers, none of them black or grey
// (black rings mark crossings, grey is engine orders and flagged speeds)
export const COLORS = ['#0072b2', '#d55e00', '#009e73', '#cc79a7', '#e69f00', '#56b4e9', '#882255', '#117733',
  '#aa4499', '#999933'];
const EO_DASH = [[6, 4], [2, 3], [10, 3, 2, 3], [12, 6], [4, 2, 1, 2], [1, 2]];
const CROSS_STROKE = '#111111';
const FLAG_STROKE = '#9ca3af';

/** The marker series' legend names (their shapes are drawn by the hook; black, apart from the mode colours). */
export const MARK_NAMES = {crossings: '○ kP crossings', critical: '◉ critical speeds', tracking: '✕ modes cross / ◇ veer'};

export function seriesFor(last, units) {
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
export function decorations(getLast, onDraw) {
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

/** What lies under the cursor (CSS px in the plot area): the nearest marker or point within 8 px, as text. */
export function hoverText(u, L, cx, cy) {
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
