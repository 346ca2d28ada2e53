// Unit tests of the pure parts of web/: request coalescing (range_fetch.js) and the choice
// of levels for a view (view_refine.js).   node web/test/unit_test.mjs
import { coalesce, parseByteranges, RangeFile } from '../range_fetch.js';
import { BOUNDS_STRIDE, Convergence, chooseLevels, detailDecay, viewScale } from '../view_refine.js';
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

// ---- several ranges in one request, against fake servers (globalThis.fetch replaced)
const file = Uint8Array.from({ length: 5000 }, (_, i) => (i * 7) & 255);
function fakeServer(multipart) {
  const log = [];
  globalThis.fetch = async (url, { headers }) => {
    const specs = /^bytes=(.*)$/.exec(headers.Range)[1].split(',').map((x) => x.split('-').map(Number));
    log.push(specs.length);
    if (specs.length === 1) {
      const [a, b] = specs[0];
      return new Response(file.slice(a, b + 1), { status: 206, headers: { 'Content-Range': `bytes ${a}-${b}/${file.length}` } });
    }
    if (!multipart) return new Response(file, { status: 200 }); // as Amazon S3 answers
    const pieces = [];
    for (const [a, b] of specs) {
      pieces.push(new TextEncoder().encode(`\r\n--XYZ\r\nContent-Type: application/octet-stream\r\nContent-Range: bytes ${a}-${b}/${file.length}\r\n\r\n`));
      pieces.push(file.slice(a, b + 1));
    }
    pieces.push(new TextEncoder().encode('\r\n--XYZ--\r\n'));
    return new Response(new Blob(pieces), { status: 206, headers: { 'Content-Type': 'multipart/byteranges; boundary=XYZ' } });
  };
  return log;
}
const wanted = [r('a', 100, 50), r('b', 1000, 10), r('c', 3000, 600), r('d', 4990, 10)];
const sameBytes = (got, want) => got.length === want.length && got.every((x, i) => x === want[i]);
const allParts = (parts) => wanted.every((w) => sameBytes(parts.get(w.key), file.slice(w.offset, w.offset + w.size)));
let log = fakeServer(true);
let rf = new RangeFile('http://x/f.pomar', { maxGap: 0 });
let got = await rf.readMany(wanted);
check(allParts(got.parts) && same(log, [4]) && rf.multiRange === true && rf.stats.requests === 1 && rf.stats.ranges === 4 &&
  rf.stats.bytesFetched === 670, `four ranges in one multipart request: ${JSON.stringify(log)} ${JSON.stringify(rf.stats)}`);
rf = new RangeFile('http://x/f.pomar', { maxGap: 0, maxRanges: 3, maxRequestBytes: 700 });
log = fakeServer(true);
got = await rf.readMany(wanted);
check(allParts(got.parts) && same(log.sort(), [1, 3]), `maxRanges splits requests: ${JSON.stringify(log)}`);
rf = new RangeFile('http://x/f.pomar', { maxGap: 0, maxRequestBytes: 620 });
log = fakeServer(true);
got = await rf.readMany(wanted);
check(allParts(got.parts) && same(log, [2, 2]), `maxRequestBytes splits requests: ${JSON.stringify(log)}`);
log = fakeServer(false);
rf = new RangeFile('http://x/f.pomar', { maxGap: 0, requestCost: 0 });
got = await rf.readMany(wanted);
check(allParts(got.parts) && same(log, [4, 1, 1, 1, 1]) && rf.multiRange === false && rf.stats.bytesFetched === 670,
  `a server answering several ranges with the whole file: dropped, one range a request: ${JSON.stringify(log)}`);
