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
// never used for crossings.  Engine-order lines are grey, each with its own
// dash, and labelled where they leave the plot.  Drag selects a zoom box (x,
// y or both); double click resets.  A reference result (another design) can
// be overlaid: its modes are thin dashed lines.

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
const FLAG_STROKE = '#9ca3af';

/** Is a case flagged (not solved, or with warnings)? */
export function flaggedCase(c) {
  return c.status !== 'solved' || (Array.isArray(c.warnings) && c.warnings.length > 0);
}

/** Cases sorted by speed: [{omega, rpm, status, flagged, modes, freqs: [rad/s | null per mode]}], and the mode count. */
export function campbellData(result) {
  const cases = (result && Array.isArray(result.cases) ? result.cases : [])
    .filter((c) => typeof c.omega === 'number')
    .slice()
    .sort((a, b) => a.omega - b.omega);
  const nModes = cases.reduce((m, c) => Math.max(m, Array.isArray(c.modes) ? c.modes.length : 0), 0);
  const rows = cases.map((c) => ({
    omega: c.omega,
    rpm: typeof c.rpm === 'number' ? c.rpm : c.omega * 60 / TWO_PI,
    status: c.status,
    flagged: flaggedCase(c),
    modes: Array.isArray(c.modes) ? c.modes : [],
    freqs: Array.from({length: nModes}, (_, k) => {
      const md = Array.isArray(c.modes) ? c.modes[k] : null;
      return md && typeof md.frequency_rad_s === 'number' ? md.frequency_rad_s : null;
    }),
  }));
  return {rows, nModes};
}

/**
 * Crossings of mode curves with the engine-order lines ω = k·Ω, k in orders:
 * a sign change of ω_m(Ω) − k·Ω between two consecutive speeds that are both
 * unflagged, interpolated linearly (rad/s).  [{mode (1-based), order, omega, freq (rad/s)}].
 */
export function crossings(rows, nModes, orders) {
  const out = [];
  for (let m = 0; m < nModes; m++) {
    for (const k of orders) {
      for (let i = 0; i + 1 < rows.length; i++) {
        const a = rows[i], b = rows[i + 1];
        if (a.flagged || b.flagged) continue;
        const fa = a.freqs[m], fb = b.freqs[m];
        if (fa === null || fb === null) continue;
        const da = fa - k * a.omega, db = fb - k * b.omega;
        if (da === 0 && i > 0 && !rows[i - 1].flagged) continue; // counted as the previous interval's end
        if (da === 0 || db === 0 || (da < 0) !== (db < 0)) {
          const t = da === db ? 0 : da / (da - db);
          const om = a.omega + t * (b.omega - a.omega);
          out.push({mode: m + 1, order: k, omega: om, freq: k * om});
        }
      }
    }
  }
  return out.sort((p, q) => p.omega - q.omega || p.mode - q.mode);
}

/** A mode's frequency in unit fu at a case (the result's own per_rev / Hz when it has them). */
export function freqIn(fu, md, omega) {
  if (!md || typeof md.frequency_rad_s !== 'number') return null;
  if (fu === 'hz' && typeof md.frequency_hz === 'number') return md.frequency_hz;
  if (fu === 'rev' && 'per_rev' in md) return typeof md.per_rev === 'number' ? md.per_rev : null;
  return FREQ_UNITS[fu].of(md.frequency_rad_s, omega);
}

/** A case's speed in unit su (the result's own rpm when it has it). */
export function speedIn(su, row) {
  return su === 'rpm' ? row.rpm : row.omega;
}

/**
 * The aligned uPlot data for rows, orders, units {speed, freq}, and an
 * optional reference {rows, nModes}: [x, modes…, orders…, crossings, ref modes…].
 */
