// request.js — the request document (DESIGN.md §3) as the editor sees it:
// defaults, JSON pointers, the editable rows of the structure, the speeds,
// number formatting and a compact JSON pretty-printer.
//
// The textarea's JSON text is what is validated and submitted.  The tables
// edit "rows" (arrays, so a joint can be renamed or briefly duplicated while
// typing); rowsToStructure turns them back into the request's objects.  A
// value typed in a numeric cell that is not a number is kept as a string so
// the daemon reports it with its own message and pointer.

import {expandTower} from './tower-model.js';

export const DEFAULTS = {
  frames: 'per_element',
  analysis: {
    modes: 3,
    geometric_stiffening: true,
    coriolis: true,
    mass: 'lumped',
    substructure_modes: 'augmented',
    modes_per_frame: 'all',
    mode_shapes: true,
  },
};

// ------------------------------------------------------------ JSON pointers

/** One RFC 6901 reference token. */
export function escToken(s) {
  return String(s).replace(/~/g, '~0').replace(/\//g, '~1');
}

/** Pointer from tokens: ptr('structure', 'joints', 'O', 0) -> "/structure/joints/O/0". */
export function ptr(...tokens) {
  return tokens.map((t) => '/' + escToken(t)).join('');
}

/** Parent pointer ("" for a top-level one, null for ""). */
export function parentPtr(p) {
  if (p === '') return null;
  return p.slice(0, p.lastIndexOf('/'));
}

// ------------------------------------------------------------------ numbers

const NUM_RE = /^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/;

/** The JSON value of a typed cell: a number when it reads as one, else the text. */
export function cellValue(text) {
  const s = String(text).trim();
  if (NUM_RE.test(s)) {
    const v = Number(s);
    if (Number.isFinite(v)) return v;
  }
  return s;
}

/** A short, exact text for a number: 7e10, 4e-4, 0.5, 12. */
export function fmtNum(v) {
  if (typeof v !== 'number') return v === undefined || v === null ? '' : String(v);
  if (!Number.isFinite(v)) return String(v);
  const a = Math.abs(v);
  if (a !== 0 && (a >= 1e6 || a < 1e-3)) {
    return v.toExponential().replace('e+', 'e');
  }
  return String(v);
}

/** Number for display with n significant digits (tables, labels). */
export function sig(v, n = 6) {
  if (typeof v !== 'number' || !Number.isFinite(v)) return '–';
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a >= 1e6 || a < 1e-4) return v.toExponential(n - 1).replace('e+', 'e');
  return String(Number(v.toPrecision(n)));
}

// -------------------------------------------------------- pretty JSON text

function inlineable(v) {
  if (Array.isArray(v)) return v.every((x) => x === null || typeof x !== 'object');
  if (v && typeof v === 'object') {
    return Object.values(v).every((x) => x === null || typeof x !== 'object' ||
      (Array.isArray(x) && x.every((y) => y === null || typeof y !== 'object')));
  }
  return true;
}

function scalar(v) {
  if (typeof v === 'number') return Number.isFinite(v) ? fmtNum(v) : 'null';
  return JSON.stringify(v);
}

function compact(v) {
  if (Array.isArray(v)) return '[' + v.map(compact).join(', ') + ']';
  if (v && typeof v === 'object') {
    return '{' + Object.entries(v).map(([k, x]) => JSON.stringify(k) + ': ' + compact(x)).join(', ') + '}';
  }
  return scalar(v);
}

/**
 * JSON text in the style of examples/*.json: small arrays and flat objects on
 * one line, everything else indented by two spaces.  Numbers use fmtNum
 * (still valid JSON: 7e10, 4e-4).
 */
export function prettyJSON(v, indent = '') {
  const one = compact(v);
  if (v === null || typeof v !== 'object' || (inlineable(v) && indent.length + one.length <= 100)) {
    return one;
  }
  const inner = indent + '  ';
  if (Array.isArray(v) && v.length && v.every((x) => x === null || typeof x !== 'object')) {
    // a long list of numbers (a sweep): as many per line as fit
    const lines = [];
    let line = '';
    for (const x of v.map(scalar)) {
      if (line && inner.length + line.length + x.length + 2 > 100) {
        lines.push(line + ',');
        line = '';
      }
      line += (line ? ', ' : '') + x;
    }
    lines.push(line);
    return '[\n' + lines.map((l) => inner + l).join('\n') + '\n' + indent + ']';
  }
  if (Array.isArray(v)) {
    if (v.length === 0) return '[]';
    return '[\n' + v.map((x) => inner + prettyJSON(x, inner)).join(',\n') + '\n' + indent + ']';
  }
  const keys = Object.keys(v);
  if (keys.length === 0) return '{}';
  return '{\n' + keys.map((k) => inner + JSON.stringify(k) + ': ' + prettyJSON(v[k], inner)).join(',\n') +
    '\n' + indent + '}';
}

