// editor.js — the structure tables (joints, sections, members, point masses,
// clamp).  Every control carries the JSON pointer of the request field it
// edits (data-pointer), which is how the daemon's errors find their field.
//
// The tables edit the rows of request.js in place and call onChange(kind):
// 'value' (a value changed: no re-render needed), 'names' (a name changed:
// the select lists are refreshed), 'rows' (rows added or removed: re-render).
//
// A spatial structure (rows.spatial, DESIGN.md 7) shows more columns: z of the
// joints, the spatial section data (EA, EI_flap, EI_edge, GJ, μ, flap and edge
// inertia), a member's twist and flap direction, a point mass's inertia.

import {ptr, freshName, convertRows, PLANAR_SECTION_KEYS, SPATIAL_SECTION_KEYS} from './request.js';

/** Column headings and control labels of the section fields. */
const SECTION_LABEL = {
  E: ['E (Pa)', 'E (Pa)'],
  A: ['A (m²)', 'A (m²)'],
  I: ['I (m⁴)', 'I (m⁴)'],
  mass_per_length: ['μ (kg/m)', 'mass per length (kg/m)'],
  EA: ['EA (N)', 'EA (N)'],
  EI_flap: ['EI<sub>flap</sub> (N·m²)', 'EI_flap (N·m²)'],
  EI_edge: ['EI<sub>edge</sub> (N·m²)', 'EI_edge (N·m²)'],
  GJ: ['GJ (N·m²)', 'GJ (N·m²)'],
  flap_inertia: ['i<sub>flap</sub> (kg·m)', 'flap inertia (kg·m)'],
  edge_inertia: ['i<sub>edge</sub> (kg·m)', 'edge inertia (kg·m)'],
};

const ACTIONS = '<th scope="col"><span class="vh">Actions</span></th>';
const th = (t, title) => `<th scope="col"${title ? ` title="${title}"` : ''}>${t}</th>`;

function h(tag, attrs = {}, ...kids) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k === 'dataset') Object.assign(e.dataset, v);
    else if (k in e && typeof v !== 'string') e[k] = v;
    else e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of kids) if (c !== null && c !== undefined) e.append(c);
  return e;
}

let uid = 0;

/** A table cell with a control, its error slot and its pointer suffix. */
function cell(control, suffix) {
  const msg = h('div', {class: 'msg', id: `msg-${++uid}`});
  control.dataset.suffix = suffix;
  control.setAttribute('aria-describedby', msg.id);
  return h('td', {}, control, msg);
}

function textInput(value, label, extra = {}) {
  return h('input', {type: 'text', value, 'aria-label': label, spellcheck: 'false', autocomplete: 'off', ...extra});
}

/** A select of names, keeping an unknown current value visible. */
function nameSelect(value, names, label, allowEmpty = false) {
  const s = h('select', {'aria-label': label});
  fillSelect(s, value, names, allowEmpty);
  return s;
}

export function fillSelect(s, value, names, allowEmpty = false) {
  s.textContent = '';
  const list = names.slice();
  if (allowEmpty || value === '') s.append(h('option', {value: ''}, '—'));
  for (const n of list) s.append(h('option', {value: n}, n));
  if (value !== '' && !list.includes(value)) s.append(h('option', {value}, `${value} (unknown)`));
  s.value = value;
}

/** Point every control of a row at base + its suffix. */
function setRowPointers(tr, base) {
  tr.dataset.pointer = base;
  for (const c of tr.querySelectorAll('[data-suffix]')) {
    c.dataset.pointer = c.dataset.suffix ? base + '/' + c.dataset.suffix : base;
  }
}

