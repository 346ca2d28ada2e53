// View-dependent refinement: which level each cluster should have for a camera.
//
// A file with a CERR section stores an error bound per cluster and level: errorModel 'auto'
// (the default) then uses it (chooseStored: every level's error known, straight to the
// coarsest level within the target whose facets are at most `maxEdgePixels` on screen: the
// viewer shades flat facets, and a coarse facet within the geometric bound still tilts
// against the finer ones, which changes its colour wherever it covers several pixels).
// Without one, the error of a cluster at
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
// `errorModel: 'measured'` (an option; see clusterError and web/README.md) bounds the error
// instead by what the last decoded level did: `detailSafety` x decay x the detail of the
// cluster's newest vertices (measured in WebAssembly), under the longest edge. On the
// dragon it saves bytes only where it draws differently from full resolution (measured
// with bench/web_fidelity_bench.py), hence not the default.
//
// A cluster is refined while its error projected to pixels exceeds `targetPixels` (largest
// first, within `triangleBudget`), straight to the level where the error extrapolated with
// the level table (as for coarsening, below) meets the target, coarsened one level when the
// error of the coarser level is below `coarsenFraction * targetPixels`, and sent back to
// the base clustered level when it leaves the view frustum. The decoder then completes
// the level map (neighbouring clusters at most one level apart: no cracks), so a request
// converges in (finest - base) steps; call again after each decode until it is stable.
//
// What the camera cannot see is not refined, and is coarsened one level per step:
//  - back-facing clusters (`backface`): every face of the cluster turns away from the eye.
//    The normal cone (axis and width, per cluster, from the current mesh) is widened by
//    `backfaceMargin` radians for the finer levels' detail, and the cluster's bounding
//    sphere (at least one error proxy wide) stands for its positions. Only right for closed
//    surfaces whose faces point outwards, so it is off by default; the viewer draws both
//    sides of every face.
//  - occluded clusters (`occlusion`): the current mesh is rasterized into a small depth
//    buffer (`occlusionWidth` pixels wide), each pixel keeping the nearest triangle's
//    farthest corner plus its longest edge (a finer surface stays within about one edge of
//    a coarser one); a cluster whose box (grown by its error proxy) lies behind every pixel
//    of its screen rectangle is hidden. This keeps the body behind a close-up coarse.

/** Floats per cluster in `clusterBounds` (pw_cluster_bounds in web/src/pomar_web.cpp):
 *  box min xyz, max xyz, longest edge, faces, normal cone axis xyz, cosine of its width,
 *  detail of its newest vertices, how many they are (0: no detail measured). */
export const BOUNDS_STRIDE = 14;

/** The per-level decay of the measured detail, from what the client has seen: for every
 *  cluster measured at two or more levels above the base clustered level (`detailSeen`:
 *  cluster -> [[level, detail], ...], levels rising), (last / first)^(1 / levels between); the median
 *  over those clusters, within [0.5, 1]; 1 (no decay: the conservative guess) while fewer
 *  than `minClusters` clusters have two measurements. */
export function detailDecay(detailSeen, minClusters = 16) {
  const ratios = [];
  for (const seen of detailSeen.values()) {
    if (seen.length < 2) continue;
    const [l0, d0] = seen[0];
    const [l1, d1] = seen[seen.length - 1];
    if (d0 > 0 && d1 > 0 && l1 > l0) ratios.push(Math.pow(d1 / d0, 1 / (l1 - l0)));
  }
  if (ratios.length < minClusters) return 1;
  ratios.sort((a, b) => a - b);
  return Math.min(1, Math.max(0.5, ratios[ratios.length >> 1]));
}

