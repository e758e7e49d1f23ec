// tower-model.js — the structure a request in the tower form stands for
// (DESIGN.md 8.5), for the drawing and the mesh only: the daemon does the
// real expansion (codec tower.c).  Tower axes (fa, ss, up) are the hub axes
// (z, x, y): joints base = base_height·up and top = height·up, member "tower"
// with flap_direction fa, clamp base, the top mass at the top.  Imports
// nothing, so request.js (structureOf) can use it.

const isObj = (v) => v !== null && typeof v === 'object' && !Array.isArray(v);

/** The structure of a tower form t, or null when it lacks a usable height. */
export function expandTower(t) {
  if (!isObj(t) || typeof t.height !== 'number' || !(t.height > 0)) return null;
  const base = typeof t.base_height === 'number' && Number.isFinite(t.base_height) ? t.base_height : 0;
  const section = isObj(t.section) ? t.section : {};
  const st = {
    joints: {base: [0, base, 0], top: [0, t.height, 0]},
    sections: {tower: {EA: 1, EI_flap: 1, EI_edge: 1, GJ: 1, mass_per_length: 1, ...section}},
    members: [{id: 'tower', from: 'base', to: 'top', section: 'tower',
      elements: Number.isInteger(t.elements) ? t.elements : 48, flap_direction: [0, 0, 1]}],
    clamp: 'base',
  };
  if (isObj(t.top_mass)) st.point_masses = [{joint: 'top', mass: t.top_mass.mass}];
  return st;
}
