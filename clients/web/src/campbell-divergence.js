// campbell-divergence.js — the divergence speeds drawn: the bands, labels and
// statically unstable ranges as elements under and over uPlot's canvas, placed
// from the x scale at each draw (divergenceBands), their text (tooltip, SVG
// titles) and their place in the exported SVG (divergenceSvg).  What they are
// (divergenceSpeeds, unstableRanges) is read in campbell-data.js.

import uPlot from 'uplot';
import {SPEED_UNITS} from './request.js';
import {sig} from './campbell-data.js';

/** Half-width (CSS px) of a divergence speed's band, on the page and in the exported SVG. */
export const DIV_BAND_PX = 4;

/**
 * The draw hook of the divergence speeds: the unstable ranges (light) and the
 * bands (translucent red, a line at the speed) as elements of .u-under (under
 * the canvas, whose lines stay on top), the labels in .u-over; placed from
 * the x scale at every draw (zoom, resize).  Nothing without divergence speeds.
 */
export function divergenceBands(getLast) {
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
export function divergenceText(d, su) {
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
