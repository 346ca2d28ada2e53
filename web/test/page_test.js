// The scripted browser test, run by viewer.js with ?test=1 (web/test/browser_test.py starts
// the server and headless Chromium, then checks what this posts to /report/).
// ?file=URL of an intact file; &missing=, &truncatedGlobal=, &truncatedBlocks=,
// &damagedBlocks=, &noRange= URLs of the error cases; &coloured= URL of a Z-up model with
// per-vertex colour (web/test/coloured_mesh.py: red, green, blue bands from bottom to top);
// &textured= URL of the textured cube of web/test/textured_mesh.py (its textures beside
// it), &texturedMissing= the same file where its textures are not.
import { closeUp } from '../camera.js';

const params = new URLSearchParams(location.search);
const targetPixels = Number(params.get('target') || 3);
const closeup = Number(params.get('closeup') || 0.3);
const $ = (id) => document.getElementById(id);
const log = [];
function note(...args) {
  const line = args.join(' ');
  log.push(line);
  console.log('page_test: ' + line);
}

async function post(name, body) {
  await fetch('/report/' + name, { method: 'POST', body });
}
// Screenshots compared with expected images (docs/images/web_test/NAME.png, given as
// &ref=URL_PREFIX): both scaled to COMPARE_WIDTH pixels wide in a 2D canvas, a pixel
// differs when its |dR|+|dG|+|dB| exceeds PIXEL_THRESHOLD; web/test/browser_test.py checks
// the fraction of differing pixels. The scaled screenshot is posted as NAME_small.png
// (browser_test.py --update-references keeps it as the new expected image).
const COMPARED = ['base', 'closeup', 'closeup_levels', 'overview', 'zoomout', 'full'];
const COMPARE_WIDTH = 320;
const PIXEL_THRESHOLD = 32;
const comparisons = {};
function pixelsOf(source, w, h) {
  const c = document.createElement('canvas');
  c.width = w;
  c.height = h;
  const ctx = c.getContext('2d');
  ctx.drawImage(source, 0, 0, w, h);
  return { canvas: c, data: ctx.getImageData(0, 0, w, h).data };
}
async function compareWithExpected(name) {
  const view = document.getElementById('view');
  const w = COMPARE_WIDTH;
  const h = Math.round((COMPARE_WIDTH * view.height) / view.width);
  const got = pixelsOf(view, w, h);
  await post(name + '_small.png', await new Promise((resolve) => got.canvas.toBlob(resolve, 'image/png')));
  const ref = params.get('ref');
  if (!ref) return;
  const response = await fetch(ref + name + '.png');
  if (!response.ok) {
    comparisons[name] = { missing: `${ref}${name}.png: HTTP ${response.status}` };
    return;
  }
  const image = await createImageBitmap(await response.blob());
  if (image.width !== w || image.height !== h) {
    comparisons[name] = { missing: `${name}.png is ${image.width}x${image.height}, the screenshot ${w}x${h}` };
    return;
  }
  const expected = pixelsOf(image, w, h).data;
  let differing = 0;
  for (let i = 0; i < expected.length; i += 4) {
    const d = Math.abs(expected[i] - got.data[i]) + Math.abs(expected[i + 1] - got.data[i + 1]) +
      Math.abs(expected[i + 2] - got.data[i + 2]);
    if (d > PIXEL_THRESHOLD) ++differing;
  }
  comparisons[name] = { fraction: differing / (w * h), differing, width: w, height: h };
}

