#!/usr/bin/env python3
"""The web viewer in a real headless browser.

    python3 web/test/browser_test.py FILE.pomar [--coloured COLOURED.pomar] [--textured DIR] [--images DIR] [--chromium PATH]

Serves the repository's web/ folder and copies of FILE (intact, truncated in the global
part, truncated in the cluster blocks, one cluster block damaged, and through a path that
ignores Range) with web/serve.py on 127.0.0.1, opens web/index.html?test=1 in headless
Chromium (WebGL2 on SwiftShader through ANGLE: --use-gl=swiftshader makes this Chromium's GPU
process fail to start and, now and then, WebGL contexts get lost) and checks what web/test/page_test.js reports: the base
mesh is drawn at once, a close-up refines and fetches a fraction of the file, zooming out
coarsens, a full-resolution view fetches every byte of the file exactly once (checked in
the server's log), and 404 / no Range support / truncated / damaged files show a message
in the page. --images DIR keeps the screenshots (base, overview, closeup, zoomout, full).
Screenshots (scaled to 320 pixels wide) are compared with the expected images in
docs/images/web_test/ (made from samples/bunny.ply encoded with --cluster-ratio 0.05, as
web/test/run.sh does): at most --max-differing of their pixels may differ by more than a
small colour threshold (see page_test.js). --update-references writes the new screenshots
there instead (after a deliberate change to the encoder, the camera or the rendering; look
at them). --no-compare skips the comparison (another file than the sample).
--coloured: a Z-up model with per-vertex colour, web/test/coloured_mesh.py encoded (run.sh
makes it): the viewer picks Z as the up axis by itself and draws the model's own colours
(red at the bottom of the picture, blue at its top), its colour buffer matches the
geometry after region refinement, coarsening and full resolution, the plain material is
grey and the Y-up choice turns the model on its side (screenshots coloured_*).
--textured DIR: the textured cube of web/test/textured_mesh.py, DIR/textured.pomar (run.sh
encodes it) with its textures DIR/a.png and DIR/maps/b.png: the viewer opens it with its
texture, the texture coordinates match the geometry after region refinement, coarsening
and full resolution (three geometry groups: three materials), each visible face shows its
chart's colour in its place (the top face its material's Kd: it has no texture) (the +Z face's upper half blue above its lower half yellow:
the texture's v = 0 at the bottom), hidden faces' colours absent, plain shows none of
them; served without its images it says so in the page and draws plain (textured_*).
Exit status 0 = pass, 1 = a check failed, 77 = Chromium or the WebAssembly build missing.
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

HERE = os.path.dirname(os.path.abspath(__file__))
WEB = os.path.dirname(HERE)
sys.path.insert(0, WEB)
REFERENCES = os.path.join(os.path.dirname(WEB), 'docs', 'images', 'web_test')
import serve  # noqa: E402
from browser_support import CHROMIUM_FLAGS, Checks, parse, stop  # noqa: E402


def coloured_checks(check, c):
    """What the page saw of the coloured Z-up model (page_test.js colouredSession)."""
    if 'exception' in c:
        check(False, 'the coloured model: ' + c['exception'])
        return
    check(c['material'] == 'own', f"a file with colours opens with its own colours (colour menu: {c['material']})")
    check(c['up'] == 'z' and c['upVector'] == [0, 0, 1], f"up: auto picks Z for a Z-up model (up {c['up']}, camera up {c['upVector']})")
    for name in ('base', 'region', 'coarsened', 'full'):
        s = c[name]
        d = s['drawn'] or {}
        check(d.get('colours') == d.get('vertices') == s['vertices'] == s['meshColours'] and s['vertices'] > 0,
              f"{name} (levels {s['minLevel']}..{s['maxLevel']}): {s['vertices']} vertices, "
              f"{d.get('vertices')} drawn with {d.get('colours')} colours")
    check(c['full']['minLevel'] == c['full']['maxLevel'] and c['region']['minLevel'] < c['region']['maxLevel'],
          'the coloured model went through a region, the base and full resolution')
    for name in ('base', 'full'):
        p = c[name]['pixels']
        hues = ', '.join(f"{h} {100 * p[h]['fraction']:.1f}%" for h in ('red', 'green', 'blue'))
        check(p['covered'] > 0.02 and all(p[h]['fraction'] > 0.05 for h in ('red', 'green', 'blue')),
              f"{name}: the model's own colours are drawn ({hues} of its {100 * p['covered']:.1f}% of the pixels)")
    p = c['full']['pixels']
    check(p['red']['height'] > p['green']['height'] > p['blue']['height'],
          f"Z up: red (bottom band) under green under blue (mean heights from the top "
          f"{p['red']['height']:.2f}, {p['green']['height']:.2f}, {p['blue']['height']:.2f})")
    check(p['aspect'] > 1.5, f"Z up: the model stands (its pixels' box is {p['aspect']:.2f} times as high as wide)")
    g = c['plain']
    saturated = sum(g[h]['fraction'] for h in ('red', 'green', 'blue'))
    check(g['covered'] > 0.02 and saturated < 0.001, f"the plain material is grey ({100 * saturated:.2f}% saturated pixels)")
    y = c['forcedY']
    check(y['up'] == 'y' and y['pixels']['aspect'] < p['aspect'] / 2,
          f"up: Y lays it on its side (up {y['up']}, box height / width {y['pixels']['aspect']:.2f})")


def textured_checks(check, t):
    """What the page saw of the textured cube (page_test.js texturedSession)."""
    if 'exception' in t:
        check(False, 'the textured model: ' + t['exception'])
        return
    check(t['material'] == 'texture' and not t['message'],
          f"a file with texture coordinates and textures opens with its texture (colour menu: {t['material']}; "
          f"message: {t['message']!r})")
    for name in ('base', 'region', 'coarsened', 'full'):
        s = t[name]
        d = s['drawn'] or {}
        check(d.get('texcoords') == d.get('vertices') == s['vertices'] == s['meshTexcoords'] and s['vertices'] > 0
              and d.get('groups') == 3,
              f"{name} (levels {s['minLevel']}..{s['maxLevel']}): {s['vertices']} vertices, {d.get('vertices')} drawn "
              f"with {d.get('texcoords')} texture coordinates in {d.get('groups')} groups (3 materials)")
    check(t['full']['minLevel'] == t['full']['maxLevel'] and t['region']['minLevel'] < t['region']['maxLevel'],
          'the textured model went through a region, the base and full resolution')
    seen = ('+z top', '+z bottom', '+x', '+y')
    hidden = ('-x', '-y', '-z')
    for name in ('base', 'full'):
        p = t[name]['pixels']
        shown = ', '.join(f"{c} {100 * p[c]['fraction']:.1f}%" for c in seen + hidden)
        check(p['covered'] > 0.02 and all(p[c]['fraction'] > 0.03 for c in seen)
              and all(p[c]['fraction'] < 0.01 for c in hidden),
              f"{name}: the faces in view show their charts' colours, the hidden ones' absent ({shown} of "
              f"{100 * p['covered']:.1f}% of the pixels)")
        present = all(p[c]['fraction'] > 0 for c in seen)  # else the places below are -1
        check(present and p['+z top']['y'] < p['+z bottom']['y'],
              f"{name}: the +Z face's upper chart half (blue, v > 0.5) above its lower half (yellow): v = 0 at the "
              f"image's bottom (mean heights from the top {p['+z top']['y']:.2f}, {p['+z bottom']['y']:.2f})")
        check(present and p['+y']['y'] < min(p['+z top']['y'], p['+x']['y']) and p['+x']['x'] > p['+z bottom']['x'],
              f"{name}: the top face's colour (green: its material's Kd, it has no texture) on top (mean height "
              f"{p['+y']['y']:.2f}), +X's on the right "
              f"(mean x {p['+x']['x']:.2f} against +Z's {p['+z bottom']['x']:.2f})")
    g = t['plain']
    coloured = sum(g[c]['fraction'] for c in seen + hidden)
    check(g['covered'] > 0.02 and coloured < 0.001, f"plain shows none of the texture's colours ({100 * coloured:.2f}%)")
    m = t.get('missing')
    if m is None:
        return
    coloured = sum(m['pixels'][c]['fraction'] for c in seen + hidden)
    check('a.png' in m['message'] and 'maps/b.png' in m['message'] and 'cannot load' in m['message']
          and m['material'] == 'plain' and m['drawn'] == 'plain' and coloured < 0.001,
          f"textures missing: the page says so ({m['message']!r}) and draws {m['drawn']} "
          f"({100 * coloured:.2f}% texture colours)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('pomar', help='a clustered .pomar file')
    ap.add_argument('--images', help='copy the screenshots into this directory (prefix web_)')
    ap.add_argument('--timeout', type=float, default=240)
    ap.add_argument('--target', type=float, default=3, help='target screen-space error in pixels')
    ap.add_argument('--closeup', type=float, default=0.3, help='close-up distance / model size')
    ap.add_argument('--max-differing', type=float, default=0.005,
                    help='largest fraction of differing pixels per compared screenshot')
    ap.add_argument('--update-references', action='store_true', help='write docs/images/web_test/*.png')
    ap.add_argument('--no-compare', action='store_true', help='do not compare screenshots')
    ap.add_argument('--max-gap', type=int, help="pomar.js maxGap for the session (bytes; default: pomar.js's)")
    ap.add_argument('--coloured', help='a Z-up .pomar with per-vertex colour (web/test/coloured_mesh.py)')
    ap.add_argument('--textured', help='a directory with textured.pomar and its textures (web/test/textured_mesh.py)')
    args = parse(ap, 'browser_test')
    if args is None:
        return 77
    check = Checks()
    failures = check.failures

    work = tempfile.mkdtemp(prefix='pomar-browser-')
    proc = None
    server = None
    try:
        root = os.path.join(work, 'root')
        data = os.path.join(root, 'data')
        os.makedirs(data)
        os.symlink(WEB, os.path.join(root, 'web'))
        os.symlink(REFERENCES, os.path.join(root, 'ref'))
        with open(args.pomar, 'rb') as f:
            blob = f.read()
        with open(os.path.join(data, 'model.pomar'), 'wb') as f:
            f.write(blob)
        # The global part's size, from the header, as `pomar info` reports it: found by
        # the page; here only cuts are needed: inside the header, inside the blocks.
        with open(os.path.join(data, 'truncated_global.pomar'), 'wb') as f:
            f.write(blob[:200])
        with open(os.path.join(data, 'truncated_blocks.pomar'), 'wb') as f:
            f.write(blob[:len(blob) * 3 // 4])
        damaged = bytearray(blob)
        damaged[len(blob) - 40] ^= 0x5A  # inside the last cluster blocks
        with open(os.path.join(data, 'damaged_blocks.pomar'), 'wb') as f:
            f.write(bytes(damaged))
        if args.coloured:
            shutil.copy(args.coloured, os.path.join(data, 'coloured.pomar'))
        if args.textured:
            # With its textures beside it (one in a subdirectory), and alone.
            for sub, files in (('textured', ('textured.pomar', 'a.png', 'maps/b.png')), ('untextured', ('textured.pomar',))):
                for name in files:
                    os.makedirs(os.path.dirname(os.path.join(data, sub, name)), exist_ok=True)
                    shutil.copy(os.path.join(args.textured, name), os.path.join(data, sub, name))
        reports = os.path.join(work, 'reports')
        os.makedirs(reports)
        server = serve.make_server(root, 0, test=True, report_dir=reports)
        threading.Thread(target=server.serve_forever, daemon=True).start()
        base = f'http://127.0.0.1:{server.server_address[1]}'
        gap = '' if args.max_gap is None else f'&maxGap={args.max_gap}'
        if not (args.no_compare or args.update_references):
            gap += '&ref=/ref/'
        if args.coloured:
            gap += '&coloured=/data/coloured.pomar'
        if args.textured:
            gap += '&textured=/data/textured/textured.pomar&texturedMissing=/data/untextured/textured.pomar'
        url = (f'{base}/web/index.html?test=1&file=/data/model.pomar{gap}'
               f'&target={args.target}&closeup={args.closeup}&missing=/data/missing.pomar'
               '&noRange=/no-range/data/model.pomar&singleRange=/single-range/data/model.pomar&truncatedGlobal=/data/truncated_global.pomar'
               '&truncatedBlocks=/data/truncated_blocks.pomar&damagedBlocks=/data/damaged_blocks.pomar')
        profile = os.path.join(work, 'profile')
        cmd = [args.chromium, *CHROMIUM_FLAGS, f'--user-data-dir={profile}', '--enable-logging=stderr', '--v=0', url]
        browser_log = open(os.path.join(work, 'chromium.log'), 'wb')
        proc = subprocess.Popen(cmd, stdout=browser_log, stderr=subprocess.STDOUT)
        result_path = os.path.join(reports, 'result.json')
        deadline = time.time() + args.timeout
        while not os.path.exists(result_path) and time.time() < deadline and proc.poll() is None:
            time.sleep(0.25)
        if not os.path.exists(result_path):
            print('browser_test: FAIL: the page reported nothing ' +
                  ('(Chromium exited)' if proc.poll() is not None else f'in {args.timeout:.0f} s'))
            with open(os.path.join(work, 'chromium.log'), 'rb') as f:
                lines = f.read().decode('utf-8', 'replace').splitlines()
            keep = [x for x in lines if 'CONSOLE' in x or 'Uncaught' in x]
            print('\n'.join('  chromium: ' + x for x in keep[-30:]))
            shutil.rmtree(work, ignore_errors=True)
            return 1
        with open(result_path) as f:
            r = json.load(f)
        if os.environ.get('POMAR_BROWSER_TEST_VERBOSE'):
            print('\n'.join('  page: ' + x for x in r.get('log', [])))
        log = server.log
    finally:
        stop(proc, server)

    try:
        if r.get('firstDraw'):
            fd = r['firstDraw']
            print(f"first draw {fd.get('decodeMs', 0):.0f} ms after the worker started, {fd.get('openMs', 0):.0f} ms "
                  f"after the page opened the file, {fd.get('pageMs', 0):.0f} ms after the page began to load, "
                  f"{fd['bytesFetched']} bytes in "
                  f"{fd['requests']} requests, {fd.get('triangles')} triangles; base clustered mesh drawn "
                  f"{r.get('firstFrameMs', 0):.0f} ms after the page opened the file")
        check(r.get('ok'), 'the scripted session ran to the end' + ('' if r.get('ok') else ': ' + str(r.get('exception'))))
        if not r.get('ok'):
            return 1
        size = r['info']['fileBytes']
        b, ov, cu, zo, full = r['base'], r['overview'], r['closeup'], r['zoomout'], r['full']
        print(f"file {size} bytes, global part {r['info']['globalBytes']}, {r['info']['clusters']} clusters, "
              f"levels {r['info']['baseLevel']}..{r['info']['finestLevel']}; first frame {r['firstFrameMs']:.0f} ms")
        for name, s in (('base', b), ('close-up', cu), ('overview', ov), ('zoomed out', zo), ('full', full)):
            print(f"  {name:10s} {s['triangles']:7d} triangles, levels {s['minLevel']}..{s['maxLevel']}, "
                  f"{s['bytesFetched']:7d} bytes fetched ({100 * s['bytesFetched'] / size:.1f}%) in {s['requests']} requests, "
                  f"{100 * (s['covered'] or 0):.1f}% of the pixels drawn")
        # The first request, then the rest; a file with sections before its levels: the
        # levels, tables and index in one request, the sections in another.
        check(b['requests'] <= 3 and b['bytesFetched'] < size, 'open reads the global part in at most three requests')
        check(b['covered'] > 0.02, 'the base clustered mesh is drawn')
        check(b['maxLevel'] == r['info']['baseLevel'], 'open decodes the base clustered mesh only')
        check(cu['maxLevel'] == r['info']['finestLevel'] and cu['minLevel'] < cu['maxLevel'],
              'the close-up refines the region in view to the finest level, not everything')
        check(cu['covered'] > 0.3, 'the close-up fills the view')
        print(f"  close-up: fetched {cu['bytesFetched']} bytes ({100 * cu['bytesFetched'] / size:.1f}%), "
              f"of which {cu['bytesForCloseup']} after the base mesh")
        check(ov['triangles'] > b['triangles'] and ov['covered'] > 0.02, 'the overview refines')
        check(zo['triangles'] < ov['triangles'] / 2 and zo['maxLevel'] <= ov['maxLevel'], 'zooming out coarsens')
        check(r['interactive']['triangles'] > zo['triangles'] and r['interactive']['covered'] > 0.02,
              "the viewer's own refinement loop refines the overview again")
        check(full['triangles'] > cu['triangles'] and full['minLevel'] == r['info']['finestLevel'], 'full resolution everywhere')
        check(full['bytesFetched'] == size, f"full resolution fetched {full['bytesFetched']} bytes of {size}")
        policy = r['fetchPolicy']
        check(full['maxInFlightSeen'] <= policy['maxInFlight'], f"at most {policy['maxInFlight']} requests in flight")
        # The bound of the fetch policy: the ranges still missing are at most one per
        # cluster block (a block is held as a prefix), grouped by up to maxRanges
        # ranges and maxRequestBytes bytes a request (a group closed by its size holds, with
        # the next range, more than maxRequestBytes).
        bound = (-(-r['info']['clusters'] // policy['maxRanges']) + 2 * -(-size // policy['maxRequestBytes']) + 1)
        check(full['requestsForFull'] <= bound,
              f"full resolution after the session: {full['requestsForFull']} requests (at most {bound}: "
              f"{r['info']['clusters']} blocks / {policy['maxRanges']} ranges a request + 2 x {size} bytes / "
              f"{policy['maxRequestBytes']} + 1); {full['requests']} requests for {full['ranges']} ranges in the whole session")
        sr = r['singleRange']
        check(sr['multiRange'] is False and sr['triangles'] == full['triangles'] and sr['minLevel'] == r['info']['finestLevel'],
              f"a server answering several ranges with the whole file: one range a request, same mesh "
              f"({sr['requests']} requests, {sr['bytesFetched']} bytes)")
        fd, sc = sr['firstDraw'], sr['closeup']
        check(fd['bytesFetched'] < fd['globalBytes'],
              f"the first frame is drawn before the global part is in ({fd['bytesFetched']} of {fd['globalBytes']} "
              f"bytes, {fd['requests']} requests)")
        check(sc['served'] == sc['requests'] and sc['requests'] <= 60 and sc['maxLevel'] == r['info']['finestLevel'],
              f"one range a request: the close-up in {sc['requests']} requests (the server answered {sc['served']}; "
              f"at most 60), {sc['bytesFetched']} bytes, requestCost {sc['requestCost']}")
        # The server's view: the intact file's bytes, each served once.
        served = sorted((e['start'], e['start'] + e['bytes']) for e in log
                        if e['path'] == '/data/model.pomar' and e['status'] == 206)
        overlap = any(a[1] > b_[0] for a, b_ in zip(served, served[1:]))
        total = sum(e - s for s, e in served)
        check(total == size and not overlap, f'the server sent {total} bytes of {size} in {len(served)} ranges, none twice')
        e = r['errors']
        check('404' in e['missing']['error'], 'a missing file shows the HTTP status: ' + e['missing']['error'])
        check('Range' in e['noRange']['error'], 'a server without Range support is named: ' + e['noRange']['error'])
        check('truncated' in e['truncatedGlobal']['error'], 'a file cut in its global part: ' + e['truncatedGlobal']['error'])
        check(not e['truncatedBlocks']['error'] and 'truncated' in e['truncatedBlocks']['warning'],
              'a file cut in its cluster blocks decodes around them: ' + e['truncatedBlocks']['warning'].splitlines()[0]
              if e['truncatedBlocks']['warning'] else 'a file cut in its cluster blocks: no warning')
        check(not e['damagedBlocks']['error'] and 'damaged' in e['damagedBlocks']['warning'],
              'a damaged cluster block is skipped with a warning')
        check(r.get('up') == 'y' and r.get('material') == 'plain',
              f"the bunny (Y-up, no colour): up {r.get('up')}, material {r.get('material')}")
        if args.coloured:
            coloured_checks(check, r.get('coloured') or {'exception': 'the page ran no coloured session'})
        if args.textured:
            textured_checks(check, r.get('textured') or {'exception': 'the page ran no textured session'})
        compared = r.get('comparisons', {})
        for name, c in sorted(compared.items()):
            if 'missing' in c:
                check(False, f'screenshot {name}: no expected image ({c["missing"]}; --update-references makes them)')
            else:
                check(c['fraction'] <= args.max_differing,
                      f"screenshot {name}: {c['differing']} of {c['width']}x{c['height']} pixels differ from "
                      f"docs/images/web_test/{name}.png ({100 * c['fraction']:.2f}%, at most {100 * args.max_differing:.1f}%)")
        if not (args.no_compare or args.update_references):
            check(len(compared) == 6, f'{len(compared)} screenshots compared with expected images')
        if args.update_references:
            os.makedirs(REFERENCES, exist_ok=True)
            names = [n[:-len('_small.png')] for n in os.listdir(reports) if n.endswith('_small.png')]
            for name in names:
                shutil.copy(os.path.join(reports, name + '_small.png'), os.path.join(REFERENCES, name + '.png'))
            print(f'expected images written: {REFERENCES}/ ({", ".join(sorted(names))})')
        if args.images:
            os.makedirs(args.images, exist_ok=True)
            names = ['base', 'closeup', 'closeup_levels', 'overview', 'overview_levels', 'zoomout', 'full']
            if args.coloured:
                names += ['coloured_base', 'coloured_full', 'coloured_plain', 'coloured_y']
            if args.textured:
                names += ['textured_base', 'textured_full', 'textured_plain', 'textured_missing']
            for name in names:
                shutil.copy(os.path.join(reports, name + '.png'), os.path.join(args.images, f'web_{name}.png'))
            print(f'screenshots: {args.images}/web_*.png')
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print('browser_test: ' + ('PASS' if not failures else f'{len(failures)} checks FAILED'))
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
