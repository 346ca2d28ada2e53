// WASM decode = native decode, bit for bit; damaged and truncated inputs give messages.
//
//   node web/test/wasm_decode_test.mjs [--textured] POMAR_TOOL FILE.pomar [FILE.pomar ...]
//
// For each file, the native tool (`pomar decode`) writes binary PLYs of: the base clustered
// mesh, a selective decode (two clusters refined, their neighbours by the level map rule)
// and the full resolution; the WebAssembly decoder (web/pomar_core.js, the worker's own
// code) decodes the same requests, in an order that exercises refinement on top of a
// decoded state and coarsening, and every position (as bits), index and colour byte (a
// file with per-vertex colour: the mesh's `colour`, drawn by the viewer) must match; so must,
// in a textured file, every corner's texture coordinate (as bits: the PLY's face `texcoord`
// against the decoder's corners, and the viewer's per-vertex `texcoords` where the mesh has
// them) and every face's texture number (`texnumber`). Then
// truncated copies and copies with flipped bytes must open and decode or fail with a
// pomar message, never trap. With --textured, every file must have per-corner texture
// coordinates (so that their comparison is not vacuous), and the checks that a selective
// request reads only some blocks and that short estimates are retried are left out: the
// clusters of copies along a seam are decoded to one level together (the decoder's cluster
// links), which on a small textured file can bring in every block.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { PomarError, layoutOf } from '../pomar_core.js';
import { PomarStream } from '../pomar_stream.js';
import { RangeFile } from '../range_fetch.js';
import { checker, loadModuleInNode } from './node_support.mjs';

const args = process.argv.slice(2);
const textured = args[0] === '--textured';
const [tool, ...files] = textured ? args.slice(1) : args;
if (!tool || files.length === 0) {
  console.error('usage: node wasm_decode_test.mjs [--textured] POMAR_TOOL FILE.pomar...');
  process.exit(2);
}
const M = await loadModuleInNode();
const work = mkdtempSync(join(tmpdir(), 'pomar-wasm-'));
const result = checker();
const check = result.check;

/** Vertices (as float bits), their colour bytes (red, green, blue, alpha if present) and
 *  faces of a binary little-endian PLY written by the tool. */
function readPly(path) {
  const buf = readFileSync(path);
  const end = buf.indexOf('end_header\n') + 'end_header\n'.length;
  const header = buf.subarray(0, end).toString('latin1').split('\n');
  if (!header[1].startsWith('format binary_little_endian')) throw new Error(path + ': not binary LE');
  const elements = [];
  for (const line of header) {
    const t = line.trim().split(/\s+/);
    if (t[0] === 'element') elements.push({ name: t[1], count: +t[2], props: [] });
    else if (t[0] === 'property') elements[elements.length - 1].props.push(t.slice(1));
  }
  const size = { char: 1, uchar: 1, short: 2, ushort: 2, int: 4, uint: 4, float: 4, double: 8 };
  const dv = new DataView(buf.buffer, buf.byteOffset, buf.byteLength);
  const get = (type, at) => {
    switch (type) {
      case 'uchar': return dv.getUint8(at);
      case 'char': return dv.getInt8(at);
      case 'int': return dv.getInt32(at, true);
      case 'uint': return dv.getUint32(at, true);
      case 'float': return dv.getUint32(at, true); // the bits
      default: throw new Error('unexpected PLY type ' + type);
    }
  };
  let at = end;
  const out = { positionBits: [], triangles: [], colour: [], cornerUvBits: [], texnumber: [] };
  for (const el of elements) {
    for (let i = 0; i < el.count; ++i) {
      for (const p of el.props) {
        if (p[0] === 'list') {
          const n = get(p[1], at);
          at += size[p[1]];
          if (el.name === 'face' && p[3] === 'vertex_indices' && n !== 3) throw new Error('non-triangle face');
          if (el.name === 'face' && p[3] === 'texcoord' && n !== 6) throw new Error('a face with ' + n + ' texcoords');
          const into = el.name === 'face' && p[3] === 'texcoord' ? out.cornerUvBits : out.triangles;
          for (let k = 0; k < n; ++k, at += size[p[2]]) into.push(get(p[2], at));
        } else {
          if (el.name === 'vertex' && 'xyz'.includes(p[1])) out.positionBits.push(get(p[0], at));
          if (el.name === 'vertex' && ['red', 'green', 'blue', 'alpha'].includes(p[1])) out.colour.push(get(p[0], at));
          if (el.name === 'face' && p[1] === 'texnumber') out.texnumber.push(get(p[0], at));
          at += size[p[0]];
        }
      }
    }
  }
  return { positionBits: Uint32Array.from(out.positionBits), triangles: Uint32Array.from(out.triangles),
    colour: Uint8Array.from(out.colour), cornerUvBits: Uint32Array.from(out.cornerUvBits),
    texnumber: Int32Array.from(out.texnumber) };
}

