#!/usr/bin/env python3
"""Small PLY reader and the checks of tests/meshlab_plugin/meshlabserver_test.sh.

Reads ASCII and binary (little/big endian) PLY with any scalar vertex properties and a face
list property; positions are compared exactly (float32 values, as MeshLab and pomar write
them).

  plytool.py count MESH.ply                      -> "<vertices> <faces>"
  plytool.py contains RESULT.ply FULL.ply AXIS MIN
        every vertex of FULL with coordinate AXIS (x|y|z) > MIN that a face uses is a vertex
        of RESULT (a region decode shows the coded mesh: no vertex that no face uses)
  plytool.py colors MESH.ply                     -> "<distinct colours> <blue> <red>" (vertices
        whose colour is pure blue (0,0,255) / pure red (255,0,0)), over the vertices faces use
"""
import struct
import sys

SCALARS = {
    'char': 'b', 'int8': 'b', 'uchar': 'B', 'uint8': 'B',
    'short': 'h', 'int16': 'h', 'ushort': 'H', 'uint16': 'H',
    'int': 'i', 'int32': 'i', 'uint': 'I', 'uint32': 'I',
    'float': 'f', 'float32': 'f', 'double': 'd', 'float64': 'd',
}


def read_ply(path):
    """Returns {element name: list of dicts property -> value (a list for list properties)}."""
    with open(path, 'rb') as f:
        data = f.read()
    end = data.find(b'end_header')
    if not data.startswith(b'ply') or end < 0:
        raise ValueError(f'{path}: not a PLY file')
    body = data.index(b'\n', end) + 1
    elements = []  # (name, count, [(prop name, type, list count type or None)])
    fmt = None
    for line in data[:body].decode('ascii').splitlines():
        w = line.split()
        if not w:
            continue
        if w[0] == 'format':
            fmt = w[1]
        elif w[0] == 'element':
            elements.append((w[1], int(w[2]), []))
        elif w[0] == 'property':
            if w[1] == 'list':
                elements[-1][2].append((w[4], w[3], w[2]))
            else:
                elements[-1][2].append((w[2], w[1], None))
    out = {}
    if fmt == 'ascii':
        tokens = data[body:].split()
        pos = 0
        for name, count, props in elements:
            rows = []
            for _ in range(count):
                row = {}
                for pname, ptype, ltype in props:
                    conv = float if SCALARS[ptype] in 'fd' else int
                    if ltype is None:
                        row[pname] = conv(tokens[pos]); pos += 1
                    else:
                        n = int(tokens[pos]); pos += 1
                        row[pname] = [conv(t) for t in tokens[pos:pos + n]]; pos += n
                rows.append(row)
            out[name] = rows
        return out
    order = {'binary_little_endian': '<', 'binary_big_endian': '>'}[fmt]
    pos = body
    for name, count, props in elements:
        rows = []
        simple = all(l is None for _, _, l in props)
        if simple:  # one struct per element
            s = struct.Struct(order + ''.join(SCALARS[t] for _, t, _ in props))
            names = [p for p, _, _ in props]
            for _ in range(count):
                rows.append(dict(zip(names, s.unpack_from(data, pos))))
                pos += s.size
        else:
            for _ in range(count):
                row = {}
                for pname, ptype, ltype in props:
                    if ltype is None:
                        s = struct.Struct(order + SCALARS[ptype])
                        row[pname] = s.unpack_from(data, pos)[0]; pos += s.size
                    else:
                        cs = struct.Struct(order + SCALARS[ltype])
                        n = cs.unpack_from(data, pos)[0]; pos += cs.size
                        s = struct.Struct(order + SCALARS[ptype] * n)
                        row[pname] = list(s.unpack_from(data, pos)); pos += s.size
                rows.append(row)
        out[name] = rows
    return out


def positions(mesh):
    return [(v['x'], v['y'], v['z']) for v in mesh.get('vertex', [])]


def used_vertices(mesh):
    """The vertices a face uses (a lossless file keeps the others, with no cluster)."""
    used = set()
    for f in mesh.get('face', []):
        used.update(next(v for v in f.values() if isinstance(v, (list, tuple))))
    return used


def main(argv):
    cmd = argv[1]
    if cmd == 'count':
        m = read_ply(argv[2])
        print(len(m.get('vertex', [])), len(m.get('face', [])))
        return 0
    if cmd == 'contains':
        result = set(positions(read_ply(argv[2])))
        axis = 'xyz'.index(argv[4])
        lo = float(argv[5])
        full = read_ply(argv[3])
        used = used_vertices(full)
        wanted = [p for i, p in enumerate(positions(full)) if i in used and p[axis] > lo]
        missing = [p for p in wanted if p not in result]
        print(f'{len(wanted)} vertices with {argv[4]} > {lo}; {len(missing)} missing')
        for p in missing[:5]:
            print('  missing', p)
        return 1 if missing or not wanted else 0
    if cmd == 'colors':
        mesh = read_ply(argv[2])
        verts = [mesh['vertex'][i] for i in sorted(used_vertices(mesh))]
        if not verts or 'red' not in verts[0]:
            print('no per-vertex colours')
            return 1
        cols = [(v['red'], v['green'], v['blue']) for v in verts]
        print(len(set(cols)), cols.count((0, 0, 255)), cols.count((255, 0, 0)))
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == '__main__':
    sys.exit(main(sys.argv))
