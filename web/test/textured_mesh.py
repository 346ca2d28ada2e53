#!/usr/bin/env python3
"""A textured test mesh for the viewer's browser test (web/test/browser_test.py --textured;
web/test/run.sh encodes it with `pomar encode`).

    python3 web/test/textured_mesh.py OUT_DIR

Writes OUT_DIR/textured.obj (`mtllib`, `usemtl`, a `vt` per corner), OUT_DIR/textured.mtl
and two PNG textures (Python's zlib and struct, no imaging library): OUT_DIR/a.png and
OUT_DIR/maps/b.png (a texture name with a directory part).

The mesh is a unit cube centred at the origin, each face a grid of 16 x 16 quads split into
triangles, vertices shared between faces (one position), texture coordinates per face
chart: a cube-map atlas, so every cube edge is a texture seam. Material `sides` (a.png, a
2 x 2 atlas) holds the faces +X (red), -X (cyan) and -Y (magenta); material `caps`
(maps/b.png, two charts side by side) holds +Z, whose chart is blue in its upper half
(v > 0.5) and yellow in its lower half, and -Z (orange); material `lid`, without a
texture, `Kd 0 1 0` (green), holds +Y (its chart is a.png's fourth cell, painted green
too but not used). Texture coordinates follow the OBJ
convention: v = 0 at the bottom of the image. On the +Z face, v grows with y, so seen Y-up
from the +Z side the blue half is at the top. Each chart keeps a margin of 1/16 of its cell
to the cell's border, so filtering never mixes two charts.
"""
import os
import struct
import sys
import zlib

N = 16  # quads along a face's side
CELL = 64  # pixels of an atlas cell's side

RED, GREEN, BLUE = (255, 0, 0), (0, 255, 0), (0, 0, 255)
CYAN, MAGENTA, YELLOW, ORANGE = (0, 255, 255), (255, 0, 255), (255, 255, 0), (255, 128, 0)

# Face: (normal axis, sign, the axes of its chart's u and v (as (axis, sign)), material,
# atlas cell (column, row from the bottom of the image)).
FACES = {
    '+x': (0, 1, ((2, -1), (1, 1)), 'sides', (0, 1)),
    '-x': (0, -1, ((2, 1), (1, 1)), 'sides', (1, 1)),
    '+y': (1, 1, ((0, 1), (2, -1)), 'lid', (0, 0)),
    '-y': (1, -1, ((0, 1), (2, 1)), 'sides', (1, 0)),
    '+z': (2, 1, ((0, 1), (1, 1)), 'caps', (0, 0)),
    '-z': (2, -1, ((0, -1), (1, 1)), 'caps', (1, 0)),
}
# Material: texture (or None), atlas cells along u and v, diffuse colour.
MATERIALS = {'sides': ('a.png', 2, 2, '1 1 1'), 'caps': ('maps/b.png', 2, 1, '1 1 1'), 'lid': (None, 2, 2, '0 1 0')}


def cell_colour(material, column, row, v_in_cell):
    """The colour of a texel in atlas cell (column, row), at height v_in_cell (0..1) in it."""
    if material == 'sides':
        return {(0, 1): RED, (1, 1): CYAN, (0, 0): GREEN, (1, 0): MAGENTA}[(column, row)]
    if column == 0:
        return BLUE if v_in_cell > 0.5 else YELLOW
    return ORANGE


def png(path, width, height, pixel):
    """Write an RGB PNG; pixel(x, y) with y from the top row."""
    rows = b''.join(b'\0' + b''.join(bytes(pixel(x, y)) for x in range(width)) for y in range(height))

    def chunk(kind, data):
        return struct.pack('>I', len(data)) + kind + data + struct.pack('>I', zlib.crc32(kind + data) & 0xffffffff)

    with open(path, 'wb') as f:
        f.write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', width, height, 8, 2, 0, 0, 0)) +
                chunk(b'IDAT', zlib.compress(rows, 9)) + chunk(b'IEND', b''))


def texture(path, material):
    _, columns, rows, _ = MATERIALS[material]
    width, height = columns * CELL, rows * CELL

    def pixel(x, y):
        v = 1 - (y + 0.5) / height  # image row y from the top: v = 1 at the top (OBJ)
        row = min(rows - 1, int(v * rows))
        return cell_colour(material, x // CELL, row, v * rows - row)

    png(path, width, height, pixel)


def mesh():
    """Positions (shared between faces), and per face of the cube its triangles as
    (position index, texcoord) corners, grouped by material."""
    index = {}
    positions = []
    faces = {m: [] for m in MATERIALS}  # material -> [((p, (u, v)), x3)]
    for name, (axis, sign, (ua, va), material, (column, row)) in FACES.items():
        _, columns, rows, _ = MATERIALS[material]
        margin = 1 / 16

        def corner(i, j):
            # Grid point (i, j) of the face: chart coordinates s, t in 0..1 along u and v.
            s, t = i / N, j / N
            g = [0, 0, 0]  # integer grid coordinates in -N..N (shared between faces)
            g[axis] = sign * N
            g[ua[0]] = ua[1] * (2 * i - N)
            g[va[0]] = va[1] * (2 * j - N)
            key = tuple(g)
            if key not in index:
                index[key] = len(positions)
                positions.append(tuple(c / (2 * N) for c in g))
            u = (column + margin + (1 - 2 * margin) * s) / columns
            v = (row + margin + (1 - 2 * margin) * t) / rows
            return index[key], (u, v)

        for i in range(N):
            for j in range(N):
                a, b, c, d = corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1)
                faces[material] += [(a, b, c), (a, c, d)]
    return positions, faces


def orientation_fix(positions, faces):
    """Make every triangle counter-clockwise seen from outside (its normal points away from
    the centre)."""
    out = {}
    for material, tris in faces.items():
        fixed = []
        for t in tris:
            p = [positions[c[0]] for c in t]
            e1 = [p[1][k] - p[0][k] for k in range(3)]
            e2 = [p[2][k] - p[0][k] for k in range(3)]
            n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
            centre = [sum(q[k] for q in p) / 3 for k in range(3)]
            fixed.append(t if sum(n[k] * centre[k] for k in range(3)) > 0 else (t[0], t[2], t[1]))
        out[material] = fixed
    return out


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__.split('\n\n')[1])
    out = sys.argv[1]
    os.makedirs(os.path.join(out, 'maps'), exist_ok=True)
    positions, faces = mesh()
    faces = orientation_fix(positions, faces)
    with open(os.path.join(out, 'textured.mtl'), 'w') as f:
        for material, (name, _, _, kd) in MATERIALS.items():
            f.write(f'newmtl {material}\nKd {kd}\n' + (f'map_Kd {name}\n' if name else '') + '\n')
    with open(os.path.join(out, 'textured.obj'), 'w') as f:
        f.write('# web/test/textured_mesh.py: a cube with a cube-map atlas in two textures\nmtllib textured.mtl\n')
        for p in positions:
            f.write('v %.6f %.6f %.6f\n' % p)
        vt = 0
        for material, tris in faces.items():
            for t in tris:
                for _, (u, v) in t:
                    f.write('vt %.6f %.6f\n' % (u, v))
        for material, tris in faces.items():
            f.write(f'usemtl {material}\n')
            for t in tris:
                f.write('f ' + ' '.join(f'{c[0] + 1}/{vt + k + 1}' for k, c in enumerate(t)) + '\n')
                vt += 3
    for material, (name, _, _, _) in MATERIALS.items():
        if name:
            texture(os.path.join(out, name), material)


if __name__ == '__main__':
    main()
