"""What web/test/browser_test.py and web/test/mobile_test.py share: the check that Chromium
and the WebAssembly build are there, and a counter of checks."""
import os
import shutil

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
