// pomar.js: stream a .pomar file over HTTP and decode it in a Web Worker.
//
//   import { open } from './pomar.js';
//   const model = await open('bunny.pomar', { onMesh: (mesh, model) => draw(mesh) });
//   await model.want({ cluster: 17, level: model.info.finestLevel });   // one cluster
//   await model.want({ all: 20 });                                     // every cluster
//   await model.wantView(view);          // refine/coarsen for a camera (view_refine.js)
//
// open() reads the header, global part and cluster index with one or two Range requests
// and decodes the base clustered mesh; want*() fetch only the cluster blocks still missing
// (adjacent blocks in one range, up to `maxRanges` ranges in one request, at most
// `maxInFlight` requests at once) and decode them
// on top of the current mesh. Meshes arrive as typed arrays: positions (Float32Array, xyz),
// triangles (Uint32Array), vertexCluster, vertexLevel (Uint32Array), clusterBounds, and
// colour ({components: 3 or 4, values: Uint8Array}, or null: the file has no colour);
// a textured file's texcoords (Float32Array, u v per vertex), faceMaterials (Uint32Array),
// materials ([{name, texture}]) and textureFiles (names as stored; pomar_core.js mesh()).
// Errors (HTTP errors, servers without Range support, damaged or truncated files) reject
// the promises with an Error whose message says what happened; damaged cluster blocks are
// skipped (as `pomar decode --skip-damaged` does) and reported through `onWarning`.
import { chooseLevels, Convergence, sameLevels } from './view_refine.js';
import { DEFAULT_REQUEST_COST } from './range_fetch.js';

/**
 * @param source URL of a .pomar file, or a File/Blob (e.g. dropped on the page)
 * @param options {onMesh(mesh, model), onPreview(mesh, stats) (first frames while the
 *   global part arrives: the base mesh and the global levels at hand, positions and
 *   triangles only; model.firstDraw keeps the stats of the first), onWarning(message), onError(message),
 *   maxInFlight = 4, maxGap = 128 bytes (ranges this close are fetched in one request;
 *   what lies between is kept: a wider gap costs more bytes than the request it saves,
 *   see web/README.md), maxRanges = 100 (ranges in one request: `Range: bytes=a-b,c-d,...`
 *   answered multipart/byteranges; a server that answers otherwise gets one range a
 *   request), requestCost = 4 KiB (a server answering one range a request: gaps between
 *   the ranges of a step shorter than this are fetched rather than paying another
 *   request; range_fetch.js), maxRequestBytes = 1 MiB, memoryBudget = 256 MiB (block bytes
 *   held; over it the worker rebuilds its decoder with only the blocks in use),
 *   firstRequestBytes = 16 KiB, tolerant = false (true: fetch whole blocks from the start;
 *   see pomar_stream.js), keepSeams = false (true: a textured file's mesh stays cut at its
 *   texture seams at full resolution too, one texture coordinate per vertex, instead of
 *   the welded input; the viewer draws textures so)}
 */
export function open(source, options = {}) {
  const model = new PomarModel(options);
  return model.start(source).then(() => model);
}

export class PomarModel {
  constructor(options) {
    this.options = { memoryBudget: 256 << 20, maxGap: 128, maxRanges: 100, maxRequestBytes: 1 << 20, maxInFlight: 4,
      requestCost: DEFAULT_REQUEST_COST, ...options };
    this.firstDraw = null; // stats (bytesFetched, requests, decodeMs, openMs, pageMs) of the first mesh drawn
    this.worker = new Worker(new URL('./pomar_worker.js', import.meta.url), { type: 'module' });
    this.info = null;
    this.mesh = null;
    this.levels = null;
    this.stats = {};
    this.nextId = 1;
    this.waiters = []; // {id, resolve, reject}
    this.errorSeen = new Map();
    this.detailSeen = new Map();
    this.lastWanted = null;
    this.convergence = new Convergence(); // damps wantView's steps for one camera
    this.worker.onmessage = (e) => this.receive(e.data);
    this.worker.onerror = (e) => this.fail(0, `the decoder worker failed: ${e.message || 'cannot load it'}`);
  }

