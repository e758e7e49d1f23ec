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
//
// The code is split by concern; this file builds the chart (campbellChart) and
// re-exports the others' API, so the page imports only campbell.js:
// campbell-data.js (the result as rows and lines, crossings, tracking marks,
// divergence speeds, the uPlot columns, the fitted y range), campbell-labels.js
// (the engine orders typed, their labels placed without overlaps),
// campbell-draw.js (series styles, the draw hook's markers and error bars, the
// tooltip), campbell-divergence.js (the divergence bands, on the page and in
// the SVG), campbell-single.js (one speed: the table with bars).

import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import {SPEED_UNITS, FREQ_UNITS} from './request.js';
import {campbellData, plotData, yFocus, divergenceSpeeds, speedIn, sig} from './campbell-data.js';
import {seriesFor, decorations, hoverText} from './campbell-draw.js';
import {divergenceBands} from './campbell-divergence.js';
import {singleSpeed} from './campbell-single.js';

/** Above this many speeds the mode lines are drawn without point markers. */
export const MARKER_MAX_SPEEDS = 60;

export {flaggedCase, lineOf, campbellData, crossings, trackingMarks, freqIn, errIn, speedIn, divergenceSpeeds,
  divergenceLabel, unstableRanges, plotData, yFocus} from './campbell-data.js';
export {orderExits, boxesOverlap, placeLabels, orderLabelLayout, parseOrders} from './campbell-labels.js';
export {COLORS, MARK_NAMES, ERRBAR_MIN_PX} from './campbell-draw.js';
export {DIV_BAND_PX, divergenceSvg} from './campbell-divergence.js';

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