log.length = 0;
got = await rf.readMany(wanted);
check(allParts(got.parts) && same(log, [1, 1, 1, 1]), 'and no second try');
// One range a request, planned with the cost of a request: the gaps (850, 1990, 1390 bytes)
// shorter than requestCost are fetched, the others cost a request each.
log = fakeServer(false);
rf = new RangeFile('http://x/f.pomar', { maxGap: 0, requestCost: 1000 });
got = await rf.readMany(wanted);
check(allParts(got.parts) && same(log, [4, 1, 1, 1]) && rf.stats.bytesFetched === 50 + 850 + 10 + 600 + 10,
  `one range a request, requestCost 1000: the 850-byte gap bridged, the others not: ${JSON.stringify(log)} ${rf.stats.bytesFetched}`);
log = fakeServer(false);
rf = new RangeFile('http://x/f.pomar', { maxGap: 0 });
got = await rf.readMany(wanted);
check(allParts(got.parts) && same(log, [4, 1]) && rf.stats.bytesFetched === 4900 && rf.requestCost === 4096,
  `one range a request, the default cost (4 KiB): every gap bridged, one request: ${JSON.stringify(log)} ${rf.stats.bytesFetched}`);
log = fakeServer(false);
rf = new RangeFile('http://x/f.pomar', { maxGap: 0, maxRanges: 1, requestCost: 1500 });
got = await rf.readMany(wanted, () => true);
check(allParts(got.parts) && same(log, [1, 1]) && rf.stats.bytesFetched === 50 + 850 + 10 + 600 + 1390 + 10,
  `maxRanges 1: planned for one range a request from the start, gaps holding bytes at hand bridged too: ${JSON.stringify(log)}`);
log = fakeServer(true);
rf = new RangeFile('http://x/f.pomar', { maxGap: 0, requestCost: 1 << 20 });
got = await rf.readMany(wanted);
check(allParts(got.parts) && same(log, [4]) && rf.stats.bytesFetched === 670, 'a multipart server: requestCost does not apply');
const parts = parseByteranges(new TextEncoder().encode('--B\r\nContent-Range: bytes 5-7/9\r\n\r\nabc\r\n--B--'), 'B');
check(parts.length === 1 && parts[0].offset === 5 && new TextDecoder().decode(parts[0].bytes) === 'abc', 'a multipart body parsed');
let message = '';
try {
  parseByteranges(new TextEncoder().encode('--B\r\nContent-Range: bytes 5-9/9\r\n\r\nabc'), 'B', 'f.pomar');
} catch (e) {
  message = e.message;
}
check(/f.pomar.*cut short/.test(message), `a part cut short is an error naming the file: ${message}`);

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
  return { eye, viewProj: m, fovY: Math.PI / 2, height: 1000, width: 1000, near: n };
}
const info = { clusters: 3, baseLevel: 2, finestLevel: 5, baseFaces: 10,
  levels: [{ faces: 20 }, { faces: 40 }, { faces: 80 }, { faces: 160 }, { faces: 320 }] };
