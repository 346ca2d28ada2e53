#!/usr/bin/env python3
"""Bits per vertex of per-vertex attributes: pomar against Draco in the same run.

    python3 bench/attributes_bench.py [--data DIR] [--build DIR] [--runs N]

For every mesh, each attribute's cost is measured as a file size difference: the file with
the attribute minus the file without it (pomar: `encode --drop`; Draco: the same mesh written
as a PLY without that property), in bits per vertex of the encoded mesh. pomar also reports
the encoder's estimate of each attribute's bytes (`info --json`). Draco runs with -cl 7 and -cl 10, its
-qp set to pomar's --bits and -qn to pomar's --normal-bits (its octahedral normal grid has the
same number of bits per coordinate); colour is 8-bit and exact in both. Draco's PLY reader
keeps position, normal, colour and texture coordinates only: named scalars (confidence,
intensity, quality) are "n/a" for it. Also: encode and decode time of the mesh with and
without its attributes, and the decode of the file with attributes with `--no-attributes`
(CPU seconds, user + system, the least of --runs; decode writes a binary PLY). Besides the data folder's meshes: samples/bunny.ply
and a generated noisy sphere (`pomar_gen_mesh`, --sphere vertices) given generated
attributes (colour from the position, radial normals, a smooth quality, spherical UVs).
Markdown on stdout, progress on stderr.
"""
import math
import argparse
import json
import os
import resource
import shutil
import struct
import subprocess
import sys
import tempfile

TYPES = {'char': 'b', 'int8': 'b', 'uchar': 'B', 'uint8': 'B', 'short': 'h', 'int16': 'h',
         'ushort': 'H', 'uint16': 'H', 'int': 'i', 'int32': 'i', 'uint': 'I', 'uint32': 'I',
         'float': 'f', 'float32': 'f', 'double': 'd', 'float64': 'd'}


def read_ply(path):
    """Vertex properties (name, type, values) and faces (lists) of a PLY file."""
    data = open(path, 'rb').read()
    end = data.index(b'end_header') + len(b'end_header')
    end = data.index(b'\n', end) + 1
    header = data[:end].decode('latin-1').splitlines()
    fmt = header[1].split()[1]
    elements = []
    for line in header:
        t = line.split()
        if t[:1] == ['element']:
            elements.append((t[1], int(t[2]), []))
        elif t[:1] == ['property']:
            elements[-1][2].append(t[1:])
    pos = [end]
    if fmt == 'ascii':
        tokens = data[end:].split()
        pos = [0]

        def value(t):
            pos[0] += 1
            v = tokens[pos[0] - 1]
            return float(v) if TYPES[t] in 'fd' else int(v)
    else:
        assert fmt == 'binary_little_endian', fmt

        def value(t):
            pos[0] += struct.calcsize(TYPES[t])
            return struct.unpack_from('<' + TYPES[t], data, pos[0] - struct.calcsize(TYPES[t]))[0]
    vertex_props, vertices, faces = [], [], []
    for name, count, props in elements:
        for _ in range(count):
            row = []
            for p in props:
                if p[0] == 'list':
                    n = value(p[1])
                    row.append([value(p[2]) for _ in range(n)])
                else:
                    row.append(value(p[0]))
            if name == 'vertex':
                vertices.append(row)
            elif name == 'face':
                faces.append(row[0])
        if name == 'vertex':
            vertex_props = props
    return vertex_props, vertices, faces


def write_ply(path, props, vertices, faces, keep):
    """A binary PLY with the vertex properties named in `keep` (x, y, z always)."""
    idx = [i for i, p in enumerate(props) if p[-1] in ('x', 'y', 'z') or p[-1] in keep]
    lines = ['ply', 'format binary_little_endian 1.0', 'element vertex %d' % len(vertices)]
    lines += ['property %s %s' % (props[i][0], props[i][1]) for i in idx]
    lines += ['element face %d' % len(faces), 'property list uchar int vertex_indices',
              'end_header']
    fmt = '<' + ''.join(TYPES[props[i][0]] for i in idx)
    out = bytearray(('\n'.join(lines) + '\n').encode())
    for row in vertices:
        out += struct.pack(fmt, *[row[i] for i in idx])
    for f in faces:
        out += struct.pack('<B%di' % len(f), len(f), *f)
    open(path, 'wb').write(bytes(out))


