// View-dependent refinement: which level each cluster should have for a camera.
//
// The file stores no geometric error per cluster and level, so the error of a cluster at
// its current level is bounded from what is decoded: the longest edge between two of its
// vertices (`clusterBounds[8c+6]`, computed in WebAssembly from the current mesh; a cluster
// that is a single vertex, as at the base clustered level, takes its incident edges). The
// vertex splits of the finer levels move the surface inside the fans they split, i.e. by
// about one edge of the current level near each split, so this length is a conservative
// proxy of how far the surface may still move (not a proven Hausdorff bound; the finest
// level has error 0: it is the encoded mesh). The error of a coarser level, needed to
// coarsen, is the one seen when the cluster was at that level, or, if it was never seen
// there, the current one scaled by sqrt(faces(l) / faces(l-1)) from the level table
// (edges grow like 1/sqrt of the face count).
//
// A cluster is refined one level per step while its error projected to pixels exceeds
// `targetPixels` (largest first, within `triangleBudget`), coarsened one level when the
// error of the coarser level is below `coarsenFraction * targetPixels`, and sent back to
// the base clustered level when it leaves the view frustum. The decoder then completes
// the level map (neighbouring clusters at most one level apart: no cracks), so a request
// converges in (finest - base) steps; call again after each decode until it is stable.

/** Does the box [lo, hi] lie entirely outside one plane of the frustum of `viewProj`
 *  (column-major 4x4, clip = viewProj * [x,y,z,1])? */
function outsideFrustum(viewProj, lo, hi) {
  const m = viewProj;
  // Planes of the clip volume: -w <= x,y,z <= w.
  const planes = [];
  for (let axis = 0; axis < 3; ++axis)
    for (const sign of [1, -1])
      planes.push([0, 1, 2, 3].map((col) => m[4 * col + 3] + sign * m[4 * col + axis]));
  for (const p of planes) {
    // The box corner furthest along the plane normal.
    const x = p[0] >= 0 ? hi[0] : lo[0];
    const y = p[1] >= 0 ? hi[1] : lo[1];
    const z = p[2] >= 0 ? hi[2] : lo[2];
    if (p[0] * x + p[1] * y + p[2] * z + p[3] < 0) return true;
  }
  return false;
}

function distanceToBox(eye, lo, hi) {
  let d2 = 0;
  for (let k = 0; k < 3; ++k) {
    const d = Math.max(lo[k] - eye[k], 0, eye[k] - hi[k]);
    d2 += d * d;
  }
  return Math.sqrt(d2);
}

/**
 * @param state {info, levels (Int32Array, current level per cluster), clusterBounds
 *   (Float32Array, 8 per cluster), errorSeen (Map "c:l" -> error, updated here)}
 * @param view {eye [3], viewProj (16, column-major), fovY (radians), height (pixels), near}
 * @returns {levels: Int32Array wanted, changed: boolean, refine, coarsen, hidden}
 */
export function chooseLevels(state, view, { targetPixels = 3, coarsenFraction = 0.5, triangleBudget = 2e6 } = {}) {
  const { info, levels, clusterBounds: b, errorSeen } = state;
  const n = info.clusters;
  const base = info.baseLevel;
  const finest = info.finestLevel;
  const faces = (l) => (l === 0 ? info.baseFaces : info.levels[l - 1].faces);
  const pixelsPerUnit = view.height / (2 * Math.tan(view.fovY / 2));
  const wanted = Int32Array.from(levels);
  let triangles = 0;
  for (let c = 0; c < n; ++c) triangles += b[8 * c + 7];
  const candidates = [];
  let coarsen = 0;
  let hidden = 0;
  for (let c = 0; c < n; ++c) {
    const l = levels[c];
    const lo = [b[8 * c], b[8 * c + 1], b[8 * c + 2]];
    const hi = [b[8 * c + 3], b[8 * c + 4], b[8 * c + 5]];
    const error = l >= finest ? 0 : b[8 * c + 6];
    errorSeen.set(`${c}:${l}`, error);
    if (outsideFrustum(view.viewProj, lo, hi)) {
      if (l > base) ++hidden;
      wanted[c] = base;
      continue;
    }
    const toPixels = pixelsPerUnit / Math.max(view.near, distanceToBox(view.eye, lo, hi));
    if (l < finest && error * toPixels > targetPixels) {
      candidates.push({ c, pixels: error * toPixels });
    } else if (l > base) {
      const coarser = errorSeen.get(`${c}:${l - 1}`) ??
        (l >= finest ? b[8 * c + 6] : error) * Math.sqrt(faces(l) / faces(l - 1));
      if (coarser * toPixels < coarsenFraction * targetPixels) {
        wanted[c] = l - 1;
        ++coarsen;
      }
    }
  }
  // Largest projected error first, while the estimated triangle count fits the budget.
  candidates.sort((x, y) => y.pixels - x.pixels);
  let refine = 0;
  for (const { c } of candidates) {
    const l = levels[c];
    const more = b[8 * c + 7] * (faces(l + 1) / faces(l) - 1);
    if (triangles + more > triangleBudget) break;
    triangles += more;
    wanted[c] = l + 1;
    ++refine;
  }
  const changed = refine > 0 || coarsen > 0 || hidden > 0;
  return { levels: wanted, changed, refine, coarsen, hidden };
}
