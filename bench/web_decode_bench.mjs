// WebAssembly decode speed (Node.js, the same web/pomar_core.js the browser's worker uses).
//
//   node bench/web_decode_bench.mjs FILE.pomar [--repeat K]
//
// Times, K times (default 5; median reported), with a fresh decoder each time:
//   open   - the base clustered mesh from the global part (pw_open)
//   full   - then every cluster to the finest level (blocks handed over + update), as
//            `pomar_ra_bench one`'s "full decode" does natively with a SelectiveDecoder
//   mesh   - copying the mesh out (positions, triangles, per-vertex cluster and level)
// Compare with the native numbers of `pomar_ra_bench one MESH` on the same file's mesh, or
// `pomar decode FILE out.ply --cluster 0 --level FINEST --stats`. See bench/README.md.
import { readFileSync } from 'node:fs';
import { Decoder, globalBytes } from '../web/pomar_core.js';
import { loadModuleInNode } from '../web/test/node_support.mjs';

const args = process.argv.slice(2);
const file = args.find((a) => !a.startsWith('--'));
const k = args.indexOf('--repeat');
const repeat = k >= 0 ? Number(args[k + 1]) : 5;
if (!file) {
  console.error('usage: node bench/web_decode_bench.mjs FILE.pomar [--repeat K]');
  process.exit(2);
}
const M = await loadModuleInNode();
const bytes = new Uint8Array(readFileSync(file));

const times = { open: [], full: [], mesh: [] };
let info = null;
for (let r = 0; r < repeat; ++r) {
  let t = performance.now();
  let n = Math.min(bytes.length, 16384);
  for (let need; (need = globalBytes(M, bytes.subarray(0, n), bytes.length)) > n;) n = need;
  const d = new Decoder(M, bytes.subarray(0, n), bytes.length);
  times.open.push(performance.now() - t);
  info = d.info;
  t = performance.now();
  const wanted = info.clusters ? new Array(info.clusters).fill(info.finestLevel) : [info.finestLevel];
  for (let c = 0; c < info.clusters; ++c)
    d.putBlock(c, bytes.subarray(d.blockOffset[c], d.blockOffset[c] + d.blockSize[c]));
  d.update(wanted);
  times.full.push(performance.now() - t);
  t = performance.now();
  d.mesh();
  times.mesh.push(performance.now() - t);
  d.close();
}
const median = (a) => a.slice().sort((x, y) => x - y)[Math.floor(a.length / 2)];
console.log(`${file}: ${info.vertices} vertices, ${info.faces} faces, ${bytes.length} bytes, ` +
  `${info.clusters} clusters, levels ${info.baseLevel}..${info.finestLevel}`);
console.log(`WASM (median of ${repeat}): open ${median(times.open).toFixed(1)} ms, ` +
  `full decode ${median(times.full).toFixed(1)} ms (${(info.vertices / median(times.full) / 1000).toFixed(2)} M vertices/s), ` +
  `mesh copy ${median(times.mesh).toFixed(1)} ms`);
