// The pomar web viewer: three.js (WebGL2; web/dist/three.module.js, vendored from npm by
// web/build.sh), orbit camera, view-dependent refinement through pomar.js.
// URL parameters: ?file=URL opens a file, &target=PX sets the target error, &refine=0 starts
// with refinement off (the base clustered mesh only), &error=measured&safety=K the measured
// error model (view_refine.js); &test=1 runs the scripted browser test
// (web/test/browser_test.py) and reports to the test server; &test=fidelity the pixel
// comparison of bench/web_fidelity_bench.py (web/test/fidelity_page.js).
import { open } from './pomar.js';
import { autoUp, extentsOf, frameMesh, orbitCamera, pan, upVector, viewOf } from './camera.js';
import * as THREE from './dist/three.module.js';

const $ = (id) => document.getElementById(id);
const canvas = $('view');
const params = new URLSearchParams(location.search);

// ------------------------------------------------------------------ renderer
// One three.js mesh drawn with a small shader: flat shading from screen-space derivatives
// (the decoded mesh has no normals), a headlight, and the colour of the material chosen in
// the colour menu (MATERIALS below). &shading=smooth shades with vertex normals instead
// (area-weighted face normals, computed at each upload), e.g. to compare refinement
// policies (bench/web_fidelity_bench.py --shading smooth).
const VS = `precision highp float;
in vec3 position;
in float cluster;
in float level;
in vec3 normal;
in vec3 rgb;
uniform mat4 projectionMatrix;
uniform mat4 modelViewMatrix;
uniform int colourMode;
uniform float finest;
uniform float base;
out vec3 vPosition;
out vec3 vNormal;
out vec3 vRgb;
flat out vec3 vColour;
vec3 hue(float h) { return clamp(abs(mod(h * 6.0 + vec3(0, 4, 2), 6.0) - 3.0) - 1.0, 0.0, 1.0); }
void main() {
  vPosition = position;
  vNormal = normal;
  vRgb = rgb;
  if (colourMode == 1) vColour = 0.35 + 0.65 * hue(fract(cluster * 0.61803));
  else if (colourMode == 2) vColour = 0.3 + 0.7 * hue(0.66 * (1.0 - (level - base) / max(1.0, finest - base)));
  else vColour = vec3(0.82, 0.80, 0.76);
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}`;
const FS = `precision highp float;
in vec3 vPosition;
in vec3 vNormal;
in vec3 vRgb;
flat in vec3 vColour;
uniform vec3 eye;
uniform highp int colourMode; // highp: the vertex shader's int precision (shared uniform)
uniform int smoothShading;
out vec4 colour;
void main() {
  vec3 n = smoothShading == 1 && dot(vNormal, vNormal) > 0.0 ? normalize(vNormal)
                                                             : normalize(cross(dFdx(vPosition), dFdy(vPosition)));
  vec3 l = normalize(eye - vPosition);
  float d = abs(dot(n, l));
  // Own colours (mode 3) are interpolated across the face and lit like the others.
  colour = vec4((colourMode == 3 ? vRgb : vColour) * (0.25 + 0.75 * d), 1.0);
}`;

const smoothShading = params.get('shading') === 'smooth';
/** Per vertex, the sum of the normals of its faces, each as long as twice its area. */
function vertexNormals(p, t) {
  const n = new Float32Array(p.length);
  for (let f = 0; f < t.length; f += 3) {
    const a = 3 * t[f];
    const b = 3 * t[f + 1];
    const c = 3 * t[f + 2];
    const u = [p[b] - p[a], p[b + 1] - p[a + 1], p[b + 2] - p[a + 2]];
    const w = [p[c] - p[a], p[c + 1] - p[a + 1], p[c + 2] - p[a + 2]];
    const x = u[1] * w[2] - u[2] * w[1];
    const y = u[2] * w[0] - u[0] * w[2];
    const z = u[0] * w[1] - u[1] * w[0];
    for (const v of [a, b, c]) {
      n[v] += x;
      n[v + 1] += y;
      n[v + 2] += z;
    }
  }
  return n;
}

