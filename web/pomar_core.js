// The WebAssembly decoder's C ABI (web/src/pomar_web.cpp) as a small synchronous class.
// Used by the Web Worker (pomar_worker.js) and by the Node tests; knows nothing about the
// network: bytes come in as Uint8Arrays, meshes go out as typed arrays (copies).
import createPomarDecoder from './dist/pomar_decoder.mjs';
import { BOUNDS_STRIDE } from './view_refine.js';

let modulePromise = null;
/** The WebAssembly module, instantiated once (`options`: emscripten's, e.g. wasmBinary). */
export function loadModule(options = {}) {
  if (!modulePromise) modulePromise = createPomarDecoder(options);
  return modulePromise;
}

export class PomarError extends Error {}

/** Attribute kinds of pw_attribute_components (pomar::AttributeKind). */
export const ATTRIBUTE_COLOUR = 1;
export const ATTRIBUTE_TEXCOORD = 4;

function lastError(M) {
  return M.UTF8ToString(M._pw_last_error());
}

/** Copy `bytes` into the WebAssembly heap for the duration of `f(ptr)`. */
function withBytes(M, bytes, f) {
  const ptr = M._malloc(Math.max(1, bytes.length));
  if (!ptr) throw new PomarError('out of memory: cannot copy ' + bytes.length + ' bytes');
  try {
    M.HEAPU8.set(bytes, ptr);
    return f(ptr);
  } finally {
    M._free(ptr);
  }
}

/** How many leading bytes of a file of `fileSize` bytes Decoder.open needs, knowing its first
 *  bytes `prefix`: grows (header size, then global part) until it is <= prefix.length. */
export function globalBytes(M, prefix, fileSize) {
  const n = withBytes(M, prefix, (p) => M._pw_global_bytes(p, prefix.length, fileSize));
  if (n < 0) throw new PomarError(lastError(M));
  return n;
}

/** Where the pieces of the global part lie, from the file's first bytes `prefix` (null
 *  while they do not hold the whole header): {headerBytes, baseEnd, attrStart, attrEnd
 *  (the span of the sections the levels need, ATTR and GEOP; 0 0: none), levelEnds (end
 *  of each global level's bytes), levelStart (level 1), tablesOffset (model tables; a progressive file: the end of its levels), globalBytes}. */
export function layoutOf(M, prefix, fileSize) {
  const ptr = withBytes(M, prefix, (p) => M._pw_layout(p, prefix.length, fileSize));
  if (!ptr) return null;
  const head = new Float64Array(M.HEAPF64.buffer, ptr, 5);
  const g = head[4];
  const d = new Float64Array(M.HEAPF64.buffer, ptr, 5 + g + 3).slice();
  return { headerBytes: d[0], baseEnd: d[1], attrStart: d[2], attrEnd: d[3], levelEnds: Array.from(d.subarray(5, 5 + g)),
    levelStart: d[5 + g], tablesOffset: d[6 + g], globalBytes: d[7 + g] };
}

/** The mesh of a first frame: the base mesh and global levels 1..`levels`, decoded from
 *  `bytes` (the file's first bytes; only the header, the base mesh, the ATTR and GEOP
 *  sections if any and those levels need to be there: layoutOf). {positions, triangles, level}. */
export function previewMesh(M, bytes, fileSize, levels) {
  const level = withBytes(M, bytes, (p) => M._pw_preview(p, bytes.length, fileSize, levels));
  if (level < 0) throw new PomarError(lastError(M));
  const nv = M._pw_preview_vertex_count();
  const nt = M._pw_preview_triangle_count();
  const mesh = {
    positions: new Float32Array(M.HEAPF32.buffer, M._pw_preview_positions(), 3 * nv).slice(),
    triangles: new Uint32Array(M.HEAPU32.buffer, M._pw_preview_triangles(), 3 * nt).slice(),
    level,
  };
  M._pw_preview_release();
  return mesh;
}

