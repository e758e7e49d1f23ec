// mesh.js — the FE mesh of a structure, numbered exactly as core/mesh.c does,
// so that result.cases[i].equilibrium.nodes and the mode shapes (one entry per
// FE node) can be drawn element by element.
//
// core/mesh.c: a breadth-first walk from the clamp joint (members in request
// order at each joint) orients every member away from the clamp; node 0 is
// the clamp, then each member in walk order adds its interior nodes and its
// far joint.  Substructures (frames) start at the first element of the
// structure, at the first element of each member unless frames is "single",
// and where the frame scheme cuts a member.
//
// Joints are [x, y] or [x, y, z] (DESIGN.md 7.1, z along the spin axis); every
// node carries z (0 for a planar joint), and every member its section axes
// (e1 along the member as written, from -> to; e3 the flap normal; e2 = e3 x e1)
// for the 3D drawing.

function finiteXY(v) {
  return Array.isArray(v) && (v.length === 2 || v.length === 3) &&
    v.every((x) => typeof x === 'number' && Number.isFinite(x));
}

/** [x, y, z] of a joint value ([x, y] has z = 0). */
export function xyz(v) {
  return [v[0], v[1], v.length > 2 ? v[2] : 0];
}

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);

/** The part of d normal to the unit vector e1, normalised (null when d is (nearly) along e1). */
function normalPart(d, e1) {
  const t = dot(d, e1);
  const v = [d[0] - t * e1[0], d[1] - t * e1[1], d[2] - t * e1[2]];
  const n = norm(v);
  return n > 1e-9 * Math.max(1, norm(d)) ? v.map((c) => c / n) : null;
}

/**
 * Section axes of a member from a to b (DESIGN.md 7.1): e1 along it; e3 the
 * part of flap_direction (else of the hub axis z, else of x) normal to e1;
 * e2 = e3 x e1; then (e2, e3) turned by twist_deg about e1.  null for a
 * member of zero length.
 */
export function sectionAxes(a, b, member) {
  const d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
  const l = norm(d);
  if (!(l > 0)) return null;
  const e1 = d.map((c) => c / l);
  const fd = member && Array.isArray(member.flap_direction) && member.flap_direction.length === 3 &&
    member.flap_direction.every((x) => typeof x === 'number' && Number.isFinite(x)) ? member.flap_direction : null;
  let e3 = (fd && normalPart(fd, e1)) || normalPart([0, 0, 1], e1) || normalPart([1, 0, 0], e1);
  let e2 = cross(e3, e1);
  const tw = member && typeof member.twist_deg === 'number' && Number.isFinite(member.twist_deg)
    ? (member.twist_deg * Math.PI) / 180 : 0;
  if (tw) {
    const c = Math.cos(tw), s = Math.sin(tw);
    const n2 = e2.map((x, i) => c * x + s * e3[i]);
    const n3 = e3.map((x, i) => -s * e2[i] + c * x);
    e2 = n2;
    e3 = n3;
  }
  return {e1, e2, e3};
}

/** Does element i (0-based within a member of ne elements) start a run? */
function runStart(frames, i, ne) {
  if (frames === 'single') return false;
  if (frames === 'per_element' || frames === undefined) return true;
  if (frames && typeof frames === 'object') {
    if (Number.isInteger(frames.elements_per_frame) && frames.elements_per_frame >= 1) {
      return i % frames.elements_per_frame === 0;
    }
    if (Number.isInteger(frames.per_member) && frames.per_member >= 1) {
      const k = Math.min(frames.per_member, ne);
      for (let r = 0; r < k; r++) if (Math.floor((r * ne) / k) === i) return true;
      return false;
    }
  }
  return false;
}