def with_generated_attributes(props, vertices):
    """Adds red green blue, nx ny nz, quality, texture_u texture_v to x y z rows."""
    props = props + [['uchar', c] for c in ('red', 'green', 'blue')] + \
        [['float', c] for c in ('nx', 'ny', 'nz', 'quality', 'texture_u', 'texture_v')]
    lo = [min(v[k] for v in vertices) for k in range(3)]
    hi = [max(v[k] for v in vertices) for k in range(3)]
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    size = max(b - a for a, b in zip(lo, hi)) or 1.0
    rows = []
    for v in vertices:
        d = [(v[k] - centre[k]) / size for k in range(3)]
        r = math.sqrt(sum(x * x for x in d)) or 1.0
        rgb = [int(127.5 + 120 * math.sin(6 * d[k] + k)) for k in range(3)]
        rows.append(v[:3] + rgb + [d[0] / r, d[1] / r, d[2] / r, 100 * d[0] * d[1],
                                   0.5 + math.atan2(d[1], d[0]) / (2 * math.pi), 0.5 + d[2]])
    return props, rows


GENERATED_GROUPS = {'colour': (['red', 'green', 'blue'], 'colour'),
                    'normals': (['nx', 'ny', 'nz'], 'normals'),
                    'quality': (['quality'], 'scalars'),
                    'texcoords': (['texture_u', 'texture_v'], 'texcoords')}


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        raise RuntimeError('%s failed: %s' % (' '.join(cmd), r.stderr.strip()))
    return r.stdout


def timed(cmd, runs):
    """CPU seconds (user + system) of the command, the smallest of `runs`: on a shared,
    loaded machine wall-clock ratios mostly measure the other processes."""
    times = []
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        run(cmd)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        times.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return min(times)