async function screenshot(name, v) {
  v.frame();
  const blob = await new Promise((resolve) => document.getElementById('view').toBlob(resolve, 'image/png'));
  await post(name + '.png', blob);
  if (COMPARED.includes(name)) await compareWithExpected(name);
  // Fraction of pixels that are not the background: the mesh is drawn.
  const gl = document.getElementById('view').getContext('webgl2');
  if (gl.isContextLost()) {
    note('the WebGL context is lost');
    return -1;
  }
  const w = gl.drawingBufferWidth;
  const h = gl.drawingBufferHeight;
  const px = new Uint8Array(4 * w * h);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let covered = 0;
  for (let i = 0; i < px.length; i += 4) {
    if (Math.abs(px[i] - 32) + Math.abs(px[i + 1] - 36) + Math.abs(px[i + 2] - 42) > 12) ++covered;
  }
  return covered / (w * h);
}
function within(ms, promise, what) {
  let timer;
  const timeout = new Promise((_, reject) => { timer = setTimeout(() => reject(new Error(`${what}: no answer in ${ms} ms`)), ms); });
  return Promise.race([promise, timeout]).finally(() => clearTimeout(timer));
}
function snapshot(model, covered, extra = {}) {
  const s = model.stats;
  return { bytesFetched: s.bytesFetched, fileBytes: s.fileBytes, requests: s.requests, triangles: s.triangles,
    vertices: s.vertices, minLevel: Math.min(...model.levels), maxLevel: Math.max(...model.levels),
    ranges: s.ranges, maxInFlightSeen: s.maxInFlightSeen, damaged: s.damaged, covered, heldBytes: s.heldBytes, blocksHeld: s.blocksHeld, ...extra };
}
/** Refinement steps for the current camera until the model is stable for it. */
async function settle(v, what) {
  let steps = 0;
  for (; steps < 64; ++steps) {
    const r = await within(30000, v.model().wantView(v.view(), { targetPixels }), what);
    if (!r.changed) break;
  }
  v.frame();
  return steps;
}

/** What the frame shows: the fraction of pixels drawn (not the background), the box of
 *  those pixels (its height / width: `aspect`), and for each pure hue (red, green, blue)
 *  the fraction of the drawn pixels of that saturated hue (its channel at least 60 and
 *  twice the other two plus 10: lighting darkens a colour but keeps its hue; grey and the
 *  background are not counted) and their mean height in the view (0 top, 1 bottom). */
function pixelStats(v) {
  v.frame();
  const gl = $('view').getContext('webgl2');
  const w = gl.drawingBufferWidth;
  const h = gl.drawingBufferHeight;
  const px = new Uint8Array(4 * w * h);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let covered = 0;
  const box = [w, h, -1, -1];
  const hues = [0, 1, 2].map(() => ({ count: 0, height: 0 }));
  for (let y = 0; y < h; ++y) {
    for (let x = 0; x < w; ++x) {
      const i = 4 * (y * w + x);
      const c = [px[i], px[i + 1], px[i + 2]];
      if (Math.abs(c[0] - 32) + Math.abs(c[1] - 36) + Math.abs(c[2] - 42) <= 12) continue;
      ++covered;
      const top = h - 1 - y; // readPixels rows start at the bottom
      box[0] = Math.min(box[0], x);
      box[1] = Math.min(box[1], top);
      box[2] = Math.max(box[2], x);
      box[3] = Math.max(box[3], top);
      for (let k = 0; k < 3; ++k) {
        const others = c.filter((_, j) => j !== k);
        if (c[k] >= 60 && c[k] >= 2 * Math.max(...others) + 10) {
          ++hues[k].count;
          hues[k].height += top / h;
        }
      }
    }
  }
  const named = {};
  ['red', 'green', 'blue'].forEach((name, k) => {
    named[name] = { fraction: hues[k].count / Math.max(1, covered), height: hues[k].count ? hues[k].height / hues[k].count : -1 };
  });
  return { covered: covered / (w * h), aspect: covered ? (box[3] - box[1] + 1) / (box[2] - box[0] + 1) : 0, ...named };
}

/** The colours of web/test/textured_mesh.py's charts (face of the cube: colour). */
const CHARTS = { '+z top': [0, 0, 255], '+z bottom': [255, 255, 0], '+x': [255, 0, 0], '+y': [0, 255, 0],
  '-x': [0, 255, 255], '-y': [255, 0, 255], '-z': [255, 128, 0] };
/** For each chart colour: the fraction of the drawn pixels of that colour (lighting scales
 *  a colour: a pixel counts when its brightest channel is at least 60 and each channel
 *  divided by the brightest is within 0.2 of the chart's), and their mean place in the
 *  view (x from the left, y from the top, 0..1); and the fraction of pixels drawn. */
