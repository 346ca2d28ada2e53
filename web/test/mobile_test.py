#!/usr/bin/env python3
"""The web viewer on an emulated phone (headless Chromium, mobile emulation, touch input).

    python3 web/test/mobile_test.py FILE.pomar [--images DIR] [--chromium PATH]

Serves the repository's web/ folder and FILE with web/serve.py on 127.0.0.1 and drives
headless Chromium through the DevTools protocol over a pipe (--remote-debugging-pipe; Python
standard library only): a 390x844 viewport at device pixel ratio 3, `mobile`, touch
enabled (Emulation.setDeviceMetricsOverride, Emulation.setTouchEmulationEnabled), the
viewer opened as a user would (web/index.html?file=..., its own refinement loop), then
touch input (Input.dispatchTouchEvent): a one-finger drag orbits, a two-finger pinch zooms
in and the view refines. Checks: the base mesh is drawn (pixels that are not the
background), the drawing buffer is the viewport at the viewer's pixel ratio (at most 2),
the drag turned the camera, the pinch brought it closer and more of the file was fetched
and decoded (finer levels, more triangles in view), and no error reached the page. This is
emulation: real phones (their GPUs, memory, browsers) are not tested.
Exit status 0 = pass, 1 = a check failed, 77 = Chromium or the WebAssembly build missing.
"""
import argparse
import base64
import fcntl
import json
import math
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
import serve  # noqa: E402
from browser_support import Checks, parse  # noqa: E402

WIDTH, HEIGHT, DPR = 390, 844, 3


class DevTools:
    """The DevTools protocol over --remote-debugging-pipe: Chromium reads commands from its
    fd 3 and writes answers and events to its fd 4, JSON messages ended by a NUL byte."""

    def __init__(self, cmd, log):
        to_chrome = os.pipe()
        from_chrome = os.pipe()

        def child_fds():
            a = fcntl.fcntl(to_chrome[0], fcntl.F_DUPFD, 10)
            b = fcntl.fcntl(from_chrome[1], fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, preexec_fn=child_fds, pass_fds=(3, 4))
        os.close(to_chrome[0])
        os.close(from_chrome[1])
        self.out = os.fdopen(to_chrome[1], 'wb')
        self.inp = os.fdopen(from_chrome[0], 'rb')
        self.next_id = 1
        self.answers = {}
        self.events = []
        self.cond = threading.Condition()
        threading.Thread(target=self.read, daemon=True).start()

    def read(self):
        buf = b''
        while True:
            data = self.inp.read1(65536)
            if not data:
                with self.cond:
                    self.answers[None] = 'closed'
                    self.cond.notify_all()
                return
            buf += data
            while b'\0' in buf:
                raw, buf = buf.split(b'\0', 1)
                msg = json.loads(raw)
                with self.cond:
                    if 'id' in msg:
                        self.answers[msg['id']] = msg
                    else:
                        self.events.append(msg)
                    self.cond.notify_all()

    def send(self, method, params=None, session=None, timeout=60):
        with self.cond:
            mid = self.next_id
            self.next_id += 1
        msg = {'id': mid, 'method': method, 'params': params or {}}
        if session:
            msg['sessionId'] = session
        self.out.write(json.dumps(msg).encode() + b'\0')
        self.out.flush()
        deadline = time.time() + timeout
        with self.cond:
            while mid not in self.answers:
                if None in self.answers or time.time() > deadline:
                    raise RuntimeError(f'{method}: no answer from Chromium')
                self.cond.wait(0.5)
            answer = self.answers.pop(mid)
        if 'error' in answer:
            raise RuntimeError(f"{method}: {answer['error'].get('message')}")
        return answer.get('result', {})