// ------------------------------------------------------------------ materials
// The colour menu. Each material is a colour mode of the shader (`mode`), the test of
// whether it applies to a mesh (`available`, default: always) and the vertex attributes it
// needs beside the positions (`attributes(mesh, model)`: name -> THREE.BufferAttribute,
// built from the same decoded mesh at every upload, so they always match the geometry).
// The first available one is chosen when a file opens: the file's own colours when it has
// them. A texture is one more entry of this list: available when the mesh has a
// "texcoord" attribute and texture files, its attributes the UVs, plus a sampler uniform
// and a mode of the shader.
const MATERIALS = [
  { id: 'own', label: 'own colours', mode: 3, available: (mesh) => !!mesh.colour,
    attributes: (mesh) => ({ rgb: new THREE.BufferAttribute(mesh.colour.values, mesh.colour.components, true) }) },
  { id: 'plain', label: 'plain', mode: 0 },
  { id: 'clusters', label: 'clusters', mode: 1,
    attributes: (mesh) => ({ cluster: new THREE.BufferAttribute(Float32Array.from(mesh.vertexCluster), 1) }) },
  { id: 'levels', label: 'levels', mode: 2, attributes: (mesh, model) => {
    // Colour by level: the level of the vertex's cluster (the level map), not the level
    // that created the vertex (which mixes all levels up to it in every region).
    const levels = model ? model.levels : null;
    const level = new Float32Array(mesh.vertexCluster.length);
    for (let v = 0; v < level.length; ++v) level[v] = levels && levels.length ? levels[mesh.vertexCluster[v]] : mesh.vertexLevel[v];
    return { level: new THREE.BufferAttribute(level, 1) };
  } },
];
const usable = (material, mesh) => !material.available || material.available(mesh);
let drawnMesh = { positions: new Float32Array(0), vertexCluster: new Uint32Array(0), colour: null };
/** The material of the colour menu, or the plain one if it does not apply to the mesh. */
function material() {
  const chosen = MATERIALS.find((m) => m.id === $('colour').value);
  return chosen && usable(chosen, drawnMesh) ? chosen : MATERIALS.find((m) => m.id === 'plain');
}
function initMaterials() {
  $('colour').replaceChildren(...MATERIALS.map((m) => new Option(m.label, m.id)));
  $('colour').value = 'plain';
}
/** Enable the materials that apply to `mesh`; with `chooseDefault`, select the first. */
function offerMaterials(mesh, chooseDefault) {
  for (const option of $('colour').options) option.disabled = !usable(MATERIALS.find((m) => m.id === option.value), mesh);
  if (chooseDefault) $('colour').value = MATERIALS.find((m) => usable(m, mesh)).id;
}

let renderer = null;
let scene = null;
let shown = null; // the THREE.Mesh
const camera3 = new THREE.PerspectiveCamera();
function initGL() {
  THREE.ColorManagement.enabled = false; // colours as given, no sRGB conversions
  renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setClearColor(new THREE.Color(0x20242a), 1);
  scene = new THREE.Scene();
  const material = new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3, vertexShader: VS, fragmentShader: FS, side: THREE.DoubleSide,
    uniforms: { colourMode: { value: 0 }, finest: { value: 1 }, base: { value: 0 }, eye: { value: new THREE.Vector3() },
      smoothShading: { value: smoothShading ? 1 : 0 } },
  });
  shown = new THREE.Mesh(new THREE.BufferGeometry(), material);
  shown.frustumCulled = false; // the geometry changes with every decode
  scene.add(shown);
}
function upload(mesh, model) {
  // Every decoded state (open, refinement of a region or of everything, coarsening, a
  // rebuilt decoder) arrives here: the attributes of all the materials that apply are
  // built from this one mesh, so switching materials needs no upload and no buffer lags
  // behind the geometry.
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(mesh.positions, 3));
  for (const m of MATERIALS) {
    if (!m.attributes || !usable(m, mesh)) continue;
    for (const [name, attribute] of Object.entries(m.attributes(mesh, model))) g.setAttribute(name, attribute);
  }
  if (smoothShading) g.setAttribute('normal', new THREE.BufferAttribute(vertexNormals(mesh.positions, mesh.triangles), 3));
  g.setIndex(new THREE.BufferAttribute(mesh.triangles, 1));
  shown.geometry.dispose();
  shown.geometry = g;
  drawnMesh = mesh;
  offerMaterials(mesh, false);
}