/** The decoder's current mesh (the viewer's `mesh()`), with the texture coordinates of its
 *  corners as bits (6 per triangle; empty without any) and each face's texture number (the
 *  texture of its material, -1 for none; empty without materials), as the native PLY has
 *  them. */
function meshOf(decoder) {
  const m = decoder.mesh();
  const ptr = M._pw_corner_texcoords(decoder.h);
  m.cornerUvBits = ptr ? new Uint32Array(M.HEAPU32.buffer, ptr, 2 * m.triangles.length).slice() : new Uint32Array(0);
  m.texnumber = m.faceMaterials ? Int32Array.from(m.faceMaterials, (f) => m.materials[f].texture) : new Int32Array(0);
  return m;
}

function native(file, args) {
  const out = join(work, 'native.ply');
  execFileSync(tool, ['decode', file, out, '-q', ...args]);
  return readPly(out);
}

function sameArrays(a, b) {
  if (a.length !== b.length) return false;
  for (let i = 0; i < a.length; ++i) if (a[i] !== b[i]) return false;
  return true;
}

function compare(wasmMesh, nativeMesh, what) {
  const bits = new Uint32Array(wasmMesh.positions.buffer, wasmMesh.positions.byteOffset, wasmMesh.positions.length);
  check(bits.length === nativeMesh.positionBits.length,
    `${what}: ${bits.length / 3} vertices in WASM, ${nativeMesh.positionBits.length / 3} native`);
  check(sameArrays(bits, nativeMesh.positionBits), `${what}: positions differ`);
  check(sameArrays(wasmMesh.triangles, nativeMesh.triangles), `${what}: triangles differ`);
  const colour = wasmMesh.colour ? wasmMesh.colour.values : new Uint8Array(0);
  check(sameArrays(colour, nativeMesh.colour), `${what}: colours differ (${colour.length} bytes in WASM, ${nativeMesh.colour.length} native)`);
  const uv = wasmMesh.cornerUvBits;
  check(uv.length === nativeMesh.cornerUvBits.length,
    `${what}: ${uv.length / 2} corner texture coordinates in WASM, ${nativeMesh.cornerUvBits.length / 2} native`);
  let uvDiffer = 0;
  for (let i = 0; i < Math.min(uv.length, nativeMesh.cornerUvBits.length); ++i) if (uv[i] !== nativeMesh.cornerUvBits[i]) ++uvDiffer;
  check(uvDiffer === 0, `${what}: ${uvDiffer} of ${uv.length} corner texture coordinates differ`);
  check(sameArrays(wasmMesh.texnumber, nativeMesh.texnumber), `${what}: face texture numbers differ`);
  if (wasmMesh.texcoords) { // the viewer's per-vertex values: those of the vertex's corners
    const vertexBits = new Uint32Array(wasmMesh.texcoords.buffer, wasmMesh.texcoords.byteOffset, wasmMesh.texcoords.length);
    let off = 0;
    for (let c = 0; c < wasmMesh.triangles.length && c < uv.length / 2; ++c) {
      const v = wasmMesh.triangles[c];
      if (vertexBits[2 * v] !== uv[2 * c] || vertexBits[2 * v + 1] !== uv[2 * c + 1]) ++off;
    }
    check(off === 0, `${what}: ${off} corners whose vertex's texture coordinate is not the corner's`);
  }
  if (result.failures === 0) {
    console.log(`  ${what}: ${bits.length / 3} vertices, ${wasmMesh.triangles.length / 3} faces` +
      `${colour.length ? `, ${colour.length} colour bytes` : ''}` +
      `${uv.length ? `, ${uv.length / 2} corner texture coordinates` : ''} identical`);
  }
}

