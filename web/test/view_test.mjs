// View-dependent selection in WebAssembly = natively: SelectiveDecoder::view_levels through
// pw_view_levels (pomar_core.js Decoder.viewLevels) against the native library's
// (`pomar_ra_bench view`), for an overview and a close-up of each file, from the base
// clustered mesh and from the level map the first selection decoded; and the client's
// stored-error model (view_refine.js, errorModel 'stored') against the stored bounds.
//
//   node web/test/view_test.mjs RA_BENCH FILE.pomar...
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { PomarStream } from '../pomar_stream.js';
import { RangeFile } from '../range_fetch.js';
import { chooseLevels, storedError } from '../view_refine.js';
import { closeUp, frameMesh, orbitCamera, viewOf } from '../camera.js';
import { checker, loadModuleInNode } from './node_support.mjs';

const [bench, ...files] = process.argv.slice(2);
if (!bench || !files.length) {
  console.error('usage: node view_test.mjs RA_BENCH FILE.pomar...');
  process.exit(2);
}
const result = checker();
const check = result.check;
const M = await loadModuleInNode();
const W = 800;
const H = 457;
const PIXELS = 3;

function camera23(v) {
  // The floats the WebAssembly side gets (Float32), printed exactly.
  return Array.from(Float32Array.from([...v.eye, ...v.viewProj, v.fovY, v.width, v.height, v.near])).join(',');
}
function native(file, v, levels) {
  const args = ['view', file, String(PIXELS), camera23(v)];
  if (levels) args.push(Array.from(levels).join(','));
  const out = execFileSync(bench, args, { encoding: 'utf8' });
  return Int32Array.from(out.split('\n')[0].replace('levels:', '').trim().split(/\s+/).map(Number));
}
const same = (a, b) => a.length === b.length && a.every((x, i) => x === b[i]);

for (const file of files) {
  const blob = new Blob([readFileSync(file)]);
  const stream = await new PomarStream(M, new RangeFile(blob, {}), {}).open();
  const info = stream.info;
  const mesh = stream.decoder.mesh();
  const views = [];
  const overview = orbitCamera();
  frameMesh(overview, mesh.positions, W / H);
  views.push(['overview', viewOf(overview, W, H)]);
  const near = orbitCamera();
  frameMesh(near, mesh.positions, W / H);
  closeUp(near, mesh.positions, 0.2);
  views.push(['close-up 0.2', viewOf(near, W, H)]);
  const name = file.split('/').pop();
  // (random-access files carry their stored errors by default; those written with
  // `pomar encode --no-stored-errors`, named *_edges*, use edges)
  check(!!info.clusterErrors === !name.includes('_edges'), `${name}: stored errors (CERR) as written`);
  for (const [what, v] of views) {
    const wasm = stream.decoder.viewLevels(v, PIXELS);
    const ref = native(file, v);
    check(same(wasm, ref), `${name} ${what}: WebAssembly selection = native (from the base clustered mesh)`);
    check(wasm.some((l) => l > info.baseLevel), `${name} ${what}: the selection refines something`);
    // From the level map that selection decodes: the boxes are then the finer ones.
    await stream.want(wasm);
    const wasm2 = stream.decoder.viewLevels(v, PIXELS);
    const ref2 = native(file, v, stream.levels);
    check(same(wasm2, ref2), `${name} ${what}: WebAssembly selection = native (after decoding it)`);
    await stream.want(stream.baseLevels);
  }
  // The client's own stored-error choice: every cluster it leaves coarse meets the target
  // at its distance, measured the client's way; the errors it reads are the library's.
  if (info.clusterErrors) {
    const v = views[1][1];
    const state = { info, levels: stream.levels, clusterBounds: stream.decoder.mesh().clusterBounds, errorSeen: new Map() };
    const choice = chooseLevels(state, v, { targetPixels: PIXELS, occlusion: false });
    check(choice.refine > 0, `${name}: the stored model refines the close-up`);
    let monotone = true;
    for (let c = 0; c < info.clusters; ++c)
      for (let l = info.baseLevel; l < info.finestLevel; ++l)
        if (storedError(info, c, l) < storedError(info, c, l + 1)) monotone = false;
    check(monotone, `${name}: stored errors never grow with the level`);
    check(storedError(info, 0, info.finestLevel) === 0, `${name}: the finest level has no error`);
  }
  stream.close();
}
result.done('view_test');
