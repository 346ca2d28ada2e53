// Bytes fetched for views of a .pomar file through the web viewer's own streaming code
// (web/pomar_stream.js over web/range_fetch.js, view_refine.js for the views), in Node.js
// with the file as a Blob: the same requests the browser would make, counted.
//
//   node bench/web_view_bench.mjs FILE.pomar [--closeup 0.1] [--target 3] [--size 800x457]
//        [--clusters 1000,2000] [--maxGap B] [--maxRanges N] [--requestCost B] [--firstRequestBytes B]
//        [--wholeBlockBytes B] [--estimateMargin F] [--maxEdgePixels PX] [--facingScale K --contourScale K]
//        [--facingEdgeScale K --contourEdgeScale K]
//        [--overview-only] [--breakdown]
//        [--backface] [--no-occlusion] [--errorModel auto|stored|edge|measured [--detailSafety K] [--maxTilt T]]
//
// Reports, each from a fresh stream: the base clustered mesh (open), the overview (whole
// model framed as the viewer frames it, refined to `target` pixels), a close-up (the
// surface point facing the camera seen from `closeup` x the model's size, as
// web/test/page_test.js does) and single clusters raised to the finest level; first the
// bytes at the first draw (the base mesh and global levels drawn while the global part
// arrives, pomar_stream.js readGlobal). --maxRanges 1: a server answering one range a
// request (every range its own request, planned with --requestCost). Percentages
// are of the file size; "requests" counts Range requests (a server answering several ranges
// in one request assumed), "ranges" the byte ranges they asked for. See web/README.md for the table.
// DEBUG=1 also prints, per refinement step, the clusters refined, coarsened, hidden
// (outside the frustum) and culled (occluded or back-facing), and for each close-up its
// final level map (level:clusters) and the bytes held per level.
import { readFileSync } from 'node:fs';
import { PomarStream } from '../web/pomar_stream.js';
import { RangeFile } from '../web/range_fetch.js';
import { chooseLevels, Convergence, detailDecay } from '../web/view_refine.js';
import { closeUp, frameMesh, orbitCamera, viewOf } from '../web/camera.js';
import { loadModuleInNode } from '../web/test/node_support.mjs';

const args = process.argv.slice(2);
const file = args[0] && !args[0].startsWith('--') ? args[0] : null;
const opt = (name, fallback) => {
  const k = args.indexOf('--' + name);
  return k >= 0 ? args[k + 1] : fallback;
};
if (!file) {
  console.error('usage: node bench/web_view_bench.mjs FILE.pomar [--closeup F] [--target PX] [--size WxH] ' +
    '[--clusters C,C] [--maxGap B] [--wholeBlockBytes B] [--estimateMargin F] [--backface] [--no-occlusion] ' +
    '[--errorModel measured [--detailSafety K] [--maxTilt T]]');
  process.exit(2);
}
const [width, height] = opt('size', '800x457').split('x').map(Number);
const fetchOptions = { maxGap: 128 }; // pomar.js's default
for (const name of ['maxGap', 'maxRanges', 'requestCost', 'firstRequestBytes', 'wholeBlockBytes', 'estimateMargin', 'estimateSlack'])
  if (opt(name) !== undefined) fetchOptions[name] = Number(opt(name));
const settings = { targetPixels: Number(opt('target', 3)), backface: args.includes('--backface'),
  occlusion: !args.includes('--no-occlusion'), errorModel: opt('errorModel', 'auto') };
for (const name of ['detailSafety', 'maxTilt', 'maxEdgePixels', 'facingScale', 'contourScale', 'facingEdgeScale', 'contourEdgeScale']) if (opt(name) !== undefined) settings[name] = Number(opt(name));
const M = await loadModuleInNode();
const blob = new Blob([readFileSync(file)]);

let firstDraw = null; // the file's stats at the first mesh drawn (a preview, or the opened mesh)
async function fresh() {
  firstDraw = null;
  const stream = await new PomarStream(M, new RangeFile(blob, fetchOptions), fetchOptions)
    .open((mesh, stats) => { firstDraw ??= { ...stats, level: mesh.level, triangles: mesh.triangles.length / 3 }; });
  return { stream, mesh: stream.decoder.mesh(), errorSeen: new Map(), detailSeen: new Map() };
}
const pct = (s, b) => `${(100 * b / s.file.size).toFixed(2)}%`;
function line(what, s, extra = '') {
  const f = s.stream.file.stats;
  const raised = s.stream.levels.filter((l) => l > s.stream.info.baseLevel).length;
  console.log(`${what.padEnd(22)} ${pct(s.stream, f.bytesFetched).padStart(7)} ${String(f.bytesFetched).padStart(8)} B ` +
    `${String(f.requests).padStart(5)} requests (${f.ranges} ranges) ${String(s.mesh.triangles.length / 3).padStart(7)} triangles ` +
    `${String(raised).padStart(5)} clusters raised, ${s.stream.retries} short prefixes${extra}`);
}
/** Refine for the camera until stable, as the viewer's loop does. */
async function settle(s, camera) {
  let steps = 0;
  const chooseMs = []; // the page's main-thread work per step (the decode runs in the worker)
  const convergence = new Convergence();
  const t0 = performance.now();
  for (; steps < 64; ++steps) {
    const v = viewOf(camera, width, height);
    const tc = performance.now();
    const choice = chooseLevels({ info: s.stream.info, levels: s.stream.levels, clusterBounds: s.mesh.clusterBounds,
      errorSeen: s.errorSeen, detailSeen: s.detailSeen, mesh: s.mesh }, v, settings);
    if (process.env.DEBUG) console.log(steps, choice.refine, choice.coarsen, choice.hidden, choice.culled,
      `decay ${detailDecay(s.detailSeen).toFixed(3)}`);
    chooseMs.push(performance.now() - tc);
    s.asked = choice.levels;
    const wanted = choice.changed ? convergence.next(choice.levels, s.stream.levels, v) : null;
    if (!wanted) break;
    await s.stream.want(wanted);
    s.mesh = s.stream.decoder.mesh();
  }
  chooseMs.sort((a, b) => a - b);
  return `, ${steps} steps, ${((performance.now() - t0) / 1000).toFixed(1)} s, choice ${chooseMs[chooseMs.length >> 1].toFixed(0)} ms ` +
    `median / ${chooseMs[chooseMs.length - 1].toFixed(0)} ms max a step`;
}