/** The mesh with vertices (and their colours) sorted by position bits and faces rotated
 *  and sorted. */
function canonical(m) {
  const bits = m.positionBits || new Uint32Array(m.positions.buffer, m.positions.byteOffset, m.positions.length);
  const n = bits.length / 3;
  const order = Array.from({ length: n }, (_, i) => i);
  order.sort((i, j) => bits[3 * i] - bits[3 * j] || bits[3 * i + 1] - bits[3 * j + 1] || bits[3 * i + 2] - bits[3 * j + 2]);
  const rank = new Uint32Array(n);
  const positionBits = new Uint32Array(3 * n);
  const colourIn = m.positionBits ? m.colour : m.colour ? m.colour.values : new Uint8Array(0);
  const per = n ? colourIn.length / n : 0; // colour bytes per vertex
  const colour = new Uint8Array(colourIn.length);
  order.forEach((v, r) => {
    rank[v] = r;
    positionBits.set(bits.subarray(3 * v, 3 * v + 3), 3 * r);
    colour.set(colourIn.subarray(per * v, per * v + per), per * r);
  });
  // A face: its three vertices from the lowest, then its corners' (u, v) bits in the same
  // rotation and its texture number (so faces on the same vertices sort by them too).
  const uv = m.cornerUvBits;
  const tex = m.texnumber;
  const faces = [];
  for (let f = 0; f < m.triangles.length; f += 3) {
    const t = [rank[m.triangles[f]], rank[m.triangles[f + 1]], rank[m.triangles[f + 2]]];
    const k = t.indexOf(Math.min(...t));
    const face = [t[k], t[(k + 1) % 3], t[(k + 2) % 3]];
    if (uv.length) for (let j = 0; j < 3; ++j) face.push(uv[2 * (f + (k + j) % 3)], uv[2 * (f + (k + j) % 3) + 1]);
    if (tex.length) face.push(tex[f / 3]);
    faces.push(face);
  }
  faces.sort((x, y) => {
    for (let j = 0; j < x.length; ++j) if (x[j] !== y[j]) return x[j] - y[j];
    return 0;
  });
  const width = 3 + (uv.length ? 6 : 0);
  return { positions: new Float32Array(positionBits.buffer), positionBits, triangles: Uint32Array.from(faces.map((x) => x.slice(0, 3)).flat()),
    cornerUvBits: Uint32Array.from(faces.map((x) => x.slice(3, width)).flat()),
    texnumber: Int32Array.from(tex.length ? faces.map((x) => x[width]) : []),
    texcoords: null, // (per vertex: not kept in canonical order; the corners are)
    // The colour as it came: bytes (a native PLY) or pomar_core.js's {components, values}.
    colour: m.positionBits ? colour : per ? { components: per, values: colour } : null };
}

/** Open `bytes` as the page does (pomar_stream.js over a RangeFile), from a Blob. */
function open(bytes, tolerant = false, options = {}) {
  // wholeBlockBytes 0: every block is fetched as a prefix first (the samples' blocks are small).
  return new PomarStream(M, new RangeFile(new Blob([bytes]), { maxGap: 64 }), { tolerant, wholeBlockBytes: 0, ...options }).open();
}

