// campbell-single.js — a result of one speed is no Campbell diagram: its
// modes as a table with bars, in the units shown (singleSpeed, put in the
// chart's container by campbell.js instead of the uPlot chart).

import {SPEED_UNITS, FREQ_UNITS} from './request.js';
import {speedIn, freqIn, sig} from './campbell-data.js';
import {COLORS} from './campbell-draw.js';

/**
 * One speed: the modes' frequencies as a table with bars (a Campbell
 * diagram needs a sweep), in the units shown, each bar in its line's
 * colour, with its frequency per revolution (the nearest engine order).
 */
export function singleSpeed(row, lines, units) {
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
