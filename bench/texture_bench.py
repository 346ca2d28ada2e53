#!/usr/bin/env python3
"""What per-corner texture coordinates cost: pomar against Draco in the same run.

    python3 bench/texture_bench.py [--data DIR] [--build DIR] [--generated N]

For every textured OBJ (the data folder's `textured/usb/usb.obj`,
`meshlab_bunny10k_textured.obj`, and a generated cube-mapped sphere of about N vertices:
6 charts, seams along the cube's edges), the texture coordinates' cost is a file size difference: the file
with them minus the file without them. pomar: `pomar encode` against `pomar encode --drop
texcoords` (default options: random access, 12-bit positions, 12-bit texture coordinates).
Draco 1.5.5: `draco_encoder -qp 12 -qt 12 -cl 10` on the OBJ against the same OBJ without
its `vt`, `mtllib` and `usemtl` lines (the faces' `/vt` removed). Also: the seam edges and
wedge copies (`pomar encode` prints them), the base mesh vertices with and without
texture coordinates (`pomar info --json`), and a `pomar verify` of the decoded file.
A second table breaks pomar's cost down (bytes with minus bytes without, from `pomar info
--json`): the base mesh block, the ATTR section (the base mesh's attribute codes), the
encoder's estimate of the wedge texture coordinates in the levels and cluster blocks,
the rest of the levels and blocks (the copies' positions and connectivity, the blocks'
own ends), the cluster index, the model tables, the MATL and LSLS sections, the sections
that grow with the cluster count (CERR stored errors, BCHK block checks) and the header
(with any other section).
A third table says why the base mesh is large: the input's seam vertices that may
collapse (twins: two wedges, two seam edges, off the boundary) and the locked ones (the
others: where three or more charts meet, or a seam meets the boundary), and the base mesh
with texture coordinates (`pomar decode --level 0` to OBJ): its vertices (one a cluster),
their distinct positions, its charts (connected sets of faces of the cut) and how many of
them are one triangle, and its vertices in one face only (a copy whose side of the seam
is one face: decimation keeps it, and its twin with it, since a collapse must leave a
face to the vertex it removes).
Markdown on stdout, progress on stderr.
"""
import argparse
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile


def run(cmd, **kw):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    if r.returncode != 0:
        sys.exit('texture_bench: %s failed (%d):\n%s%s' % (' '.join(cmd), r.returncode, r.stdout,
                                                          r.stderr))
    return r.stdout + r.stderr


def strip_texture(src, dst):
    """The OBJ without texture coordinates and materials."""
    with open(src) as f, open(dst, 'w') as out:
        for line in f:
            s = line.lstrip()
            if s.startswith(('vt ', 'mtllib', 'usemtl')):
                continue
            if s.startswith('f '):
                corners = []
                for c in s.split()[1:]:
                    parts = c.split('/')
                    corners.append(parts[0] + ('//' + parts[2] if len(parts) > 2 and parts[2] else ''))
                line = 'f ' + ' '.join(corners) + '\n'
            out.write(line)


