// The texture coordinates and materials of the WebAssembly decoder's meshes (the C ABI of
// web/src/pomar_web.cpp through web/pomar_core.js), on the cube of web/test/textured_mesh.py.
//
//   node web/test/texture_test.mjs TEXTURED.pomar

// At the base clustered mesh, with one cluster refined, coarsened back and at full
// resolution with keepSeams (as the viewer asks): one (u, v) per vertex, no vertex whose
// corners disagree, a material per triangle, the file's three materials (name, texture or
// none, their `Kd` line) and two texture names;
// every triangle's three texture coordinates lie inside one chart (atlas cell, inside its
// margin) of its own material's atlas, so no face is drawn across a seam. At full
// resolution without keepSeams the mesh is the welded input (1538 vertices): its seam
// vertices have corners in two or three charts, no per-vertex value is given and they are
// counted (the 12 x 15 + 8 = 188 vertices on the cube's edges).
import { readFileSync } from 'node:fs';
import { PomarStream } from '../pomar_stream.js';
import { RangeFile } from '../range_fetch.js';
import { checker, loadModuleInNode } from './node_support.mjs';

const [file] = process.argv.slice(2);
if (!file) {
  console.error('usage: node texture_test.mjs TEXTURED.pomar');
  process.exit(2);
}
const M = await loadModuleInNode();
const result = checker();
const check = result.check;

// textured_mesh.py's atlases: materials `sides` and `lid` 2 x 2 cells, `caps` 2 x 1; a chart keeps a
// margin of 1/16 of its cell to the cell's border.
const CELLS = { sides: [2, 2], caps: [2, 1], lid: [2, 2] };
const MARGIN = 1 / 16;
const EPS = 1e-3; // the decoded texture coordinates' grid (12 bits over their range)

function checkMesh(mesh, what) {
  const nv = mesh.positions.length / 3;
  const nt = mesh.triangles.length / 3;
  check(mesh.texcoords && mesh.texcoords.length === 2 * nv && mesh.texcoordConflicts === 0,
    `${what}: ${nv} vertices, ${mesh.texcoords ? mesh.texcoords.length / 2 : 'no'} texture coordinates, ${mesh.texcoordConflicts} in conflict`);
  check(mesh.faceMaterials && mesh.faceMaterials.length === nt, `${what}: a material per triangle (${nt})`);
  const materials = mesh.materials.map((m) => ({ name: m.name, texture: m.texture, kd: (/^\s*Kd\s+(.*\S)\s*$/m.exec(m.properties) || [])[1] }));
  check(JSON.stringify(materials) === JSON.stringify([{ name: 'sides', texture: 0, kd: '1 1 1' }, { name: 'caps', texture: 1, kd: '1 1 1' },
    { name: 'lid', texture: -1, kd: '0 1 0' }]) &&
    JSON.stringify(mesh.textureFiles) === JSON.stringify(['a.png', 'maps/b.png']),
  `${what}: materials ${JSON.stringify(mesh.materials)}, textures ${JSON.stringify(mesh.textureFiles)}`);
  if (!mesh.texcoords || !mesh.faceMaterials) return;
  let outside = 0;
  const used = new Set();
  for (let f = 0; f < nt; ++f) {
    const material = mesh.materials[mesh.faceMaterials[f]].name;
    const [cu, cv] = CELLS[material];
    let cell = null;
    for (let k = 0; k < 3; ++k) {
      const v = mesh.triangles[3 * f + k];
      const u = mesh.texcoords[2 * v] * cu;
      const w = mesh.texcoords[2 * v + 1] * cv;
      const at = [Math.floor(u), Math.floor(w)];
      const inside = u - at[0] > MARGIN - EPS && u - at[0] < 1 - MARGIN + EPS && w - at[1] > MARGIN - EPS && w - at[1] < 1 - MARGIN + EPS &&
        at[0] >= 0 && at[0] < cu && at[1] >= 0 && at[1] < cv;
      if (!inside || (cell && (cell[0] !== at[0] || cell[1] !== at[1]))) {
        ++outside;
        break;
      }
      cell = at;
    }
    if (cell) used.add(`${material} ${cell}`);
  }
  check(outside === 0, `${what}: ${outside} triangles of ${nt} not inside one chart of their material`);
  check(used.size === 6, `${what}: the triangles use ${used.size} charts (6: one per cube face)`);
}

const bytes = readFileSync(file);
const open = (options) => new PomarStream(M, new RangeFile(new Blob([bytes]), { maxGap: 64 }), { tolerant: false, ...options }).open();
const s = await open();
const { clusters, baseLevel, finestLevel } = s.info;
const cut = { keepSeams: true };
checkMesh(s.decoder.mesh(cut), 'base clustered mesh');
const one = new Array(clusters).fill(baseLevel);
one[0] = finestLevel;
await s.want(one);
const region = s.decoder.mesh(cut);
check(Math.max(...s.levels) === finestLevel && Math.min(...s.levels) < finestLevel, 'one cluster refined, not all');
checkMesh(region, 'one cluster at the finest level');
await s.want(new Array(clusters).fill(baseLevel));
checkMesh(s.decoder.mesh(cut), 'coarsened back');
await s.want(new Array(clusters).fill(finestLevel));
const full = s.decoder.mesh(cut);
checkMesh(full, 'full resolution, seams kept');
const welded = s.decoder.mesh();
check(welded.positions.length / 3 === 1538 && full.positions.length / 3 > 1538,
  `full resolution: the welded input has ${welded.positions.length / 3} vertices (1538), the cut ${full.positions.length / 3}`);
check(welded.texcoords === null && welded.texcoordConflicts === 188,
  `full resolution welded: no per-vertex texture coordinates (${welded.texcoords ? 'given' : 'none'}), ` +
  `${welded.texcoordConflicts} seam vertices counted (188 on the cube's edges)`);
s.close();
result.done('texture_test');