/** Where a settled view's bytes go: the global part; the region (the prefixes of the levels
 *  the policy asks for); the rings (what the level map rule adds above them: clusters the
 *  policy left lower, raised so that neighbours are at most one level apart); the rest
 *  (bytes fetched that no block holds: gaps bridged between ranges, bytes past a prefix). */
function breakdown(s) {
  const st = s.stream;
  const { baseLevel: base } = st.info;
  let region = 0;
  let regionClusters = 0;
  let ring = 0;
  let ringClusters = 0;
  let ringOnly = 0;
  for (let c = 0; c < st.info.clusters; ++c) {
    const l = st.levels[c];
    if (l <= base) continue;
    const asked = Math.min(l, s.asked[c]);
    const own = asked >= l ? st.have[c] : Math.min(st.have[c], st.need(c, asked));
    region += own;
    ring += st.have[c] - own;
    if (asked > base) ++regionClusters;
    if (asked < l) ++ringClusters;
    if (asked <= base) ++ringOnly;
  }
  const f = st.file.stats.bytesFetched;
  const g = st.info.globalBytes;
  const p = (x) => `${(100 * x / st.file.size).toFixed(2)}%`;
  console.log(`  breakdown: global part ${g} B (${p(g)}); region ${Math.round(region)} B (${p(region)}, ${regionClusters} ` +
    `clusters asked above the base level); rings ${Math.round(ring)} B (${p(ring)}, ${ringClusters} clusters raised ` +
    `above what was asked, ${ringOnly} of them asked at the base level); other ${Math.round(f - g - region - ring)} B ` +
    `(${p(f - g - region - ring)})`);
}

let s = await fresh();
const info = s.stream.info;
console.log(`${file}: ${info.vertices} vertices, ${info.fileBytes} bytes, ${info.clusters} clusters, levels ` +
  `${info.baseLevel}..${info.finestLevel}, global part ${info.globalBytes} B (${pct(s.stream, info.globalBytes)}); ` +
  `view ${width}x${height}, target ${settings.targetPixels} px, backface ${settings.backface}, occlusion ` +
  `${settings.occlusion}, error model ${settings.errorModel}` +
  `${settings.errorModel === 'measured' ? ` (detailSafety ${settings.detailSafety ?? 1}, maxTilt ${settings.maxTilt ?? 'none'})` : ''}, ` +
  `fetch ${JSON.stringify(fetchOptions)}`);
if (firstDraw)
  console.log(`${'first draw'.padEnd(22)} ${pct(s.stream, firstDraw.bytesFetched).padStart(7)} ${String(firstDraw.bytesFetched).padStart(8)} B ` +
    `${String(firstDraw.requests).padStart(5)} requests, global level ${firstDraw.level}, ${firstDraw.triangles} triangles (before the global part is in)`);
line('open (base mesh)', s);
if (info.clusters) {
  const camera = orbitCamera();
  frameMesh(camera, s.mesh.positions);
  line('overview', s, await settle(s, camera));
  s.stream.close();
  if (args.includes('--overview-only')) process.exit(0);
  for (const fraction of opt('closeup', '0.1').split(',').map(Number)) {
    s = await fresh();
    const c = orbitCamera();
    frameMesh(c, s.mesh.positions);
    closeUp(c, s.mesh.positions, fraction);
    line(`close-up ${fraction}`, s, await settle(s, c));
    if (args.includes('--breakdown')) breakdown(s);
    // The level map it converged to, asked at once from a fresh stream: the bytes the
    // fetch policy alone costs, without the steps of refinement.
    const final = s.stream.levels;
    if (process.env.DEBUG) {
      const histogram = new Map();
      for (const l of final) histogram.set(l, (histogram.get(l) || 0) + 1);
      console.log([...histogram.entries()].sort((a, b) => a[0] - b[0]).map(([l, k]) => `${l}:${k}`).join(' '));
    }
    s.stream.close();
    s = await fresh();
    await s.stream.want(final);
    s.mesh = s.stream.decoder.mesh();
    line(`  its map at once`, s);
    if (process.env.DEBUG) {
      const byLevel = new Map();
      for (let c = 0; c < final.length; ++c) byLevel.set(final[c], (byLevel.get(final[c]) || 0) + s.stream.have[c]);
      console.log([...byLevel.entries()].sort((a, b) => a[0] - b[0]).map(([l, k]) => `${l}:${k}`).join(' '));
    }
    s.stream.close();
  }
  const clusters = opt('clusters', [1, 2, 3, 4].map((k) => Math.floor(k * info.clusters / 4.5)).join(','));
  for (const c of clusters.split(',').map(Number)) {
    s = await fresh();
    const levels = s.stream.baseLevels;
    levels[c] = info.finestLevel;
    await s.stream.want(levels);
    s.mesh = s.stream.decoder.mesh();
    line(`cluster ${c} finest`, s);
    s.stream.close();
  }
}