export function plotData(rows, nModes, orders, units, ref = null) {
  const su = units.speed, fu = units.freq;
  const cross = crossings(rows, nModes, orders);
  const xOf = (omega) => SPEED_UNITS[su].of(omega);
  const pts = new Map(); // x -> omega (rad/s)
  for (const r of rows) pts.set(speedIn(su, r), r.omega);
  for (const c of cross) pts.set(xOf(c.omega), c.omega);
  const refRows = ref ? ref.rows : [];
  for (const r of refRows) pts.set(speedIn(su, r), r.omega);
  const xs = Array.from(pts.keys()).sort((a, b) => a - b);
  const at = new Map(rows.map((r) => [speedIn(su, r), r]));
  const data = [xs];
  for (let m = 0; m < nModes; m++) {
    data.push(xs.map((x) => {
      const r = at.get(x);
      if (!r) return undefined;
      return r.flagged ? null : freqIn(fu, r.modes[m], r.omega);
    }));
  }
  for (const k of orders) {
    data.push(xs.map((x) => (fu === 'rev' ? k : FREQ_UNITS[fu].of(k * pts.get(x), pts.get(x)))));
  }
  const cx = new Map(cross.map((c) => [xOf(c.omega), fu === 'rev' ? c.order : FREQ_UNITS[fu].of(c.freq, c.omega)]));
  data.push(xs.map((x) => (cx.has(x) ? cx.get(x) : undefined)));
  if (ref) {
    const rat = new Map(refRows.map((r) => [speedIn(su, r), r]));
    for (let m = 0; m < ref.nModes; m++) {
      data.push(xs.map((x) => {
        const r = rat.get(x);
        if (!r) return undefined;
        return r.flagged ? null : freqIn(fu, r.modes[m], r.omega);
      }));
    }
  }
  // the flagged speeds' modes, drawn hollow by the hook
  const flagged = [];
  for (const r of rows) {
    if (!r.flagged) continue;
    for (let m = 0; m < nModes; m++) {
      const v = freqIn(fu, r.modes[m], r.omega);
      if (v !== null) flagged.push({x: speedIn(su, r), y: v, mode: m + 1, status: r.status});
    }
  }
  return {data, cross, flagged};
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

function seriesFor(nModes, orders, units, ref, labels) {
  const fu = FREQ_UNITS[units.freq].label, su = SPEED_UNITS[units.speed].label;
  const fmt = (v) => (v === null || v === undefined ? '–' : Number(v.toPrecision(6)) + ' ' + fu);
  const s = [{label: `Ω (${su})`, value: (self, v) => (v === null || v === undefined ? '–' : Number(v.toPrecision(6)))}];
  for (let m = 0; m < nModes; m++) {
    s.push({label: `mode ${m + 1}` + (labels[m] ? ` (${labels[m]})` : ''), stroke: COLORS[m % COLORS.length], width: 2,
      value: (self, v) => fmt(v), points: {show: true, size: 5}});
  }
  orders.forEach((k, i) => {
    s.push({label: `${k}P`, stroke: '#6b7280', width: 1, dash: EO_DASH[i % EO_DASH.length], value: (self, v) => fmt(v),
      points: {show: false}});
  });
  s.push({label: 'crossings', stroke: CROSS_STROKE, fill: CROSS_STROKE, width: 0, paths: () => null,
    value: (self, v) => fmt(v), points: {show: true, size: 10, stroke: CROSS_STROKE, fill: '#ffffff', width: 2}});
  if (ref) {
    for (let m = 0; m < ref.nModes; m++) {
      s.push({label: `ref mode ${m + 1}`, stroke: COLORS[m % COLORS.length] + '99', width: 1.5, dash: [3, 3],
        value: (self, v) => fmt(v), points: {show: false}});
    }
  }
  return s;
}

/** The draw hook: the flagged speeds' modes as hollow grey circles, and the engine-order labels. */
function decorations(getLast) {
  return (u) => {
    const L = getLast();
    if (!L) return;
    const ctx = u.ctx, px = uPlot.pxRatio || 1;
    const {left, top, width, height} = u.bbox;
    ctx.save();
    ctx.beginPath();
    ctx.rect(left, top, width, height);
    ctx.clip();
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
    // engine-order labels where each line leaves the plot (top or right edge)
    ctx.font = `${Math.round(11 * px)}px system-ui, sans-serif`;
    ctx.fillStyle = '#374151';
    ctx.textBaseline = 'middle';
    const xMax = u.scales.x.max, yMax = u.scales.y.max, yMin = u.scales.y.min;
    const base = 1 + L.nModes;
    L.orders.forEach((k, i) => {
      const ys = u.data[base + i], xs = u.data[0];
      // the last point of the line inside the y range
      let xi = -1;
      for (let j = 0; j < xs.length; j++) if (xs[j] <= xMax && ys[j] <= yMax && ys[j] >= yMin) xi = j;
      if (xi < 0) return;
      let x = xs[xi], y = ys[xi];
      if (xi + 1 < xs.length && ys[xi + 1] > yMax && ys[xi + 1] !== ys[xi]) { // interpolate to the top edge
        const t = (yMax - ys[xi]) / (ys[xi + 1] - ys[xi]);
        x = xs[xi] + t * (xs[xi + 1] - xs[xi]);
        y = yMax;
      }
      let X = u.valToPos(Math.min(x, xMax), 'x', true), Y = u.valToPos(y, 'y', true);
      const text = `${k}P`;
      const w = ctx.measureText(text).width;
      X = Math.min(X + 3 * px, left + width - w - 2 * px);
      Y = Math.max(top + 8 * px, Math.min(Y - 7 * px, top + height - 8 * px));
      ctx.fillStyle = 'rgba(255,255,255,0.85)';
      ctx.fillRect(X - 1 * px, Y - 7 * px, w + 2 * px, 14 * px);
      ctx.fillStyle = '#374151';
      ctx.fillText(text, X, Y);
    });
    ctx.restore();
  };
}

/** A Campbell chart in container; update({result, orders, units, ref, labels}); destroy(). */
export function campbellChart(container) {
  let plot = null;
  let last = null;

  function width() {
    return Math.max(280, Math.floor(container.clientWidth || 560));
  }

  function update({result, orders, units, ref = null, labels = []}) {
    const {rows, nModes} = campbellData(result);
    const refData = ref ? campbellData(ref) : null;
    const {data, cross, flagged} = plotData(rows, nModes, orders, units, refData);
    last = {rows, nModes, orders, units, cross, data, flagged, ref: refData};
    if (plot) plot.destroy();
    const fu = FREQ_UNITS[units.freq], su = SPEED_UNITS[units.speed];
    const yl = `frequency ${fu.sym} (${fu.label})`;
    let ymax = 0;
    const refFrom = 1 + nModes + orders.length + 1; // the reference's modes follow the crossings
    for (let i = 1; i < data.length; i++) {
      if (i > nModes && i < refFrom) continue;
      for (const v of data[i]) if (typeof v === 'number') ymax = Math.max(ymax, v);
    }
    for (const p of flagged) ymax = Math.max(ymax, p.y);
    if (units.freq === 'rev') {
      // per rev explodes towards Ω = 0: show the band of the engine orders and the modes at the top
      // speed (the lower speeds' values stay in the table; zoom works inside this range)
      const top = data[1 + 0] ? data.slice(1, 1 + nModes).map((col) => {
        for (let j = col.length - 1; j >= 0; j--) if (typeof col[j] === 'number') return col[j];
        return 0;
      }) : [];
      ymax = Math.min(ymax, Math.max(1.5 * (orders.length ? orders[orders.length - 1] : 1), ...top));
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
      hooks: {draw: [decorations(() => last)]},
      series: seriesFor(nModes, orders, units, refData, labels),
    }, data, container);
    const cv = plot.root.querySelector('canvas');
    if (cv) {
      cv.setAttribute('role', 'img');
      cv.setAttribute('aria-label', rows.length
        ? `Campbell diagram: ${nModes} modes at ${rows.length} speeds from ${sig(speedIn(units.speed, rows[0]))} to ` +
          `${sig(speedIn(units.speed, rows[rows.length - 1]))} ${su.label}, frequencies in ${fu.label}, engine orders ` +
          `${orders.join(', ') || 'none'}, ${cross.length} crossings (listed below)` +
          (flagged.length ? `, ${new Set(flagged.map((p) => p.x)).size} speeds flagged (hollow grey)` : '')
        : 'Campbell diagram: no speeds');
    }
    container.dataset.cases = String(rows.length);
    container.dataset.crossings = String(cross.length);
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
      const labels = plot.series.map((s) => s.label);
      return {
        units: {...last.units},
        unit: last.units.freq,
        x: Array.from(plot.data[0]),
        series: labels.slice(1).map((label, i) => ({label, values: Array.from(plot.data[i + 1])})),
        crossings: last.cross.map((c) => ({...c})),
        flagged: last.flagged.map((p) => ({...p})),
        scales: {x: [plot.scales.x.min, plot.scales.x.max], y: [plot.scales.y.min, plot.scales.y.max]},
        axisLabels: plot.axes.map((a) => a.label),
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