/**
 * Mesh of a structure object (possibly invalid).  Returns
 * {ok, reason, spatial, joints: {name: [x, y] | [x, y, z]}, nodes: [{x, y, z, joint}],
 *  elems: [{n1, n2, member}], frames: [{node, angle, axes}], lines: [[a, b, memberIndex]],
 *  axes: [{e1, e2, e3} | null per member]}.
 * spatial: some joint has a z (the request may still be spatial through its sections:
 * see request.js isSpatial).  angle is the in-plane direction of the member (the
 * planar drawing); axes its section axes (the 3D drawing).
 * `lines` (member ends) is filled even when the mesh cannot be built, for a
 * drawing of whatever is drawable.
 */
export function buildMesh(st, frames) {
  const out = {ok: false, reason: '', spatial: false, joints: {}, nodes: [], elems: [], frames: [], lines: [], axes: []};
  if (!st || typeof st !== 'object') {
    out.reason = 'no structure';
    return out;
  }
  const joints = st.joints && typeof st.joints === 'object' ? st.joints : {};
  for (const [name, xy] of Object.entries(joints)) {
    if (finiteXY(xy)) {
      out.joints[name] = xy;
      if (xy.length === 3) out.spatial = true;
    }
  }
  const members = Array.isArray(st.members) ? st.members : [];
  members.forEach((m, i) => {
    const ok = m && out.joints[m.from] && out.joints[m.to];
    if (ok) out.lines.push([out.joints[m.from], out.joints[m.to], i]);
    out.axes.push(ok ? sectionAxes(xyz(out.joints[m.from]), xyz(out.joints[m.to]), m) : null);
  });
  const clamp = st.clamp;
  if (typeof clamp !== 'string' || !out.joints[clamp]) {
    out.reason = 'the clamp is not a joint';
    return out;
  }
  for (const m of members) {
    if (!m || !out.joints[m.from] || !out.joints[m.to] || !Number.isInteger(m.elements) ||
        m.elements < 1 || m.elements > 100000) {
      out.reason = 'a member is incomplete';
      return out;
    }
  }
  // breadth-first walk from the clamp
  const seen = new Set([clamp]);
  const used = new Array(members.length).fill(false);
  const order = [], near = [];
  const queue = [clamp];
  while (queue.length) {
    const j = queue.shift();
    for (let i = 0; i < members.length; i++) {
      const b = members[i];
      if (used[i] || (b.from !== j && b.to !== j)) continue;
      const other = b.from === j ? b.to : b.from;
      if (seen.has(other)) {
        out.reason = 'the members form a cycle';
        return out;
      }
      used[i] = true;
      seen.add(other);
      order.push(i);
      near.push(j);
      queue.push(other);
    }
  }
  if (used.some((u) => !u)) {
    out.reason = 'a member is not connected to the clamp';
    return out;
  }
  const jointNode = {[clamp]: 0};
  const c0 = xyz(out.joints[clamp]);
  out.nodes.push({x: c0[0], y: c0[1], z: c0[2], joint: clamp});
  for (let k = 0; k < order.length; k++) {
    const b = members[order[k]];
    const a = near[k], z = b.from === a ? b.to : b.from;
    const [x0, y0, z0] = xyz(out.joints[a]), [x1, y1, z1] = xyz(out.joints[z]);
    const angle = Math.atan2(y1 - y0, x1 - x0);
    const axes = out.axes[order[k]];
    let prev = jointNode[a];
    for (let i = 1; i <= b.elements; i++) {
      const t = i / b.elements;
      const last = i === b.elements;
      out.nodes.push({x: last ? x1 : x0 + t * (x1 - x0), y: last ? y1 : y0 + t * (y1 - y0),
        z: last ? z1 : z0 + t * (z1 - z0), joint: last ? z : null});
      const n2 = out.nodes.length - 1;
      const e = i - 1;
      const first = out.elems.length === 0;
      if (first || (e === 0 && frames !== 'single') || runStart(frames, e, b.elements)) {
        out.frames.push({node: prev, angle, axes});
      }
      out.elems.push({n1: prev, n2, member: order[k]});
      if (last) jointNode[z] = n2;
      prev = n2;
    }
  }
  out.jointNode = jointNode;
  out.ok = true;
  return out;
}