function bounds(boxes) {
  const b = new Float32Array(BOUNDS_STRIDE * boxes.length);
  boxes.forEach(([lo, hi, edge, faces, cone = [0, 0, 0, -1]], c) => b.set([...lo, ...hi, edge, faces, ...cone], BOUNDS_STRIDE * c));
  return b;
}
const view = lookAlongMinusZ([0, 0, 0]);
const near = [[-0.1, -0.1, -1.1], [0.1, 0.1, -1], 0.05, 10];   // 1 unit ahead
const far = [[-0.1, -0.1, -50.1], [0.1, 0.1, -50], 0.05, 10];  // 50 units ahead
const behind = [[-0.1, -0.1, 1], [0.1, 0.1, 1.1], 0.05, 10];   // behind the eye
let state = { info, levels: Int32Array.of(2, 2, 3), clusterBounds: bounds([near, far, behind]), errorSeen: new Map() };
let choice = chooseLevels(state, view, { targetPixels: 3 });
// near: 0.05 units at distance 1 with 500 px per unit = 25 px > 3: refine, at once to the
// finest level (25 px / sqrt(8) at level 5 is still over 3). far: 0.5 px: keep.
check(same(Array.from(choice.levels), [5, 2, 2]), `near refines, far stays, behind goes to the base: ${choice.levels}`);
// 5 px at level 2: level 3 has 5 / sqrt(2) = 3.5 px, level 4 2.5 px: straight to level 4.
const five = [near[0], near[1], 0.01, 10];
choice = chooseLevels({ ...state, clusterBounds: bounds([five, far, behind]) }, view, { targetPixels: 3 });
check(choice.levels[0] === 4, `refines straight to the level meeting the target: ${choice.levels}`);
check(choice.refine === 1 && choice.hidden === 1, 'counts of refined and hidden clusters');
// Coarsening: the far cluster at level 4 whose error at level 3 was seen small.
state = { info, levels: Int32Array.of(2, 4, 2), clusterBounds: bounds([near, far, behind]), errorSeen: new Map([['1:3', 0.01]]) };
choice = chooseLevels(state, view, { targetPixels: 3 });
check(choice.levels[1] === 3 && choice.coarsen === 1, `a far cluster coarsens one level: ${choice.levels}`);
// The triangle budget stops refinement.
state = { info, levels: Int32Array.of(2, 2, 2), clusterBounds: bounds([near, far, behind]), errorSeen: new Map() };
choice = chooseLevels(state, view, { targetPixels: 3, triangleBudget: 35 });
check(choice.levels[0] === 2 && choice.refine === 0, `over the triangle budget nothing refines: ${choice.levels}`);
choice = chooseLevels(state, view, { targetPixels: 3, triangleBudget: 45 });
check(choice.levels[0] === 3, `refines as far as the triangle budget goes: ${choice.levels}`);
// The finest level has no error: never refined further.
state = { info, levels: Int32Array.of(5, 2, 2), clusterBounds: bounds([near, far, behind]), errorSeen: new Map() };
choice = chooseLevels(state, view, { targetPixels: 3 });
check(choice.levels[0] === 5, 'the finest level stays');


// Back-face culling: a cluster ahead whose normals all point away from the eye (-z) is not
// refined, and is coarsened; facing the eye (+z) it refines. Off by default.
const away = [near[0], near[1], near[2], near[3], [0, 0, -1, 0.9]];
const towards = [near[0], near[1], near[2], near[3], [0, 0, 1, 0.9]];
state = { info, levels: Int32Array.of(3, 2, 2), clusterBounds: bounds([away, towards, far]), errorSeen: new Map() };
choice = chooseLevels(state, view, { targetPixels: 3, backface: true, occlusion: false });
check(same(Array.from(choice.levels), [2, 5, 2]) && choice.culled === 1, `back-facing coarsens, facing refines: ${choice.levels}`);
choice = chooseLevels(state, view, { targetPixels: 3, occlusion: false });
check(same(Array.from(choice.levels), [5, 5, 2]), `without back-face culling both refine: ${choice.levels}`);
// Occlusion: a wall (two triangles) at z = -5 hides the far cluster, not the near one.
const wall = { positions: Float32Array.of(-10, -10, -5, 10, -10, -5, 10, 10, -5, -10, 10, -5),
  triangles: Uint32Array.of(0, 1, 2, 0, 2, 3) };
const farButBig = [[-0.1, -0.1, -50.1], [0.1, 0.1, -50], 1, 10]; // 1-unit error: 10 px
state = { info, levels: Int32Array.of(2, 3, 2), clusterBounds: bounds([near, farButBig, behind]), errorSeen: new Map(), mesh: wall };
choice = chooseLevels(state, view, { targetPixels: 3 });
check(same(Array.from(choice.levels), [5, 2, 2]) && choice.culled === 1, `behind a wall: coarsens, in front: refines: ${choice.levels}`);
choice = chooseLevels(state, view, { targetPixels: 3, occlusion: false });
check(choice.levels[1] === 5, `without occlusion culling the far cluster refines: ${choice.levels}`);
const hole = { positions: wall.positions, triangles: Uint32Array.of(0, 1, 2) }; // half the wall
choice = chooseLevels({ ...state, mesh: hole }, view, { targetPixels: 3 });
check(choice.levels[1] === 5, `a cluster seen past the edge of an occluder refines: ${choice.levels}`);