def cube_mapped_sphere(path, n, seed=3):
    """A noisy sphere (a latitude-longitude grid of about n vertices, radii jittered by 1%)
    whose faces go to the chart of their centroid's dominant axis: 6 charts in a 3 x 2
    atlas, the seams along the cube's edges."""
    rng = random.Random(seed)
    rows = max(4, int(math.sqrt(n / 2.0)))
    cols = 2 * rows
    pos = [(0.0, 0.0, 1.0)]
    for i in range(1, rows):
        th = math.pi * i / rows
        for j in range(cols):
            ph = 2 * math.pi * j / cols
            r = 1 + 0.01 * (rng.random() - 0.5)
            pos.append((r * math.sin(th) * math.cos(ph), r * math.sin(th) * math.sin(ph),
                        r * math.cos(th)))
    pos.append((0.0, 0.0, -1.0))
    south = len(pos) - 1

    def ring(i, j):
        return 1 + (i - 1) * cols + j % cols

    faces = []
    for j in range(cols):
        faces.append((0, ring(1, j), ring(1, j + 1)))
        faces.append((south, ring(rows - 1, j + 1), ring(rows - 1, j)))
    for i in range(1, rows - 1):
        for j in range(cols):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            faces.append((a, c, d))
            faces.append((a, d, b))
    with open(path, 'w') as out:
        for p in pos:
            out.write('v %.7f %.7f %.7f\n' % p)
        vt, corners = {}, []
        for fa in faces:
            cen = [sum(pos[v][j] for v in fa) / 3 for j in range(3)]
            axis = max(range(3), key=lambda j: abs(cen[j]))
            chart = axis + (3 if cen[axis] < 0 else 0)
            cs = []
            for v in fa:
                q = pos[v]
                s = 0.5 + 0.45 * max(-1.0, min(1.0, q[(axis + 1) % 3]))
                t = 0.5 + 0.45 * max(-1.0, min(1.0, q[(axis + 2) % 3]))
                key = ('%.6f' % ((chart % 3 + s) / 3), '%.6f' % ((chart // 3 + t) / 2))
                if key not in vt:
                    vt[key] = len(vt) + 1
                    out.write('vt %s %s\n' % key)
                cs.append(vt[key])
            corners.append(cs)
        for fa, cs in zip(faces, corners):
            out.write('f ' + ' '.join('%d/%d' % (v + 1, t) for v, t in zip(fa, cs)) + '\n')


def read_obj(path):
    """Positions (as read) and triangles of an OBJ, each corner a (v, vt) pair of 0-based
    indices (vt -1 if none); polygons fanned."""
    pos, nvt, tris = [], 0, []

    def index(t, n):
        i = int(t)
        return i - 1 if i > 0 else n + i
    with open(path) as f:
        for line in f:
            s = line.split()
            if not s:
                continue
            if s[0] == 'v':
                pos.append(tuple(s[1:4]))
            elif s[0] == 'vt':
                nvt += 1
            elif s[0] == 'f':
                cs = []
                for c in s[1:]:
                    parts = c.split('/')
                    vt = index(parts[1], nvt) if len(parts) > 1 and parts[1] else -1
                    cs.append((index(parts[0], len(pos)), vt))
                tris.extend((cs[0], cs[i], cs[i + 1]) for i in range(1, len(cs) - 1))
    return pos, tris


def seam_vertices(path):
    """The input's seam vertices: (twins, locked). A seam edge has two faces whose
    texture coordinate indices differ at either end (the indices, not the values: near
    enough to the encoder's bit-for-bit test on these files)."""
    _, tris = read_obj(path)
    edges = {}
    for t in tris:
        for k in range(3):
            a, b = t[k], t[(k + 1) % 3]
            key = (min(a[0], b[0]), max(a[0], b[0]))
            edges.setdefault(key, []).append({a[0]: a[1], b[0]: b[1]})
    seam, boundary, wedges = {}, set(), {}
    for (a, b), fs in edges.items():
        if len(fs) != 2:
            boundary.update((a, b))
        elif fs[0] != fs[1]:
            seam[a] = seam.get(a, 0) + 1
            seam[b] = seam.get(b, 0) + 1
    for t in tris:
        for v, vt in t:
            wedges.setdefault(v, set()).add(vt)
    twins = sum(1 for v, n in seam.items() if n == 2 and len(wedges[v]) == 2 and v not in boundary)
    return twins, len(seam) - twins


def base_charts(path):
    """The decoded base mesh (an OBJ of the cut): vertices, distinct positions, faces,
    charts, one-triangle charts, vertices in one face only."""
    pos, tris = read_obj(path)
    parent = list(range(len(pos)))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    for t in tris:
        for c in t[1:]:
            parent[find(c[0])] = find(t[0][0])
    faces = {}
    for t in tris:
        r = find(t[0][0])
        faces[r] = faces.get(r, 0) + 1
    valence = {}
    for t in tris:
        for v, _ in t:
            valence[v] = valence.get(v, 0) + 1
    return (len(pos), len(set(pos)), len(tris), len(faces),
            sum(1 for n in faces.values() if n == 1), sum(1 for n in valence.values() if n == 1))


def breakdown(w, o):
    """Where the bytes of the file with texture coordinates (`pomar info --json` w) go
    beyond those of the file without (o)."""
    def section(d, tag):
        return sum(x['bytes'] for x in d.get('sections', []) if x['name'] == tag)

    def levels(d):  # global levels and cluster blocks
        return sum(l.get('connectivity_bytes', 0) + l.get('geometry_bytes', 0)
                   for l in d['levels'][1:]) + d['cluster_bytes']
    uv = sum(a['bytes'] for a in w.get('attributes', []) if a['name'] == 'pomar:corner texcoord')
    d = {
        'base mesh': w['base_bytes'] - o['base_bytes'],
        'ATTR': section(w, 'ATTR') - section(o, 'ATTR'),
        'UV in levels': uv,
        'rest of levels': levels(w) - levels(o) - uv,
        'cluster index': w['index_bytes'] - o['index_bytes'],
        'model tables': w['tables_bytes'] - o['tables_bytes'],
        'MATL + LSLS': sum(section(w, t) - section(o, t) for t in ('MATL', 'LSLS')),
        'CERR + BCHK': sum(section(w, t) - section(o, t) for t in ('CERR', 'BCHK')),
        'header': w['header_bytes'] - o['header_bytes'],
    }
    rest = (w['total_bytes'] - o['total_bytes']) - sum(d.values())
    d['header'] += rest  # (anything else: other sections)
    return '%d / %d' % (o['clusters'], w['clusters']), d


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--data', default=os.path.join(here, '..', '..', 'shared', 'data'))
    ap.add_argument('--build', default=os.path.join(here, '..', 'build-test'))
    ap.add_argument('--generated', type=int, default=30000)
    a = ap.parse_args()
    pomar = os.path.join(a.build, 'codec', 'pomar')
    if not os.path.exists(pomar):
        sys.exit('texture_bench: no %s (build first)' % pomar)
    if not shutil.which('draco_encoder'):
        sys.exit('texture_bench: draco_encoder not found (Debian package draco)')
    tmp = tempfile.mkdtemp(prefix='pomar_texture_bench_')
    meshes = []
    for rel in ('textured/usb/usb.obj', 'meshlab_bunny10k_textured.obj'):
        p = os.path.join(a.data, rel)
        if os.path.exists(p):
            meshes.append((os.path.basename(p)[:-4], p))
        else:
            print('texture_bench: %s absent, skipped' % p, file=sys.stderr)
    if a.generated:
        g = os.path.join(tmp, 'sphere.obj')
        cube_mapped_sphere(g, a.generated)
        meshes.append(('cube-mapped sphere', g))
    rows, parts, bases = [], [], []
    for name, path in meshes:
        print('texture_bench: %s' % name, file=sys.stderr)
        plain = os.path.join(tmp, name.replace(' ', '_') + '_plain.obj')
        strip_texture(path, plain)
        with_uv = os.path.join(tmp, 'with.pomar')
        without = os.path.join(tmp, 'without.pomar')
        out = run([pomar, 'encode', path, with_uv])
        run([pomar, 'encode', path, without, '--drop', 'texcoords'])
        run([pomar, 'verify', path, with_uv])
        seams = re.search(r'(\d+) texture seam edges? \((\d+) vertex cop', out)
        info_with = json.loads(run([pomar, 'info', '--json', with_uv]))
        info_without = json.loads(run([pomar, 'info', '--json', without]))
        nv = info_without['vertices']
        drc_with, drc_without = os.path.join(tmp, 'with.drc'), os.path.join(tmp, 'without.drc')
        run(['draco_encoder', '-i', path, '-o', drc_with, '-qp', '12', '-qt', '12', '-cl', '10'])
        run(['draco_encoder', '-i', plain, '-o', drc_without, '-qp', '12', '-cl', '10'])
        parts.append((name, nv, breakdown(info_with, info_without)))
        base_obj = os.path.join(tmp, 'base.obj')
        run([pomar, 'decode', '-q', '--level', '0', with_uv, base_obj])
        bases.append((name, seam_vertices(path), base_charts(base_obj)))
        pc = os.path.getsize(with_uv) - os.path.getsize(without)
        dc = os.path.getsize(drc_with) - os.path.getsize(drc_without)
        rows.append((name, nv, seams.group(1) if seams else '0', seams.group(2) if seams else '0',
                     info_without['base_vertices'], info_with['base_vertices'],
                     os.path.getsize(without), os.path.getsize(with_uv), os.path.getsize(drc_without),
                     os.path.getsize(drc_with), pc, dc))
    print('| mesh | vertices | seam edges | wedge copies | base vertices without / with UVs '
          '| pomar without / with (bytes) | Draco without / with | UV cost pomar (bpv) '
          '| UV cost Draco (bpv) | pomar / Draco |')
    print('|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|')
    for r in rows:
        name, nv, se, wc, bw, bu, pw, pu, dw, du, pc, dc = r
        print('| %s | %d | %s | %s | %d / %d | %d / %d | %d / %d | %.2f | %.2f | %.2f |' %
              (name, nv, se, wc, bw, bu, pw, pu, dw, du, 8.0 * pc / nv, 8.0 * dc / nv,
               pc / dc if dc else float('nan')))
    keys = ['base mesh', 'ATTR', 'UV in levels', 'rest of levels', 'cluster index',
            'model tables', 'MATL + LSLS', 'CERR + BCHK', 'header']
    print()
    print('| mesh | clusters without / with | ' + ' | '.join(keys) + ' | total (bpv) |')
    print('|---|--:|' + '--:|' * len(keys) + '--:|')
    for name, nv, (clusters, d) in parts:
        print('| %s | %s | %s | %.2f |' % (name, clusters, ' | '.join('%+d' % d[k] for k in keys),
                                          8.0 * sum(d.values()) / nv))
    print()
    print('| mesh | seam vertices: twins / locked | base vertices (clusters) | their distinct '
          'positions | base faces | charts | one-triangle charts | vertices in one face |')
    print('|---|--:|--:|--:|--:|--:|--:|--:|')
    for name, (twins, locked), b in bases:
        print('| %s | %d / %d | %s |' % (name, twins, locked, ' | '.join('%d' % x for x in b)))
    shutil.rmtree(tmp)


if __name__ == '__main__':
    main()