function chartStats(v) {
  v.frame();
  const gl = $('view').getContext('webgl2');
  const w = gl.drawingBufferWidth;
  const h = gl.drawingBufferHeight;
  const px = new Uint8Array(4 * w * h);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const names = Object.keys(CHARTS);
  const found = names.map(() => ({ count: 0, x: 0, y: 0 }));
  let covered = 0;
  for (let y = 0; y < h; ++y) {
    for (let x = 0; x < w; ++x) {
      const i = 4 * (y * w + x);
      const c = [px[i], px[i + 1], px[i + 2]];
      if (Math.abs(c[0] - 32) + Math.abs(c[1] - 36) + Math.abs(c[2] - 42) <= 12) continue;
      ++covered;
      const top = Math.max(...c);
      if (top < 60) continue;
      const k = names.findIndex((n) => CHARTS[n].every((p, j) => Math.abs(c[j] / top - p / 255) < 0.2));
      if (k < 0) continue;
      ++found[k].count;
      found[k].x += x / w;
      found[k].y += (h - 1 - y) / h; // readPixels rows start at the bottom
    }
  }
  const out = { covered: covered / (w * h) };
  names.forEach((n, k) => {
    const f = found[k];
    out[n] = { fraction: f.count / Math.max(1, covered), x: f.count ? f.x / f.count : -1, y: f.count ? f.y / f.count : -1 };
  });
  return out;
}

/** The textured cube: opens with its texture (two materials, two images, one of them in a
 *  subdirectory), the texture coordinates in step with the geometry through region
 *  refinement, coarsening and full resolution, each chart's colour where its face is;
 *  plain shows none of them; with its images missing, a message and no texture. */
async function texturedSession(v) {
  const out = {};
  const viewer = window.pomarViewer;
  const texturesLoaded = () => (viewer.textures ? viewer.textures() : Promise.resolve());
  try {
    const m = await within(20000, v.openSource(params.get('textured')), 'textured model');
    await within(20000, texturesLoaded(), 'textured model: its textures');
    // A view from the +Z side, a little from the right (+X) and from above (+Y), the whole
    // cube in view (the session before may have orbited).
    Object.assign(v.camera, { yaw: 0.6, pitch: 0.3, distance: 3 });
    const state = () => ({ drawn: viewer.drawn(), vertices: m.mesh.positions.length / 3,
      meshTexcoords: m.mesh.texcoords ? m.mesh.texcoords.length / 2 : 0, minLevel: Math.min(...m.levels), maxLevel: Math.max(...m.levels) });
    out.material = $('colour').value;
    out.message = $('textures') ? $('textures').textContent : '';
    out.base = { ...state(), pixels: chartStats(v) };
    await screenshot('textured_base', v);
    await within(20000, m.want({ cluster: 0, level: m.info.finestLevel }), 'textured: one cluster');
    out.region = state();
    await within(20000, m.want({ all: m.info.baseLevel }), 'textured: coarsened');
    out.coarsened = state();
    await within(20000, m.want({ all: m.info.finestLevel }), 'textured: full resolution');
    out.full = { ...state(), pixels: chartStats(v) };
    await screenshot('textured_full', v);
    $('colour').value = 'plain';
    out.plain = chartStats(v);
    await screenshot('textured_plain', v);
    const missing = params.get('texturedMissing');
    if (missing) {
      await within(20000, v.openSource(missing), 'textured model without its images');
      await within(20000, texturesLoaded(), 'textured model without its images: its textures');
      out.missing = { material: $('colour').value, drawn: viewer.drawn().material, message: $('textures') ? $('textures').textContent : '', pixels: chartStats(v) };
      await screenshot('textured_missing', v);
    }
  } catch (e) {
    out.exception = String(e && e.stack ? e.stack : e);
  }
  note('textured model', JSON.stringify(out));
  return out;
}

/** The coloured Z-up model: drawn with its own colours by default, the colour buffer in
 *  step with the geometry through region refinement, coarsening and full resolution, grey
 *  in the plain material, the camera Z-up by itself and Y-up when asked. */
