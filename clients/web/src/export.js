// export.js — the Campbell diagram and the mode shape as SVG and PNG files.
//
// The mode shape is already an SVG: it is copied with the page's SVG style
// rules inlined, so the file looks as on the screen anywhere.  The Campbell
// diagram is a uPlot canvas: it is redrawn as SVG from what uPlot plots (its
// scales, tick values and data, the same series styles), with the legend and
// the engine-order labels, so the file is vector graphics, not a picture of
// the canvas.  PNG is either SVG rasterised at twice its size.

import {orderLabelLayout} from './campbell.js';

const NS = 'http://www.w3.org/2000/svg';

function esc(t) {
  return String(t).replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;').replace(/"/g, '&quot;');
}

/** The page's style rules for SVG drawings (those starting with "svg"), as CSS text. */
function svgRules() {
  const out = [];
  for (const sheet of Array.from(document.styleSheets)) {
    let rules;
    try {
      rules = sheet.cssRules;
    } catch {
      continue;
    }
    for (const r of Array.from(rules || [])) if (r.selectorText && /^svg[ .[]/.test(r.selectorText)) out.push(r.cssText);
  }
  // the page's custom properties (var(--mode) …) mean nothing outside it: put their values in
  const root = getComputedStyle(document.documentElement);
  return out.join('\n').replace(/var\((--[\w-]+)\)/g, (m, name) => root.getPropertyValue(name).trim() || '#333');
}

/** A standalone SVG text of an <svg> of the page (styles inlined, white background, a title). */
export function exportSvg(svg, title) {
  const c = svg.cloneNode(true);
  const vb = (svg.getAttribute('viewBox') || '0 0 600 360').split(/\s+/).map(Number);
  c.setAttribute('xmlns', NS);
  c.setAttribute('width', String(vb[2]));
  c.setAttribute('height', String(vb[3]));
  c.removeAttribute('tabindex');
  c.removeAttribute('class');
  const style = document.createElementNS(NS, 'style');
  style.textContent = svgRules();
  const bg = document.createElementNS(NS, 'rect');
  for (const [k, v] of Object.entries({x: vb[0], y: vb[1], width: vb[2], height: vb[3], fill: '#ffffff'})) bg.setAttribute(k, v);
  c.insertBefore(bg, c.firstChild);
  c.insertBefore(style, c.firstChild);
  if (title) {
    const t = document.createElementNS(NS, 'title');
    t.textContent = title;
    c.insertBefore(t, c.firstChild);
  }
  return '<?xml version="1.0" encoding="UTF-8"?>\n' + new XMLSerializer().serializeToString(c) + '\n';
}

/** PNG blob of an SVG text, drawn at scale× its size on white. */
export function svgToPng(text, scale = 2) {
  return new Promise((resolve, reject) => {
    const img = new Image();
    const url = URL.createObjectURL(new Blob([text], {type: 'image/svg+xml'}));
    img.onload = () => {
      const cv = document.createElement('canvas');
      cv.width = Math.round(img.width * scale);
      cv.height = Math.round(img.height * scale);
      const ctx = cv.getContext('2d');
      ctx.fillStyle = '#ffffff';
      ctx.fillRect(0, 0, cv.width, cv.height);
      ctx.drawImage(img, 0, 0, cv.width, cv.height);
      URL.revokeObjectURL(url);
      cv.toBlob((b) => (b ? resolve(b) : reject(new Error('PNG encoding failed'))), 'image/png');
    };
    img.onerror = () => {
      URL.revokeObjectURL(url);
      reject(new Error('the SVG could not be drawn'));
    };
    img.src = url;
  });
}

/** PNG blob of a canvas. */
export function canvasPng(canvas) {
  return new Promise((resolve, reject) => canvas.toBlob((b) => (b ? resolve(b) : reject(new Error('PNG encoding failed'))),
    'image/png'));
}

/**
 * The Campbell diagram as SVG text, from the uPlot instance u (scales, ticks,
 * data, series styles) and what campbell.js drew (last: orders, flagged points).
 */
export function campbellSvg(u, last, title) {
  const W = 760, H = 440, L = 70, R = 20, T = 34, B = 60;
  const legendW = 150;
  const pw = W - L - R - legendW, ph = H - T - B;
  const xs = u.scales.x, ys = u.scales.y;
  const X = (v) => L + ((v - xs.min) / (xs.max - xs.min || 1)) * pw;
  const Y = (v) => T + ph - ((v - ys.min) / (ys.max - ys.min || 1)) * ph;
  const r2 = (v) => Math.round(v * 100) / 100;
  const out = [];
  out.push(`<svg xmlns="${NS}" width="${W}" height="${H}" viewBox="0 0 ${W} ${H}" font-family="system-ui, sans-serif" font-size="12">`);
  out.push(`<title>${esc(title || 'Campbell diagram')}</title>`);
  out.push(`<rect x="0" y="0" width="${W}" height="${H}" fill="#ffffff"/>`);
  if (title) out.push(`<text x="${L}" y="20" font-size="13" font-weight="600">${esc(title)}</text>`);
  // grid and ticks (uPlot's own)
  const ax = u.axes;
  const ticks = (a, scale) => {
    const sp = a._splits || [];
    const vals = a._values || sp.map(String);
    return sp.map((v, i) => [v, vals[i]]).filter(([v]) => v >= scale.min - 1e-12 && v <= scale.max + 1e-12);
  };
  for (const [v, t] of ticks(ax[0], xs)) {
    out.push(`<line x1="${r2(X(v))}" y1="${T}" x2="${r2(X(v))}" y2="${T + ph}" stroke="#e5e7eb"/>`);
    out.push(`<text x="${r2(X(v))}" y="${T + ph + 16}" text-anchor="middle" fill="#333">${esc(t)}</text>`);
  }
  for (const [v, t] of ticks(ax[1], ys)) {
    out.push(`<line x1="${L}" y1="${r2(Y(v))}" x2="${L + pw}" y2="${r2(Y(v))}" stroke="#e5e7eb"/>`);
    out.push(`<text x="${L - 6}" y="${r2(Y(v) + 4)}" text-anchor="end" fill="#333">${esc(t)}</text>`);
  }
  out.push(`<rect x="${L}" y="${T}" width="${pw}" height="${ph}" fill="none" stroke="#333"/>`);
  out.push(`<text x="${L + pw / 2}" y="${H - 16}" text-anchor="middle" fill="#333">${esc(ax[0].label || '')}</text>`);
  out.push(`<text transform="translate(18 ${T + ph / 2}) rotate(-90)" text-anchor="middle" fill="#333">${esc(ax[1].label || '')}</text>`);
  out.push(`<clipPath id="plot"><rect x="${L}" y="${T}" width="${pw}" height="${ph}"/></clipPath><g clip-path="url(#plot)">`);
  const xv = u.data[0];
  const legend = [];
  const meta = last.meta || [];
  // error bars first (under the lines), where they reach beyond their point as on the screen
  for (const b of last.errbars || []) {
    const h = Math.abs(Y(b.y + b.e) - Y(b.y));
    if (h < 3 || b.x < xs.min || b.x > xs.max) continue;
    const x = r2(X(b.x)), y0 = r2(Y(b.y - b.e)), y1 = r2(Y(b.y + b.e));
    const col = (u.series[1 + (last.lines || []).findIndex((l) => l.id === b.line)] || {}).stroke || '#333';
    out.push(`<path d="M${x} ${y0}V${y1}M${x - 3} ${y0}h6M${x - 3} ${y1}h6" stroke="${col}" stroke-width="1.25" fill="none"/>`);
  }
  u.series.forEach((s, i) => {
    if (i === 0) return;
    const kind = (meta[i] || {}).kind;
    const yv = u.data[i];
    const stroke = typeof s.stroke === 'function' ? s.stroke(u, i) : s.stroke || '#333';
    const dash = s.dash ? ` stroke-dasharray="${s.dash.join(' ')}"` : '';
    if (kind === 'critical' || kind === 'tracking') { // drawn below from last, with their shapes
      const list = kind === 'critical' ? last.crit || [] : last.marks || [];
      // in the legend only when there are some; the shape is the legend's marker, the label without it
      if (list.length) {
        legend.push({label: kind === 'critical' ? 'critical speeds' : list.some((m) => m.kind === 'veering')
          ? (list.some((m) => m.kind === 'crossing') ? 'modes cross / veer' : 'modes veer') : 'modes cross',
        stroke, marker: kind === 'tracking' && !list.some((m) => m.kind === 'crossing') ? 'veering' : kind});
      }
      return;
    }
    if (kind === 'crossings') {
      for (let j = 0; j < xv.length; j++) {
        if (typeof yv[j] === 'number') out.push(`<circle cx="${r2(X(xv[j]))}" cy="${r2(Y(yv[j]))}" r="4.5" fill="#fff" stroke="${stroke}" stroke-width="2"/>`);
      }
      if (yv.some((v) => typeof v === 'number')) legend.push({label: 'kP crossings', stroke, marker: 'ring'});
      return;
    }
    let d = '', pen = false;
    for (let j = 0; j < xv.length; j++) {
      const v = yv[j];
      if (v === undefined) continue; // joined over
      if (v === null) {
        pen = false;
        continue;
      }
      d += `${pen ? 'L' : 'M'}${r2(X(xv[j]))} ${r2(Y(v))}`;
      pen = true;
    }
    out.push(`<path d="${d}" fill="none" stroke="${stroke}" stroke-width="${s.width || 1}"${dash} stroke-linejoin="round"/>`);
    if (kind === 'mode' && last.markers !== false) { // no beads on a dense sweep (campbell.js MARKER_MAX_SPEEDS)
      for (let j = 0; j < xv.length; j++) {
        if (typeof yv[j] === 'number') out.push(`<circle cx="${r2(X(xv[j]))}" cy="${r2(Y(yv[j]))}" r="2.2" fill="${stroke}"/>`);
      }
    }
    legend.push({label: s.label, stroke, dash: s.dash, width: s.width});
  });
  for (const p of last.flagged || []) {
    out.push(`<circle cx="${r2(X(p.x))}" cy="${r2(Y(p.y))}" r="4" fill="#fff" stroke="#9ca3af" stroke-width="1.5"/>`);
  }
  for (const c of last.crit || []) out.push(shape(c.refined ? 'critical' : 'ring', X(c.x), Y(c.y)));
  for (const m of last.marks || []) out.push(shape(m.kind, X(m.x), Y(m.y)));
  // the engine orders' labels where their lines leave the plot, none over another (as on the page)
  const lay = orderLabelLayout(u.data, meta, last.orders || [], {xMin: xs.min, xMax: xs.max, yMin: ys.min, yMax: ys.max},
    (v) => X(v) - L, (v) => Y(v) - T, pw, ph, (t) => 6.6 * t.length, 14);
  for (const l of lay) {
    if (!l.box) continue;
    const b = l.box;
    out.push(`<rect class="eo-label-box" x="${r2(L + b.x)}" y="${r2(T + b.y)}" width="${r2(b.w)}" height="${b.h}" ` +
      'fill="#ffffff" fill-opacity="0.85"/>');
    out.push(`<text class="eo-label" x="${r2(L + b.x + 2)}" y="${r2(T + b.y + 11)}" fill="#374151" font-size="11">${esc(l.text)}</text>`);
  }
  out.push('</g>');
  if ((last.flagged || []).length) legend.push({label: 'flagged speeds', stroke: '#9ca3af', marker: 'ring'});
  // legend
  let ly = T + 6;
  const lx = L + pw + 14;
  for (const e of legend) {
    if (e.marker === 'critical' || e.marker === 'tracking' || e.marker === 'veering') {
      out.push(shape(e.marker === 'tracking' ? 'crossing' : e.marker, lx + 10, ly));
    } else if (e.marker === 'ring') out.push(`<circle cx="${lx + 10}" cy="${ly}" r="4" fill="#fff" stroke="${e.stroke}" stroke-width="2"/>`);
    else out.push(`<line x1="${lx}" y1="${ly}" x2="${lx + 20}" y2="${ly}" stroke="${e.stroke}" stroke-width="${e.width || 1}"${e.dash ? ` stroke-dasharray="${e.dash.join(' ')}"` : ''}/>`);
    out.push(`<text x="${lx + 26}" y="${ly + 4}" fill="#1b1f24">${esc(e.label)}</text>`);
    ly += 17;
    if (ly > H - 10) break;
  }
  out.push('</svg>');
  return '<?xml version="1.0" encoding="UTF-8"?>\n' + out.join('\n') + '\n';
}

/** A black marker: ◉ critical speed, ○ ring, ✕ crossing, ◇ veering, at (x, y) px. */
function shape(kind, x, y) {
  const a = (v) => Math.round(v * 100) / 100;
  const st = 'stroke="#111111" stroke-width="2"';
  if (kind === 'crossing') return `<path d="M${a(x - 5)} ${a(y - 5)}L${a(x + 5)} ${a(y + 5)}M${a(x + 5)} ${a(y - 5)}L${a(x - 5)} ${a(y + 5)}" ${st}/>`;
  if (kind === 'veering') return `<path d="M${a(x)} ${a(y - 6.5)}L${a(x + 5)} ${a(y)}L${a(x)} ${a(y + 6.5)}L${a(x - 5)} ${a(y)}Z" fill="#fff" ${st}/>`;
  return `<circle cx="${a(x)}" cy="${a(y)}" r="5.5" fill="#fff" ${st}/>` +
    (kind === 'critical' ? `<circle cx="${a(x)}" cy="${a(y)}" r="2.5" fill="#111111"/>` : '');
}

/** Offer a blob as a download named name. */
export function saveBlob(blob, name) {
  const a = document.createElement('a');
  const url = URL.createObjectURL(blob);
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 60000);
}