export class StructureEditor {
  /** root: document; getRows(): the current rows; onChange(kind). */
  constructor(doc, getRows, onChange) {
    this.doc = doc;
    this.getRows = getRows;
    this.onChange = onChange;
    this.t = {
      joints: doc.querySelector('#joints tbody'),
      sections: doc.querySelector('#sections tbody'),
      members: doc.querySelector('#members tbody'),
      masses: doc.querySelector('#point-masses tbody'),
    };
    this.clamp = doc.getElementById('clamp');
    this.clamp.dataset.pointer = '/structure/clamp';
    this.clamp.setAttribute('aria-describedby', 'msg-clamp');
    this.clamp.addEventListener('change', () => {
      this.getRows().clamp = this.clamp.value;
      this.onChange('value');
    });
    this.spatial = doc.getElementById('spatial');
    this.spatial.addEventListener('change', () => {
      convertRows(this.getRows(), this.spatial.checked);
      this.render();
      this.onChange('rows');
    });
    doc.getElementById('add-joint').addEventListener('click', () => this.addJoint());
    doc.getElementById('add-section').addEventListener('click', () => this.addSection());
    doc.getElementById('add-member').addEventListener('click', () => this.addMember());
    doc.getElementById('add-mass').addEventListener('click', () => this.addMass());
    doc.querySelector('#joints').dataset.pointer = '/structure/joints';
    doc.querySelector('#sections').dataset.pointer = '/structure/sections';
    doc.querySelector('#members').dataset.pointer = '/structure/members';
    doc.querySelector('#point-masses').dataset.pointer = '/structure/point_masses';
  }

  names(kind) {
    return this.getRows()[kind].map((r) => r.name);
  }

  /** The column headings of the tables for a planar or a spatial structure. */
  renderHeads(spatial) {
    const head = (sel, html) => {
      const tr = this.doc.querySelector(sel + ' thead tr');
      if (tr.innerHTML !== html) tr.innerHTML = html;
    };
    head('#joints', th('Name') + th('x (m)') + th('y (m)') +
      (spatial ? th('z (m)', 'along the spin axis; empty: 0') : '') + ACTIONS);
    head('#sections', th('Name') + (spatial ? SPATIAL_SECTION_KEYS : PLANAR_SECTION_KEYS)
      .map((k) => th(SECTION_LABEL[k][0], k)).join('') + ACTIONS);
    head('#members', th('Id') + th('From') + th('To') + th('Section') + th('Elements') +
      (spatial ? th('Twist (°)', 'twist_deg: about the member axis; empty: 0') +
        th('Flap direction', 'flap_direction [x, y, z]; empty: the default (the part of z normal to the member)') : '') +
      ACTIONS);
    head('#point-masses', th('Joint') + th('Mass (kg)') +
      (spatial ? th('Inertia (kg·m²)', 'inertia [Ixx, Iyy, Izz] about the hub axes; empty: none') : '') + ACTIONS);
  }

  render() {
    const rows = this.getRows();
    this.renderHeads(rows.spatial);
    this.spatial.checked = rows.spatial;
    for (const tb of Object.values(this.t)) tb.textContent = '';
    rows.joints.forEach((r, i) => this.t.joints.append(this.jointRow(r, i)));
    rows.sections.forEach((r, i) => this.t.sections.append(this.sectionRow(r, i)));
    rows.members.forEach((r, i) => this.t.members.append(this.memberRow(r, i)));
    rows.point_masses.forEach((r, i) => this.t.masses.append(this.massRow(r, i)));
    fillSelect(this.clamp, rows.clamp, this.names('joints'));
  }

  /** Refresh the name lists of every select (after a rename). */
  refreshSelects() {
    const rows = this.getRows();
    const joints = this.names('joints'), sections = this.names('sections');
    this.t.members.querySelectorAll('tr').forEach((tr, i) => {
      const m = rows.members[i];
      if (!m) return;
      fillSelect(tr.querySelector('[data-suffix="from"]'), m.from, joints);
      fillSelect(tr.querySelector('[data-suffix="to"]'), m.to, joints);
      fillSelect(tr.querySelector('[data-suffix="section"]'), m.section, sections);
    });
    this.t.masses.querySelectorAll('tr').forEach((tr, i) => {
      const p = rows.point_masses[i];
      if (p) fillSelect(tr.querySelector('[data-suffix="joint"]'), p.joint, joints);
    });
    fillSelect(this.clamp, rows.clamp, joints);
  }

  removeButton(label, onClick) {
    const b = h('button', {type: 'button', class: 'remove', 'aria-label': label, title: label}, '×');
    b.addEventListener('click', onClick);
    return h('td', {class: 'actions'}, b);
  }