# (file, attribute groups: label -> (PLY properties, pomar --drop word)), extra encode flags
MESHES = [
    ('armadillo_photo_colour.ply', {'colour': (['red', 'green', 'blue'], 'colour')}, []),
    ('meshlab_many_small_holes.ply',
     {'colour RGBA': (['red', 'green', 'blue', 'alpha'], 'colour'),
      'quality': (['quality'], 'scalars')}, ['--repair']),
    ('bunny.ply', {'confidence + intensity': (['confidence', 'intensity'], 'scalars')}, []),
    ('horse.ply', {'normals': (['nx', 'ny', 'nz'], 'normals')}, []),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument('--data', default=os.path.join(here, '..', '..', 'shared', 'data'))
    ap.add_argument('--build', default='build')
    ap.add_argument('--runs', type=int, default=5)
    ap.add_argument('--bits', type=int, default=12)
    ap.add_argument('--normal-bits', type=int, default=9)
    ap.add_argument('--sphere', type=int, default=200000,
                    help='vertices of the generated noisy sphere (0: none)')
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix='pomar-attr-bench.')
    pomar = os.path.join(tmp, 'pomar')
    shutil.copy(os.path.join(a.build, 'codec', 'pomar'), pomar)
    meshes = [(os.path.join(a.data, n), n, g, f, False) for n, g, f in MESHES]
    meshes.append((os.path.join(here, '..', 'samples', 'bunny.ply'),
                   'samples/bunny.ply + generated', GENERATED_GROUPS, [], True))
    if a.sphere:
        sphere = os.path.join(tmp, 'sphere.ply')
        run([os.path.join(a.build, 'bench', 'pomar_gen_mesh'), 'noisy_sphere', str(a.sphere),
             sphere])
        meshes.append((sphere, 'noisy_sphere + generated', GENERATED_GROUPS, [], True))
    rows, times = [], []
    try:
        for src, name, groups, flags, generate in meshes:
            if not os.path.exists(src):
                print('skip %s (absent)' % name, file=sys.stderr)
                continue
            print('measuring %s' % name, file=sys.stderr)
            props, vertices, faces = read_ply(src)
            if generate:
                props, vertices = with_generated_attributes(props, vertices)
            all_props = [p for g in groups.values() for p in g[0]]
            full = os.path.join(tmp, 'full.ply')
            write_ply(full, props, vertices, faces, all_props)
            out = os.path.join(tmp, 'o.pomar')
            enc = [pomar, 'encode', '-q', '--bits', str(a.bits), '--normal-bits',
                   str(a.normal_bits)] + flags
            run(enc + [full, out])
            info = json.loads(run([pomar, 'info', '--json', out]))
            nv = info['vertices']
            with_size = os.path.getsize(out)
            t_enc = timed(enc + [full, out], a.runs)
            t_dec = timed([pomar, 'decode', '-q', out, os.path.join(tmp, 'd.ply')], a.runs)
            t_skip = timed([pomar, 'decode', '-q', '--no-attributes', out,
                            os.path.join(tmp, 'd.ply')], a.runs)
            plain = os.path.join(tmp, 'plain.ply')
            write_ply(plain, props, vertices, faces, [])
            t_enc_no = timed(enc + [plain, out], a.runs)
            run(enc + [plain, out])
            t_dec_no = timed([pomar, 'decode', '-q', out, os.path.join(tmp, 'd.ply')], a.runs)
            times.append((name, nv, t_enc_no, t_enc, t_dec_no, t_dec, t_skip))
            for label, (ply_props, drop) in groups.items():
                # pomar: the file with everything minus the file without this group
                run(enc + ['--drop', drop, full, out])
                pomar_bpv = 8.0 * (with_size - os.path.getsize(out)) / nv
                names = {'colour': ['colour'], 'normals': ['normal'], 'texcoords': ['texcoord'],
                         'scalars': ply_props}[drop]
                stream = sum(x['bytes'] for x in info['attributes'] if x['name'] in names)
                precision = ', '.join(
                    'exact' if x['exact'] else '%d bits, <= %.3g%s' % (
                        x['bits'], x['bound'], ' deg' if x['kind'] == 'normal' else '')
                    for x in info['attributes'] if x['name'] in names)
                draco = []
                for cl in (7, 10):
                    sizes = []
                    for keep in (all_props, [p for p in all_props if p not in ply_props]):
                        ply = os.path.join(tmp, 'k.ply')
                        write_ply(ply, props, vertices, faces, keep)
                        drc = os.path.join(tmp, 'k.drc')
                        run(['draco_encoder', '-i', ply, '-o', drc, '-cl', str(cl), '-qp',
                             str(a.bits), '-qn', str(a.normal_bits), '-qt', '12', '-qg', '16'])
                        sizes.append(os.path.getsize(drc))
                    diff = 8.0 * (sizes[0] - sizes[1]) / nv
                    draco.append(diff if sizes[0] != sizes[1] else None)
                rows.append((name, nv, label, precision, pomar_bpv, 8.0 * stream / nv, draco[0],
                             draco[1]))
    finally:
        shutil.rmtree(tmp)

    fmt = lambda x: 'n/a' if x is None else '%.2f' % x
    print('| mesh | vertices | attribute | pomar precision | pomar bpv | pomar estimate bpv | '
          'Draco -cl 7 bpv | Draco -cl 10 bpv |')
    print('|:--|--:|:--|:--|--:|--:|--:|--:|')
    for r in rows:
        print('| %s | %d | %s | %s | %s | %s | %s | %s |' % (r[0], r[1], r[2], r[3], fmt(r[4]),
                                                         fmt(r[5]), fmt(r[6]), fmt(r[7])))
    print()
    print('| mesh | vertices | encode CPU s (no attributes) | encode CPU s (attributes) | '
          'decode CPU s (no attributes) | decode CPU s (attributes) | decode ratio | '
          'decode CPU s (attributes, --no-attributes) | its ratio |')
    print('|:--|--:|--:|--:|--:|--:|--:|--:|--:|')
    for t in times:
        print('| %s | %d | %.3f | %.3f | %.3f | %.3f | %.2f | %.3f | %.2f |' % (
            t[:6] + (t[5] / t[4], t[6], t[6] / t[4])))
    return 0


if __name__ == '__main__':
    sys.exit(main())
