// The Web Worker behind pomar.js: fetches byte ranges, decodes with the WebAssembly decoder,
// posts meshes (transferred typed arrays) and messages back. One file per worker.
//
// in:  {type:'open', source (URL or File), options}, {type:'want', id, levels}, {type:'close'}
// out: {type:'opened'|'mesh', id, info, mesh, levels, stats}, {type:'warning', message},
//      {type:'error', id, message}
import { Decoder, globalBytes, loadModule } from './pomar_core.js';
import { RangeFile } from './range_fetch.js';

let M = null;
let file = null;
let prefix = null;
let decoder = null;
let options = {};
/** Cluster blocks handed to the decoder, kept to rebuild it within the memory budget. */
const held = new Map();
let heldBytes = 0;
let damagedReported = 0;
let rebuilds = 0;
let busy = false;
let pending = null; // the latest want not yet served (older ones are superseded)

function stats(extra = {}) {
  return {
    fileBytes: file ? file.size : 0,
    bytesFetched: file ? file.stats.bytesFetched : 0,
    requests: file ? file.stats.requests : 0,
    maxInFlightSeen: file ? file.stats.maxInFlightSeen : 0,
    blocksHeld: held.size,
    heldBytes,
    blocksPrefetched: prefetched.size,
    prefetchedBytes,
    rebuilds,
    damaged: decoder ? decoder.damaged().count : 0,
    ...extra,
  };
}

function concat(a, b) {
  const out = new Uint8Array(a.length + b.length);
  out.set(a);
  out.set(b, a.length);
  return out;
}

function postMesh(type, id, levels, extra) {
  const mesh = decoder.mesh();
  const transfer = [mesh.positions.buffer, mesh.triangles.buffer, mesh.vertexCluster.buffer,
    mesh.vertexLevel.buffer, mesh.clusterBounds.buffer];
  self.postMessage({ type, id, info: decoder.info, mesh, levels,
    stats: stats({ vertices: mesh.positions.length / 3, triangles: mesh.triangles.length / 3, ...extra }) }, transfer);
}

function reportDamage() {
  const d = decoder.damaged();
  if (d.count > damagedReported) {
    damagedReported = d.count;
    self.postMessage({ type: 'warning', message: `damaged blocks skipped (as --skip-damaged does):\n${d.text}` });
  }
}

async function open(source, opts) {
  options = opts || {};
  const t0 = performance.now();
  if (!M) M = await loadModule();
  file = new RangeFile(source, options);
  // The header and, usually, the whole global part in one request; a second one if not.
  prefix = await file.read(0, options.firstRequestBytes || 16384);
  if (prefix.length === 0) throw new Error(`${file.name} is empty`);
  for (let need; (need = globalBytes(M, prefix, file.size)) > prefix.length;)
    prefix = concat(prefix, await file.read(prefix.length, need - prefix.length));
  decoder = new Decoder(M, prefix, file.size);
  postMesh('opened', 0, new Int32Array(decoder.info.clusters).fill(decoder.info.baseLevel),
    { decodeMs: performance.now() - t0 });
}

/** Blocks fetched before they are needed (in the gaps of coalesced requests), by cluster,
 *  oldest first; at most options.prefetchBudget bytes. */
const prefetched = new Map();
let prefetchedBytes = 0;
let byOffset = null; // cluster ids sorted by block offset

