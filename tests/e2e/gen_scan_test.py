#!/usr/bin/env python3
"""pomar_gen_mesh scan: the streamed scan-like mesh is what bench/scan_mesh.h says.

usage: gen_scan_test.py POMAR_GEN_MESH POMAR

Checks, on small meshes: the PLY's header and size, determinism per seed, the components
and holes (connected components, boundary loops), every vertex used, every edge manifold and
consistently oriented, a lossless round trip through pomar, and that the generator's memory
does not grow with the mesh (peak RSS at 500k vertices below what holding it would take).
"""
import os
import struct
import subprocess
import sys
import tempfile

GEN, POMAR = sys.argv[1], sys.argv[2]
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def gen(args, out):
    r = subprocess.run([GEN, "scan"] + [str(a) for a in args[:1]] + [out] + [str(a) for a in args[1:]],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit("pomar_gen_mesh failed: " + r.stderr)
    return r.stdout


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    nv = int(header.split("element vertex ")[1].split()[0])
    nf = int(header.split("element face ")[1].split()[0])
    check("format binary_little_endian 1.0" in header, path + ": binary little-endian")
    check(len(data) == end + 12 * nv + 13 * nf, path + ": size = header + 12 V + 13 F")
    faces = []
    off = end + 12 * nv
    not_triangles = 0
    for f in range(nf):
        n, a, b, c = struct.unpack_from("<BIII", data, off + 13 * f)
        not_triangles += n != 3
        faces.append((a, b, c))
    check(not_triangles == 0, path + ": every face a triangle")
    check(all(max(t) < nv for t in faces), path + ": indices in range")
    return nv, faces


def topology(nv, faces):
    """(components, boundary loops, unused vertices, bad edges)"""
    parent = list(range(nv))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    directed = {}
    used = [False] * nv
    for a, b, c in faces:
        for u, v in ((a, b), (b, c), (c, a)):
            directed[(u, v)] = directed.get((u, v), 0) + 1
            used[u] = True
            parent[find(u)] = find(v)
    bad = sum(1 for k, n in directed.items() if n > 1)  # an edge twice in one direction
    # Boundary halfedges: no opposite; each boundary vertex has one outgoing one.
    nxt = {}
    for (u, v) in directed:
        if (v, u) not in directed:
            if u in nxt:
                bad += 1
            nxt[u] = v
    loops, seen = 0, set()
    for start in nxt:
        if start in seen:
            continue
        loops += 1
        v = start
        while v not in seen:
            seen.add(v)
            v = nxt.get(v, start)
    comps = len({find(v) for v in range(nv) if used[v]})
    return comps, loops, used.count(False), bad


with tempfile.TemporaryDirectory() as tmp:
    # Bounded memory: holding 500k vertices and 1M faces takes 18 MB (floats and indices);
    # the stream keeps a few rings.
    big = os.path.join(tmp, "big.ply")
    if os.path.exists("/usr/bin/time"):
        r = subprocess.run(["/usr/bin/time", "-f", "%M", GEN, "scan", "500000", big],
                           capture_output=True, text=True)
        peak_kib = int(r.stderr.strip().splitlines()[-1])
        check(peak_kib < 10 * 1024, "peak RSS at 500k vertices: %d KiB" % peak_kib)
    else:
        print("skipped the peak RSS check: no /usr/bin/time")
        gen([500000], big)
    check(os.path.getsize(big) > 18 * 1000 * 1000, "the 500k file holds the mesh")


    a = os.path.join(tmp, "a.ply")
    out = gen([6000, 7], a)
    nv, faces = read_ply(a)
    check(out.strip() == "%s: %d vertices, %d faces" % (a, nv, len(faces)), "printed counts: " + out)
    check(5000 <= nv <= 6000, "about 6000 vertices: %d" % nv)
    comps, loops, unused, bad = topology(nv, faces)
    check(comps == 5, "5 components: %d" % comps)
    check(loops == 6, "6 holes (3 + 1 + 1 + 1 + 0): %d boundary loops" % loops)
    check(unused == 0, "every vertex used: %d unused" % unused)
    check(bad == 0, "manifold, consistently oriented: %d bad edges" % bad)

    b = os.path.join(tmp, "b.ply")
    gen([6000, 7], b)
    check(open(a, "rb").read() == open(b, "rb").read(), "same seed: same bytes")
    gen([6000, 8], b)
    check(open(a, "rb").read() != open(b, "rb").read(), "another seed: another mesh")

    one = os.path.join(tmp, "one.ply")
    gen([3000, 1, 1], one)
    comps, loops, unused, bad = topology(*read_ply(one))
    check((comps, loops, unused, bad) == (1, 3, 0, 0), "1 component, 3 holes: %s" % ((comps, loops, unused, bad),))

    p = os.path.join(tmp, "a.pomar")
    r = subprocess.run([POMAR, "encode", "--quiet", a, p], capture_output=True, text=True)
    check(r.returncode == 0, "pomar encode: " + r.stderr)
    r = subprocess.run([POMAR, "verify", a, p], capture_output=True, text=True)
    check(r.returncode == 0, "pomar verify: " + r.stdout + r.stderr)
    r = subprocess.run([POMAR, "info", p], capture_output=True, text=True)
    check("section" not in r.stdout.lower() or "lsls" not in r.stdout.lower(),
          "a clean mesh: no lossless record")

if failures:
    print("%d failure(s)" % len(failures))
    sys.exit(1)
print("ok")