  /** A value input bound to obj[key]. */
  bind(input, obj, key) {
    input.addEventListener('input', () => {
      obj[key] = input.value;
      this.onChange('value');
    });
    return input;
  }

  jointRow(r) {
    const spatial = this.getRows().spatial;
    const name = textInput(r.name, `name of joint ${r.name}`, {class: 'name'});
    const x = textInput(r.x, `x of joint ${r.name} (m)`, {inputmode: 'decimal', class: 'num'});
    const y = textInput(r.y, `y of joint ${r.name} (m)`, {inputmode: 'decimal', class: 'num'});
    const z = spatial ? textInput(r.z, `z of joint ${r.name} (m)`, {inputmode: 'decimal', class: 'num', placeholder: '0'})
      : null;
    const tr = h('tr', {}, cell(name, ''), cell(this.bind(x, r, 'x'), '0'), cell(this.bind(y, r, 'y'), '1'),
      z ? cell(this.bind(z, r, 'z'), '2') : null,
      this.removeButton(`remove joint ${r.name}`, () => this.remove('joints', r)));
    setRowPointers(tr, ptr('structure', 'joints', r.name));
    name.addEventListener('input', () => {
      const old = r.name, nu = name.value;
      const rows = this.getRows();
      r.name = nu;
      const others = rows.joints.filter((j) => j !== r).map((j) => j.name);
      if (!others.includes(old)) {
        // references follow the renamed joint
        for (const m of rows.members) {
          if (m.from === old) m.from = nu;
          if (m.to === old) m.to = nu;
        }
        for (const p of rows.point_masses) if (p.joint === old) p.joint = nu;
        if (rows.clamp === old) rows.clamp = nu;
      }
      setRowPointers(tr, ptr('structure', 'joints', nu));
      x.setAttribute('aria-label', `x of joint ${nu} (m)`);
      y.setAttribute('aria-label', `y of joint ${nu} (m)`);
      if (z) z.setAttribute('aria-label', `z of joint ${nu} (m)`);
      this.refreshSelects();
      this.onChange('names');
    });
    return tr;
  }

  sectionRow(r) {
    const name = textInput(r.name, `name of section ${r.name}`, {class: 'name'});
    const inputs = [];
    const f = (key) => {
      const input = textInput(r.v[key], `${SECTION_LABEL[key][1]} of section ${r.name}`, {inputmode: 'decimal', class: 'num'});
      inputs.push([input, key]);
      return cell(this.bind(input, r.v, key), key);
    };
    const tr = h('tr', {}, cell(name, ''), ...Object.keys(r.v).map(f),
      this.removeButton(`remove section ${r.name}`, () => this.remove('sections', r)));
    setRowPointers(tr, ptr('structure', 'sections', r.name));
    name.addEventListener('input', () => {
      const old = r.name, nu = name.value;
      const rows = this.getRows();
      r.name = nu;
      if (!rows.sections.some((s) => s !== r && s.name === old)) {
        for (const m of rows.members) if (m.section === old) m.section = nu;
      }
      setRowPointers(tr, ptr('structure', 'sections', nu));
      for (const [input, key] of inputs) input.setAttribute('aria-label', `${SECTION_LABEL[key][1]} of section ${nu}`);
      this.refreshSelects();
      this.onChange('names');
    });
    return tr;
  }

  memberRow(r, i) {
    const joints = this.names('joints'), sections = this.names('sections');
    const label = `member ${i + 1}`;
    const id = textInput(r.id, `id of ${label}`, {class: 'name'});
    id.addEventListener('input', () => {
      r.id = id.value;
      r.hasId = true;
      this.onChange('value');
    });
    const sel = (key, names, what) => {
      const s = nameSelect(r[key], names, `${what} of ${label}`);
      s.addEventListener('change', () => {
        r[key] = s.value;
        this.onChange('value');
      });
      return s;
    };
    const el = textInput(r.elements, `elements of ${label}`, {inputmode: 'numeric', class: 'num short'});
    const spatial = this.getRows().spatial;
    const tw = spatial ? textInput(r.twist, `twist (degrees) of ${label}`, {inputmode: 'decimal', class: 'num short',
      placeholder: '0'}) : null;
    const fd = spatial ? textInput(r.fdir, `flap direction (x, y, z) of ${label}`, {class: 'num', placeholder: 'default'})
      : null;
    const tr = h('tr', {}, cell(id, 'id'), cell(sel('from', joints, 'from joint'), 'from'),
      cell(sel('to', joints, 'to joint'), 'to'), cell(sel('section', sections, 'section'), 'section'),
      cell(this.bind(el, r, 'elements'), 'elements'),
      tw ? cell(this.bind(tw, r, 'twist'), 'twist_deg') : null,
      fd ? cell(this.bind(fd, r, 'fdir'), 'flap_direction') : null,
      this.removeButton(`remove ${label}`, () => this.remove('members', r)));
    setRowPointers(tr, ptr('structure', 'members', i));
    return tr;
  }

