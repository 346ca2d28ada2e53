// Requests and bytes of the browser test's session (web/test/page_test.js) through the
// viewer's own streaming code in Node.js (the file as a Blob): open, close-up, overview,
// zoom out, full resolution, each step's own requests and bytes and the totals.
//
//   node bench/web_session_bench.mjs FILE.pomar [--closeup 0.1] [--target 3] [--size 800x457] [--OPTION N]
//
// --OPTION N sets a pomar.js fetch option (maxGap, maxRanges, maxRequestBytes, ...);
// --maxRanges 1: one range a request (a server without multipart/byteranges answers).
import { readFileSync } from 'node:fs';
import { PomarStream } from '../web/pomar_stream.js';
import { RangeFile } from '../web/range_fetch.js';
import { chooseLevels, Convergence } from '../web/view_refine.js';
import { closeUp, frameMesh, orbitCamera, viewOf } from '../web/camera.js';
import { loadModuleInNode } from '../web/test/node_support.mjs';

const args = process.argv.slice(2);
const file = args[0];
const opt = (name, fallback) => {
  const k = args.indexOf('--' + name);
  return k >= 0 ? args[k + 1] : fallback;
};
const [width, height] = opt('size', '800x457').split('x').map(Number);
const options = { maxGap: 128 }; // pomar.js's default
for (let k = 1; k < args.length; k += 2) {
  const name = args[k].slice(2);
  if (!['closeup', 'target', 'size'].includes(name)) options[name] = Number(args[k + 1]);
}
const settings = { targetPixels: Number(opt('target', 3)) };
const M = await loadModuleInNode();
const blob = new Blob([readFileSync(file)]);
let firstDraw = null;
const stream = await new PomarStream(M, new RangeFile(blob, options), options)
  .open((m, stats) => { firstDraw ??= { ...stats, level: m.level }; });
let mesh = stream.decoder.mesh();
const errorSeen = new Map();
const detailSeen = new Map();
const info = stream.info;
let last = { bytesFetched: 0, requests: 0 };
function line(what) {
  const f = stream.file.stats;
  console.log(`${what.padEnd(12)} step ${String(f.requests - last.requests).padStart(5)} requests ` +
    `${String(f.bytesFetched - last.bytesFetched).padStart(8)} B; total ${String(f.requests).padStart(5)} requests ` +
    `(${String(f.ranges).padStart(5)} ranges) ` +
    `${String(f.bytesFetched).padStart(8)} B (${(100 * f.bytesFetched / info.fileBytes).toFixed(1)}%), ` +
    `${mesh.triangles.length / 3} triangles`);
  last = { ...f };
}
async function settle(camera) {
  const convergence = new Convergence();
  for (let steps = 0; steps < 64; ++steps) {
    const v = viewOf(camera, width, height);
    const choice = chooseLevels({ info, levels: stream.levels, clusterBounds: mesh.clusterBounds, errorSeen, detailSeen, mesh }, v, settings);
    const wanted = choice.changed ? convergence.next(choice.levels, stream.levels, v) : null;
    if (!wanted) break;
    await stream.want(wanted);
    mesh = stream.decoder.mesh();
  }
}
console.log(`${file}: ${info.fileBytes} bytes, ${info.clusters} clusters, options ${JSON.stringify(options)}`);
if (firstDraw)
  console.log(`first draw   ${firstDraw.requests} requests ${firstDraw.bytesFetched} B ` +
    `(${(100 * firstDraw.bytesFetched / info.fileBytes).toFixed(2)}%), global level ${firstDraw.level}`);
line('open');
const camera = orbitCamera();
frameMesh(camera, mesh.positions);
const center = camera.target.slice();
closeUp(camera, mesh.positions, Number(opt('closeup', 0.1)));
await settle(camera);
line('close-up');
camera.target = center;
camera.distance = 1.6 * camera.extent;
await settle(camera);
line('overview');
camera.distance = 30 * camera.extent;
await settle(camera);
line('zoom out');
await stream.want(new Int32Array(info.clusters).fill(info.finestLevel));
mesh = stream.decoder.mesh();
line('full');
stream.close();