/** Position in byOffset of the first block starting at or after `offset`. */
function firstBlockFrom(offset) {
  if (!byOffset)
    byOffset = Array.from(decoder.blockOffset.keys()).sort((a, b) => decoder.blockOffset[a] - decoder.blockOffset[b]);
  let lo = 0;
  let hi = byOffset.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (decoder.blockOffset[byOffset[mid]] < offset) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/** Does [start, end) hold bytes already at hand (the first request, blocks held or
 *  prefetched)? Such gaps are not fetched again. */
function haveSome(start, end) {
  if (start < prefix.length) return true;
  for (let i = firstBlockFrom(start); i < byOffset.length && decoder.blockOffset[byOffset[i]] < end; ++i)
    if (held.has(byOffset[i]) || prefetched.has(byOffset[i])) return true;
  return false;
}

function keepPrefetched(chunks, wanted) {
  const budget = options.prefetchBudget ?? 64 << 20;
  for (const { offset, bytes } of chunks) {
    // The blocks lying whole in this response.
    for (let i = firstBlockFrom(offset); i < byOffset.length; ++i) {
      const c = byOffset[i];
      const end = decoder.blockOffset[c] + decoder.blockSize[c];
      if (end > offset + bytes.length) break;
      if (wanted.has(c) || held.has(c) || prefetched.has(c) || decoder.blockSize[c] === 0) continue;
      prefetched.set(c, bytes.slice(decoder.blockOffset[c] - offset, end - offset));
      prefetchedBytes += decoder.blockSize[c];
    }
  }
  for (const [c, bytes] of prefetched) {
    if (prefetchedBytes <= budget) break;
    prefetched.delete(c);
    prefetchedBytes -= bytes.length;
  }
}

/** Decode to the completed level map of `levels`, fetching the blocks it lacks. */
async function want(id, levels) {
  const t0 = performance.now();
  const ids = decoder.info.clusters ? decoder.plan(levels) : [];
  // What the first request or an earlier gap brought is not fetched again.
  const ranges = [];
  const got = new Map();
  for (const c of ids) {
    if (prefetched.has(c)) {
      got.set(c, prefetched.get(c));
      prefetchedBytes -= prefetched.get(c).length;
      prefetched.delete(c);
      continue;
    }
    const start = Math.max(decoder.blockOffset[c], prefix.length);
    ranges.push({ key: c, offset: start, size: decoder.blockOffset[c] + decoder.blockSize[c] - start });
  }
  const { parts, chunks } = await file.readMany(ranges, haveSome);
  keepPrefetched(chunks, new Set(ids));
  for (const [c, bytes] of parts) got.set(c, bytes);
  for (const c of ids) {
    const offset = decoder.blockOffset[c];
    if (offset < prefix.length && !(got.get(c) instanceof Error)) {
      const head = prefix.subarray(offset, Math.min(prefix.length, offset + decoder.blockSize[c]));
      got.set(c, concat(head, got.get(c) || new Uint8Array(0)));
    }
  }
  const t1 = performance.now();
  const failed = [];
  for (const c of ids) {
    let bytes = got.get(c);
    if (bytes instanceof Error) {
      failed.push(bytes.message);
      bytes = new Uint8Array(0); // the decoder skips the cluster as missing
    }
    decoder.putBlock(c, bytes);
    held.set(c, bytes);
    heldBytes += bytes.length;
  }
  if (failed.length)
    self.postMessage({ type: 'warning', message: `${failed.length} block fetches failed: ${failed[0]}` });
  let now = decoder.update(levels);
  if (options.memoryBudget && heldBytes > options.memoryBudget) now = rebuild(levels);
  reportDamage();
  postMesh('mesh', id, now, { fetchMs: t1 - t0, decodeMs: performance.now() - t1, newBlocks: ids.length });
}

/** Over the memory budget: a new decoder from the global part, given only the blocks the
 *  current level map needs (the others are dropped), decoded to the same map. */
function rebuild(levels) {
  ++rebuilds;
  decoder.close();
  decoder = new Decoder(M, prefix, file.size);
  const keep = new Set(decoder.plan(levels));
  heldBytes = 0;
  for (const [c, bytes] of held) {
    if (!keep.has(c)) {
      held.delete(c);
      continue;
    }
    decoder.putBlock(c, bytes);
    heldBytes += bytes.length;
  }
  damagedReported = 0;
  return decoder.update(levels);
}

async function serve() {
  busy = true;
  while (pending) {
    const { id, levels } = pending;
    pending = null;
    try {
      await want(id, levels);
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
      await open(msg.source, msg.options);
    } catch (e) {
      self.postMessage({ type: 'error', id: 0, fatal: true, message: e.message || String(e) });
    }
  } else if (msg.type === 'want') {
    if (!decoder) {
      self.postMessage({ type: 'error', id: msg.id, message: 'no file is open' });
      return;
    }
    pending = { id: msg.id, levels: msg.levels };
    if (!busy) serve();
  } else if (msg.type === 'close') {
    if (decoder) decoder.close();
    decoder = null;
    self.close();
  }
};