  /** The stats of a first mesh, with when it came: `openMs` after open() was called and
   *  `pageMs` after the page started loading (performance.now() of the page). */
  drawnAt(stats) {
    const now = performance.now();
    return { ...stats, openMs: now - this.openedAt, pageMs: now };
  }

  start(source) {
    this.openedAt = performance.now();
    return new Promise((resolve, reject) => {
      this.waiters.push({ id: 0, resolve, reject });
      const { onMesh, onPreview, onWarning, onError, ...plain } = this.options;
      this.worker.postMessage({ type: 'open', source, options: plain });
    });
  }

  receive(msg) {
    if (msg.type === 'preview') {
      // A first frame from the global levels at hand (positions and triangles only).
      if (!this.firstDraw) this.firstDraw = this.drawnAt(msg.stats);
      if (this.options.onPreview) this.options.onPreview(msg.mesh, msg.stats);
      return;
    }
    if (!this.firstDraw && msg.type === 'opened') this.firstDraw = this.drawnAt(msg.stats);
    if (msg.type === 'warning') {
      if (this.options.onWarning) this.options.onWarning(msg.message);
      return;
    }
    if (msg.type === 'error') {
      this.fail(msg.id, msg.message);
      return;
    }
    this.info = msg.info;
    this.mesh = msg.mesh;
    this.levels = msg.levels;
    this.stats = msg.stats;
    if (this.options.onMesh) this.options.onMesh(msg.mesh, this);
    this.settle(msg.id, (w) => w.resolve(msg.mesh));
  }

  /** Resolve/reject every request up to `id` (later requests supersede earlier ones). */
  settle(id, f) {
    const done = this.waiters.filter((w) => w.id <= id);
    this.waiters = this.waiters.filter((w) => w.id > id);
    done.forEach(f);
  }

  fail(id, message) {
    if (this.options.onError) this.options.onError(message);
    this.settle(id, (w) => w.reject(new Error(message)));
  }

  /** Wanted levels: {cluster, level} (that cluster at least at `level`, the others as they
   *  are), {all: level}, or {levels: per-cluster array}. Resolves with the new mesh. */
  want(request, fromView = false) {
    if (!fromView) this.convergence.forget();
    const n = this.info.clusters;
    let levels;
    if (request.levels) levels = Int32Array.from(request.levels);
    else if (n === 0) levels = Int32Array.of(request.all ?? request.level);
    else if (request.all !== undefined) levels = new Int32Array(n).fill(request.all);
    else {
      levels = Int32Array.from(this.lastWanted || this.levels);
      levels[request.cluster] = Math.max(levels[request.cluster], request.level);
    }
    this.lastWanted = levels;
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      this.waiters.push({ id, resolve, reject });
      this.worker.postMessage({ type: 'want', id, levels });
    });
  }

  /** One step of view-dependent refinement for `view` (see view_refine.js): resolves with
   *  {changed, refine, coarsen, hidden}; call again while `changed` (the page does this
   *  after each frame, so the model converges as the camera rests). */
  async wantView(view, settings = {}) {
    if (this.info.clusters === 0) {
      // A progressive file has one level everywhere: the finest one the view needs is
      // found the same way, treating the whole model as one cluster.
      return { changed: false, refine: 0, coarsen: 0, hidden: 0 };
    }
    const choice = chooseLevels({ info: this.info, levels: this.levels, clusterBounds: this.mesh.clusterBounds,
      errorSeen: this.errorSeen, detailSeen: this.detailSeen, mesh: this.mesh }, view, settings);
    const wanted = this.convergence.next(choice.levels, this.levels, view);
    if (!wanted || sameLevels(wanted, this.lastWanted)) return { ...choice, changed: false };
    await this.want({ levels: wanted }, true);
    return { ...choice, changed: true };
  }

  close() {
    this.worker.postMessage({ type: 'close' });
  }
}