export class Decoder {
  /** Decode the base clustered mesh from the file's first bytes (>= globalBytes).
   *  `tolerant`: skip damaged or missing cluster blocks (and read every block whole);
   *  otherwise read blocks only as far as the wanted levels need, and fail on damage. */
  constructor(M, prefix, fileSize, tolerant = true) {
    this.M = M;
    this.tolerant = tolerant;
    this.h = withBytes(M, prefix, (p) => M._pw_open(p, prefix.length, fileSize, tolerant ? 1 : 0));
    if (!this.h) throw new PomarError(lastError(M));
    try {
      this.refreshInfo();
    } catch (e) {
      M._pw_close(this.h);
      throw e;
    }
    const n = this.info.clusters;
    this.blockOffset = new Float64Array(n);
    this.blockSize = new Float64Array(n);
    for (let c = 0; c < n; ++c) {
      this.blockOffset[c] = M._pw_block_offset(this.h, c);
      this.blockSize[c] = M._pw_block_size(this.h, c);
    }
  }

  refreshInfo() {
    const M = this.M;
    const n = M._pw_info_size(this.h);
    const d = new Float64Array(M.HEAPF64.buffer, M._pw_info(this.h), n).slice();
    const levels = [];
    for (let i = 18; i + 1 < n; i += 2) levels.push({ vertices: d[i], faces: d[i + 1] });
    if (this.clusterErrors === undefined) {
      // The stored error bounds (section CERR), level-major from the base clustered level
      // to the one below the finest; null when the file stores none. A damaged section is
      // an error, as for the rest of the global part.
      const stored = M._pw_cluster_errors(this.h);
      if (stored < 0) throw new PomarError(lastError(M));
      this.clusterErrors = stored
        ? new Float32Array(M.HEAPF32.buffer, M._pw_cluster_errors_data(this.h), d[0] * (d[2] - d[1])).slice()
        : null;
    }
    this.info = {
      clusters: d[0], baseLevel: d[1], finestLevel: d[2], vertices: d[3], faces: d[4],
      fileBytes: d[5], globalBytes: d[6], bboxMin: [d[7], d[8], d[9]], bboxMax: [d[10], d[11], d[12]],
      version: d[13], decoderBytesRead: d[14], blocksRead: d[15], baseVertices: d[16], baseFaces: d[17], levels,
      clusterErrors: this.clusterErrors,
    };
    return this.info;
  }

  close() {
    if (this.h) this.M._pw_close(this.h);
    this.h = 0;
  }

  /** Call f(ptr) with `levels` (one per cluster; progressive files: [level]) in the heap. */
  withLevels(levels, f) {
    const M = this.M;
    const n = Math.max(1, levels.length);
    const ptr = M._malloc(4 * n);
    try {
      M.HEAP32.set(Int32Array.from(levels), ptr >> 2);
      return f(ptr);
    } finally {
      M._free(ptr);
    }
  }

  /** The level map update(wanted) would decode (the level map rule applied). */
  complete(wanted) {
    const M = this.M;
    if (this.withLevels(wanted, (p) => M._pw_complete(this.h, p)) < 0)
      throw new PomarError(lastError(M));
    return new Int32Array(M.HEAP32.buffer, M._pw_levels(this.h), this.info.clusters).slice();
  }

  /** SelectiveDecoder::view_levels for `view` (camera.js viewOf: eye, viewProj, fovY,
   *  width, height, near) and a budget of `pixels`: the level per cluster the library's
   *  want_view would ask for, from the current mesh (no occlusion), without decoding. */
  viewLevels(view, pixels) {
    const M = this.M;
    const cam = [...view.eye, ...view.viewProj, view.fovY, view.width, view.height, view.near];
    const ptr = M._malloc(4 * cam.length);
    try {
      M.HEAPF32.set(Float32Array.from(cam), ptr >> 2);
      if (M._pw_view_levels(this.h, ptr, pixels) < 0) throw new PomarError(lastError(M));
    } finally {
      M._free(ptr);
    }
    return new Int32Array(M.HEAP32.buffer, M._pw_levels(this.h), Math.max(1, this.info.clusters)).slice();
  }

  /** Hand over the first bytes of cluster c's block (all of it, or what its levels need). */
  putBlock(c, bytes) {
    const M = this.M;
    if (withBytes(M, bytes, (p) => M._pw_put_block(this.h, c, p, bytes.length)) < 0)
      throw new PomarError(lastError(M));
  }

  /** Decode to the completed level map of `wanted`; returns the level of every cluster.
   *  Throws a PomarError; its `missingCluster` is the cluster whose block lacked bytes (-1 if
   *  that was not the problem; then coarsen everything to the base level before retrying). */
  update(wanted) {
    const M = this.M;
    if (this.withLevels(wanted, (p) => M._pw_update(this.h, p)) < 0) {
      const e = new PomarError(lastError(M));
      e.missingCluster = M._pw_missing_cluster(this.h);
      throw e;
    }
    this.refreshInfo();
    return new Int32Array(M.HEAP32.buffer, M._pw_levels(this.h), this.info.clusters).slice();
  }