// ------------------------------------------------------------------ camera
const camera = orbitCamera();
let cameraVersion = 0;
// The up axis: the menu's Y or Z, or `auto`: camera.js autoUp on the box of the base mesh
// (Z when Z is the longest extent and 1.2 x the Y extent or more). The orbit turns around it.
let modelExtents = null;
function applyUp() {
  const auto = modelExtents ? autoUp(modelExtents) : 'y';
  camera.up = $('up').value === 'auto' ? auto : $('up').value;
  $('up').options[0].textContent = modelExtents ? `auto (${auto.toUpperCase()})` : 'auto';
}
// Pixels drawn per CSS pixel: the device's, at most 2 (a phone at 3 would draw 2.25x the
// pixels for little to see, and the target error is in drawn pixels).
const MAX_PIXEL_RATIO = 2;
function view() {
  const dpr = Math.min(window.devicePixelRatio || 1, MAX_PIXEL_RATIO);
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  return viewOf(camera, w, h);
}
function frame(model) {
  if (!renderer) return;
  const v = view();
  renderer.setSize(canvas.width, canvas.height, false);
  const c = camera3;
  c.fov = (v.fovY * 180) / Math.PI;
  c.aspect = v.width / v.height;
  c.near = v.near;
  c.far = v.far;
  c.position.set(...v.eye);
  c.up.set(...upVector(camera));
  c.lookAt(...camera.target);
  c.updateProjectionMatrix();
  const u = shown.material.uniforms;
  u.eye.value.set(...v.eye);
  u.colourMode.value = material().mode;
  u.finest.value = model ? model.info.finestLevel : 1;
  u.base.value = model ? model.info.baseLevel : 0;
  renderer.render(scene, c);
}

// ------------------------------------------------------------------ the model
let model = null;
let refining = false;
function showStats() {
  if (!model) return;
  const s = model.stats;
  const lv = model.levels.length ? [Math.min(...model.levels), Math.max(...model.levels)] : [0, 0];
  const kb = (b) => (b / 1024).toFixed(1) + ' KiB';
  $('stats').textContent =
    `fetched ${kb(s.bytesFetched)} of ${kb(s.fileBytes)} (${(100 * s.bytesFetched / s.fileBytes).toFixed(1)}%) in ${s.requests} requests\n` +
    `${s.triangles} triangles, ${s.vertices} vertices, levels ${lv[0]}..${lv[1]} of ${model.info.finestLevel} ` +
    `(base clustered ${model.info.baseLevel}), ${model.info.clusters} clusters\n` +
    `blocks held ${s.blocksHeld} (${kb(s.heldBytes)}), damaged ${s.damaged}, last decode ${(s.decodeMs || 0).toFixed(0)} ms`;
}
function onMesh(mesh, m = model) {
  upload(mesh, m);
  frame(model);
  showStats();
}
function showError(message) {
  $('error').textContent = message ? 'error: ' + message : '';
}

// &error=measured[&safety=K]: view_refine.js's measured error model (default: the edge).
const errorModel = params.get('error') === 'measured'
  ? { errorModel: 'measured', ...(params.get('safety') ? { detailSafety: Number(params.get('safety')) } : {}) } : {};

/** Refine/coarsen for the current view until the model is stable for it. */
async function refineLoop() {
  if (refining || !model || !$('refine').checked) return;
  refining = true;
  try {
    for (let step = 0; step < 64; ++step) {
      const version = cameraVersion;
      // The target is in CSS pixels (what one sees), the view in drawn pixels.
      const v = view();
      const targetPixels = (Number($('target').value) || 3) * (v.width / Math.max(1, canvas.clientWidth));
      const r = await model.wantView(v, { targetPixels, ...errorModel });
      if (!r.changed && version === cameraVersion) break;
    }
  } catch (e) {
    showError(e.message);
  } finally {
    refining = false;
  }
}

async function openSource(source, extraOptions = {}) {
  showError('');
  $('warning').textContent = '';
  if (model) model.close();
  model = null;
  upload({ positions: new Float32Array(0), triangles: new Uint32Array(0), vertexCluster: new Uint32Array(0), vertexLevel: new Uint32Array(0), colour: null });
  frame(null);
  const m = await open(source, {
    ...extraOptions,
    onMesh: (mesh, m) => onMesh(mesh, m),
    onWarning: (message) => { $('warning').textContent = 'warning: ' + message; },
  });
  model = m;
  // The header's box is the quantization cube; frame the base mesh's own box instead.
  frameMesh(camera, m.mesh.positions, canvas.clientWidth / Math.max(1, canvas.clientHeight));
  modelExtents = extentsOf(m.mesh.positions);
  applyUp();
  offerMaterials(m.mesh, true);
  ++cameraVersion;
  onMesh(m.mesh, m);
  if (m.info.clusters === 0) await m.want({ all: m.info.finestLevel }); // progressive: no regions
  return m;
}

