// campbell.js — the Campbell diagram (natural frequencies against speed) with
// engine-order lines k·Ω and their crossings, drawn with uPlot.
//
// uPlot wants one shared, sorted x array: it is the union of the solved
// speeds and the crossing speeds.  A mode's value is `undefined` at a
// crossing-only x (joined over) and `null` at a speed without modes (a gap);
// the crossing series has values only at the crossings and no line.

import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';

const TWO_PI = 2 * Math.PI;
const COLORS = ['#1f5fbf', '#c2410c', '#15803d', '#7e22ce', '#b91c1c', '#0e7490', '#a16207', '#be185d',
  '#4d7c0f', '#1d4ed8'];

/** Cases sorted by speed: [{omega, freqs: [rad/s | null per mode]}], and the mode count. */
export function campbellData(result) {
  const cases = (result && Array.isArray(result.cases) ? result.cases : [])
    .filter((c) => typeof c.omega === 'number')
    .slice()
    .sort((a, b) => a.omega - b.omega);
  const nModes = cases.reduce((m, c) => Math.max(m, Array.isArray(c.modes) ? c.modes.length : 0), 0);
  const rows = cases.map((c) => ({
    omega: c.omega,
    status: c.status,
    freqs: Array.from({length: nModes}, (_, k) => {
      const md = Array.isArray(c.modes) ? c.modes[k] : null;
      return md && typeof md.frequency_rad_s === 'number' ? md.frequency_rad_s : null;
    }),
  }));
  return {rows, nModes};
}

/**
 * Crossings of mode curves with the engine-order lines k·Ω, k = 1..orders:
 * a sign change of ω_m(Ω) − k·Ω between two consecutive solved speeds,
 * interpolated linearly.  [{mode (1-based), order, omega, freq (rad/s)}].
 */
export function crossings(rows, nModes, orders) {
  const out = [];
  for (let m = 0; m < nModes; m++) {
    for (let k = 1; k <= orders; k++) {
      for (let i = 0; i + 1 < rows.length; i++) {
        const a = rows[i], b = rows[i + 1];
        const fa = a.freqs[m], fb = b.freqs[m];
        if (fa === null || fb === null) continue;
        const da = fa - k * a.omega, db = fb - k * b.omega;
        if (da === 0 && i > 0) continue; // counted as the previous interval's end
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

/** The aligned uPlot data and series for rows, orders and unit ('rad' | 'hz'). */
export function plotData(rows, nModes, orders, unit) {
  const sc = unit === 'hz' ? 1 / TWO_PI : 1;
  const cross = crossings(rows, nModes, orders);
  const xs = Array.from(new Set(rows.map((r) => r.omega).concat(cross.map((c) => c.omega)))).sort((a, b) => a - b);
  const at = new Map(rows.map((r) => [r.omega, r]));
  const data = [xs];
  for (let m = 0; m < nModes; m++) {
    data.push(xs.map((x) => {
      const r = at.get(x);
      if (!r) return undefined;
      return r.freqs[m] === null ? null : r.freqs[m] * sc;
    }));
  }
  for (let k = 1; k <= orders; k++) data.push(xs.map((x) => k * x * sc));
  const cx = new Map(cross.map((c) => [c.omega, c.freq * sc]));
  data.push(xs.map((x) => (cx.has(x) ? cx.get(x) : undefined)));
  return {data, cross};
}

function seriesFor(nModes, orders, unit) {
  const u = unit === 'hz' ? 'Hz' : 'rad/s';
  const fmt = (v) => (v === null || v === undefined ? '–' : Number(v.toPrecision(6)) + ' ' + u);
  const s = [{label: 'Ω (rad/s)', value: (self, v) => (v === null || v === undefined ? '–' : Number(v.toPrecision(6)))}];
  for (let m = 0; m < nModes; m++) {
    s.push({label: `mode ${m + 1}`, stroke: COLORS[m % COLORS.length], width: 2, value: (self, v) => fmt(v),
      points: {show: true, size: 5}});
  }
  for (let k = 1; k <= orders; k++) {
    s.push({label: `${k}×`, stroke: '#8a8f98', width: 1, dash: [5, 4], value: (self, v) => fmt(v),
      points: {show: false}});
  }
  s.push({label: 'crossings', stroke: '#dc2626', fill: '#dc2626', width: 0, paths: () => null,
    value: (self, v) => fmt(v), points: {show: true, size: 9, stroke: '#dc2626', fill: '#ffffff', width: 2}});
  return s;
}

/** A Campbell chart in container; update({result, orders, unit}); destroy(). */
export function campbellChart(container) {
  let plot = null;
  let last = null;

  function width() {
    return Math.max(280, Math.floor(container.clientWidth || 560));
  }

  function update({result, orders, unit}) {
    const {rows, nModes} = campbellData(result);
    const {data, cross} = plotData(rows, nModes, orders, unit);
    last = {rows, nModes, orders, unit, cross, data};
    if (plot) plot.destroy();
    const yl = unit === 'hz' ? 'frequency f (Hz)' : 'frequency ω (rad/s)';
    let ymax = 0;
    for (const r of rows) for (const v of r.freqs) if (v !== null) ymax = Math.max(ymax, v);
    ymax *= unit === 'hz' ? 1 / TWO_PI : 1;
    plot = new uPlot({
      width: width(),
      height: 340,
      scales: {
        x: {time: false},
        // modes set the y range; engine-order lines are cut at the top
        y: {range: (self, min, max) => [0, (ymax > 0 ? ymax : max || 1) * 1.08]},
      },
      axes: [
        {label: 'speed Ω (rad/s)', stroke: '#333'},
        {label: yl, stroke: '#333', size: 60},
      ],
      legend: {live: true},
      cursor: {drag: {x: true, y: false}},
      series: seriesFor(nModes, orders, unit),
    }, data, container);
    const cv = plot.root.querySelector('canvas');
    if (cv) {
      cv.setAttribute('role', 'img');
      cv.setAttribute('aria-label', rows.length
        ? `Campbell diagram: ${nModes} modes at ${rows.length} speeds from ${rows[0].omega} to ` +
          `${rows[rows.length - 1].omega} rad/s, ${orders} engine orders, ${cross.length} crossings (listed below)`
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
        unit: last.unit,
        x: Array.from(plot.data[0]),
        series: labels.slice(1).map((label, i) => ({label, values: Array.from(plot.data[i + 1])})),
        crossings: last.cross.map((c) => ({...c})),
      };
    },
    destroy() {
      if (ro) ro.disconnect();
      if (plot) plot.destroy();
      plot = null;
    },
  };
}