  /** The extracted mesh's attribute of `kind` (ATTRIBUTE_*) for its `nv` vertices:
   *  {components, values} (a copy: Uint8Array for colour, Float32Array otherwise), or null. */
  attribute(kind, nv) {
    const M = this.M;
    const components = M._pw_attribute_components(this.h, kind);
    if (!components) return null;
    const ptr = M._pw_attribute_values(this.h, kind);
    const values = kind === ATTRIBUTE_COLOUR ? new Uint8Array(M.HEAPU8.buffer, ptr, components * nv).slice()
      : new Float32Array(M.HEAPF32.buffer, ptr, components * nv).slice();
    return { components, values };
  }

  /** Damaged blocks skipped so far: { count, text } (text: one line per block). */
  damaged() {
    const M = this.M;
    return { count: M._pw_damaged_count(this.h), text: M.UTF8ToString(M._pw_damaged(this.h)) };
  }

  /** The current mesh as typed arrays (copies, transferable), plus per-cluster bounds:
   *  BOUNDS_STRIDE floats per cluster (bbox min, max, longest edge, face count, normal cone,
   *  detail of its newest vertices and their count: see view_refine.js), and `colour`:
   *  the per-vertex colour, {components: 3 (RGB) or 4 (RGBA), values: Uint8Array of
   *  vertices x components}, or null when the file has none. A textured file's mesh also
   *  has `texcoords` (Float32Array, u and v per vertex, v = 0 at the bottom of the image;
   *  null when a vertex's corners disagree: `texcoordConflicts` counts those vertices),
   *  `faceMaterials` (Uint32Array, per triangle: an index into `materials`, or null),
   *  `materials` ([{name, texture, properties}]: texture an index into `textureFiles`, -1
   *  for none; properties the material's other MTL lines, e.g. "Kd 0.8 0.2 0.2") and
   *  `textureFiles` (the names the file stores). `keepSeams`: at full resolution too, a
   *  textured file gives the coded mesh cut at its seams (one texture coordinate per
   *  vertex) rather than the welded input, whose seam vertices have two. */
  mesh({ keepSeams = false } = {}) {
    const M = this.M;
    M._pw_keep_seams(this.h, keepSeams ? 1 : 0);
    if (M._pw_extract(this.h) < 0) throw new PomarError(lastError(M));
    const nv = M._pw_vertex_count(this.h);
    const nt = M._pw_triangle_count(this.h);
    const f32 = (ptr, n) => new Float32Array(M.HEAPF32.buffer, ptr, n).slice();
    const u32 = (ptr, n) => new Uint32Array(M.HEAPU32.buffer, ptr, n).slice();
    const uv = M._pw_texcoords(this.h);
    const faceMaterials = M._pw_face_materials(this.h);
    const materials = [];
    for (let i = 0; i < M._pw_material_count(this.h); ++i)
      materials.push({ name: M.UTF8ToString(M._pw_material_name(this.h, i)), texture: M._pw_material_texture(this.h, i),
        properties: M.UTF8ToString(M._pw_material_properties(this.h, i)) });
    const textureFiles = [];
    for (let i = 0; i < M._pw_texture_count(this.h); ++i) textureFiles.push(M.UTF8ToString(M._pw_texture_file(this.h, i)));
    return {
      colour: this.attribute(ATTRIBUTE_COLOUR, nv),
      texcoords: uv ? f32(uv, 2 * nv) : null,
      texcoordConflicts: M._pw_texcoord_conflicts(this.h),
      faceMaterials: faceMaterials ? u32(faceMaterials, nt) : null,
      materials,
      textureFiles,
      positions: f32(M._pw_positions(this.h), 3 * nv),
      triangles: u32(M._pw_triangles(this.h), 3 * nt),
      vertexCluster: u32(M._pw_vertex_cluster(this.h), nv),
      vertexLevel: u32(M._pw_vertex_level(this.h), nv),
      clusterBounds: f32(M._pw_cluster_bounds(this.h), BOUNDS_STRIDE * Math.max(1, this.info.clusters)),
    };
  }
}
