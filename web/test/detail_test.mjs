// The measured detail of pw_cluster_bounds (web/src/pomar_web.cpp) and its use as the
// error bound of view_refine.js's 'measured' model, on a generated grid whose left half is
// flat and whose right half is bumpy:
//
//   node web/test/detail_test.mjs POMAR_TOOL
//
// The grid is encoded by the native tool and decoded by the WebAssembly decoder (the
// worker's code) at a level between the base clustered level and the finest one, then at
// the finest level. Checks: the detail of every cluster equals its definition recomputed
// here from the decoded mesh (the largest distance of its newest vertices to the plane of
// their neighbours); flat clusters measure no detail and get a measured error far below
// their longest edge (so a close flat cluster that the edge model refines stays); bumpy
// clusters measure at least a quarter of the bumps' height and keep an error of that order.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { PomarStream } from '../pomar_stream.js';
import { RangeFile } from '../range_fetch.js';
import { BOUNDS_STRIDE as S, chooseLevels, clusterError } from '../view_refine.js';
import { checker, loadModuleInNode } from './node_support.mjs';

const [tool] = process.argv.slice(2);
if (!tool) {
  console.error('usage: node detail_test.mjs POMAR_TOOL');
  process.exit(2);
}
const result = checker();
const check = result.check;
const work = mkdtempSync(join(tmpdir(), 'pomar-detail-'));

// A 121 x 121 grid over [0, 1]^2: z = 0 for x < 0.5; beyond, bumps of height BUMP (a
// product of sines, 6 periods across) plus a deterministic jitter of +-BUMP/2.
const N = 121;
const BUMP = 0.02;
let seed = 12345;
const jitter = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648 - 0.5);
const lines = ['OFF', `${N * N} ${2 * (N - 1) * (N - 1)} 0`];
for (let j = 0; j < N; ++j)
  for (let i = 0; i < N; ++i) {
    const x = i / (N - 1);
    const y = j / (N - 1);
    const z = x < 0.5 ? 0 : BUMP * (Math.sin(12 * Math.PI * x) * Math.sin(12 * Math.PI * y) + jitter());
    lines.push(`${x} ${y} ${z}`);
  }
for (let j = 0; j + 1 < N; ++j)
  for (let i = 0; i + 1 < N; ++i) {
    const v = j * N + i;
    lines.push(`3 ${v} ${v + 1} ${v + N + 1}`, `3 ${v} ${v + N + 1} ${v + N}`);
  }
writeFileSync(join(work, 'grid.off'), lines.join('\n') + '\n');
execFileSync(tool, ['encode', join(work, 'grid.off'), join(work, 'grid.pomar'), '-q']);
const M = await loadModuleInNode();
const stream = await new PomarStream(M, new RangeFile(new Blob([readFileSync(join(work, "grid.pomar"))])), {}).open();
const info = stream.info;
check(info.clusters > 8 && info.finestLevel > info.baseLevel + 2,
  `the grid has clusters and levels: ${info.clusters} clusters, levels ${info.baseLevel}..${info.finestLevel}`);

/** The detail of every cluster, recomputed from its definition in pw_cluster_bounds. */
function detailByDefinition(mesh, clusters) {
  const p = mesh.positions;
  const t = mesh.triangles;
  const nv = p.length / 3;
  const sum = new Float64Array(3 * nv);
  const normal = new Float64Array(3 * nv);
  const count = new Uint32Array(nv);
  for (let f = 0; f < t.length; f += 3) {
    const [a, b, c] = [t[f], t[f + 1], t[f + 2]];
    const e1 = [0, 1, 2].map((k) => p[3 * b + k] - p[3 * a + k]);
    const e2 = [0, 1, 2].map((k) => p[3 * c + k] - p[3 * a + k]);
    const n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
    for (const [v, u, w] of [[a, b, c], [b, c, a], [c, a, b]]) {
      for (let k = 0; k < 3; ++k) {
        sum[3 * v + k] += p[3 * u + k] + p[3 * w + k];
        normal[3 * v + k] += n[k];
      }
      count[v] += 2;
    }
  }
  const newest = new Int32Array(clusters).fill(-1);
  const detail = new Float64Array(clusters);
  const d = new Float64Array(nv).fill(-1);
  for (let v = 0; v < nv; ++v) {
    const n = [0, 1, 2].map((k) => normal[3 * v + k]);
    const length = Math.hypot(...n);
    if (!(length > 0)) continue;
    let dot = 0;
    for (let k = 0; k < 3; ++k) dot += (p[3 * v + k] - sum[3 * v + k] / count[v]) * n[k];
    d[v] = Math.abs(dot) / length;
    const c = mesh.vertexCluster[v];
    newest[c] = Math.max(newest[c], mesh.vertexLevel[v]);
  }
  for (let v = 0; v < nv; ++v)
    if (d[v] >= 0 && mesh.vertexLevel[v] === newest[mesh.vertexCluster[v]])
      detail[mesh.vertexCluster[v]] = Math.max(detail[mesh.vertexCluster[v]], d[v]);
  return detail;
}