for (const file of files) {
  console.log(file);
  const bytes = new Uint8Array(readFileSync(file));
  const probe = await open(bytes);
  const info = probe.info;
  probe.close();

  // First frames (pomar_stream.js readGlobal): a first request that ends after the base
  // mesh, or after half the global levels when they follow it, draws the base mesh and the
  // levels at hand before the global part is in; a file whose sections (stored errors) lie
  // between the base mesh and the levels draws the last global level once the levels are
  // in. Each drawn mesh is the native decode of its level (positions and triangles).
  const layout = layoutOf(M, bytes, bytes.length);
  const half = layout.levelEnds[Math.floor(layout.levelEnds.length / 2)];
  for (const first of [layout.baseEnd + 1, ...(half && layout.levelStart < layout.baseEnd + 64 ? [half + 1] : [])]) {
    if (first >= info.globalBytes) continue;
    const previews = [];
    const stream = await new PomarStream(M, new RangeFile(new Blob([bytes]), {}), { firstRequestBytes: first })
      .open((mesh, stats) => previews.push({ mesh, bytes: stats.bytesFetched }));
    check(previews.length > 0 && previews[0].bytes < info.globalBytes,
      `first request of ${first} bytes: a first frame at ${previews[0]?.bytes} bytes, before the global part (${info.globalBytes}) is in`);
    const sections = layout.levelStart > layout.baseEnd + 64 && layout.attrStart === 0;
    const last = previews[previews.length - 1]?.mesh;
    check(!sections || last?.level === layout.levelEnds.length,
      `a file with sections before its levels: the last global level drawn before the sections (${last?.level})`);
    for (const { mesh } of previews) {
      // (A progressive file's finest level is the encoded mesh, before its lossless record.)
      if (!info.clusters && mesh.level === info.finestLevel) continue;
      const want = native(file, ['--level', `${mesh.level}`]);
      // (A first frame has positions and triangles only.)
      compare({ ...mesh, cornerUvBits: new Uint32Array(0), texnumber: new Int32Array(0) },
        { ...want, colour: new Uint8Array(0), cornerUvBits: new Uint32Array(0), texnumber: new Int32Array(0) },
        `first frame (first request ${first} bytes): global level ${mesh.level}`);
    }
    compare(meshOf(stream.decoder), native(file, ['--level', `${info.clusters ? info.baseLevel : 0}`, ...(info.clusters ? ['--cluster', '0:0'] : [])]),
      'opened after the first frames');
    stream.close();
  }
  if (info.clusters > 0) {
    const base = info.baseLevel;
    const finest = info.finestLevel;
    const a = 5 % info.clusters;
    const b = Math.floor(info.clusters / 2);
    const selective = new Array(info.clusters).fill(base);
    selective[a] = Math.min(finest, base + 4);
    selective[b] = Math.min(finest, base + 2);
    const nativeBase = native(file, ['--level', `${base}`, '--cluster', '0:0']);
    if (textured) check(nativeBase.cornerUvBits.length > 0, `${file}: per-corner texture coordinates (--textured)`);
    const nativeSelective = native(file, ['--cluster', `${a}:${selective[a]}`, '--cluster', `${b}:${selective[b]}`]);
    const nativeFull = native(file, ['--level', `${finest}`, '--cluster', '0']);
    const fetched = {};
    for (const tolerant of [false, true]) {
      const mode = tolerant ? 'tolerant (whole blocks)' : 'block prefixes';
      const s = await open(bytes, tolerant);
      compare(meshOf(s.decoder), nativeBase, `${mode}: base clustered mesh`);
      await s.want(selective);
      compare(meshOf(s.decoder), nativeSelective, `${mode}: clusters ${a}:${selective[a]} and ${b}:${selective[b]}`);
      fetched[mode] = s.stats().bytesFetched;
      console.log(`  ${mode}: the selective request fetched ${fetched[mode]} of ${bytes.length} bytes ` +
        `(${s.stats().blocksHeld} blocks, ${s.retries} short estimates)`);
      if (!textured) check(s.decoder.info.blocksRead < info.clusters, `${mode}: a selective decode reads some blocks`);
      // Refining on top of a decoded state numbers the new vertices in decoding order: the
      // same mesh as a fresh decode, up to vertex numbering.
      await s.want(new Array(info.clusters).fill(finest));
      compare(canonical(meshOf(s.decoder)), canonical(nativeFull), `${mode}: full resolution refined from the selective state (canonical order)`);
      check(s.stats().bytesFetched === bytes.length, `${mode}: every byte fetched once (${s.stats().bytesFetched} of ${bytes.length})`);
      check(s.decoder.info.blocksRead === info.clusters, `${mode}: every block read (${s.decoder.info.blocksRead} of ${info.clusters})`);
      // Coarsening decodes again from the base clustered mesh, in a fresh decode's order.
      await s.want(selective);
      compare(meshOf(s.decoder), nativeSelective, `${mode}: coarsened back to the selective request`);
      check(s.stats().bytesFetched === bytes.length, `${mode}: coarsening fetches nothing`);
      check(s.decoder.damaged().count === 0 && s.tolerant === tolerant, `${mode}: an intact file reports no damage`);
      s.close();
      const fresh = await open(bytes, tolerant);
      await fresh.want(new Array(info.clusters).fill(finest));
      compare(meshOf(fresh.decoder), nativeFull, `${mode}: full resolution`);
      fresh.close();
    }
    check(fetched['block prefixes'] <= fetched['tolerant (whole blocks)'], 'block prefixes fetch no more than whole blocks');
    // Estimates far too short: the missing bytes are fetched and the map decoded again.
    const short = await open(bytes, false, { estimateMargin: 0.2 });
    const middle = new Array(info.clusters).fill(Math.min(finest - 1, base + 6));
    await short.want(selective);
    compare(meshOf(short.decoder), nativeSelective, 'short estimates: selective request');
    await short.want(middle);
    compare(canonical(meshOf(short.decoder)), canonical(native(file, ['--level', `${middle[0]}`, '--cluster', '0:0'])),
      `short estimates: every cluster at level ${middle[0]} (canonical order)`);
    check((textured || short.retries > 0) && !short.tolerant && short.decoder.damaged().count === 0,
      `short estimates are retried (${short.retries} retries), not taken for damage`);
    console.log(`  short estimates: ${short.retries} retries, results identical`);
    short.close();
  } else {
    const s = await open(bytes);
    compare(meshOf(s.decoder), native(file, ['--level', '0']), 'base mesh');
    const mid = Math.min(10, info.finestLevel);
    await s.want([mid]);
    compare(meshOf(s.decoder), native(file, ['--level', `${mid}`]), `level ${mid}`);
    await s.want([info.finestLevel]);
    compare(meshOf(s.decoder), native(file, []), 'full resolution');
    s.close();
  }

  // Damaged inputs: every outcome is a decoded mesh or a PomarError with a message.
  let messages = 0;
  let decoded = 0;
  let skipped = 0;
  const attempt = async (damaged, what) => {
    let s = null;
    try {
      s = await open(damaged);
      const top = s.info.clusters > 0 ? new Array(s.info.clusters).fill(s.info.finestLevel) : [s.info.finestLevel];
      await s.want(top);
      const m = meshOf(s.decoder);
      check(m.triangles.every((v) => v < m.positions.length / 3), `${what}: index out of range`);
      if (s.decoder.damaged().count > 0) ++skipped;
      else ++decoded;
    } catch (e) {
      check(e instanceof PomarError && e.message.length > 0, `${what}: ${e && e.stack}`);
      ++messages;
    } finally {
      if (s) s.close();
    }
  };
  const cuts = [0, 10, 59, 60, 100, info.globalBytes - 1, info.globalBytes];
  for (let k = 1; k <= 12; ++k) cuts.push(Math.floor((bytes.length * k) / 13));
  for (const cut of cuts) if (cut < bytes.length) await attempt(bytes.slice(0, cut), `truncated at ${cut}`);
  let seed = 12345;
  const random = () => ((seed = (seed * 1103515245 + 12345) >>> 0) / 4294967296);
  for (let i = 0; i < 100; ++i) {
    const copy = bytes.slice();
    const flips = 1 + Math.floor(random() * 3);
    // Half in the global part (header, base mesh, tables, index), half anywhere.
    for (let f = 0; f < flips; ++f) {
      const range = i % 2 ? copy.length : info.globalBytes;
      copy[Math.floor(random() * range)] ^= 1 + Math.floor(random() * 255);
    }
    await attempt(copy, `corruption ${i}`);
  }
  console.log(`  damaged inputs: ${messages} errors with a message, ${skipped} decoded around ` +
    `damaged blocks, ${decoded} decoded (damage not detected or harmless), no trap`);
  check(messages > 0 && skipped + decoded > 0, 'damaged inputs exercise both errors and skipping');
  const truncatedInBlocks = bytes.slice(0, Math.floor((bytes.length + info.globalBytes) / 2));
  if (info.clusters > 0) {
    const s = await open(truncatedInBlocks);
    await s.want(new Array(info.clusters).fill(info.finestLevel));
    const dmg = s.decoder.damaged();
    check(dmg.count > 0 && /truncated/.test(dmg.text), `truncated cluster blocks are reported: ${dmg.text}`);
    s.close();
  }
}
rmSync(work, { recursive: true, force: true });
result.done('wasm decode test');