// ------------------------------------------------------------- rows <-> doc

function isObj(v) {
  return v !== null && typeof v === 'object' && !Array.isArray(v);
}

function pick(o, known) {
  const extra = {};
  if (isObj(o)) for (const [k, v] of Object.entries(o)) if (!known.includes(k)) extra[k] = v;
  return extra;
}

function text(v) {
  if (v === undefined) return '';
  if (typeof v === 'number') return fmtNum(v);
  if (typeof v === 'string') return v;
  return JSON.stringify(v);
}

// Section fields (DESIGN.md 1.1 and 7.3).  The tables show the planar columns
// or the spatial ones (EA form); a section's other keys (the E, G, A, I_flap,
// I_edge, J form of a spatial section, stations, …) are kept as they are.
export const PLANAR_SECTION_KEYS = ['E', 'A', 'I', 'mass_per_length'];
export const SPATIAL_SECTION_KEYS = ['EA', 'EI_flap', 'EI_edge', 'GJ', 'mass_per_length', 'flap_inertia',
  'edge_inertia'];
/** Keys that make a section spatial (DESIGN.md 7.3: "a request is spatial when its sections are spatial"). */
const SPATIAL_ONLY = ['EA', 'EI_flap', 'EI_edge', 'GJ', 'G', 'I_flap', 'I_edge', 'J', 'flap_inertia', 'edge_inertia'];

/**
 * Is the structure spatial (3D)?  Its sections are spatial, or it uses a field
 * only a spatial request may carry ([x, y, z] joints, twist_deg, flap_direction,
 * point-mass inertia): shown as spatial so that field can be edited (the daemon
 * then says what it needs).
 */
export function isSpatial(st) {
  if (!isObj(st)) return false;
  if (isObj(st.sections) && Object.values(st.sections).some((o) => isObj(o) && SPATIAL_ONLY.some((k) => k in o))) {
    return true;
  }
  if (isObj(st.joints) && Object.values(st.joints).some((v) => Array.isArray(v) && v.length === 3)) return true;
  if (Array.isArray(st.members) && st.members.some((m) => isObj(m) && ('twist_deg' in m || 'flap_direction' in m))) {
    return true;
  }
  return Array.isArray(st.point_masses) && st.point_masses.some((p) => isObj(p) && 'inertia' in p);
}

/** A short list of numbers as a cell's text: [1, 0, 0] -> "1, 0, 0" (anything else as JSON). */
function listText(v) {
  if (v === undefined) return '';
  if (Array.isArray(v) && v.every((x) => typeof x === 'number')) return v.map(fmtNum).join(', ');
  return text(v);
}

/** The JSON value of a list cell: "1, 0, 0" or "[1, 0, 0]" -> [1, 0, 0] (items as cellValue). */
export function listValue(t) {
  const s = String(t).trim().replace(/^\[/, '').replace(/\]$/, '');
  return s.split(/[\s,;]+/).filter((x) => x !== '').map(cellValue);
}

function sectionRow(name, o, spatial) {
  const keys = spatial ? SPATIAL_SECTION_KEYS : PLANAR_SECTION_KEYS;
  const v = {}, had = {};
  for (const k of keys) {
    v[k] = text(o[k]);
    had[k] = k in o;
  }
  return {name, v, had, extra: pick(o, keys)};
}

/**
 * Editable rows of a request's structure (tolerant: whatever the JSON holds
 * is shown as text, so a half-typed request still fills the tables).
 * rows.spatial says which columns the tables show (isSpatial of the structure).
 */
