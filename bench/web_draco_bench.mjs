// Draco's own WebAssembly decoder (npm package draco3d) on a .drc file, timed like
// bench/web_decode_bench.mjs times pomar's: decode + copy of positions and triangles out of
// the WebAssembly heap, median of K runs.
//
//   npm install --prefix /tmp/draco draco3d          (not a dependency of the project)
//   draco_encoder -i bunny.ply -o bunny.drc -qp 12   (Debian's draco package; 12-bit grid as pomar)
//   node bench/web_draco_bench.mjs /tmp/draco/node_modules/draco3d bunny.drc [--repeat K]
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join } from 'node:path';

const args = process.argv.slice(2);
const [dir, file] = args.filter((a) => !a.startsWith('--') && !/^\d+$/.test(a));
const k = args.indexOf('--repeat');
const repeat = k >= 0 ? Number(args[k + 1]) : 5;
if (!dir || !file) {
  console.error('usage: node bench/web_draco_bench.mjs DRACO3D_DIR FILE.drc [--repeat K]');
  process.exit(2);
}
const draco3d = createRequire(import.meta.url)(join(dir, 'draco3d.js'));
const M = await draco3d.createDecoderModule({});
const bytes = new Uint8Array(readFileSync(file));

function decode() {
  const decoder = new M.Decoder();
  const buffer = new M.DecoderBuffer();
  buffer.Init(new Int8Array(bytes.buffer, bytes.byteOffset, bytes.length), bytes.length);
  const mesh = new M.Mesh();
  const status = decoder.DecodeBufferToMesh(buffer, mesh);
  if (!status.ok()) throw new Error('draco: ' + status.error_msg());
  const points = mesh.num_points();
  const faces = mesh.num_faces();
  const attribute = decoder.GetAttribute(mesh, decoder.GetAttributeId(mesh, M.POSITION));
  let ptr = M._malloc(points * 12);
  decoder.GetAttributeDataArrayForAllPoints(mesh, attribute, M.DT_FLOAT32, points * 12, ptr);
  const positions = new Float32Array(M.HEAPF32.buffer, ptr, points * 3).slice();
  M._free(ptr);
  ptr = M._malloc(faces * 12);
  decoder.GetTrianglesUInt32Array(mesh, faces * 12, ptr);
  const triangles = new Uint32Array(M.HEAPU32.buffer, ptr, faces * 3).slice();
  M._free(ptr);
  M.destroy(mesh);
  M.destroy(buffer);
  M.destroy(decoder);
  return { positions, triangles };
}

const times = [];
let out = null;
for (let r = 0; r < repeat; ++r) {
  const t = performance.now();
  out = decode();
  times.push(performance.now() - t);
}
const median = times.slice().sort((x, y) => x - y)[Math.floor(times.length / 2)];
console.log(`${file}: ${out.positions.length / 3} vertices, ${out.triangles.length / 3} faces, ${bytes.length} bytes`);
console.log(`Draco WASM (draco3d, median of ${repeat}): decode + copy ${median.toFixed(1)} ms ` +
  `(${(out.positions.length / 3 / median / 1000).toFixed(2)} M vertices/s)`);
