// The Web Worker behind pomar.js: one PomarStream (pomar_stream.js) over a RangeFile; posts
// meshes (transferred typed arrays) and messages back.
//
// in:  {type:'open', source (URL or File), options}, {type:'want', id, levels}, {type:'close'}
// out: {type:'preview', mesh, stats} (first frames while the global part arrives),
//      {type:'opened'|'mesh', id, info, mesh, levels, stats}, {type:'warning', message},
//      {type:'error', id, message}
import { loadModule } from './pomar_core.js';
import { PomarStream } from './pomar_stream.js';
import { RangeFile } from './range_fetch.js';

let stream = null;
let damagedReported = 0;
let warningsReported = 0;
let busy = false;
let pending = null; // the latest want not yet served (older ones are superseded)
let keepSeams = false; // open's option: textured meshes stay cut at full resolution

function post(type, id, extra) {
  const mesh = stream.decoder.mesh({ keepSeams });
  const transfer = [mesh.positions.buffer, mesh.triangles.buffer, mesh.vertexCluster.buffer,
    mesh.vertexLevel.buffer, mesh.clusterBounds.buffer];
  if (mesh.colour) transfer.push(mesh.colour.values.buffer);
  if (mesh.texcoords) transfer.push(mesh.texcoords.buffer);
  if (mesh.faceMaterials) transfer.push(mesh.faceMaterials.buffer);
  const stats = { ...stream.stats(), vertices: mesh.positions.length / 3, triangles: mesh.triangles.length / 3, ...extra };
  self.postMessage({ type, id, info: stream.info, mesh, levels: stream.levels, stats }, transfer);
}

function report() {
  for (; warningsReported < stream.warnings.length; ++warningsReported)
    self.postMessage({ type: 'warning', message: stream.warnings[warningsReported] });
  const d = stream.decoder.damaged();
  if (d.count > damagedReported) {
    damagedReported = d.count;
    self.postMessage({ type: 'warning', message: `damaged blocks skipped (as --skip-damaged does):\n${d.text}` });
  }
}

async function serve() {
  busy = true;
  while (pending) {
    const { id, levels } = pending;
    pending = null;
    try {
      const t0 = performance.now();
      await stream.want(levels);
      report();
      post('mesh', id, { decodeMs: performance.now() - t0 });
    } catch (e) {
      self.postMessage({ type: 'error', id, message: e.message || String(e) });
    }
  }
  busy = false;
}

self.onmessage = async (event) => {
  const msg = event.data;
  if (msg.type === 'open') {
    try {
      const t0 = performance.now();
      const M = await loadModule();
      keepSeams = !!(msg.options && msg.options.keepSeams);
      // First frames before the global part is in: the base mesh and the global levels
      // (positions and triangles; the page draws them until the base clustered mesh comes).
      const preview = (mesh, stats) => self.postMessage({ type: 'preview', mesh, stats: { ...stats,
        vertices: mesh.positions.length / 3, triangles: mesh.triangles.length / 3, decodeMs: performance.now() - t0 } },
      [mesh.positions.buffer, mesh.triangles.buffer]);
      stream = await new PomarStream(M, new RangeFile(msg.source, msg.options), msg.options).open(preview);
      post('opened', 0, { decodeMs: performance.now() - t0 });
    } catch (e) {
      self.postMessage({ type: 'error', id: 0, fatal: true, message: e.message || String(e) });
    }
  } else if (msg.type === 'want') {
    if (!stream) {
      self.postMessage({ type: 'error', id: msg.id, message: 'no file is open' });
      return;
    }
    pending = { id: msg.id, levels: msg.levels };
    if (!busy) serve();
  } else if (msg.type === 'close') {
    if (stream) stream.close();
    stream = null;
    self.close();
  }
};