  massRow(r, i) {
    const label = `point mass ${i + 1}`;
    const s = nameSelect(r.joint, this.names('joints'), `joint of ${label}`);
    s.addEventListener('change', () => {
      r.joint = s.value;
      this.onChange('value');
    });
    const m = textInput(r.mass, `mass of ${label} (kg)`, {inputmode: 'decimal', class: 'num'});
    const inr = this.getRows().spatial ? textInput(r.inertia, `inertia (Ixx, Iyy, Izz) of ${label} (kg·m²)`,
      {class: 'num', placeholder: 'none'}) : null;
    const tr = h('tr', {}, cell(s, 'joint'), cell(this.bind(m, r, 'mass'), 'mass'),
      inr ? cell(this.bind(inr, r, 'inertia'), 'inertia') : null,
      this.removeButton(`remove ${label}`, () => this.remove('point_masses', r)));
    setRowPointers(tr, ptr('structure', 'point_masses', i));
    return tr;
  }

  remove(kind, row) {
    const rows = this.getRows();
    const i = rows[kind].indexOf(row);
    if (i >= 0) rows[kind].splice(i, 1);
    if (kind === 'point_masses') rows.hasPointMasses = rows.point_masses.length > 0;
    this.render();
    this.onChange('rows');
    const add = {joints: 'add-joint', sections: 'add-section', members: 'add-member', point_masses: 'add-mass'}[kind];
    this.doc.getElementById(add).focus();
  }

  focusLast(tbody) {
    const tr = tbody.lastElementChild;
    const c = tr && tr.querySelector('input, select');
    if (c) c.focus();
  }

  addJoint() {
    const rows = this.getRows();
    const last = rows.joints[rows.joints.length - 1];
    rows.joints.push({name: freshName('J', this.names('joints')), x: last ? last.x : '0', y: last ? last.y : '0',
      z: last ? last.z : '', more: []});
    this.render();
    this.onChange('rows');
    this.focusLast(this.t.joints);
  }

  addSection() {
    const rows = this.getRows();
    const s = rows.sections[0] || (rows.spatial
      ? {v: {EA: '1.08444e8', EI_flap: '14000', EI_edge: '14000', GJ: '10758', mass_per_length: '1.2',
        flap_inertia: '1.549e-4', edge_inertia: '1.549e-4'}}
      : {v: {E: '7e10', A: '4e-4', I: '2e-7', mass_per_length: '1.2'}});
    rows.sections.push({name: freshName('s', this.names('sections')), v: {...s.v}, had: {}, extra: {}});
    this.render();
    this.onChange('rows');
    this.focusLast(this.t.sections);
  }

  addMember() {
    const rows = this.getRows();
    const j = this.names('joints');
    rows.members.push({id: freshName('m', rows.members.map((m) => m.id)), hasId: true,
      from: j[j.length - 2] ?? rows.clamp, to: j[j.length - 1] ?? '', section: this.names('sections')[0] ?? '',
      elements: '8', twist: '', fdir: '', extra: {}});
    this.render();
    this.onChange('rows');
    this.focusLast(this.t.members);
  }

  addMass() {
    const rows = this.getRows();
    const j = this.names('joints');
    rows.point_masses.push({joint: j[j.length - 1] ?? '', mass: '0.1', inertia: '', extra: {}});
    rows.hasPointMasses = true;
    this.render();
    this.onChange('rows');
    this.focusLast(this.t.masses);
  }
}