export function structureToRows(st) {
  const s = isObj(st) ? st : {};
  const spatial = isSpatial(s);
  const rows = {spatial, joints: [], sections: [], members: [], point_masses: [], clamp: '', extra: {}};
  if (isObj(s.joints)) {
    for (const [name, xy] of Object.entries(s.joints)) {
      const a = Array.isArray(xy) ? xy : [];
      rows.joints.push({name, x: text(a[0]), y: text(a[1]), z: a.length > 2 ? text(a[2]) : '',
        more: a.length > 3 ? a.slice(3) : []});
    }
  }
  if (isObj(s.sections)) {
    for (const [name, sec] of Object.entries(s.sections)) rows.sections.push(sectionRow(name, isObj(sec) ? sec : {}, spatial));
  }
  if (Array.isArray(s.members)) {
    for (const m of s.members) {
      const o = isObj(m) ? m : {};
      rows.members.push({id: text(o.id), hasId: 'id' in o, from: text(o.from), to: text(o.to),
        section: text(o.section), elements: text(o.elements),
        twist: text(o.twist_deg), hadTwist: 'twist_deg' in o,
        fdir: listText(o.flap_direction), hadFdir: 'flap_direction' in o,
        extra: pick(o, ['id', 'from', 'to', 'section', 'elements', 'twist_deg', 'flap_direction'])});
    }
  }
  if (Array.isArray(s.point_masses)) {
    for (const p of s.point_masses) {
      const o = isObj(p) ? p : {};
      rows.point_masses.push({joint: text(o.joint), mass: text(o.mass),
        inertia: listText(o.inertia), hadInertia: 'inertia' in o, extra: pick(o, ['joint', 'mass', 'inertia'])});
    }
  }
  rows.clamp = text(s.clamp);
  rows.hasPointMasses = 'point_masses' in s;
  rows.extra = pick(s, ['joints', 'sections', 'members', 'point_masses', 'clamp']);
  return rows;
}

/** An optional cell: written when it holds text or the request had the key. */
function optional(out, key, t, had, value = cellValue) {
  if (t !== '' || had) out[key] = value(t);
}

/** The request's structure object from the rows. */
export function rowsToStructure(rows) {
  const joints = {};
  for (const j of rows.joints) {
    joints[j.name] = [cellValue(j.x), cellValue(j.y)];
    if (j.z !== '' || (j.more && j.more.length)) joints[j.name].push(cellValue(j.z), ...(j.more || []));
  }
  const sections = {};
  for (const s of rows.sections) {
    const o = {};
    for (const [k, t] of Object.entries(s.v)) {
      // the planar columns are always written (the daemon names an empty one); a
      // spatial column only when it holds text or the section had it (so a section
      // in the E, G, A, I_flap, I_edge, J form does not gain empty EA-form keys)
      if (!rows.spatial || k === 'mass_per_length') o[k] = cellValue(t);
      else optional(o, k, t, s.had[k]);
    }
    sections[s.name] = Object.assign(o, s.extra);
  }
  const members = rows.members.map((m) => {
    const o = {};
    if (m.hasId || m.id !== '') o.id = m.id;
    o.from = m.from;
    o.to = m.to;
    o.section = m.section;
    o.elements = cellValue(m.elements);
    optional(o, 'twist_deg', m.twist, m.hadTwist);
    optional(o, 'flap_direction', m.fdir, m.hadFdir, listValue);
    return Object.assign(o, m.extra);
  });
  const st = {joints, sections, members};
  if (rows.point_masses.length || rows.hasPointMasses) {
    st.point_masses = rows.point_masses.map((p) => {
      const o = {joint: p.joint, mass: cellValue(p.mass)};
      optional(o, 'inertia', p.inertia, p.hadInertia, listValue);
      return Object.assign(o, p.extra);
    });
  }
  st.clamp = rows.clamp;
  return Object.assign(st, rows.extra);
}

const num = (t) => {
  const v = cellValue(t);
  return typeof v === 'number' ? v : null;
};
const prod = (a, b) => (a !== null && b !== null ? fmtNum(Number((a * b).toPrecision(12))) : '');

/**
 * Switch the rows between a planar and a spatial model (the "spatial" switch).
 * To spatial: EA = E·A and EI_edge = E·I (the planar bending is in the plane:
 * edgewise); EI_flap and GJ are left for the user (nothing in a planar section
 * says them; the daemon names them).  To planar: the E, A, I the section had
 * when it was made spatial here (if EA and EI_edge were not edited since),
 * else those of a section in the E, G, A, I_flap, I_edge, J form (I = I_edge),
 * else empty; the z coordinates,
 * twists, flap directions and point-mass inertias are dropped (a planar request
 * cannot carry them).  mass_per_length and unknown keys stay.
 */
