"""What web/test/browser_test.py, web/test/mobile_test.py and bench/web_fidelity_bench.py
share: the check that Chromium and the WebAssembly build are there, Chromium's flags, the
end of a session, and a counter of checks."""
import os
import shutil
import subprocess

# Headless Chromium with WebGL2 on SwiftShader through ANGLE, an 800x600 window.
CHROMIUM_FLAGS = ['--headless=new', '--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
                  '--ignore-gpu-blocklist', '--no-first-run', '--no-default-browser-check', '--disable-extensions',
                  '--window-size=800,600']


def stop(proc, server):
    """End the browser (terminate, kill after 10 s) and the server, whichever was started."""
    if proc is not None:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
    if server is not None:
        server.shutdown()

WEB = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def parse(ap, name):
    """The arguments of `ap` plus --chromium; None, after a SKIP line (the caller exits
    77), when Chromium or the WebAssembly build is missing."""
    ap.add_argument('--chromium', default=shutil.which('chromium') or shutil.which('chromium-browser'))
    args = ap.parse_args()
    why = ('chromium not installed' if not args.chromium else
           'web/dist/pomar_decoder.wasm not built (bash web/build.sh)'
           if not os.path.exists(os.path.join(WEB, 'dist', 'pomar_decoder.wasm')) else None)
    if why:
        print(f'{name}: SKIP: {why}')
        return None
    return args


class Checks:
    """check(ok, what) prints 'ok' or 'FAIL' and what; failures lists the failed ones."""

    def __init__(self):
        self.failures = []

    def __call__(self, ok, what):
        print(('ok   ' if ok else 'FAIL ') + what)
        if not ok:
            self.failures.append(what)
