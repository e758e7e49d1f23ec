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

function finite2(v) {
  return Array.isArray(v) && v.length === 2 && v.every((x) => typeof x === 'number' && Number.isFinite(x));
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
 * {ok, reason, joints: {name: [x, y]}, nodes: [{x, y, joint}], elems: [{n1, n2, member}],
 *  frames: [{node, angle}], lines: [[[x, y], [x, y], memberIndex]]}.
 * `lines` (member ends) is filled even when the mesh cannot be built, for a
 * drawing of whatever is drawable.
 */
export function buildMesh(st, frames) {
  const out = {ok: false, reason: '', joints: {}, nodes: [], elems: [], frames: [], lines: []};
  if (!st || typeof st !== 'object') {
    out.reason = 'no structure';
    return out;
  }
  const joints = st.joints && typeof st.joints === 'object' ? st.joints : {};
  for (const [name, xy] of Object.entries(joints)) if (finite2(xy)) out.joints[name] = xy;
  const members = Array.isArray(st.members) ? st.members : [];
  members.forEach((m, i) => {
    if (m && out.joints[m.from] && out.joints[m.to]) out.lines.push([out.joints[m.from], out.joints[m.to], i]);
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
  out.nodes.push({x: out.joints[clamp][0], y: out.joints[clamp][1], joint: clamp});
  for (let k = 0; k < order.length; k++) {
    const b = members[order[k]];
    const a = near[k], z = b.from === a ? b.to : b.from;
    const [x0, y0] = out.joints[a], [x1, y1] = out.joints[z];
    const angle = Math.atan2(y1 - y0, x1 - x0);
    let prev = jointNode[a];
    for (let i = 1; i <= b.elements; i++) {
      const t = i / b.elements;
      const last = i === b.elements;
      out.nodes.push({x: last ? x1 : x0 + t * (x1 - x0), y: last ? y1 : y0 + t * (y1 - y0), joint: last ? z : null});
      const n2 = out.nodes.length - 1;
      const e = i - 1;
      const first = out.elems.length === 0;
      if (first || (e === 0 && frames !== 'single') || runStart(frames, e, b.elements)) {
        out.frames.push({node: prev, angle});
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