// The measured error model: the detail of a cluster's newest vertices (entries 12, 13 of
// its bounds; web/test/detail_test.mjs checks how WebAssembly measures it) x detailSafety x
// the decay, under its longest edge; the edge alone where no detail was measured.
const withDetail = (box, detail, count = 5) => {
  const b = bounds([box]);
  b.set([detail, count], 12);
  return b;
};
const measured = { targetPixels: 3, occlusion: false, errorModel: 'measured', detailSafety: 4 };
// near: 25 px by its edge; a detail of 0.001 x 4 = 2 px: kept at level 2 (not refined).
const one = { ...info, clusters: 1 };
choice = chooseLevels({ info: one, levels: Int32Array.of(2), clusterBounds: withDetail(near, 0.001), errorSeen: new Map() }, view, measured);
check(choice.levels[0] === 2 && choice.refine === 0, `a small measured detail is not refined: ${choice.levels}`);
choice = chooseLevels({ info: one, levels: Int32Array.of(2), clusterBounds: withDetail(near, 0.001), errorSeen: new Map() }, view,
  { targetPixels: 3, occlusion: false });
check(choice.levels[0] === 5, `the edge model refines the same cluster: ${choice.levels}`);
// A detail of 0.0025 x 4 = 5 px: refined, to level 4 (faces x4: 5 / 2 = 2.5 px).
choice = chooseLevels({ info: one, levels: Int32Array.of(2), clusterBounds: withDetail(near, 0.0025), errorSeen: new Map() }, view, measured);
check(choice.levels[0] === 4, `a measured detail over the target refines to the level meeting it: ${choice.levels}`);
// A detail larger than the edge: the edge caps it (same choice as the edge model).
choice = chooseLevels({ info: one, levels: Int32Array.of(2), clusterBounds: withDetail(five, 1), errorSeen: new Map() }, view, measured);
check(choice.levels[0] === 4, `the longest edge caps the measured error: ${choice.levels}`);
// maxTilt: a detail over maxTilt x the edge (facets that would tilt by more) takes the edge.
choice = chooseLevels({ info: one, levels: Int32Array.of(2), clusterBounds: withDetail(near, 0.001), errorSeen: new Map() }, view,
  { ...measured, maxTilt: 0.01 });
check(choice.levels[0] === 5, `a detail over maxTilt x the edge is refined as by the edge: ${choice.levels}`);
choice = chooseLevels({ info: one, levels: Int32Array.of(2), clusterBounds: withDetail(near, 0.001), errorSeen: new Map() }, view,
  { ...measured, maxTilt: 0.05 });
check(choice.levels[0] === 2, `a detail under maxTilt x the edge keeps the measured error: ${choice.levels}`);
// No vertex measured (count 0): the edge.
choice = chooseLevels({ info: one, levels: Int32Array.of(2), clusterBounds: withDetail(near, 0, 0), errorSeen: new Map() }, view, measured);
check(choice.levels[0] === 5, `without a measured detail, the edge model: ${choice.levels}`);
// The decay: the median over clusters seen at two levels of (last / first)^(1 / levels).
const seen = new Map();
for (let c = 0; c < 20; ++c) seen.set(c, [[3, 1], [5, c < 11 ? 0.64 : 0.81]]);
check(Math.abs(detailDecay(seen) - 0.8) < 1e-9, `decay per level, the median of 0.8 and 0.9: ${detailDecay(seen)}`);
check(detailDecay(new Map([...seen].slice(0, 10))) === 1, 'too few clusters seen twice: no decay assumed');
seen.set(99, [[3, 1]]);
for (let c = 0; c < 20; ++c) seen.set(c, [[3, 1], [4, 0.1]]);
check(detailDecay(seen) === 0.5, `the decay is at least 0.5 a level: ${detailDecay(seen)}`);

