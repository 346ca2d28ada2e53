// The orbit camera of the viewer as plain math (no WebGL): used by the page (viewer.js),
// its scripted test (test/page_test.js) and the Node bench (bench/web_view_bench.mjs), so
// that all three look at a model the same way.

export function perspective(fovY, aspect, near, far) {
  const f = 1 / Math.tan(fovY / 2);
  const nf = 1 / (near - far);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
}

export function lookAt(eye, target, up) {
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const norm = (a) => { const l = Math.hypot(...a) || 1; return a.map((x) => x / l); };
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const z = norm(sub(eye, target));
  const x = norm(cross(up, z));
  const y = cross(z, x);
  return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
}

/** a * b, column-major 4x4. */
export function multiply(a, b) {
  const out = new Array(16).fill(0);
  for (let c = 0; c < 4; ++c)
    for (let r = 0; r < 4; ++r)
      for (let k = 0; k < 4; ++k) out[4 * c + r] += a[4 * k + r] * b[4 * c + k];
  return out;
}

/** A camera orbiting `target` at `distance`, framing a model of size `extent`, around the
 *  up axis `up` ('y' or 'z'): yaw turns around it, pitch lifts the eye towards it. */
export function orbitCamera() {
  return { target: [0, 0, 0], distance: 1, yaw: 0.6, pitch: 0.3, fovY: Math.PI / 4, extent: 1, up: 'y' };
}

/** The orbit is computed in a Y-up frame; with up 'z' that frame is turned by 90 degrees
 *  around X (its Y becomes the model's +Z, its front +Z the model's -Y: a Z-up model is
 *  seen from its -Y side, as Z-up tools call the front). */
export function toModel(c, v) {
  return c.up === 'z' ? [v[0], -v[2], v[1]] : v;
}

/** The camera's up vector in model coordinates. */
export function upVector(c) {
  return toModel(c, [0, 1, 0]);
}

/** The up axis `auto` picks for a box of extents [dx, dy, dz]: 'z' when Z is the longest
 *  extent and at least UP_Z_RATIO x the Y extent (a standing scan stored Z-up: its height
 *  is along Z), else 'y' (the default of most mesh files). A box cannot tell more: a flat
 *  or wide Z-up model (a relief, a car) stays Y-up and needs the menu. */
export const UP_Z_RATIO = 1.2;
export function autoUp(extents) {
  const [dx, dy, dz] = extents;
  return dz >= dx && dz >= UP_Z_RATIO * dy ? 'z' : 'y';
}

/** Extents [dx, dy, dz] of the box of `positions` (xyz). */
export function extentsOf(positions) {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; ++i) {
    lo[i % 3] = Math.min(lo[i % 3], positions[i]);
    hi[i % 3] = Math.max(hi[i % 3], positions[i]);
  }
  return [0, 1, 2].map((k) => (hi[k] > lo[k] ? hi[k] - lo[k] : 0));
}

/** Frame the mesh (positions, xyz): target its box centre, from 1.6 x its size (divided by
 *  `aspect`, width / height, on a portrait screen: the model's width fits too). */
export function frameMesh(camera, positions, aspect = 1) {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; ++i) {
    lo[i % 3] = Math.min(lo[i % 3], positions[i]);
    hi[i % 3] = Math.max(hi[i % 3], positions[i]);
  }
  camera.target = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
  camera.extent = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  camera.distance = (1.6 * camera.extent) / Math.min(1, aspect);
}

export function eyeOf(c) {
  const offset = toModel(c, [Math.cos(c.pitch) * Math.sin(c.yaw), Math.sin(c.pitch), Math.cos(c.pitch) * Math.cos(c.yaw)]);
  return c.target.map((t, k) => t + c.distance * offset[k]);
}

/** Move the target by (dx, dy) in the camera's screen plane (right, up), in model units. */
export function pan(c, dx, dy) {
  const right = toModel(c, [Math.cos(c.yaw), 0, -Math.sin(c.yaw)]);
  const up = toModel(c, [-Math.sin(c.pitch) * Math.sin(c.yaw), Math.cos(c.pitch), -Math.sin(c.pitch) * Math.cos(c.yaw)]);
  c.target = c.target.map((t, k) => t + dx * right[k] + dy * up[k]);
}

/** The view of view_refine.js / PomarModel.wantView for a `width` x `height` viewport. */
export function viewOf(c, width, height) {
  const eye = eyeOf(c);
  const near = Math.max(c.distance * 0.01, c.extent * 1e-4);
  const far = c.distance + 4 * c.extent;
  const viewProj = multiply(perspective(c.fovY, width / height, near, far), lookAt(eye, c.target, upVector(c)));
  return { eye, viewProj, fovY: c.fovY, height, width, near, far };
}

/** A close-up: target the vertex furthest towards the eye (a surface point facing the
 *  camera) and come within `fraction` x the model's size of it. */
export function closeUp(c, positions, fraction) {
  const eye = eyeOf(c);
  const dir = [0, 1, 2].map((k) => eye[k] - c.target[k]);
  let best = 0;
  let bestDot = -Infinity;
  for (let i = 0; i < positions.length / 3; ++i) {
    let d = 0;
    for (let k = 0; k < 3; ++k) d += (positions[3 * i + k] - c.target[k]) * dir[k];
    if (d > bestDot) { bestDot = d; best = i; }
  }
  c.target = [positions[3 * best], positions[3 * best + 1], positions[3 * best + 2]];
  c.distance = fraction * c.extent;
}