# The viewer's state (window.pomarViewer, set by viewer.js) and the fraction of the drawing
# buffer's pixels that are not the background (the WebGL canvas keeps its buffer).
STATE = r'''(() => {
  const v = window.pomarViewer;
  const m = v && v.model();
  const canvas = document.getElementById('view');
  if (!canvas || !document.getElementById('error')) return {};  // the page is still loading
  const out = { error: document.getElementById('error').textContent, dpr: devicePixelRatio,
    touchPoints: navigator.maxTouchPoints, cssWidth: canvas.clientWidth, cssHeight: canvas.clientHeight,
    width: canvas.width, height: canvas.height };
  if (!m || !m.stats || !m.levels) return out;
  const gl = canvas.getContext('webgl2');
  const px = new Uint8Array(4 * gl.drawingBufferWidth * gl.drawingBufferHeight);
  gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let covered = 0;
  for (let i = 0; i < px.length; i += 4)
    if (Math.abs(px[i] - 32) + Math.abs(px[i + 1] - 36) + Math.abs(px[i + 2] - 42) > 12) ++covered;
  let finest = 0;
  for (const l of m.levels) finest += l === m.info.finestLevel;
  return Object.assign(out, { open: true, refining: v.refining(), triangles: m.stats.triangles,
    bytesFetched: m.stats.bytesFetched, requests: m.stats.requests, fileBytes: m.stats.fileBytes,
    minLevel: Math.min(...m.levels), maxLevel: Math.max(...m.levels), finestClusters: finest,
    baseLevel: m.info.baseLevel, finestLevel: m.info.finestLevel, covered: covered / (px.length / 4),
    firstDraw: m.firstDraw,
    distance: v.camera.distance, yaw: v.camera.yaw, target: v.camera.target.slice() });
})()'''


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('pomar', help='a clustered .pomar file')
    ap.add_argument('--images', help='keep the screenshots here (mobile_base.png, mobile_pinch.png)')
    ap.add_argument('--timeout', type=float, default=120, help='seconds for each stage')
    ap.add_argument('--target', type=float, default=12, help="the viewer's target error in pixels")
    args = parse(ap, 'mobile_test')
    if args is None:
        return 77
    work = tempfile.mkdtemp(prefix='pomar-mobile-')
    server = devtools = None
    check = Checks()
    try:
        root = os.path.join(work, 'root')
        os.makedirs(os.path.join(root, 'data'))
        os.symlink(WEB, os.path.join(root, 'web'))
        shutil.copy(args.pomar, os.path.join(root, 'data', 'model.pomar'))
        server = serve.make_server(root, 0, test=True)
        threading.Thread(target=server.serve_forever, daemon=True).start()
        url = (f'http://127.0.0.1:{server.server_address[1]}/web/index.html?file=/data/model.pomar'
               f'&target={args.target}&refine=0')
        cmd = [args.chromium, '--headless=new', '--no-sandbox', '--use-angle=swiftshader',
               '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-first-run',
               '--no-default-browser-check', '--disable-extensions', '--remote-debugging-pipe',
               f'--user-data-dir={os.path.join(work, "profile")}', 'about:blank']
        log = open(os.path.join(work, 'chromium.log'), 'wb')
        devtools = DevTools(cmd, log)
        target = devtools.send('Target.createTarget', {'url': 'about:blank'})['targetId']
        session = devtools.send('Target.attachToTarget', {'targetId': target, 'flatten': True})['sessionId']

        def page(method, params=None):
            return devtools.send(method, params, session)

        page('Runtime.enable')
        page('Page.enable')
        page('Emulation.setDeviceMetricsOverride', {'width': WIDTH, 'height': HEIGHT, 'deviceScaleFactor': DPR,
                                                    'mobile': True})
        page('Emulation.setTouchEmulationEnabled', {'enabled': True, 'maxTouchPoints': 5})
        page('Page.navigate', {'url': url})

        def state():
            r = page('Runtime.evaluate', {'expression': STATE, 'returnByValue': True})
            if 'exceptionDetails' in r:
                raise RuntimeError('the state query failed: ' + json.dumps(r['exceptionDetails'])[:300])
            return r['result']['value']

        def settled(what):
            """The state once the viewer's refinement loop has stopped (twice the same)."""
            deadline = time.time() + args.timeout
            last = None
            while time.time() < deadline:
                s = state()
                if s.get('error'):
                    return s
                if s.get('open') and not s['refining']:
                    key = (s['triangles'], s['bytesFetched'])
                    if last == key:
                        return s
                    last = key
                else:
                    last = None
                time.sleep(0.5)
            raise RuntimeError(f'{what}: the viewer did not settle in {args.timeout:.0f} s')

        def shot(name):
            if args.images:
                os.makedirs(args.images, exist_ok=True)
                # In CSS pixels (390x844), not the device's 1170x2532.
                clip = {'x': 0, 'y': 0, 'width': WIDTH, 'height': HEIGHT, 'scale': 1 / DPR}
                png = base64.b64decode(page('Page.captureScreenshot', {'format': 'png', 'clip': clip})['data'])
                with open(os.path.join(args.images, name), 'wb') as f:
                    f.write(png)

        def touch(kind, points):
            page('Input.dispatchTouchEvent', {'type': kind, 'touchPoints': [
                {'x': x, 'y': y, 'id': i, 'radiusX': 5, 'radiusY': 5, 'force': 1} for i, (x, y) in points]})

        first = settled('open')
        print(f"file {first.get('fileBytes')} bytes; viewport {first['cssWidth']}x{first['cssHeight']} CSS px at "
              f"DPR {first['dpr']}, drawing buffer {first['width']}x{first['height']}, {first['touchPoints']} touch points")
        fd = first.get('firstDraw') or {}
        if fd:
            print(f"first draw {fd.get('openMs', 0):.0f} ms after the viewer opened the file, {fd.get('pageMs', 0):.0f} ms "
                  f"after the page began to load ({fd.get('bytesFetched')} bytes in {fd.get('requests')} requests, "
                  f"{fd.get('triangles')} triangles)")
        check(not first['error'], 'the file opens: ' + (first['error'] or 'no error'))
        if first['error'] or not first.get('open'):
            return 1
        check(first['dpr'] == DPR and first['touchPoints'] >= 2, 'the phone is emulated (DPR 3, touch)')
        check(first['width'] == 2 * first['cssWidth'] and first['height'] == 2 * first['cssHeight'],
              'the drawing buffer is the viewport at pixel ratio 2 (the device has 3)')
        check(first['maxLevel'] == first['baseLevel'] and first['covered'] > 0.02,
              f"the base clustered mesh is drawn: {first['triangles']} triangles, {100 * first['covered']:.1f}% "
              f"of the pixels, {first['bytesFetched']} bytes in {first['requests']} requests")
        shot('mobile_base.png')

        # A tap on "refine with the view" (the page opened with it off).
        box = page('Runtime.evaluate', {'expression': "(() => { const r = document.getElementById('refine')"
                                        ".getBoundingClientRect(); return [r.x + r.width / 2, r.y + r.height / 2]; })()",
                                        'returnByValue': True})['result']['value']
        touch('touchStart', [(0, box)])
        touch('touchEnd', [])
        refined = settled('refinement on')
        # (the file stores its errors: at the phone's overview the base clustered mesh may
        # already be within the pixel budget, so the tap need not refine; the pinch below must)
        on = page('Runtime.evaluate', {'expression': "document.getElementById('refine').checked",
                                       'returnByValue': True})['result']['value']
        check(on and refined['maxLevel'] >= first['maxLevel'] and refined['bytesFetched'] >= first['bytesFetched'],
              f"a tap turns refinement on: levels {refined['minLevel']}..{refined['maxLevel']}, {refined['triangles']} "
              f"triangles, {refined['bytesFetched']} bytes")

        # One finger: orbit.
        cx, cy = WIDTH / 2, HEIGHT * 0.55
        touch('touchStart', [(0, (cx - 60, cy))])
        for k in range(1, 11):
            touch('touchMove', [(0, (cx - 60 + 12 * k, cy))])
        touch('touchEnd', [])
        orbit = settled('orbit')
        check(abs(orbit['yaw'] - refined['yaw']) > 0.5, f"a one-finger drag orbits (yaw {refined['yaw']:.2f} -> {orbit['yaw']:.2f})")

        # Two fingers: pinch open around the middle of the screen, 4x.
        touch('touchStart', [(0, (cx - 30, cy)), (1, (cx + 30, cy))])
        for k in range(1, 16):
            d = 30 + 90 * k / 15
            touch('touchMove', [(0, (cx - d, cy)), (1, (cx + d, cy))])
        touch('touchEnd', [])
        pinch = settled('pinch')
        shot('mobile_pinch.png')
        print(f"  pinched: {pinch['triangles']} triangles, levels {pinch['minLevel']}..{pinch['maxLevel']}, "
              f"{pinch['finestClusters']} clusters at the finest level, {pinch['bytesFetched']} bytes in "
              f"{pinch['requests']} requests, camera distance {orbit['distance']:.4g} -> {pinch['distance']:.4g}")
        check(pinch['distance'] < orbit['distance'] / 2, 'a two-finger pinch zooms in')
        # (At DPR 3 a small model's overview may already hold (nearly) the whole file: then the pinch
        # must show the region in view at the finest level from what is held.)
        whole = orbit['bytesFetched'] >= 0.99 * first.get('fileBytes', float('inf'))
        check((pinch['finestClusters'] > orbit['finestClusters'] or pinch['maxLevel'] > orbit['maxLevel'])
              and pinch['triangles'] > orbit['triangles'] and pinch['bytesFetched'] > orbit['bytesFetched']
              or whole and pinch['maxLevel'] == pinch['finestLevel'] and pinch['finestClusters'] > 0,
              f"the pinch refined: levels up to {orbit['maxLevel']} -> {pinch['maxLevel']}, {orbit['finestClusters']} -> "
              f"{pinch['finestClusters']} clusters at the finest level, {orbit['triangles']} -> {pinch['triangles']} "
              f"triangles ({pinch['bytesFetched'] - orbit['bytesFetched']} more bytes)")
        check(pinch['covered'] > first['covered'], 'the model fills more of the screen')

        # Two fingers moving together: pan (the target follows their midpoint).
        touch('touchStart', [(0, (cx - 40, cy)), (1, (cx + 40, cy))])
        for k in range(1, 9):
            touch('touchMove', [(0, (cx - 40 + 8 * k, cy)), (1, (cx + 40 + 8 * k, cy))])
        touch('touchEnd', [])
        panned = settled('pan')
        moved = sum((a - b) ** 2 for a, b in zip(panned['target'], pinch['target'])) ** 0.5
        # 64 CSS pixels at the target's distance (vertical field of view 45 degrees).
        expected = 64 * 2 * pinch['distance'] * math.tan(math.pi / 8) / HEIGHT
        check(0.5 * expected < moved < 1.5 * expected and abs(panned['distance'] - pinch['distance']) < 0.01 * pinch['distance'],
              f"two fingers moving together pan: the target moved {moved:.3g} ({expected:.3g} expected), no zoom")
        check(not pinch['error'], 'no error in the page: ' + (pinch['error'] or 'none'))
        with devtools.cond:
            thrown = [e for e in devtools.events if e.get('method') == 'Runtime.exceptionThrown']
        check(not thrown, 'no uncaught exception' + (': ' + json.dumps(thrown[0])[:300] if thrown else ''))
    except RuntimeError as e:
        check(False, str(e))
    finally:
        if devtools is not None:
            devtools.proc.terminate()
            try:
                devtools.proc.wait(10)
            except subprocess.TimeoutExpired:
                devtools.proc.kill()
        if server is not None:
            server.shutdown()
        shutil.rmtree(work, ignore_errors=True)
    print('mobile_test: ' + ('PASS' if not check.failures else f'{len(check.failures)} checks FAILED'))
    return 1 if check.failures else 0


if __name__ == '__main__':
    sys.exit(main())
