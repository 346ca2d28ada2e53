#!/usr/bin/env python3
"""The corpus table of docs/robustness.md: every mesh file of a folder (default
../shared/data) through `pomar encode` with default options (lossless as is) and
`pomar verify`, then with --strict (the old behaviour) for comparison.

    python3 scripts/robustness_table.py [--pomar build/codec/pomar] [--data DIR]

Prints a Markdown table: file, lossless as is (verify), file size, what the lossless record
stores (the one stderr line of encode), its cost in bytes and bits per coded vertex, and
what --strict says.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def first_error(text, data):
    for line in text.splitlines():
        if line.startswith("pomar: error:"):
            line = line[len("pomar: error: "):].replace(data + os.sep, "")
            return line.split(" (without --strict")[0]  # the hint is the same everywhere
    return text.strip().splitlines()[-1] if text.strip() else ""


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pomar", default=os.path.join(root, "build", "codec", "pomar"))
    ap.add_argument("--data", default=os.path.join(root, "..", "shared", "data"))
    a = ap.parse_args()
    if not os.path.isdir(a.data):
        print(f"{a.data} is absent", file=sys.stderr)
        return 0
    files = sorted(f for f in os.listdir(a.data)
                   if os.path.splitext(f)[1].lower() in (".ply", ".obj", ".off", ".stl"))
    print("| file | lossless as is | file bytes | stored for an exact decode | record bytes | "
          "record bpv | with `--strict` |")
    print("|:--|:--|--:|:--|--:|--:|:--|")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.pomar")
        out_strict = os.path.join(tmp, "strict.pomar")
        for f in files:
            path = os.path.join(a.data, f)
            rc, _, err = run([a.pomar, "encode", path, out])
            if rc != 0:
                print(f"| {f} | refused (exit {rc}) | | {first_error(err, a.data)} | | | "
                  "refused: the same message |")
                continue
            stored = ""
            for line in err.splitlines():
                if line.startswith("pomar: stored for an exact decode: "):
                    stored = line[len("pomar: stored for an exact decode: "):]
                    stored = stored[:stored.rfind(" (")]  # the bytes are in their own column
            vrc, _, _ = run([a.pomar, "verify", path, out])
            _, info, _ = run([a.pomar, "info", "--json", out])
            i = json.loads(info)
            size = i["total_bytes"]
            rec, bpv = i.get("lossless_bytes", 0), i.get("lossless_bits_per_vertex", 0.0)
            verdict = "exact (verify OK)" if vrc == 0 else f"MISMATCH (verify exit {vrc})"
            src, _, serr = run([a.pomar, "encode", "--strict", path, out_strict])
            if src != 0:
                strict = "refused: " + first_error(serr, a.data)
            elif open(out, "rb").read() == open(out_strict, "rb").read():
                strict = "the same bytes"
            else:
                strict = "encodes, unreferenced vertices dropped"
            print(f"| {f} | {verdict} | {size} | {stored or 'nothing (clean)'} | {rec} | "
                  f"{bpv:.3f} | {strict} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
