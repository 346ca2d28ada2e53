#!/usr/bin/env python3
"""How far the web viewer's refinement policies draw a view from the same view at full
resolution, in headless Chromium (WebGL2 on SwiftShader), and what they fetch.

    python3 bench/web_fidelity_bench.py FILE.pomar [--views closeup:0.1,overview]
        [--policy JSON]... [--shading flat|smooth] [--images DIR] [--timeout S]

Each --policy is a JSON object of view_refine.js chooseLevels settings (default: one
policy, the defaults). For each view (closeup:F = the surface point facing the camera from
F x the model's size, as web/test/page_test.js; overview = the whole model framed), the page
(web/test/fidelity_page.js) draws the view at full resolution, then, for each policy, from
a fresh stream, the view refined until stable, and counts the pixels of the 800x457 drawing
buffer that differ (|dR|+|dG|+|dB| > 32, the browser test's metric). Prints one line per
view and policy: bytes fetched (% of the file), triangles, finest level used, steps,
differing pixels, and how many of those are covered by the surface in one image only (the
silhouette moved; the others differ by their shading), and the shading ones split by the
reference's brightness: where the surface is seen at a grazing angle (|n.l| < 0.5 with the
viewer's headlight) or facing the eye. See web/README.md, "View-dependent refinement".
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import urllib.parse

WEB = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'web')
sys.path.insert(0, WEB)
sys.path.insert(0, os.path.join(WEB, 'test'))
import serve  # noqa: E402
from browser_support import CHROMIUM_FLAGS, parse, stop  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('pomar')
    ap.add_argument('--views', default='closeup:0.1,overview')
    ap.add_argument('--policy', action='append', help='chooseLevels settings as JSON (repeatable)')
    ap.add_argument('--images', help='keep the screenshots here (VIEW_full.png, VIEW_K.png for policy K)')
    ap.add_argument('--timeout', type=float, default=900)
    ap.add_argument('--shading', choices=['flat', 'smooth'], default='flat',
                    help="the viewer's shading: flat facets (its default) or vertex normals")
    args = parse(ap, 'web_fidelity_bench')
    if args is None:
        return 77
    policies = [json.loads(p) for p in (args.policy or ['{}'])]
    work = tempfile.mkdtemp(prefix='pomar-fidelity-')
    proc = server = None
    try:
        root = os.path.join(work, 'root')
        os.makedirs(os.path.join(root, 'data'))
        os.symlink(WEB, os.path.join(root, 'web'))
        shutil.copy(args.pomar, os.path.join(root, 'data', 'model.pomar'))
        reports = os.path.join(work, 'reports')
        os.makedirs(reports)
        server = serve.make_server(root, 0, test=True, report_dir=reports)
        threading.Thread(target=server.serve_forever, daemon=True).start()
        query = urllib.parse.urlencode({'test': 'fidelity', 'file': '/data/model.pomar', 'views': args.views,
                                        'policies': json.dumps(policies), 'shading': args.shading})
        url = f'http://127.0.0.1:{server.server_address[1]}/web/index.html?{query}'
        cmd = [args.chromium, *CHROMIUM_FLAGS, f'--user-data-dir={os.path.join(work, "profile")}', url]
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        result_path = os.path.join(reports, 'result.json')
        deadline = time.time() + args.timeout
        while not os.path.exists(result_path) and time.time() < deadline and proc.poll() is None:
            time.sleep(0.5)
        if not os.path.exists(result_path):
            print('web_fidelity_bench: the page reported nothing')
            return 1
        with open(result_path) as f:
            r = json.load(f)
        if args.images:
            os.makedirs(args.images, exist_ok=True)
            for name in os.listdir(reports):
                if name.endswith('.png'):
                    shutil.copy(os.path.join(reports, name), os.path.join(args.images, name))
    finally:
        stop(proc, server)
        shutil.rmtree(work, ignore_errors=True)
    if not r.get('ok'):
        print('web_fidelity_bench: the page failed: ' + str(r.get('exception')))
        return 1
    for v in r['views']:
        total = v['width'] * v['height']
        print(f"{v['view']}: full resolution {v['fullTriangles']} triangles, {v['width']}x{v['height']} pixels")
        for p in v['policies']:
            print(f"  {json.dumps(p['settings']):60s} {100 * p['bytesFetched'] / v['fileBytes']:6.2f}% "
                  f"{p['bytesFetched']:8d} B {p['triangles']:7d} triangles, max level {p['maxLevel']}, "
                  f"{p['steps']:2d} steps, {p['differing']:6d} pixels differ ({100 * p['differing'] / total:.2f}%), "
                  f"{p['silhouette']} of them on the silhouette; shading: {p['grazingDiffer']} of "
                  f"{p['grazingPixels']} grazing (|n.l| < 0.5), {p['facingDiffer']} of {p['facingPixels']} facing, "
                  f"{p['brighter']} drawn brighter")
    return 0


if __name__ == '__main__':
    sys.exit(main())