for (const level of [info.finestLevel - 2, info.finestLevel]) {
  await stream.want(new Int32Array(info.clusters).fill(level));
  const mesh = stream.decoder.mesh();
  const b = mesh.clusterBounds;
  const expected = detailByDefinition(mesh, info.clusters);
  let flat = 0;
  let bumpy = 0;
  let worst = 0;
  let least = Infinity;
  for (let c = 0; c < info.clusters; ++c) {
    const measured = b[S * c + 12];
    worst = Math.max(worst, Math.abs(measured - expected[c]) / Math.max(1e-6, expected[c]));
    check(b[S * c + 13] > 0, `level ${level}, cluster ${c}: detail measured on its newest vertices`);
    const edge = b[S * c + 6];
    const model = { finest: info.finestLevel, errorModel: 'measured', detailSafety: 4, decay: 1 };
    const error = clusterError(b, c, info.finestLevel - 1, model);
    if (b[S * c + 3] < 0.45) { // the whole cluster on the flat half
      ++flat;
      check(measured < 1e-4 * edge, `level ${level}, flat cluster ${c}: no detail (${measured}, edge ${edge})`);
      check(error < 0.01 * edge, `level ${level}, flat cluster ${c}: measured error ${error} far below its edge ${edge}`);
    } else if (b[S * c] > 0.55) { // the whole cluster on the bumpy half
      ++bumpy;
      least = Math.min(least, measured);
      check(error >= Math.min(edge, measured), `level ${level}, bumpy cluster ${c}: error ${error} not below its detail`);
    }
  }
  check(worst < 1e-3, `level ${level}: detail of pw_cluster_bounds = its definition (worst relative gap ${worst})`);
  // The jitter alone (+-BUMP/2, uniform) moves a vertex off its neighbours' plane by a
  // few tenths of BUMP; the largest over a cluster's newest vertices more.
  check(least > BUMP / 10, `level ${level}: every bumpy cluster measures at least ${BUMP / 10} (least ${least})`);
  check(flat >= 3 && bumpy >= 3, `level ${level}: ${flat} flat and ${bumpy} bumpy clusters checked`);
  if (level === info.finestLevel) break;
  // A flat cluster and a bumpy one seen up close (their box 1 unit ahead: 500 px per
  // unit): the edge model refines both, the measured one only the bumpy one.
  const pick = (test) => [...Array(info.clusters).keys()].find((c) => test(b[S * c], b[S * c + 3]));
  const flatC = pick((lo, hi) => hi < 0.45);
  const bumpyC = pick((lo) => lo > 0.55);
  const view = { eye: [0, 0, 0], viewProj: lookDown(), fovY: Math.PI / 2, height: 1000, width: 1000, near: 0.01 };
  const place = (c) => { // the cluster's bounds moved to (0, 0, -1) and its box made 0.1 wide
    const out = b.slice(S * c, S * c + S);
    out.set([-0.05, -0.05, -1.05, 0.05, 0.05, -1]);
    return out;
  };
  const bounds = new Float32Array(2 * S);
  bounds.set(place(flatC), 0);
  bounds.set(place(bumpyC), S);
  const two = { ...info, clusters: 2 };
  const state = () => ({ info: two, levels: Int32Array.of(level, level), clusterBounds: bounds, errorSeen: new Map() });
  const edgePx = (c) => bounds[S * c + 6] * 500;
  check(edgePx(0) > 3 && edgePx(1) > 3, `both clusters' edges project over 3 px (${edgePx(0)}, ${edgePx(1)})`);
  const byEdge = chooseLevels(state(), view, { targetPixels: 3, occlusion: false });
  check(byEdge.levels[0] > level && byEdge.levels[1] > level, `the edge model refines both: ${byEdge.levels}`);
  const byDetail = chooseLevels(state(), view, { targetPixels: 3, occlusion: false, errorModel: 'measured', detailSafety: 4 });
  check(byDetail.levels[0] <= level, `the measured model does not refine the flat cluster (it may coarsen it): ${byDetail.levels}`);
  check(byDetail.levels[1] > level || bounds[S + 12] * 4 * 500 <= 3,
    `the measured model refines the bumpy cluster where its detail projects over the target: ${byDetail.levels}`);
}

/** Looking down -z from the origin, 90 degrees, square: a column-major projection. */
function lookDown() {
  const n = 0.01;
  const f = 100;
  return [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -(f + n) / (f - n), -1, 0, 0, -2 * f * n / (f - n), 0];
}
stream.close();
rmSync(work, { recursive: true, force: true });
result.done('detail_test');
