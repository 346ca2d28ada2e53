#!/usr/bin/env python3
"""bench/readme_results.py in its quickest modes (--quick --sizes-only, then --quick --times-only
--runs 1: samples/bunny.ply) on a copy of README.md: the table between the markers is rewritten
with the command, the date and the machine, the sizes are consistent, and nothing outside the
markers changes.

    python3 tests/e2e/readme_results_test.py BUILD_DIR

Exit 77 (skipped) when draco_encoder or draco_decoder is not on PATH.
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(REPO, "bench", "readme_results.py")
BEGIN, END = "<!-- readme_results:sizes begin -->", "<!-- readme_results:sizes end -->"


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def outside(text):
    return text[:text.index(BEGIN)] + text[text.index(END):]


def main():
    build = sys.argv[1]
    if not (shutil.which("draco_encoder") and shutil.which("draco_decoder")):
        print("draco_encoder/draco_decoder not on PATH: skipped")
        sys.exit(77)
    with open(os.path.join(REPO, "README.md"), encoding="utf-8") as f:
        original = f.read()
    for marker in (BEGIN, END, BEGIN.replace("sizes", "times"), END.replace("sizes", "times")):
        if original.count(marker) != 1:
            fail("README.md must hold the marker %s exactly once" % marker)
    with tempfile.TemporaryDirectory(prefix="pomar-readme-test.") as tmp:
        copy = os.path.join(tmp, "README.md")
        shutil.copy(os.path.join(REPO, "README.md"), copy)
        r = subprocess.run([sys.executable, SCRIPT, "--quick", "--sizes-only", "--build", build,
                            "--readme", copy],
                           capture_output=True, text=True)
        if r.returncode != 0:
            fail("readme_results.py exit %d: %s" % (r.returncode, r.stderr.strip()))
        with open(copy, encoding="utf-8") as f:
            text = f.read()
    if outside(text) != outside(original):
        fail("text outside the sizes markers changed")
    block = text[text.index(BEGIN):text.index(END)]
    if "`python3 bench/readme_results.py --quick --sizes-only" not in block:
        fail("the block does not name the command that made it:\n" + block)
    if not re.search(r"nproc \d+", block) or not re.search(r"measured \d{4}-\d\d-\d\d", block):
        fail("the block does not give the machine (nproc) and the date:\n" + block)
    if "passes `pomar verify" not in block:
        fail("the bunny's files are not reported lossless:\n" + block)
    row = re.search(r"^\| bunny \(sample\) \| ([\d,]+) \| ([\d.]+) \(([\d.]+) \+ ([\d.]+)\) \| "
                    r"\*\*([\d.]+)\*\* \| \+([\d.]+)% \| ([\d.]+)\\?\*? \| ([\d.]+) \|$", block, re.M)
    if not row:
        fail("no bunny row in the sizes table:\n" + block)
    vertices = int(row.group(1).replace(",", ""))
    prog, conn, geom, ra, overhead, draco, ratio = map(float, row.groups()[1:])
    if vertices != 34834:
        fail("bunny vertices %d, expected 34,834 (samples/bunny.ply)" % vertices)
    if not (conn + geom <= prog < ra):
        fail("progressive bpv %.2f should hold conn + geom %.2f and be below random access %.2f"
             % (prog, conn + geom, ra))
    if abs(ra / prog - 1 - overhead / 100) > 0.002:
        fail("overhead %.1f%% does not match %.2f / %.2f" % (overhead, ra, prog))
    if abs(ra / draco - ratio) > 0.01:
        fail("size / Draco %.2f does not match %.2f / %.2f" % (ratio, ra, draco))
    print("ok: " + row.group(0))

    # The times table's code path, one round (the figures of a loaded machine mean nothing;
    # only the table's shape is checked).
    with tempfile.TemporaryDirectory(prefix="pomar-readme-test.") as tmp:
        copy = os.path.join(tmp, "README.md")
        shutil.copy(os.path.join(REPO, "README.md"), copy)
        r = subprocess.run([sys.executable, SCRIPT, "--quick", "--times-only", "--runs", "1",
                            "--build", build, "--readme", copy], capture_output=True, text=True)
        if r.returncode != 0:
            fail("readme_results.py --times-only exit %d: %s" % (r.returncode, r.stderr.strip()))
        with open(copy, encoding="utf-8") as f:
            text = f.read()
    tb, te = BEGIN.replace("sizes", "times"), END.replace("sizes", "times")
    if text[:text.index(tb)] + text[text.index(te):] != \
            original[:original.index(tb)] + original[original.index(te):]:
        fail("text outside the times markers changed")
    block = text[text.index(tb):text.index(te)]
    row = re.search(r"^\| bunny \(sample\) \| 34,834 \| ([\d.]+) \| ([\d.]+) \| "
                    r"[\d.]+ \([\d.]+\) \| [\d.]+ \([\d.]+\) \|$", block, re.M)
    if not row or not all(float(g) > 0 for g in row.groups()):
        fail("no bunny row in the times table:\n" + block)
    print("ok: " + row.group(0))


if __name__ == "__main__":
    main()