export function convertRows(rows, spatial) {
  if (rows.spatial === spatial) return;
  rows.spatial = spatial;
  for (const s of rows.sections) {
    const mu = s.v.mass_per_length ?? '';
    if (spatial) {
      const E = num(s.v.E), A = num(s.v.A), I = num(s.v.I);
      for (const k of ['E', 'A', 'I']) delete s.extra[k];
      const v = {EA: prod(E, A), EI_flap: '', EI_edge: prod(E, I), GJ: '', mass_per_length: mu, flap_inertia: '',
        edge_inertia: ''};
      s.memo = {E: s.v.E, A: s.v.A, I: s.v.I, EA: v.EA, EI_edge: v.EI_edge};
      s.v = v;
      s.had = {};
    } else {
      const x = s.extra, m = s.memo;
      s.v = m && m.EA === s.v.EA && m.EI_edge === s.v.EI_edge
        ? {E: m.E, A: m.A, I: m.I, mass_per_length: mu}
        : {E: text(x.E), A: text(x.A), I: text(x.I_edge), mass_per_length: mu};
      s.had = {};
      delete s.memo;
      for (const k of SPATIAL_ONLY) delete x[k];
    }
  }
  if (!spatial) {
    for (const j of rows.joints) {
      j.z = '';
      j.more = [];
    }
    for (const m of rows.members) {
      m.twist = m.fdir = '';
      m.hadTwist = m.hadFdir = false;
    }
    for (const p of rows.point_masses) {
      p.inertia = '';
      p.hadInertia = false;
    }
  }
}

/** A name not yet used among names: prefix + first free number. */
export function freshName(prefix, names) {
  const used = new Set(names);
  for (let i = 1; ; i++) if (!used.has(prefix + i)) return prefix + i;
}

// -------------------------------------------------------------------- speeds

/** n speeds from a to b inclusive, rounded to 12 significant digits. */
export function linspace(a, b, n) {
  if (n <= 1) return [a];
  const out = [];
  for (let i = 0; i < n; i++) out.push(Number((a + ((b - a) * i) / (n - 1)).toPrecision(12)));
  out[n - 1] = b;
  return out;
}

/**
 * How analysis.omega reads in the form: {mode: 'single', value} for a
 * number, {mode: 'sweep', from, to, count} for an evenly spaced array of two
 * or more speeds, {mode: 'list', list} for any other array (or anything else).
 */
export function speedsForm(omega) {
  const r = rangeOf(omega);
  if (r) return {mode: 'sweep', from: fmtNum(r.from), to: fmtNum(r.to), count: String(r.steps + 1), range: true};
  if (typeof omega === 'number' || typeof omega === 'string' || omega === undefined) {
    return {mode: 'single', value: text(omega)};
  }
  if (Array.isArray(omega) && omega.length >= 2 && omega.every((x) => typeof x === 'number' && Number.isFinite(x))) {
    const n = omega.length;
    const ref = linspace(omega[0], omega[n - 1], n);
    const span = Math.abs(omega[n - 1] - omega[0]) || 1;
    if (omega[0] !== omega[n - 1] && ref.every((x, i) => Math.abs(x - omega[i]) <= 1e-9 * span)) {
      return {mode: 'sweep', from: fmtNum(omega[0]), to: fmtNum(omega[n - 1]), count: String(n)};
    }
  }
  if (Array.isArray(omega)) return {mode: 'list', list: omega.map(text).join(', ')};
  return {mode: 'single', value: text(omega)};
}

/**
 * analysis.omega from the form fields (strings): {value}, or {error, field}
 * when the sweep fields cannot make a list of speeds (the daemon never sees
 * that: there is no request to send).
 */
export function speedsValue(f) {
  if (f.mode === 'single') return {value: cellValue(f.value)};
  if (f.mode === 'sweep') {
    const a = cellValue(f.from), b = cellValue(f.to), n = cellValue(f.count);
    const u = f.unit || 'rad/s';
    if (typeof a !== 'number') return {error: `the first speed must be a number (${u})`, field: 'from'};
    if (typeof b !== 'number') return {error: `the last speed must be a number (${u})`, field: 'to'};
    if (!Number.isInteger(n) || n < 2 || n > 100000) {
      return {error: 'the number of speeds must be an integer between 2 and 100000', field: 'count'};
    }
    // a request that gave a range keeps the range form (steps + 1 speeds, DESIGN.md 8.1)
    return {value: f.range ? {from: a, to: b, steps: n - 1} : linspace(a, b, n)};
  }
  const parts = String(f.list).split(/[\s,;]+/).filter((s) => s !== '');
  return {value: parts.map(cellValue)};
}

