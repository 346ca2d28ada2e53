// Unit tests of the pure parts of web/: request coalescing (range_fetch.js) and the choice
// of levels for a view (view_refine.js).   node web/test/unit_test.mjs
import { coalesce } from '../range_fetch.js';
import { chooseLevels } from '../view_refine.js';
import { checker } from './node_support.mjs';

const result = checker();
const check = result.check;
const same = (a, b) => JSON.stringify(a) === JSON.stringify(b);

// ---- coalesce
const r = (key, offset, size) => ({ key, offset, size });
let out = coalesce([r('c', 200, 50), r('a', 0, 100), r('b', 100, 100)]);
check(out.length === 1 && out[0].offset === 0 && out[0].size === 250 && same(out[0].parts.map((p) => p.key), ['a', 'b', 'c']),
  'adjacent ranges, in any order, become one request');
out = coalesce([r('a', 0, 100), r('b', 150, 10)]);
check(out.length === 2, 'a gap is not bridged with maxGap 0');
out = coalesce([r('a', 0, 100), r('b', 150, 10)], 64);
check(out.length === 1 && out[0].size === 160, 'a gap up to maxGap is bridged');
out = coalesce([r('a', 0, 100), r('b', 150, 10)], 64, 1 << 20, (s, e) => s === 100 && e === 150);
check(out.length === 2, 'a gap holding bytes at hand is not bridged');
out = coalesce([r('a', 0, 600), r('b', 600, 600), r('c', 1200, 600)], 0, 1000);
check(out.length === 3, 'maxRequestBytes splits requests');
out = coalesce([r('a', 0, 0), r('b', 10, 5)]);
check(out.length === 1 && out[0].parts.length === 1, 'empty ranges are dropped');

// ---- chooseLevels: two clusters, one near the eye and one far, one behind it.
function lookAlongMinusZ(eye) {
  // Column-major perspective (fovY 90 degrees, aspect 1, near 0.1, far 100) times a view
  // matrix that translates by -eye (looking down -z).
  const n = 0.1;
  const f = 100;
  const p = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, (f + n) / (n - f), -1, 0, 0, (2 * f * n) / (n - f), 0];
  const v = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -eye[0], -eye[1], -eye[2], 1];
  const m = new Array(16).fill(0);
  for (let c = 0; c < 4; ++c)
    for (let row = 0; row < 4; ++row)
      for (let k = 0; k < 4; ++k) m[4 * c + row] += p[4 * k + row] * v[4 * c + k];
  return { eye, viewProj: m, fovY: Math.PI / 2, height: 1000, near: n };
}
const info = { clusters: 3, baseLevel: 2, finestLevel: 5, baseFaces: 10,
  levels: [{ faces: 20 }, { faces: 40 }, { faces: 80 }, { faces: 160 }, { faces: 320 }] };
function bounds(boxes) {
  const b = new Float32Array(8 * boxes.length);
  boxes.forEach(([lo, hi, edge, faces], c) => b.set([...lo, ...hi, edge, faces], 8 * c));
  return b;
}
const view = lookAlongMinusZ([0, 0, 0]);
const near = [[-0.1, -0.1, -1.1], [0.1, 0.1, -1], 0.05, 10];   // 1 unit ahead
const far = [[-0.1, -0.1, -50.1], [0.1, 0.1, -50], 0.05, 10];  // 50 units ahead
const behind = [[-0.1, -0.1, 1], [0.1, 0.1, 1.1], 0.05, 10];   // behind the eye
let state = { info, levels: Int32Array.of(2, 2, 3), clusterBounds: bounds([near, far, behind]), errorSeen: new Map() };
let choice = chooseLevels(state, view, { targetPixels: 3 });
// near: 0.05 units at distance 1 with 500 px per unit = 25 px > 3: refine. far: 0.5 px: keep.
check(same(Array.from(choice.levels), [3, 2, 2]), `near refines, far stays, behind goes to the base: ${choice.levels}`);
check(choice.refine === 1 && choice.hidden === 1, 'counts of refined and hidden clusters');
// Coarsening: the far cluster at level 4 whose error at level 3 was seen small.
state = { info, levels: Int32Array.of(2, 4, 2), clusterBounds: bounds([near, far, behind]), errorSeen: new Map([['1:3', 0.01]]) };
choice = chooseLevels(state, view, { targetPixels: 3 });
check(choice.levels[1] === 3 && choice.coarsen === 1, `a far cluster coarsens one level: ${choice.levels}`);
// The triangle budget stops refinement.
state = { info, levels: Int32Array.of(2, 2, 2), clusterBounds: bounds([near, far, behind]), errorSeen: new Map() };
choice = chooseLevels(state, view, { targetPixels: 3, triangleBudget: 35 });
check(choice.levels[0] === 2 && choice.refine === 0, `over the triangle budget nothing refines: ${choice.levels}`);
// The finest level has no error: never refined further.
state = { info, levels: Int32Array.of(5, 2, 2), clusterBounds: bounds([near, far, behind]), errorSeen: new Map() };
choice = chooseLevels(state, view, { targetPixels: 3 });
check(choice.levels[0] === 5, 'the finest level stays');

result.done('unit tests');
