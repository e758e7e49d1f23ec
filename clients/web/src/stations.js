// stations.js — the read-only table of a blade's or a tower's stations
// (DESIGN.md 8.1, 8.5: the properties along the span or the height).  Each
// cell carries the JSON pointer of its field (data-pointer), so the daemon's
// errors find it; the stations are edited in the JSON.

import {ptr, sig} from './request.js';

const STATION_COLS = [
  ['s', 's'], ['mass_per_length', 'μ (kg/m)'], ['EA', 'EA (N)'], ['EI_flap', 'EI<sub>flap</sub> (N·m²)'],
  ['EI_edge', 'EI<sub>edge</sub> (N·m²)'], ['GJ', 'GJ (N·m²)'], ['flap_inertia', 'i<sub>flap</sub> (kg·m)'],
  ['edge_inertia', 'i<sub>edge</sub> (kg·m)'], ['twist_deg', 'twist (°)'], ['inertia_twist_deg', 'inertia twist (°)'],
  ['cg_offset', 'cg offset (m)'], ['shear_center_offset', 'shear centre offset (m)'],
  ['tension_center_offset', 'tension centre offset (m)'],
];

/**
 * Fill table (thead + tbody) with the stations of the request's form
 * ('blade' or 'tower'): the columns any station has, one row a station.
 * labels: {s: heading of the s column} (a tower's EI_flap is fore-aft).
 * Returns how many stations there are.
 */
export function renderStations(table, form, stations, labels = {}) {
  const st = Array.isArray(stations) ? stations : [];
  const keys = STATION_COLS.filter(([k]) => st.some((r) => r && typeof r === 'object' && k in r));
  table.tHead.innerHTML = '<tr>' + keys.map(([k, l]) => `<th scope="col">${labels[k] || l}</th>`).join('') + '</tr>';
  const tbody = table.tBodies[0];
  tbody.textContent = '';
  st.forEach((r, j) => {
    const tr = tbody.insertRow();
    tr.dataset.pointer = ptr(form, 'stations', j);
    for (const [k] of keys) {
      const td = tr.insertCell();
      td.dataset.pointer = ptr(form, 'stations', j, k);
      const v = r && typeof r === 'object' ? r[k] : undefined;
      const t = document.createElement('span');
      t.textContent = Array.isArray(v) ? v.map((x) => sig(x, 5)).join(', ')
        : typeof v === 'number' ? sig(v, 6) : v === undefined ? '' : String(v);
      const m = document.createElement('div');
      m.className = 'msg';
      td.append(t, m);
    }
  });
  return st.length;
}
