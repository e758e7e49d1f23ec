// tower.js — the tower panel: a request in the tower form (DESIGN.md 8.5)
// edited in a few fields (height, base height, elements, the top mass's
// mass, offset and inertia, gravity) with its stations as a read-only table
// (stations.js).  The structure tables are hidden meanwhile; the drawing
// shows the tower expanded (tower-model.js).  Every field carries the JSON
// pointer of the request field it edits (data-pointer), so the daemon's
// errors land next to it.  Wires, foundation, platform and the section stay
// in the JSON (they are kept as they are).

import {cellValue, fmtNum, listValue} from './request.js';
import {renderStations} from './stations.js';
import {$} from './dom.js';
import {S} from './state.js';

const isObj = (v) => v !== null && typeof v === 'object' && !Array.isArray(v);

/** The tower object of the request, made when missing (an edit of an empty form). */
function towerOf() {
  if (!isObj(S.doc.tower)) S.doc.tower = {};
  return S.doc.tower;
}

/** A list [a, b, c] as a field's text: "a, b, c". */
function listText(v) {
  return Array.isArray(v) ? v.map(fmtNum).join(', ') : v === undefined ? '' : JSON.stringify(v);
}

/** Show the tower panel instead of the structure tables for a request in the tower form. */
export function renderTower() {
  $('tower-panel').hidden = !S.tower;
  if (!S.tower) return;
  const t = isObj(S.doc.tower) ? S.doc.tower : {};
  for (const e of document.querySelectorAll('#tower-panel input[data-key]')) e.value = fmtNum(t[e.dataset.key]);
  const tm = isObj(t.top_mass) ? t.top_mass : {};
  $('tower-top-mass').value = fmtNum(tm.mass);
  $('tower-top-offset').value = listText(tm.offset);
  $('tower-top-inertia').value = listText(tm.inertia);
  $('tower-gravity').checked = t.gravity === true;
  const n = renderStations($('tower-stations'), 'tower', t.stations,
    {s: 's (from the base)', EI_flap: 'EI<sub>fa</sub> (N·m²)', EI_edge: 'EI<sub>ss</sub> (N·m²)'});
  $('tower-stations-count').textContent = n ? `(${n}, from the top of the rigid base s = 0 to the top s = 1)`
    : '(none: the section holds along the height)';
}

/** One top-mass field: key of top_mass, its text parsed by value; the top mass goes when it is empty. */
function setTopMass(key, text, value) {
  const t = towerOf();
  const tm = isObj(t.top_mass) ? t.top_mass : {};
  if (text.trim() === '') delete tm[key];
  else tm[key] = value(text);
  if (Object.keys(tm).length) t.top_mass = tm;
  else delete t.top_mass;
}

/** Wire the tower fields; onEdit() after each edit of S.doc.tower (JSON text, checks, drawing). */
export function initTower(onEdit) {
  for (const e of document.querySelectorAll('#tower-panel input[data-key]')) {
    e.addEventListener('input', () => {
      const t = towerOf();
      if (e.value.trim() === '' && e.dataset.key !== 'height') delete t[e.dataset.key];
      else t[e.dataset.key] = cellValue(e.value);
      onEdit();
    });
  }
  for (const [id, key, value] of [['tower-top-mass', 'mass', cellValue], ['tower-top-offset', 'offset', listValue],
    ['tower-top-inertia', 'inertia', listValue]]) {
    $(id).addEventListener('input', () => {
      setTopMass(key, $(id).value, value);
      onEdit();
    });
  }
  $('tower-gravity').addEventListener('change', () => {
    const t = towerOf();
    if ($('tower-gravity').checked) t.gravity = true;
    else delete t.gravity;
    onEdit();
  });
}
