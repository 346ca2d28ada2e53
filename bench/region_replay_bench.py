#!/usr/bin/env python3
"""Vertices a region-by-region replay of the clustered levels decodes, against the mesh's.

    python3 bench/region_replay_bench.py POMAR FILE.pomar N [N ...]

Cuts the file's grid cube into N x N x N boxes and decodes each box's clusters at full
resolution (`pomar decode --box`; the other clusters at the base clustered level, raised by the
level map: one ring of neighbours per level). The sum over the boxes of the vertices decoded past
the base clustered mesh, divided by the mesh's vertices past it, is the work a replay region by
region repeats: the rings around each region (bench/README.md, "Encoding larger than memory").
"""
import json
import os
import re
import subprocess
import sys
import tempfile


def grid(pomar, path):
    info = json.loads(subprocess.run([pomar, "info", "--json", path], capture_output=True,
                                     text=True, check=True).stdout)
    text = subprocess.run([pomar, "info", path], capture_output=True, text=True, check=True).stdout
    m = re.search(r"grid from \(([-\d.e+]+), ([-\d.e+]+), ([-\d.e+]+)\), cell ([-\d.e+]+)", text)
    if not m:
        sys.exit("region_replay_bench: no grid in `pomar info %s`" % path)
    origin = [float(m.group(i)) for i in (1, 2, 3)]
    extent = float(m.group(4)) * ((1 << info["bits"]) - 1)
    return info, origin, extent


def region(pomar, path, lo, hi, out):
    spec = ",".join("%.9g" % x for x in lo + hi)
    r = subprocess.run([pomar, "decode", "--stats", "--threads", "1", "--box", spec, path, out],
                       capture_output=True, text=True)
    m = re.search(r"(\d+) vertices, \d+ faces; (\d+) of \d+ clusters refined", r.stdout + r.stderr)
    if r.returncode != 0 or not m:
        sys.exit("region_replay_bench: pomar decode --box %s failed:\n%s" % (spec, r.stderr))
    return int(m.group(1)), int(m.group(2))


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    pomar, path = sys.argv[1], sys.argv[2]
    info, origin, extent = grid(pomar, path)
    if not info.get("clusters"):
        sys.exit("region_replay_bench: %s is not a random-access file" % path)
    past = info["vertices"] - info["clusters"]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "region.ply")
        for n in map(int, sys.argv[3:]):
            decoded, regions, largest = 0, 0, 0
            for i in range(n):
                for j in range(n):
                    for k in range(n):
                        cell = (i, j, k)
                        lo = [origin[a] + extent * cell[a] / n for a in range(3)]
                        # the last box on an axis reaches past the grid (no root on two boxes'
                        # shared face is lost; one there may count in both)
                        hi = [origin[a] + extent * (cell[a] + 1) / n + (extent if cell[a] == n - 1
                                                                         else 0) for a in range(3)]
                        vertices, refined = region(pomar, path, lo, hi, out)
                        if refined == 0:
                            continue
                        regions += 1
                        decoded += vertices - info["clusters"]
                        largest = max(largest, vertices)
            print("%s, %d^3 boxes: %d regions, largest %d vertices; decoded past the base "
                  "clustered mesh %.3f times the mesh's (%d / %d)"
                  % (os.path.basename(path), n, regions, largest, decoded / past, decoded, past))


if __name__ == "__main__":
    main()
