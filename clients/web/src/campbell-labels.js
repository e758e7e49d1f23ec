// campbell-labels.js — the engine orders: the orders typed (parseOrders) and
// their labels ("2P") where each line leaves the plot, placed so that none
// overlaps another or a divergence label (placeLabels, orderLabelLayout; the
// exported SVG, export.js, places them the same way), and the labels as
// elements of uPlot's .u-over (orderLabels, called by the draw hook).

import uPlot from 'uplot';

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

/**
 * The engine-order labels as elements of .u-over (CSS px of the plot area),
 * where each line leaves the plot, moved so that none overlaps another or a
 * divergence label; L.labelBoxes keeps what was placed.
 */
export function orderLabels(u, L) {
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