// Convergence: a cluster sent back to a level it had for this camera keeps its level; the
// same map asked again is converged; another camera starts afresh.
const conv = new Convergence();
const A = Int32Array.of(1, 2, 5);
const B = Int32Array.of(1, 3, 5);
check(same(Array.from(conv.next(B, A, view)), [1, 3, 5]), 'a first step is asked as chosen');
check(conv.next(A, B, view) === null, 'back to a map it had: damped, nothing new to ask');
check(same(Array.from(conv.next(Int32Array.of(2, 2, 4), B, view)), [2, 3, 4]),
  'only the clusters flipping back are damped');
check(same(Array.from(conv.next(A, B, lookAlongMinusZ([0, 0, 1]))), [1, 2, 5]), 'another camera starts afresh');
{
  // Refined 21 -> 22 -> 23, then asked at 17: back past a level it had, damped.
  const past = new Convergence();
  const cam = lookAlongMinusZ([0, 0, 2]);
  past.next(Int32Array.of(22, 5), Int32Array.of(21, 5), cam);
  past.next(Int32Array.of(23, 5), Int32Array.of(22, 5), cam);
  check(past.next(Int32Array.of(17, 5), Int32Array.of(23, 5), cam) === null,
    'sent back past a level it had (21 -> 22 -> 23 -> 17): damped, nothing new to ask');
  // Asked at 16, kept at 18 by the level map rule: asking 16 again is not new.
  const kept = new Convergence();
  check(same(Array.from(kept.next(Int32Array.of(16, 7), Int32Array.of(18, 6), cam)), [16, 7]), 'first ask as chosen');
  check(kept.next(Int32Array.of(16, 7), Int32Array.of(18, 7), cam) === null,
    'a level asked and not given (the level map rule), asked again: nothing new');
  const moved = kept.next(Int32Array.of(16, 8), Int32Array.of(18, 7), cam);
  check(moved && same(Array.from(moved), [18, 8]), `the refused one kept, another one still asked: ${moved}`);
}

// ---- the stored error model's facet size (maxEdgePixels): the near cluster's stored error
// projects to 0.005 px, its longest edge (0.02 at distance 1, 500 px a unit) to 10 px.
const storedInfo = { ...info, clusterErrors: new Float32Array(3 * 3).fill(1e-5) };
const facets = [[-0.1, -0.1, -1.1], [0.1, 0.1, -1], 0.02, 10];
const storedState = () => ({ info: storedInfo, levels: Int32Array.of(2, 2, 2),
  clusterBounds: bounds([facets, far, behind]), errorSeen: new Map() });
choice = chooseLevels(storedState(), view, { targetPixels: 3, occlusion: false, maxEdgePixels: Infinity });
check(choice.levels[0] === 2, `stored errors under the target, no facet bound: kept coarse (${choice.levels})`);
choice = chooseLevels(storedState(), view, { targetPixels: 3, occlusion: false });
check(choice.levels[0] === 3 && choice.levels[1] === 2,
  `facets over 8 px (the default) refined to the level whose extrapolated edge (10 / sqrt 2 px) is under it; far kept: ${choice.levels}`);
choice = chooseLevels(storedState(), view, { targetPixels: 3, occlusion: false, maxEdgePixels: 4 });
check(choice.levels[0] === 5, `maxEdgePixels 4: refined to level 5 (edge 10 / sqrt 4 = 5 px at level 4): ${choice.levels}`);
state = { ...storedState(), levels: Int32Array.of(3, 2, 2) };
choice = chooseLevels(state, view, { targetPixels: 3, occlusion: false, maxEdgePixels: 30 });
check(choice.levels[0] === 2, `coarsened when the coarser level's facets are under half the bound: ${choice.levels}`);
choice = chooseLevels(state, view, { targetPixels: 3, occlusion: false, maxEdgePixels: 12 });
check(choice.levels[0] === 3, `kept when they would be over half of it: ${choice.levels}`);

