// examples.js — structures to start from.  The β = 90° angled beam, the
// straight blade and the two spatial structures (DESIGN.md 7) are the
// repository's examples/*.json (bundled at build time); β = 0° and 45° move
// the free end P of the same two 5 m beams.  Each has a one-line description
// (the title of its entry in the list, and the text beside it).

import angled90 from '../../../examples/angled-beam-90.json';
import blade from '../../../examples/straight-blade.json';
import flapping from '../../../examples/flapping-blade.json';
import arm3d from '../../../examples/out-of-plane-arm.json';

function clone(v) {
  return JSON.parse(JSON.stringify(v));
}

/** The Kim & Yoo angled beam with the second beam at angle beta (degrees) to the first. */
function angled(betaDeg) {
  const doc = clone(angled90);
  const b = (betaDeg * Math.PI) / 180;
  const round = (x) => Number(x.toPrecision(15));
  doc.structure.joints.P = [round(5 + 5 * Math.cos(b)), round(5 * Math.sin(b))];
  if (betaDeg === 90) doc.structure.joints.P = clone(angled90.structure.joints.P);
  return doc;
}

const branched = {
  structure: {
    joints: {H: [0.5, 0], A: [3, 0], B: [5.5, 1.5], D: [5.5, -1.5]},
    sections: {
      trunk: {E: 7e10, A: 6e-4, I: 4e-7, mass_per_length: 1.8},
      arm: {E: 7e10, A: 4e-4, I: 2e-7, mass_per_length: 1.2},
    },
    members: [
      {id: 'trunk', from: 'H', to: 'A', section: 'trunk', elements: 12},
      {id: 'upper', from: 'A', to: 'B', section: 'arm', elements: 10},
      {id: 'lower', from: 'A', to: 'D', section: 'arm', elements: 10},
    ],
    point_masses: [{joint: 'B', mass: 0.3}, {joint: 'D', mass: 0.3}],
    clamp: 'H',
  },
  frames: 'per_element',
  analysis: {omega: 10, modes: 4, mode_shapes: true},
};

export const EXAMPLES = [
  {key: 'angled-90', label: 'Angled beam, β = 90° (Kim & Yoo)', doc: () => angled(90),
    desc: 'Two 5 m aluminium beams at a right angle in the hub plane (the paper\'s case).'},
  {key: 'angled-45', label: 'Angled beam, β = 45°', doc: () => angled(45),
    desc: 'The same two beams with the second one at 45°.'},
  {key: 'angled-0', label: 'Angled beam, β = 0° (straight 10 m)', doc: () => angled(0),
    desc: 'The same two beams in line: a straight 10 m beam.'},
  {key: 'blade', label: 'Straight blade with tip mass', doc: () => clone(blade),
    desc: 'A 5 m blade from a 0.5 m hub with a 0.2 kg tip mass, planar.'},
  {key: 'branched', label: 'Branched frame (Y)', doc: () => clone(branched),
    desc: 'A trunk that splits into two arms with end masses, planar.'},
  {key: 'flapping-blade', label: 'Flapping blade (3D)', doc: () => clone(flapping),
    desc: 'Spatial: a 10 m blade from a 0.5 m hub, flap, lead-lag and torsion; sweep 0…10 rad/s.'},
  {key: 'out-of-plane-arm', label: 'Out-of-plane arm (3D)', doc: () => clone(arm3d),
    desc: 'Spatial: a 3 m radial arm with a 2 m mast along the spin axis at its end.'},
];