/** The error bound of cluster c at its current level `l` used to refine it:
 *  - 'edge': the longest edge (b[6]);
 *  - 'measured': `detailSafety` x decay x the detail of its newest vertices (b[12], measured
 *    in WebAssembly: how far the last level's vertex splits moved the surface off the
 *    coarser one; the level after them is expected to move it by `decay` times that),
 *    never above the longest edge; the edge alone where no detail was measured (no
 *    vertex of the cluster has a defined plane, b[13] = 0) or where the detail exceeds
 *    `maxTilt` x the edge (facets that would tilt by more than that). At the base
 *    clustered level the detail is the offset of the cluster's one vertex. */
export function clusterError(b, c, l, { finest, errorModel, detailSafety = 1, decay = 1, maxTilt = Infinity }) {
  const S = BOUNDS_STRIDE;
  if (l >= finest) return 0;
  const edge = b[S * c + 6];
  if (errorModel !== 'measured' || !(b[S * c + 13] > 0)) return edge;
  if (b[S * c + 12] > maxTilt * edge) return edge;
  return Math.min(edge, detailSafety * decay * b[S * c + 12]);
}

/** The six planes of the clip volume of `viewProj` (column-major 4x4, clip = viewProj *
 *  [x,y,z,1]; -w <= x,y,z <= w), 4 coefficients each, computed once per view. */
function frustumPlanes(viewProj) {
  const m = viewProj;
  const planes = new Float64Array(24);
  let k = 0;
  for (let axis = 0; axis < 3; ++axis)
    for (const sign of [1, -1])
      for (let col = 0; col < 4; ++col) planes[k++] = m[4 * col + 3] + sign * m[4 * col + axis];
  return planes;
}