// The stored model's back-face culling: the near cluster with facets over 8 px, its faces
// turned away from the eye (normal cone axis -z, narrow).
const turnedAway = [facets[0], facets[1], facets[2], facets[3], [0, 0, -1, 0.99]];
const awayState = () => ({ info: storedInfo, levels: Int32Array.of(2, 2, 2), clusterBounds: bounds([turnedAway, far, behind]),
  errorSeen: new Map() });
choice = chooseLevels(awayState(), view, { targetPixels: 3, occlusion: false });
check(choice.levels[0] === 3, `stored errors, back-facing, backface off: refined as any (${choice.levels})`);
choice = chooseLevels(awayState(), view, { targetPixels: 3, occlusion: false, backface: true });
check(choice.levels[0] === 2 && choice.culled >= 1, `backface on: culled, kept (${choice.levels}, ${choice.culled} culled)`);

// ---- the stored error model seen edge-on or facing (facingScale, contourScale): two
// clusters 1 unit ahead with the same stored error, 0.004 (2 px) at every level below the
// finest, facets of 1 px; one faces the eye (normal cone axis +z), one is seen edge-on
// (axis +x: a contour).
const angled = { ...info, clusters: 2, clusterErrors: new Float32Array(3 * 2).fill(0.004) };
const facingBox = [[-0.1, -0.1, -1.1], [0.1, 0.1, -1], 0.002, 10, [0, 0, 1, 0.9]];
const contourBox = [[-0.1, -0.1, -1.1], [0.1, 0.1, -1], 0.002, 10, [1, 0, 0, 0.9]];
const angledState = () => ({ info: angled, levels: Int32Array.of(2, 2), clusterBounds: bounds([facingBox, contourBox]),
  errorSeen: new Map() });
const ab = bounds([facingBox, contourBox, [[-0.1, -0.1, -1.1], [0.1, 0.1, -1], 0.002, 10, [Math.SQRT1_2, 0, Math.SQRT1_2, 0.9]],
  [[-0.1, -0.1, -1.1], [0.1, 0.1, -1], 0.002, 10]]);
check(viewScale([0, 0, 0], ab, 0, 2, 0.5) === 2, `facing the eye: facingScale (${viewScale([0, 0, 0], ab, 0, 2, 0.5)})`);
check(Math.abs(viewScale([0, 0, 0], ab, 1, 2, 0.5) - 0.5) < 1e-6, `edge-on: contourScale (${viewScale([0, 0, 0], ab, 1, 2, 0.5)})`);
const tilted = viewScale([0, 0, 0], ab, 2, 2, 0.5);
check(tilted > 0.5 && tilted < 2, `at about 45 degrees, in between: ${tilted}`);
check(viewScale([0, 0, 0], ab, 3, 2, 0.5) === 1, 'no normal cone (a cone of every direction): 1');
choice = chooseLevels(angledState(), view, { targetPixels: 3, occlusion: false });
check(same(Array.from(choice.levels), [2, 2]), `2 px under the 3 px target, both kept (default scales 1): ${choice.levels}`);
choice = chooseLevels(angledState(), view, { targetPixels: 3, occlusion: false, contourScale: 0.5 });
check(same(Array.from(choice.levels), [2, 5]), `contourScale 0.5 (1.5 px on the contour): the edge-on one refined: ${choice.levels}`);
choice = chooseLevels(angledState(), view, { targetPixels: 1.5, occlusion: false, facingScale: 2 });
check(same(Array.from(choice.levels), [2, 5]), `target 1.5 px, facingScale 2: the facing one kept: ${choice.levels}`);
choice = chooseLevels({ ...angledState(), levels: Int32Array.of(5, 5) }, view,
  { targetPixels: 3, occlusion: false, facingScale: 4, contourScale: 1, coarsenFraction: 0.5 });
check(choice.levels[0] === 2 && choice.levels[1] === 5,
  `coarsened by the scaled error too (facing: 0.5 px under half of 3 px; edge-on: 2 px is not): ${choice.levels}`);

result.done('unit tests');
