// How far a view refined by a policy is from the same view at full resolution, in pixels
// (run by viewer.js with ?test=fidelity; bench/web_fidelity_bench.py serves the page and
// reads what this posts to /report/result.json).
// ?file=URL &views=closeup:0.1,overview &policies=[{...chooseLevels settings}, ...] (JSON)
// For each view: a fresh model at full resolution draws the reference; then for each
// policy, a fresh model is refined for the view until stable and drawn. A pixel differs
// when |dR|+|dG|+|dB| > 32 (as page_test.js compares screenshots), here at the drawing
// buffer's full size.
import { closeUp } from '../camera.js';

const params = new URLSearchParams(location.search);
const PIXEL_THRESHOLD = 32;
const $ = (id) => document.getElementById(id);

function pixels() {
  const gl = $('view').getContext('webgl2');
  const w = gl.drawingBufferWidth;
  const h = gl.drawingBufferHeight;
  const px = new Uint8Array(4 * w * h);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  return { w, h, px };
}
// The background's colour (viewer.js clears to it; page_test.js tells it apart the same way).
const background = (px, i) => Math.abs(px[i] - 32) + Math.abs(px[i + 1] - 36) + Math.abs(px[i + 2] - 42) <= 12;
/** Pixels that differ, and of those the ones where the surface covers one image only (the
 *  silhouette moved: geometry; the others differ by their shading). */
/** Plain grey (viewer.js: 0.82 x (0.25 + 0.75 |n.l|) in red) seen at a grazing angle:
 *  |n.l| under 0.5, i.e. the surface turned more than 60 degrees from the eye. */
const grazing = (px, i) => (px[i] / 255 / 0.82 - 0.25) / 0.75 < 0.5;
function differing(a, b) {
  let n = 0;
  let silhouette = 0;
  // Of the surface pixels (in the reference `a`), how many face the eye at a grazing angle,
  // and how many of those and of the others differ by their shading.
  let grazingPixels = 0;
  let facingPixels = 0;
  let grazingDiffer = 0;
  let facingDiffer = 0;
  let brighter = 0; // shading pixels drawn brighter than at full resolution
  for (let i = 0; i < a.px.length; i += 4) {
    const d = Math.abs(a.px[i] - b.px[i]) + Math.abs(a.px[i + 1] - b.px[i + 1]) + Math.abs(a.px[i + 2] - b.px[i + 2]);
    const surface = !background(a.px, i);
    const steep = surface && grazing(a.px, i);
    if (surface) steep ? ++grazingPixels : ++facingPixels;
    if (d > PIXEL_THRESHOLD) {
      ++n;
      if (surface === background(b.px, i)) ++silhouette;
      else if (steep) ++grazingDiffer;
      else if (surface) ++facingDiffer;
      if (surface && surface !== background(b.px, i) && b.px[i] > a.px[i]) ++brighter;
    }
  }
  return { n, silhouette, grazingPixels, facingPixels, grazingDiffer, facingDiffer, brighter };
}
async function post(name, body) {
  await fetch('/report/' + name, { method: 'POST', body });
}
async function save(name) {
  const blob = await new Promise((resolve) => $('view').toBlob(resolve, 'image/png'));
  await post(name + '.png', blob);
}

export async function run(v) {
  const result = { ok: false, views: [] };
  try {
    $('refine').checked = false;
    $('view').style.width = '800px';
    $('view').style.height = '457px';
    const file = params.get('file');
    const policies = JSON.parse(params.get('policies') || '[{}]');
    const views = (params.get('views') || 'closeup:0.1,overview').split(',');
    // The camera of each view, from the camera openSource frames the model with.
    const framed = { ...v.camera, target: v.camera.target.slice() };
    const place = async (name, model) => {
      Object.assign(v.camera, framed, { target: framed.target.slice() });
      const [kind, fraction] = name.split(':');
      if (kind === 'closeup') closeUp(v.camera, model.mesh.positions, Number(fraction));
      else v.camera.distance = 1.6 * v.camera.extent;
    };
    for (const name of views) {
      let model = await v.openSource(file);
      Object.assign(framed, v.camera, { target: v.camera.target.slice() });
      await place(name, model);
      await model.want({ all: model.info.finestLevel });
      v.frame();
      const reference = pixels();
      await save(`${name.replace(':', '_')}_full`);
      const entry = { view: name, width: reference.w, height: reference.h, fileBytes: model.info.fileBytes,
        fullTriangles: model.stats.triangles, policies: [] };
      for (const settings of policies) {
        model = await v.openSource(file);
        await place(name, model);
        let steps = 0;
        for (; steps < 64; ++steps) if (!(await model.wantView(v.view(), settings)).changed) break;
        v.frame();
        const got = pixels();
        await save(`${name.replace(':', '_')}_${policies.indexOf(settings)}`);
        entry.policies.push({ settings, steps, bytesFetched: model.stats.bytesFetched, triangles: model.stats.triangles,
          maxLevel: Math.max(...model.levels), ...(({ n, ...rest }) => ({ differing: n, ...rest }))(differing(reference, got)) });
      }
      result.views.push(entry);
    }
    result.ok = true;
  } catch (e) {
    result.exception = String(e && e.stack ? e.stack : e);
  }
  await post('result.json', JSON.stringify(result));
}