/**
 * A range {from, to, steps} (DESIGN.md 8.1: steps + 1 speeds) as the sweep
 * form reads it, or null for anything else.
 */
export function rangeOf(v) {
  if (!isObj(v)) return null;
  const {from, to, steps} = v;
  if (![from, to, steps].every((x) => typeof x === 'number' && Number.isFinite(x))) return null;
  return {from, to, steps};
}

/** The speeds of analysis.omega or analysis.rpm as numbers (a range expanded), in their own unit. */
export function speedList(v) {
  const r = rangeOf(v);
  if (r) return r.steps >= 1 ? linspace(r.from, r.to, Math.round(r.steps) + 1) : [r.from];
  if (typeof v === 'number') return [v];
  if (Array.isArray(v)) return v.filter((x) => typeof x === 'number' && Number.isFinite(x));
  return [];
}

// ------------------------------------------------------------------- units

export const RPM_PER_RAD_S = 60 / (2 * Math.PI);

/** Speed units: rad/s (the request's omega) or rpm (its rpm). */
export const SPEED_UNITS = {
  rad: {label: 'rad/s', of: (omega) => omega},
  rpm: {label: 'rpm', of: (omega) => omega * RPM_PER_RAD_S},
};

/** Frequency units: rad/s, Hz, per-rev (ω/Ω, null at Ω = 0). */
export const FREQ_UNITS = {
  rad: {label: 'rad/s', sym: 'ω', of: (w) => w},
  hz: {label: 'Hz', sym: 'f', of: (w) => w / (2 * Math.PI)},
  rev: {label: 'per rev', sym: 'ω/Ω', of: (w, omega) => (omega > 0 ? w / omega : null)},
};

/** One speed value converted from rad/s to rpm or back, rounded to 12 significant digits. */
export function convertSpeed(v, toRpm) {
  return Number((toRpm ? v * RPM_PER_RAD_S : v / RPM_PER_RAD_S).toPrecision(12));
}

// ------------------------------------------------------------------ blades

/**
 * The structure a request in the blade form stands for (DESIGN.md 8.1), for
 * the drawing and the mesh: b1 = (cos p, 0, sin p), b3 = (−sin p, 0, cos p)
 * with p the precone; joints root = hub_radius·b1 and tip = (hub_radius +
 * length)·b1; member "blade" (root → tip, elements, flap_direction b3,
 * twist_deg = pitch); clamp root; the tip mass at the tip.  null when the
 * blade lacks a usable length.  The daemon does the real expansion; this one
 * only has to draw the same mesh (node numbering of core/mesh.c).
 */
export function expandBlade(b) {
  if (!isObj(b) || typeof b.length !== 'number' || !(b.length > 0)) return null;
  const num = (v, d) => (typeof v === 'number' && Number.isFinite(v) ? v : d);
  const p = (num(b.precone_deg, 0) * Math.PI) / 180;
  const hub = num(b.hub_radius, 0), len = b.length;
  const b1 = [Math.cos(p), 0, Math.sin(p)], b3 = [-Math.sin(p), 0, Math.cos(p)];
  const at = (r) => b1.map((c) => Number((r * c).toPrecision(15)));
  const section = isObj(b.section) ? b.section : {};
  const st = {
    joints: {root: at(hub), tip: at(hub + len)},
    sections: {blade: {EA: 1, EI_flap: 1, EI_edge: 1, GJ: 1, mass_per_length: 1, ...section}},
    members: [{id: 'blade', from: 'root', to: 'tip', section: 'blade', elements: Number.isInteger(b.elements) ? b.elements : 48,
      flap_direction: b3.map((c) => Number(c.toPrecision(15))), twist_deg: num(b.pitch_deg, 0)}],
    clamp: 'root',
  };
  if (isObj(b.tip_mass)) st.point_masses = [{joint: 'tip', mass: b.tip_mass.mass}];
  return st;
}

/** The structure of a request: its "structure", or its expanded "blade" or "tower". */
export function structureOf(doc) {
  if (!isObj(doc)) return null;
  if ('structure' in doc) return doc.structure;
  if ('blade' in doc) return expandBlade(doc.blade);
  if ('tower' in doc) return expandTower(doc.tower);
  return doc.structure;
}