async function colouredSession(v) {
  const out = {};
  const viewer = window.pomarViewer;
  const drawn = () => (viewer.drawn ? viewer.drawn() : null);
  try {
    const m = await within(20000, v.openSource(params.get('coloured')), 'coloured model');
    const state = () => ({ drawn: drawn(), vertices: m.mesh.positions.length / 3, meshColours: m.mesh.colour ? m.mesh.colour.values.length / m.mesh.colour.components : 0,
      minLevel: Math.min(...m.levels), maxLevel: Math.max(...m.levels) });
    out.material = $('colour').value;
    out.up = v.camera.up || null;
    out.upVector = viewer.upVector ? viewer.upVector() : null;
    out.base = { ...state(), pixels: pixelStats(v) };
    await screenshot('coloured_base', v);
    await within(20000, m.want({ cluster: 0, level: m.info.finestLevel }), 'coloured: one cluster');
    out.region = state();
    await within(20000, m.want({ all: m.info.baseLevel }), 'coloured: coarsened');
    out.coarsened = state();
    await within(20000, m.want({ all: m.info.finestLevel }), 'coloured: full resolution');
    out.full = { ...state(), pixels: pixelStats(v) };
    await screenshot('coloured_full', v);
    $('colour').value = 'plain';
    out.plain = pixelStats(v);
    await screenshot('coloured_plain', v);
    $('colour').value = 'own';
    if ($('up')) {
      $('up').value = 'y';
      $('up').dispatchEvent(new Event('change'));
    }
    out.forcedY = { up: v.camera.up || null, pixels: pixelStats(v) };
    await screenshot('coloured_y', v);
    if ($('up')) {
      $('up').value = 'auto';
      $('up').dispatchEvent(new Event('change'));
    }
  } catch (e) {
    out.exception = String(e && e.stack ? e.stack : e);
  }
  note('coloured model', JSON.stringify(out));
  return out;
}