/** Does the box [lo, hi] lie entirely outside one of the `planes` (frustumPlanes)? */
function outsideFrustum(planes, lo, hi) {
  for (let k = 0; k < 24; k += 4) {
    // The box corner furthest along the plane normal.
    const x = planes[k] >= 0 ? hi[0] : lo[0];
    const y = planes[k + 1] >= 0 ? hi[1] : lo[1];
    const z = planes[k + 2] >= 0 ? hi[2] : lo[2];
    if (planes[k] * x + planes[k + 1] * y + planes[k + 2] * z + planes[k + 3] < 0) return true;
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

/** Screen position (pixels, y down) and depth w of the points `xyz` (flat) for `view`;
 *  w < near: in front of the near plane or behind the eye. */
function project(view, xyz, width, height) {
  const m = view.viewProj;
  const n = xyz.length / 3;
  const out = new Float32Array(3 * n);
  for (let i = 0; i < n; ++i) {
    const x = xyz[3 * i];
    const y = xyz[3 * i + 1];
    const z = xyz[3 * i + 2];
    const w = m[3] * x + m[7] * y + m[11] * z + m[15];
    const cx = m[0] * x + m[4] * y + m[8] * z + m[12];
    const cy = m[1] * x + m[5] * y + m[9] * z + m[13];
    out[3 * i] = (cx / w * 0.5 + 0.5) * width;
    out[3 * i + 1] = (0.5 - cy / w * 0.5) * height;
    out[3 * i + 2] = w;
  }
  return out;
}

/** A conservative depth buffer of `mesh` for `view`: per pixel, the smallest over the
 *  triangles covering its centre of (farthest corner depth + longest edge); Infinity where
 *  nothing is drawn. Triangles crossing the near plane are left out. */
export function occlusionBuffer(mesh, view, width) {
  const height = Math.max(1, Math.round(width * view.height / (view.width || view.height)));
  const depth = new Float32Array(width * height).fill(Infinity);
  const p = mesh.positions;
  const t = mesh.triangles;
  const s = project(view, p, width, height);
  for (let f = 0; f < t.length; f += 3) {
    const a = 3 * t[f];
    const b = 3 * t[f + 1];
    const c = 3 * t[f + 2];
    const wa = s[a + 2];
    const wb = s[b + 2];
    const wc = s[c + 2];
    if (wa < view.near || wb < view.near || wc < view.near) continue;
    const x0 = Math.max(0, Math.ceil(Math.min(s[a], s[b], s[c]) - 0.5));
    const x1 = Math.min(width - 1, Math.floor(Math.max(s[a], s[b], s[c]) - 0.5));
    const y0 = Math.max(0, Math.ceil(Math.min(s[a + 1], s[b + 1], s[c + 1]) - 0.5));
    const y1 = Math.min(height - 1, Math.floor(Math.max(s[a + 1], s[b + 1], s[c + 1]) - 0.5));
    if (x0 > x1 || y0 > y1) continue;
    const edge = Math.max(Math.hypot(p[a] - p[b], p[a + 1] - p[b + 1], p[a + 2] - p[b + 2]),
      Math.hypot(p[b] - p[c], p[b + 1] - p[c + 1], p[b + 2] - p[c + 2]),
      Math.hypot(p[c] - p[a], p[c + 1] - p[a + 1], p[c + 2] - p[a + 2]));
    const d = Math.max(wa, wb, wc) + edge;
    // Edge functions; the sign of the area makes the test independent of the winding.
    const area = (s[b] - s[a]) * (s[c + 1] - s[a + 1]) - (s[b + 1] - s[a + 1]) * (s[c] - s[a]);
    if (area === 0) continue;
    const sign = area > 0 ? 1 : -1;
    for (let y = y0; y <= y1; ++y) {
      const py = y + 0.5;
      for (let x = x0; x <= x1; ++x) {
        const px = x + 0.5;
        const e0 = ((s[b] - s[a]) * (py - s[a + 1]) - (s[b + 1] - s[a + 1]) * (px - s[a])) * sign;
        const e1 = ((s[c] - s[b]) * (py - s[b + 1]) - (s[c + 1] - s[b + 1]) * (px - s[b])) * sign;
        const e2 = ((s[a] - s[c]) * (py - s[c + 1]) - (s[a + 1] - s[c + 1]) * (px - s[c])) * sign;
        if (e0 >= 0 && e1 >= 0 && e2 >= 0 && d < depth[y * width + x]) depth[y * width + x] = d;
      }
    }
  }
  return { width, height, depth };
}

/** Is the box [lo, hi] behind the depth buffer everywhere it could appear? */
function occluded(buffer, view, lo, hi) {
  const m = view.viewProj;
  let nearest = Infinity;
  let x0 = Infinity;
  let x1 = -Infinity;
  let y0 = Infinity;
  let y1 = -Infinity;
  for (let k = 0; k < 8; ++k) {
    // The corner's screen position in the buffer's pixels (y down) and depth w, as project().
    const x = k & 1 ? hi[0] : lo[0];
    const y = k & 2 ? hi[1] : lo[1];
    const z = k & 4 ? hi[2] : lo[2];
    const w = m[3] * x + m[7] * y + m[11] * z + m[15];
    if (w < view.near) return false;
    const sx = ((m[0] * x + m[4] * y + m[8] * z + m[12]) / w * 0.5 + 0.5) * buffer.width;
    const sy = (0.5 - (m[1] * x + m[5] * y + m[9] * z + m[13]) / w * 0.5) * buffer.height;
    nearest = Math.min(nearest, w);
    x0 = Math.min(x0, sx);
    x1 = Math.max(x1, sx);
    y0 = Math.min(y0, sy);
    y1 = Math.max(y1, sy);
  }
  // Every pixel the box may touch, one more on each side.
  const i0 = Math.max(0, Math.floor(x0) - 1);
  const i1 = Math.min(buffer.width - 1, Math.floor(x1) + 1);
  const j0 = Math.max(0, Math.floor(y0) - 1);
  const j1 = Math.min(buffer.height - 1, Math.floor(y1) + 1);
  if (i0 > i1 || j0 > j1) return false;
  for (let j = j0; j <= j1; ++j)
    for (let i = i0; i <= i1; ++i) if (!(buffer.depth[j * buffer.width + i] < nearest)) return false;
  return true;
}

/** Do all faces of the cluster (normal cone `axis`, `cosWidth`; bounding sphere `centre`,
 *  `radius`) turn away from `eye`, with `margin` radians to spare? */
function backFacing(eye, centre, radius, axis, cosWidth, margin) {
  if (cosWidth <= -1) return false;
  const d = [centre[0] - eye[0], centre[1] - eye[1], centre[2] - eye[2]];
  const distance = Math.hypot(d[0], d[1], d[2]);
  if (distance <= radius) return false;
  const cosAngle = (d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2]) / distance;
  const angle = Math.acos(Math.max(-1, Math.min(1, cosAngle)));
  return angle + Math.acos(Math.min(1, cosWidth)) + margin + Math.asin(radius / distance) < Math.PI / 2;
}

/** What both error models start from: the face count of a level, the pixels per unit of
 *  distance, the occlusion buffer of the current mesh (or null) and a copy of the levels. */
function viewFrame(state, view, occlusion, occlusionWidth) {
  const { info } = state;
  return {
    faces: (l) => (l === 0 ? info.baseFaces : info.levels[l - 1].faces),
    pixelsPerUnit: view.height / (2 * Math.tan(view.fovY / 2)),
    buffer: occlusion && state.mesh && view.width ? occlusionBuffer(state.mesh, view, occlusionWidth) : null,
    wanted: Int32Array.from(state.levels),
    planes: frustumPlanes(view.viewProj),
  };
}

/**
 * @param state {info, levels (Int32Array, current level per cluster), clusterBounds
 *   (Float32Array, BOUNDS_STRIDE per cluster), errorSeen (Map "c:l" -> error, updated
 *   here), mesh (positions, triangles: the occluders; optional)}
 * @param view {eye [3], viewProj (16, column-major), fovY (radians), height, width (pixels),
 *   near}
 * @returns {levels: Int32Array wanted, changed: boolean, refine, coarsen, hidden (clusters
 *   above the base level outside the frustum), culled (back-facing or occluded)}
 */
export function chooseLevels(state, view, {
  targetPixels = 3, coarsenFraction = 0.5, triangleBudget = 2e6, backface = false, backfaceMargin = 0.3,
  occlusion = true, occlusionWidth = 128, errorModel = 'auto', detailSafety = 1, maxTilt = Infinity,
  maxEdgePixels = 8, facingScale = 1, contourScale = 1, facingEdgeScale = 1, contourEdgeScale = 1,
} = {}) {
  const { info, levels, clusterBounds: b, errorSeen } = state;
  const S = BOUNDS_STRIDE;
  const n = info.clusters;
  const base = info.baseLevel;
  const finest = info.finestLevel;
  const stored = info.clusterErrors;
  if (errorModel === 'auto') errorModel = stored ? 'stored' : 'edge';
  if (errorModel === 'stored' && !stored) errorModel = 'edge';
  if (errorModel === 'stored') {
    return chooseStored(state, view, { targetPixels, coarsenFraction, triangleBudget, occlusion, occlusionWidth,
      maxEdgePixels, facingScale, contourScale, facingEdgeScale, contourEdgeScale, backface, backfaceMargin });
  }
  // The detail measured per cluster and level, kept for the decay (state.detailSeen, made
  // here when the caller keeps none).
  const detailSeen = state.detailSeen ?? (state.detailSeen = new Map());
  for (let c = 0; c < n; ++c) {
    const level = levels[c];
    if (level <= base || level >= finest || !(b[S * c + 13] > 0)) continue;
    const seen = detailSeen.get(c) ?? [];
    if (!seen.length || seen[seen.length - 1][0] < level) seen.push([level, b[S * c + 12]]);
    else if (seen[seen.length - 1][0] === level) seen[seen.length - 1][1] = b[S * c + 12];
    detailSeen.set(c, seen);
  }
  const model = { finest, base, errorModel, detailSafety, maxTilt, decay: detailDecay(detailSeen) };
  const { faces, pixelsPerUnit, buffer, wanted, planes } = viewFrame(state, view, occlusion, occlusionWidth);
  let triangles = 0;
  for (let c = 0; c < n; ++c) triangles += b[S * c + 7];
  const candidates = [];
  let coarsen = 0;
  let hidden = 0;
  let culled = 0;
  for (let c = 0; c < n; ++c) {
    const l = levels[c];
    const lo = [b[S * c], b[S * c + 1], b[S * c + 2]];
    const hi = [b[S * c + 3], b[S * c + 4], b[S * c + 5]];
    const error = clusterError(b, c, l, model);
    errorSeen.set(`${c}:${l}`, error);
    if (outsideFrustum(planes, lo, hi)) {
      if (l > base) ++hidden;
      wanted[c] = base;
      continue;
    }
    // Hidden from the eye: not refined, coarsened one level per step. The box grows by the
    // error proxy: a coarse cluster (one vertex at the base level) stands for more surface.
    const grow = b[S * c + 6];
    const centre = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
    const radius = Math.max(grow, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2);
    if ((backface && backFacing(view.eye, centre, radius, [b[S * c + 8], b[S * c + 9], b[S * c + 10]], b[S * c + 11],
      backfaceMargin)) || (buffer && occluded(buffer, view, lo.map((x) => x - grow), hi.map((x) => x + grow)))) {
      ++culled;
      if (l > base) {
        wanted[c] = l - 1;
        ++coarsen;
      }
      continue;
    }
    const toPixels = pixelsPerUnit / Math.max(view.near, distanceToBox(view.eye, lo, hi));
    if (l < finest && error * toPixels > targetPixels) {
      candidates.push({ c, pixels: error * toPixels });
    } else if (l > base) {
      // Never seen at l - 1: at the finest level, the longest edge scaled (or, measured,
      // the detail the finest level added); otherwise the current error scaled.
      let coarser = errorSeen.get(`${c}:${l - 1}`);
      if (coarser === undefined) {
        coarser = (l >= finest ? b[S * c + 6] : error) * Math.sqrt(faces(l) / faces(l - 1));
        if (l >= finest && errorModel === 'measured' && b[S * c + 13] > 0)
          coarser = Math.min(coarser, detailSafety * b[S * c + 12]);
      }
      if (coarser * toPixels < coarsenFraction * targetPixels) {
        wanted[c] = l - 1;
        ++coarsen;
      }
    }
  }
  // Largest projected error first, while the estimated triangle count fits the budget.
  // A cluster goes at once to the level whose error, extrapolated from the current one with
  // the level table's face counts, is under the target (all its bytes in one request, not
  // one level per step); the next step measures it again and goes on if that fell short.
  candidates.sort((x, y) => y.pixels - x.pixels);
  let refine = 0;
  for (const { c, pixels } of candidates) {
    const l = levels[c];
    let to = l + 1;
    while (to < finest && pixels * Math.sqrt(faces(l) / faces(to)) > targetPixels) ++to;
    const more = (level) => b[S * c + 7] * (faces(level) / faces(l) - 1);
    while (to > l + 1 && triangles + more(to) > triangleBudget) --to; // as far as the budget goes
    if (triangles + more(to) > triangleBudget) break;
    triangles += more(to);
    wanted[c] = to;
    ++refine;
  }
  const changed = refine > 0 || coarsen > 0 || hidden > 0;
  return { levels: wanted, changed, refine, coarsen, hidden, culled };
}

/** The stored error bound of cluster c at level l (info.clusterErrors, section CERR). */
export function storedError(info, c, l) {
  if (l >= info.finestLevel) return 0;
  return info.clusterErrors[(Math.max(l, info.baseLevel) - info.baseLevel) * info.clusters + c];
}

/** How much more error than the target cluster c tolerates from `eye` (it divides its
 *  projected error and facet size): `facingScale` where its normal cone's axis points at the
 *  eye, `contourScale` where the axis is square to the line of sight (a contour), in between
 *  by the sine of the angle between them. A normal displacement shows on screen by that sine,
 *  and a flat facet's tilt changes its brightness (the headlight's |n.l|) by it too. 1 for a
 *  cluster without an axis. */
export function viewScale(eye, b, c, facingScale, contourScale) {
  if (facingScale === contourScale) return facingScale;
  const S = BOUNDS_STRIDE;
  const ax = b[S * c + 8];
  const ay = b[S * c + 9];
  const az = b[S * c + 10];
  if (!(b[S * c + 11] > -1) || !(ax * ax + ay * ay + az * az > 0.5)) return 1;
  const dx = (b[S * c] + b[S * c + 3]) / 2 - eye[0];
  const dy = (b[S * c + 1] + b[S * c + 4]) / 2 - eye[1];
  const dz = (b[S * c + 2] + b[S * c + 5]) / 2 - eye[2];
  const d = Math.hypot(dx, dy, dz);
  if (!(d > 0)) return 1;
  const cos = Math.min(1, Math.abs(ax * dx + ay * dy + az * dz) / d);
  const sin = Math.sqrt(1 - cos * cos);
  return facingScale + (contourScale - facingScale) * sin;
}

/** chooseLevels with the file's stored errors (errorModel 'stored'): every level's error is
 *  known, so each cluster in view goes straight to the coarsest level whose error, projected
 *  at the distance to its box (grown by its error at the current level), is within the
 *  target and whose longest edge (the current one, extrapolated with the level table's face
 *  counts) is within `maxEdgePixels`, and coarsens straight to the coarsest under
 *  `coarsenFraction` of both; outside the frustum: the base level; occluded or (with
 *  `backface`) back-facing, its box grown by its stored error: one level coarser per step. */
function chooseStored(state, view, { targetPixels, coarsenFraction, triangleBudget, occlusion, occlusionWidth,
  maxEdgePixels, facingScale, contourScale, facingEdgeScale, contourEdgeScale, backface, backfaceMargin }) {
  const { info, levels, clusterBounds: b } = state;
  const S = BOUNDS_STRIDE;
  const n = info.clusters;
  const base = info.baseLevel;
  const finest = info.finestLevel;
  const { faces, pixelsPerUnit, buffer, wanted, planes } = viewFrame(state, view, occlusion, occlusionWidth);
  let triangles = 0;
  for (let c = 0; c < n; ++c) triangles += b[S * c + 7];
  const candidates = [];
  let coarsen = 0;
  let hidden = 0;
  let culled = 0;
  for (let c = 0; c < n; ++c) {
    const l = levels[c];
    const grow = storedError(info, c, l);
    const lo = [b[S * c] - grow, b[S * c + 1] - grow, b[S * c + 2] - grow];
    const hi = [b[S * c + 3] + grow, b[S * c + 4] + grow, b[S * c + 5] + grow];
    if (outsideFrustum(planes, lo, hi)) {
      if (l > base) ++hidden;
      wanted[c] = base;
      continue;
    }
    const centre = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
    const radius = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2;
    if ((backface && backFacing(view.eye, centre, radius, [b[S * c + 8], b[S * c + 9], b[S * c + 10]], b[S * c + 11],
      backfaceMargin)) || (buffer && occluded(buffer, view, lo, hi))) {
      ++culled;
      if (l > base) {
        wanted[c] = l - 1;
        ++coarsen;
      }
      continue;
    }
    const projected = pixelsPerUnit / Math.max(view.near, distanceToBox(view.eye, lo, hi));
    const toPixels = projected / viewScale(view.eye, b, c, facingScale, contourScale);
    // The facets' size on screen (maxEdgePixels): the longest edge of the current level,
    // extrapolated to level k with the level table's face counts.
    const edgeToPixels = projected / viewScale(view.eye, b, c, facingEdgeScale, contourEdgeScale);
    const edgePixels = (k) => b[S * c + 6] * edgeToPixels * Math.sqrt(faces(l) / faces(k));
    let to = base;
    while (to < finest && (storedError(info, c, to) * toPixels > targetPixels || edgePixels(to) > maxEdgePixels)) ++to;
    if (to > l) {
      candidates.push({ c, to, pixels: storedError(info, c, l) * toPixels });
    } else if (to < l) {
      let down = l;
      while (down > base && storedError(info, c, down - 1) * toPixels < coarsenFraction * targetPixels &&
        edgePixels(down - 1) < coarsenFraction * maxEdgePixels) --down;
      if (down < l) {
        wanted[c] = down;
        ++coarsen;
      }
    }
  }
  candidates.sort((x, y) => y.pixels - x.pixels);
  let refine = 0;
  for (const { c, to } of candidates) {
    const l = levels[c];
    const more = (level) => b[S * c + 7] * (faces(level) / faces(l) - 1);
    let level = to;
    while (level > l + 1 && triangles + more(level) > triangleBudget) --level;
    if (triangles + more(level) > triangleBudget) break;
    triangles += more(level);
    wanted[c] = level;
    ++refine;
  }
  const changed = refine > 0 || coarsen > 0 || hidden > 0;
  return { levels: wanted, changed, refine, coarsen, hidden, culled };
}

export function sameLevels(a, b) {
  return !!a && !!b && a.length === b.length && a.every((l, i) => l === b[i]);
}

/** Damps a view's refinement until it converges. For one camera, it remembers the last
 *  level maps the model had: a cluster that the choice would send back to a level it had
 *  there, or past it, keeps its current level (a cluster occluded only at its finer level,
 *  or coarsened on an extrapolated error it does not meet, would flip back and forth, and
 *  clusters flipping out of phase keep the whole map from ever repeating); so does a
 *  cluster asked again at a level it was asked at and did not get (the level map rule
 *  keeps it above: asking again changes nothing). `forget()` after any other request. */
export class Convergence {
  constructor(depth = 4) {
    this.depth = depth;
    this.forget();
    this.viewProj = null;
  }
  forget() {
    this.history = [];
    this.lastAsked = null;
    this.refused = null; // per cluster, a level asked and not given (-1: none)
  }
  /** The level map to ask for `view` given chooseLevels' `choice` and the `current` levels,
   *  or null when there is nothing new to ask (converged). */
  next(choice, current, view) {
    if (!sameLevels(view.viewProj, this.viewProj)) this.forget();
    if (!this.refused || this.refused.length !== current.length) this.refused = new Int32Array(current.length).fill(-1);
    this.viewProj = Array.from(view.viewProj);
    const wanted = Int32Array.from(choice);
    if (this.lastAsked)
      for (let c = 0; c < wanted.length; ++c) if (this.lastAsked[c] !== current[c]) this.refused[c] = this.lastAsked[c];
    for (let c = 0; c < wanted.length; ++c) {
      const w = wanted[c];
      const l = current[c];
      if (w === l) continue;
      // Back to a level it had, or past it (21 -> 22 -> 23, then 17: a cluster refined on
      // facets extrapolated from one level's longest edge and coarsened on another's).
      if (this.history.some((h) => (w < l ? h[c] < l && w <= h[c] : h[c] > l && w >= h[c]))) wanted[c] = l;
      // Asked before and not given: the level map rule keeps it there (a raised neighbour).
      else if (this.refused[c] === w) wanted[c] = l;
    }
    this.history = [Int32Array.from(current), ...this.history].slice(0, this.depth);
    // The same map again: the level map rule keeps some clusters above what the view wants.
    if (sameLevels(wanted, this.lastAsked) || sameLevels(wanted, current)) return null;
    this.lastAsked = wanted;
    return wanted;
  }
}
