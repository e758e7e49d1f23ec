// request.js — the request document (DESIGN.md §3) as the editor sees it:
// defaults, JSON pointers, the editable rows of the structure, the speeds,
// number formatting and a compact JSON pretty-printer.
//
// The textarea's JSON text is what is validated and submitted.  The tables
// edit "rows" (arrays, so a joint can be renamed or briefly duplicated while
// typing); rowsToStructure turns them back into the request's objects.  A
// value typed in a numeric cell that is not a number is kept as a string so
// the daemon reports it with its own message and pointer.

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

/**
 * Editable rows of a request's structure (tolerant: whatever the JSON holds
 * is shown as text, so a half-typed request still fills the tables).
 */
export function structureToRows(st) {
  const s = isObj(st) ? st : {};
  const rows = {joints: [], sections: [], members: [], point_masses: [], clamp: '', extra: {}};
  if (isObj(s.joints)) {
    for (const [name, xy] of Object.entries(s.joints)) {
      const a = Array.isArray(xy) ? xy : [];
      rows.joints.push({name, x: text(a[0]), y: text(a[1])});
    }
  }
  if (isObj(s.sections)) {
    for (const [name, sec] of Object.entries(s.sections)) {
      const o = isObj(sec) ? sec : {};
      rows.sections.push({name, E: text(o.E), A: text(o.A), I: text(o.I), mu: text(o.mass_per_length),
        extra: pick(o, ['E', 'A', 'I', 'mass_per_length'])});
    }
  }
  if (Array.isArray(s.members)) {
    for (const m of s.members) {
      const o = isObj(m) ? m : {};
      rows.members.push({id: text(o.id), hasId: 'id' in o, from: text(o.from), to: text(o.to),
        section: text(o.section), elements: text(o.elements),
        extra: pick(o, ['id', 'from', 'to', 'section', 'elements'])});
    }
  }
  if (Array.isArray(s.point_masses)) {
    for (const p of s.point_masses) {
      const o = isObj(p) ? p : {};
      rows.point_masses.push({joint: text(o.joint), mass: text(o.mass), extra: pick(o, ['joint', 'mass'])});
    }
  }
  rows.clamp = text(s.clamp);
  rows.hasPointMasses = 'point_masses' in s;
  rows.extra = pick(s, ['joints', 'sections', 'members', 'point_masses', 'clamp']);
  return rows;
}

/** The request's structure object from the rows. */
export function rowsToStructure(rows) {
  const joints = {};
  for (const j of rows.joints) joints[j.name] = [cellValue(j.x), cellValue(j.y)];
  const sections = {};
  for (const s of rows.sections) {
    sections[s.name] = {E: cellValue(s.E), A: cellValue(s.A), I: cellValue(s.I),
      mass_per_length: cellValue(s.mu), ...s.extra};
  }
  const members = rows.members.map((m) => {
    const o = {};
    if (m.hasId || m.id !== '') o.id = m.id;
    o.from = m.from;
    o.to = m.to;
    o.section = m.section;
    o.elements = cellValue(m.elements);
    return Object.assign(o, m.extra);
  });
  const st = {joints, sections, members};
  if (rows.point_masses.length || rows.hasPointMasses) {
    st.point_masses = rows.point_masses.map((p) => ({joint: p.joint, mass: cellValue(p.mass), ...p.extra}));
  }
  st.clamp = rows.clamp;
  return Object.assign(st, rows.extra);
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
    if (typeof a !== 'number') return {error: 'the first speed must be a number (rad/s)', field: 'from'};
    if (typeof b !== 'number') return {error: 'the last speed must be a number (rad/s)', field: 'to'};
    if (!Number.isInteger(n) || n < 2 || n > 100000) {
      return {error: 'the number of speeds must be an integer between 2 and 100000', field: 'count'};
    }
    return {value: linspace(a, b, n)};
  }
  const parts = String(f.list).split(/[\s,;]+/).filter((s) => s !== '');
  return {value: parts.map(cellValue)};
}
