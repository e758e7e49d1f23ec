// editor.js — the structure tables (joints, sections, members, point masses,
// clamp).  Every control carries the JSON pointer of the request field it
// edits (data-pointer), which is how the daemon's errors find their field.
//
// The tables edit the rows of request.js in place and call onChange(kind):
// 'value' (a value changed: no re-render needed), 'names' (a name changed:
// the select lists are refreshed), 'rows' (rows added or removed: re-render).

import {ptr, freshName} from './request.js';

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

  render() {
    const rows = this.getRows();
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
    const name = textInput(r.name, `name of joint ${r.name}`, {class: 'name'});
    const x = textInput(r.x, `x of joint ${r.name} (m)`, {inputmode: 'decimal', class: 'num'});
    const y = textInput(r.y, `y of joint ${r.name} (m)`, {inputmode: 'decimal', class: 'num'});
    const tr = h('tr', {}, cell(name, ''), cell(this.bind(x, r, 'x'), '0'), cell(this.bind(y, r, 'y'), '1'),
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
      this.refreshSelects();
      this.onChange('names');
    });
    return tr;
  }

  sectionRow(r) {
    const name = textInput(r.name, `name of section ${r.name}`, {class: 'name'});
    const f = (key, label, suffix) => cell(this.bind(textInput(r[key], `${label} of section ${r.name}`,
      {inputmode: 'decimal', class: 'num'}), r, key), suffix);
    const tr = h('tr', {}, cell(name, ''), f('E', 'E (Pa)', 'E'), f('A', 'A (m²)', 'A'), f('I', 'I (m⁴)', 'I'),
      f('mu', 'mass per length (kg/m)', 'mass_per_length'),
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
    const tr = h('tr', {}, cell(id, 'id'), cell(sel('from', joints, 'from joint'), 'from'),
      cell(sel('to', joints, 'to joint'), 'to'), cell(sel('section', sections, 'section'), 'section'),
      cell(this.bind(el, r, 'elements'), 'elements'),
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
    const tr = h('tr', {}, cell(s, 'joint'), cell(this.bind(m, r, 'mass'), 'mass'),
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
    rows.joints.push({name: freshName('J', this.names('joints')), x: last ? last.x : '0', y: last ? last.y : '0'});
    this.render();
    this.onChange('rows');
    this.focusLast(this.t.joints);
  }

  addSection() {
    const rows = this.getRows();
    const s = rows.sections[0] || {E: '7e10', A: '4e-4', I: '2e-7', mu: '1.2'};
    rows.sections.push({name: freshName('s', this.names('sections')), E: s.E, A: s.A, I: s.I, mu: s.mu, extra: {}});
    this.render();
    this.onChange('rows');
    this.focusLast(this.t.sections);
  }

  addMember() {
    const rows = this.getRows();
    const j = this.names('joints');
    rows.members.push({id: freshName('m', rows.members.map((m) => m.id)), hasId: true,
      from: j[j.length - 2] ?? rows.clamp, to: j[j.length - 1] ?? '', section: this.names('sections')[0] ?? '',
      elements: '8', extra: {}});
    this.render();
    this.onChange('rows');
    this.focusLast(this.t.members);
  }

  addMass() {
    const rows = this.getRows();
    const j = this.names('joints');
    rows.point_masses.push({joint: j[j.length - 1] ?? '', mass: '0.1', extra: {}});
    rows.hasPointMasses = true;
    this.render();
    this.onChange('rows');
    this.focusLast(this.t.masses);
  }
}
