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
// the colour menu (MATERIALS below). A textured file is drawn in one geometry group per
// material of the file, each with its own copy of the shader's material and texture.
// &shading=smooth shades with vertex normals instead (area-weighted face normals, computed
// at each upload), e.g. to compare refinement policies (bench/web_fidelity_bench.py
// --shading smooth).
const VS = `precision highp float;
in vec3 position;
in float cluster;
in float level;
in vec3 normal;
in vec3 rgb;
in vec2 uv;
uniform mat4 projectionMatrix;
uniform mat4 modelViewMatrix;
uniform int colourMode;
uniform float finest;
uniform float base;
out vec3 vPosition;
out vec3 vNormal;
out vec3 vRgb;
out vec2 vUv;
flat out vec3 vColour;
vec3 hue(float h) { return clamp(abs(mod(h * 6.0 + vec3(0, 4, 2), 6.0) - 3.0) - 1.0, 0.0, 1.0); }
void main() {
  vPosition = position;
  vNormal = normal;
  vRgb = rgb;
  vUv = uv;
  if (colourMode == 1) vColour = 0.35 + 0.65 * hue(fract(cluster * 0.61803));
  else if (colourMode == 2) vColour = 0.3 + 0.7 * hue(0.66 * (1.0 - (level - base) / max(1.0, finest - base)));
  else vColour = vec3(0.82, 0.80, 0.76);
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}`;
const FS = `precision highp float;
in vec3 vPosition;
in vec3 vNormal;
in vec3 vRgb;
in vec2 vUv;
flat in vec3 vColour;
uniform vec3 eye;
uniform highp int colourMode; // highp: the vertex shader's int precision (shared uniform)
uniform int smoothShading;
uniform sampler2D map;
uniform vec3 diffuse;
out vec4 colour;
void main() {
  vec3 n = smoothShading == 1 && dot(vNormal, vNormal) > 0.0 ? normalize(vNormal)
                                                             : normalize(cross(dFdx(vPosition), dFdy(vPosition)));
  vec3 l = normalize(eye - vPosition);
  float d = abs(dot(n, l));
  // Own colours (mode 3) are interpolated across the face, a texture (mode 4) is looked up
  // at the interpolated texture coordinate, a material without one (mode 5) has its
  // diffuse colour; all are lit like the others.
  vec3 base = colourMode == 3 ? vRgb : colourMode == 4 ? texture(map, vUv).rgb : colourMode == 5 ? diffuse : vColour;
  colour = vec4(base * (0.25 + 0.75 * d), 1.0);
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
// The first available one is chosen when a file opens: the file's texture when it has
// texture coordinates and texture files (and they load), else its own colours when it has
// them, else plain.
const MATERIALS = [
  { id: 'texture', label: 'texture', mode: 4, available: (mesh) => !!mesh.texcoords && textures.usable(mesh),
    attributes: (mesh) => ({ uv: new THREE.BufferAttribute(mesh.texcoords, 2) }) },
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
let drawnMesh = { positions: new Float32Array(0), vertexCluster: new Uint32Array(0), colour: null, texcoords: null };
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

// ------------------------------------------------------------------ textures
// The file's texture names are URLs relative to the .pomar file's own URL (as an OBJ's MTL
// names its images relative to the MTL: a name with a directory part stays relative).
// Each is loaded once per opened file as an image; v = 0 is the image's bottom row (OBJ),
// which is three.js's default upload (flipY). A texture that does not load is named in
// the page (#textures) and the texture entry is taken away: the model is drawn with its
// own colours, or plain.
/** A mesh whose vertices' corners disagree (a welded one) cannot be drawn with its texture. */
function reportConflicts(mesh) {
  if (!mesh.texcoords && mesh.texcoordConflicts) {
    $('textures').textContent = `texture: ${mesh.texcoordConflicts} vertices have corners with different texture coordinates ` +
      '(a welded mesh): the texture is not drawn';
  }
}
const textures = {
  base: null,     // the URL the names are relative to (null: a dropped file, no URL)
  files: [],      // the file's texture names
  loaded: [],     // per name: THREE.Texture, or null (loading, or failed)
  failed: [],     // per name: a message, or ''
  ready: Promise.resolve(),
  /** Start loading the textures of a newly opened file (`source`: its URL or File). */
  start(source, mesh) {
    this.dispose();
    this.files = mesh.textureFiles || [];
    this.base = typeof source === 'string' ? new URL(source, location.href) : null;
    this.loaded = this.files.map(() => null);
    this.failed = this.files.map(() => '');
    $('textures').textContent = '';
    reportConflicts(mesh);
    if (!mesh.texcoords || !this.files.length) return (this.ready = Promise.resolve());
    const generation = ++this.generation;
    this.ready = Promise.all(this.files.map((name, i) => this.load(name, i, generation))).then(() => {
      if (generation !== this.generation) return;
      const failed = this.failed.filter((f) => f);
      $('textures').textContent = failed.length ? `${failed.join('\n')}\n(drawn ${material().id === 'own' ? 'with its own colours' : 'plain'} instead)` : '';
    });
    return this.ready;
  },
  generation: 0,
  load(name, i, generation) {
    if (!this.base) {
      this.failed[i] = `texture ${name}: a dropped file's textures cannot be fetched (their names are relative to the file's URL: open it by URL)`;
      return Promise.resolve();
    }
    const url = new URL(name.replace(/\\/g, '/').split('/').map(encodeURIComponent).join('/'), this.base).href;
    return new THREE.TextureLoader().loadAsync(url).then((texture) => {
      if (generation !== this.generation) return texture.dispose();
      texture.flipY = true; // the image's first row at v = 1: OBJ's v = 0 at the bottom
      texture.wrapS = texture.wrapT = THREE.RepeatWrapping;
      texture.anisotropy = renderer ? renderer.capabilities.getMaxAnisotropy() : 1;
      this.loaded[i] = texture;
    }, () => {
      if (generation === this.generation) this.failed[i] = `texture ${name}: cannot load ${url}`;
    }).then(() => {
      if (generation !== this.generation) return;
      // A failed texture takes the entry away: choose again if it was shown.
      if (this.failed[i] && $('colour').value === 'texture') offerMaterials(drawnMesh, true);
      else offerMaterials(drawnMesh, false);
      frame(model);
    });
  },
  /** The texture entry applies: every texture of the file is loaded or loading. */
  usable(mesh) {
    return (mesh.textureFiles || []).length > 0 && this.failed.every((f) => !f);
  },
  /** The texture of material index m of the file (its materials, or texture 0 if it has none). */
  of(mesh, m) {
    const t = mesh.materials && mesh.materials.length ? (mesh.materials[m] || { texture: -1 }).texture : 0;
    return t >= 0 && t < this.loaded.length ? this.loaded[t] : null;
  },
  dispose() {
    ++this.generation;
    for (const t of this.loaded) if (t) t.dispose();
    this.loaded = [];
    this.failed = [];
    this.files = [];
  },
};

let renderer = null;
let scene = null;
let shown = null; // the THREE.Mesh
let plainMaterial = null; // the shader's material (every colour mode but the texture)
let textureMaterials = []; // per material of the file: the shader's material with its texture
const camera3 = new THREE.PerspectiveCamera();
const sharedUniforms = { finest: { value: 1 }, base: { value: 0 }, eye: { value: new THREE.Vector3() },
  smoothShading: { value: smoothShading ? 1 : 0 } };
/** The shader as a three.js material: its own `own` uniforms, the others shared (one
 *  update in frame() reaches every material). */
function shaderMaterial(own) {
  return new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3, vertexShader: VS, fragmentShader: FS, side: THREE.DoubleSide,
    uniforms: { ...sharedUniforms, ...own },
  });
}
/** A material's diffuse colour (its MTL `Kd r g b` line), or null. */
function diffuseOf(material) {
  const kd = material && /^\s*Kd\s+(\S+)\s+(\S+)\s+(\S+)/m.exec(material.properties || '');
  const rgb = kd ? kd.slice(1, 4).map(Number) : null;
  return rgb && rgb.every((c) => Number.isFinite(c)) ? rgb.map((c) => Math.max(0, Math.min(1, c))) : null;
}
/** The texture materials for `mesh`'s materials: each draws its texture (mode 4); one
 *  without a texture its diffuse colour (mode 5) if it has one; else, and while its image
 *  loads, plain grey. */
function updateTextureMaterials(mesh) {
  const count = Math.max(1, (mesh.materials || []).length);
  while (textureMaterials.length < count) textureMaterials.push(shaderMaterial({ colourMode: { value: 0 }, map: { value: null }, diffuse: { value: new THREE.Vector3() } }));
  for (let m = 0; m < textureMaterials.length; ++m) {
    const texture = m < count ? textures.of(mesh, m) : null;
    const own = mesh.materials && mesh.materials[m];
    const diffuse = own && own.texture < 0 ? diffuseOf(own) : null;
    const u = textureMaterials[m].uniforms;
    u.map.value = texture;
    if (diffuse) u.diffuse.value.set(...diffuse);
    u.colourMode.value = texture ? 4 : diffuse ? 5 : 0;
  }
}
/** The triangles of `mesh` ordered by material (a stable counting sort) and one geometry
 *  group per material present: {index, groups}. Without face materials: as they are. */
function trianglesByMaterial(mesh) {
  const t = mesh.triangles;
  const fm = mesh.faceMaterials;
  if (!fm || !mesh.texcoords) return { index: t, groups: [] };
  const count = Math.max(1, mesh.materials.length);
  const start = new Uint32Array(count + 1);
  for (let f = 0; f < fm.length; ++f) ++start[Math.min(fm[f], count - 1) + 1];
  for (let m = 0; m < count; ++m) start[m + 1] += start[m];
  const groups = [];
  for (let m = 0; m < count; ++m) if (start[m + 1] > start[m]) groups.push({ start: 3 * start[m], count: 3 * (start[m + 1] - start[m]), materialIndex: m });
  const next = start.slice(0, count);
  const index = new Uint32Array(t.length);
  for (let f = 0; f < fm.length; ++f) {
    const to = 3 * next[Math.min(fm[f], count - 1)]++;
    index[to] = t[3 * f];
    index[to + 1] = t[3 * f + 1];
    index[to + 2] = t[3 * f + 2];
  }
  return { index, groups };
}
function initGL() {
  THREE.ColorManagement.enabled = false; // colours as given, no sRGB conversions
  renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setClearColor(new THREE.Color(0x20242a), 1);
  scene = new THREE.Scene();
  plainMaterial = shaderMaterial({ colourMode: { value: 0 }, map: { value: null }, diffuse: { value: new THREE.Vector3() } });
  shown = new THREE.Mesh(new THREE.BufferGeometry(), plainMaterial);
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
  // By material (a textured file: one group per material; the order of the triangles does
  // not matter to the other colour modes).
  const { index, groups } = trianglesByMaterial(mesh);
  g.setIndex(new THREE.BufferAttribute(index, 1));
  for (const group of groups) g.addGroup(group.start, group.count, group.materialIndex);
  shown.geometry.dispose();
  shown.geometry = g;
  drawnMesh = mesh;
  reportConflicts(mesh);
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
  const u = sharedUniforms;
  u.eye.value.set(...v.eye);
  u.finest.value = model ? model.info.finestLevel : 1;
  u.base.value = model ? model.info.baseLevel : 0;
  const chosen = material();
  if (chosen.id === 'texture') {
    // One material per group (a geometry without groups: the first material, all of it).
    updateTextureMaterials(drawnMesh);
    shown.material = shown.geometry.groups.length ? textureMaterials : textureMaterials[0];
  } else {
    plainMaterial.uniforms.colourMode.value = chosen.mode;
    shown.material = plainMaterial;
  }
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
  textures.dispose();
  $('textures').textContent = '';
  upload({ positions: new Float32Array(0), triangles: new Uint32Array(0), vertexCluster: new Uint32Array(0), vertexLevel: new Uint32Array(0), colour: null, texcoords: null });
  frame(null);
  let previewed = false;
  const m = await open(source, {
    keepSeams: true, // a textured mesh: one texture coordinate per vertex at full resolution too
    ...extraOptions,
    onMesh: (mesh, m) => onMesh(mesh, m),
    // The base mesh and global levels while the global part arrives: drawn plain.
    onPreview: (mesh, stats) => {
      if (!previewed) frameMesh(camera, mesh.positions, canvas.clientWidth / Math.max(1, canvas.clientHeight));
      previewed = true;
      const nv = mesh.positions.length / 3;
      upload({ ...mesh, vertexCluster: new Uint32Array(nv), vertexLevel: new Uint32Array(nv), colour: null, texcoords: null });
      frame(null);
      $('stats').textContent = `fetched ${(stats.bytesFetched / 1024).toFixed(1)} KiB of ${(stats.fileBytes / 1024).toFixed(1)} KiB ` +
        `in ${stats.requests} requests: global level ${mesh.level}, ${stats.triangles} triangles`;
    },
    onWarning: (message) => { $('warning').textContent = 'warning: ' + message; },
  });
  model = m;
  // The header's box is the quantization cube; frame the base mesh's own box instead.
  frameMesh(camera, m.mesh.positions, canvas.clientWidth / Math.max(1, canvas.clientHeight));
  modelExtents = extentsOf(m.mesh.positions);
  applyUp();
  textures.start(source, m.mesh);
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
// drawn(): what the drawn geometry holds (vertices, colours and texture coordinates
// uploaded, geometry groups, the material); textures(): settles when the open file's
// textures have loaded or failed.
window.pomarViewer = { model: () => model, camera, refining: () => refining, upVector: () => upVector(camera),
  drawn: () => ({ vertices: shown.geometry.attributes.position.count, colours: shown.geometry.attributes.rgb ? shown.geometry.attributes.rgb.count : 0,
    texcoords: shown.geometry.attributes.uv ? shown.geometry.attributes.uv.count : 0, groups: shown.geometry.groups.length,
    material: material().id }),
  textures: () => textures.ready };
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