export async function run(v) {
  const result = { ok: false, log };
  try {
    $('refine').checked = false; // the test drives refinement itself (but see below)
    // A fixed canvas size: the screenshots compared with expected images do not depend on
    // the size the browser gives its window.
    $('view').style.width = '800px';
    $('view').style.height = '457px';
    const t0 = performance.now();
    const fetchOptions = params.has('maxGap') ? { maxGap: Number(params.get('maxGap')) } : {};
    const model = await within(30000, v.openSource(params.get('file'), fetchOptions), 'open');
    result.firstFrameMs = performance.now() - t0;
    result.firstDraw = model.firstDraw; // (a first frame before the global part, or the opened mesh)
    result.up = v.camera.up;
    result.material = $('colour').value;
    result.info = { clusters: model.info.clusters, baseLevel: model.info.baseLevel, finestLevel: model.info.finestLevel,
      fileBytes: model.info.fileBytes, globalBytes: model.info.globalBytes };
    result.base = snapshot(model, await screenshot('base', v));
    note('base clustered mesh', JSON.stringify(result.base));

    // Close-up: the surface point facing the camera, seen from `closeup` x the model's size.
    const center = v.camera.target.slice();
    closeUp(v.camera, model.mesh.positions, closeup);
    const before = model.stats.bytesFetched;
    result.closeupSteps = await settle(v, 'close-up');
    result.closeup = snapshot(model, await screenshot('closeup', v), { bytesForCloseup: model.stats.bytesFetched - before });
    $('colour').value = 'levels'; // the same view coloured by level
    await screenshot('closeup_levels', v);
    $('colour').value = 'plain';
    note('close-up', JSON.stringify(result.closeup));

    // The whole model on screen: refine until the projected error is under the target.
    v.camera.target = center;
    v.camera.distance = 1.6 * v.camera.extent;
    result.overviewSteps = await settle(v, 'overview');
    result.overview = snapshot(model, await screenshot('overview', v));
    $('colour').value = 'levels';
    await screenshot('overview_levels', v);
    $('colour').value = 'plain';
    note('overview', JSON.stringify(result.overview));

    // Zoom out: what shrinks to a few pixels coarsens.
    v.camera.distance = 30 * v.camera.extent;
    result.zoomoutSteps = await settle(v, 'zoom out');
    result.zoomout = snapshot(model, await screenshot('zoomout', v));
    note('zoomed out', JSON.stringify(result.zoomout));

    // The viewer's own loop (what orbiting and zooming run): back to the overview.
    $('refine').checked = true;
    v.camera.distance = 1.6 * v.camera.extent;
    await within(60000, v.refineLoop(), 'the viewer refinement loop');
    $('refine').checked = false;
    result.interactive = snapshot(model, await screenshot('interactive', v));
    note('viewer loop', JSON.stringify(result.interactive));

    // Full resolution everywhere: every block, each fetched once, in few requests.
    v.camera.distance = 1.6 * v.camera.extent;
    const requestsBefore = model.stats.requests;
    await within(30000, model.want({ all: model.info.finestLevel }), 'full resolution');
    result.full = snapshot(model, await screenshot('full', v), { requestsForFull: model.stats.requests - requestsBefore });
    const { maxRanges, maxRequestBytes, maxInFlight } = model.options;
    result.fetchPolicy = { maxRanges, maxRequestBytes, maxInFlight };
    note('full resolution', JSON.stringify(result.full));

    // A server that answers a request for several ranges with the whole file (as Amazon
    // S3 does): the answer is dropped, then one range a request; same mesh. (Two clusters
    // first: their neighbours' block prefixes leave holes for full resolution to fill.)
    // Opened with a first request of 2 KiB: the first frame is drawn before the global part
    // is in. Then the close-up, its requests counted by the server (one range each).
    const served = async () => (await (await fetch('/log')).json()).filter((e) => e.path.startsWith('/single-range/')).length;
    const single = await within(20000, v.openSource(params.get('singleRange'), { firstRequestBytes: 2048 }), 'single-range server');
    const firstDraw = { ...single.firstDraw, globalBytes: single.info.globalBytes };
    closeUp(v.camera, single.mesh.positions, closeup);
    const servedBefore = await served();
    const singleRequestsBefore = single.stats.requests;
    await settle(v, 'single-range close-up');
    const singleCloseup = { requests: single.stats.requests - singleRequestsBefore, served: (await served()) - servedBefore,
      bytesFetched: single.stats.bytesFetched, maxLevel: Math.max(...single.levels), requestCost: single.options.requestCost };
    await within(30000, single.want({ cluster: 0, level: single.info.finestLevel }), 'single-range server');
    await within(30000, single.want({ cluster: single.info.clusters >> 1, level: single.info.finestLevel }), 'single-range server');
    await within(30000, single.want({ all: single.info.finestLevel }), 'single-range server');
    result.singleRange = snapshot(single, -1, { multiRange: single.stats.multiRange, firstDraw, closeup: singleCloseup });
    note('single-range server', JSON.stringify(result.singleRange));

    // Error cases: each must show a message in the page, never hang.
    result.errors = {};
    for (const key of ['missing', 'noRange', 'truncatedGlobal', 'truncatedBlocks', 'damagedBlocks']) {
      const url = params.get(key);
      if (!url) continue;
      v.showError('');
      $('warning').textContent = '';
      try {
        const m = await within(20000, v.openSource(url), key);
        if (m.info.clusters) await within(20000, m.want({ all: m.info.finestLevel }), key);
      } catch (e) {
        v.showError(e.message);
      }
      result.errors[key] = { error: $('error').textContent, warning: $('warning').textContent };
      note(key, JSON.stringify(result.errors[key]));
    }
    if (params.get('coloured')) result.coloured = await colouredSession(v);
    if (params.get('textured')) result.textured = await texturedSession(v);
    result.ok = true;
  } catch (e) {
    result.exception = String(e && e.stack ? e.stack : e);
    note('exception', result.exception);
  }
  result.comparisons = comparisons;
  await post('result.json', JSON.stringify(result));
}