// ------------------------------------------------------------------ interaction
function moved() {
  ++cameraVersion;
  frame(model);
  refineLoop();
}
// Mouse and touch through pointer events (the canvas has `touch-action: none`): one pointer
// orbits; two (a pinch) zoom by the change of the distance between them and pan the target
// with their midpoint.
const pointers = new Map();
canvas.addEventListener('pointerdown', (e) => { canvas.setPointerCapture(e.pointerId); pointers.set(e.pointerId, [e.clientX, e.clientY]); });
canvas.addEventListener('pointerup', (e) => pointers.delete(e.pointerId));
canvas.addEventListener('pointercancel', (e) => pointers.delete(e.pointerId));
canvas.addEventListener('pointermove', (e) => {
  if (!pointers.has(e.pointerId)) return;
  const [x, y] = pointers.get(e.pointerId);
  if (pointers.size === 2) {
    const other = [...pointers.entries()].find(([id]) => id !== e.pointerId)[1];
    const before = Math.hypot(x - other[0], y - other[1]);
    const after = Math.hypot(e.clientX - other[0], e.clientY - other[1]);
    if (before > 0 && after > 0) camera.distance *= before / after;
    // The midpoint moves by half this pointer's move: the target follows it on screen.
    const perPixel = (2 * camera.distance * Math.tan(camera.fovY / 2)) / Math.max(1, canvas.clientHeight);
    pan(camera, (-(e.clientX - x) / 2) * perPixel, ((e.clientY - y) / 2) * perPixel);
  } else if (pointers.size === 1) {
    camera.yaw -= (e.clientX - x) * 0.01;
    camera.pitch = Math.max(-1.5, Math.min(1.5, camera.pitch + (e.clientY - y) * 0.01));
  }
  pointers.set(e.pointerId, [e.clientX, e.clientY]);
  moved();
});
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  camera.distance *= Math.exp(e.deltaY * 0.001);
  moved();
}, { passive: false });
window.addEventListener('resize', moved);
$('colour').addEventListener('change', () => frame(model));
$('up').addEventListener('change', () => { applyUp(); moved(); });
$('target').addEventListener('change', moved);
$('refine').addEventListener('change', moved);
$('open').addEventListener('submit', (e) => {
  e.preventDefault();
  const url = $('url').value.trim();
  if (url) openSource(url).then(() => refineLoop(), (err) => showError(err.message));
});
window.addEventListener('dragover', (e) => { e.preventDefault(); $('drop').style.display = 'block'; });
window.addEventListener('dragleave', () => { $('drop').style.display = 'none'; });
window.addEventListener('drop', (e) => {
  e.preventDefault();
  $('drop').style.display = 'none';
  const f = e.dataTransfer.files[0];
  if (f) openSource(f).then(() => refineLoop(), (err) => showError(err.message));
});

// ------------------------------------------------------------------ start
// For the console and the browser tests (web/test/mobile_test.py): the viewer's state.
// drawn(): what the drawn geometry holds (vertices, colours uploaded, the material).
window.pomarViewer = { model: () => model, camera, refining: () => refining, upVector: () => upVector(camera),
  drawn: () => ({ vertices: shown.geometry.attributes.position.count, colours: shown.geometry.attributes.rgb ? shown.geometry.attributes.rgb.count : 0,
    material: material().id }) };
try {
  initMaterials();
  initGL();
  frame(null);
  if (params.get('test')) {
    import(params.get('test') === 'fidelity' ? './test/fidelity_page.js' : './test/page_test.js').then((t) => t.run({ openSource, camera, moved, view, frame: () => frame(model),
      model: () => model, showError, refineLoop }));
  } else if (params.get('file')) {
    if (params.get('target')) $('target').value = params.get('target');
    if (params.get('refine') === '0') $('refine').checked = false;
    $('url').value = params.get('file');
    openSource(params.get('file')).then(() => refineLoop(), (err) => showError(err.message));
  }
} catch (e) {
  showError(e.message);
}
