#!/usr/bin/env python3
"""A coloured Z-up test mesh for the viewer's browser test (web/test/browser_test.py
--coloured; web/test/run.sh encodes it with `pomar encode`).

    python3 web/test/coloured_mesh.py OUT.ply

An ellipsoid standing along Z (semi-axes 0.5, 0.6, 1.5: Z is the longest extent and 2.5 x
the Y extent, so the viewer's `up: auto` takes Z), a UV sphere of 128 x 96 quads split into
triangles, written as binary PLY with per-vertex red, green, blue: three bands along Z,
pure red at the bottom (z < -0.5), pure green in the middle, pure blue at the top (z >
0.5). Seen Z-up, red is at the bottom of the picture and blue at its top.
"""
import math
import struct
import sys

SEGMENTS, RINGS = 128, 96
AXES = (0.5, 0.6, 1.5)
BANDS = ((255, 0, 0), (0, 255, 0), (0, 0, 255))  # bottom, middle, top


def mesh():
    vertices = []  # (x, y, z, r, g, b)

    def vertex(x, y, z):
        band = 0 if z < -0.5 else 2 if z > 0.5 else 1
        vertices.append((x, y, z) + BANDS[band])
        return len(vertices) - 1

    bottom = vertex(0, 0, -AXES[2])
    rings = []
    for i in range(1, RINGS):
        theta = math.pi * i / RINGS  # from the bottom pole
        ring = []
        for j in range(SEGMENTS):
            phi = 2 * math.pi * j / SEGMENTS
            ring.append(vertex(AXES[0] * math.sin(theta) * math.cos(phi), AXES[1] * math.sin(theta) * math.sin(phi),
                               -AXES[2] * math.cos(theta)))
        rings.append(ring)
    top = vertex(0, 0, AXES[2])
    faces = []  # counter-clockwise seen from outside
    for j in range(SEGMENTS):
        k = (j + 1) % SEGMENTS
        faces.append((bottom, rings[0][k], rings[0][j]))
        faces.append((top, rings[-1][j], rings[-1][k]))
        for a, b in zip(rings, rings[1:]):
            faces.append((a[j], a[k], b[k]))
            faces.append((a[j], b[k], b[j]))
    return vertices, faces


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__.split('\n\n')[1])
    vertices, faces = mesh()
    header = ('ply\nformat binary_little_endian 1.0\ncomment web/test/coloured_mesh.py\n'
              f'element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n'
              'property uchar red\nproperty uchar green\nproperty uchar blue\n'
              f'element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n')
    with open(sys.argv[1], 'wb') as f:
        f.write(header.encode('ascii'))
        for v in vertices:
            f.write(struct.pack('<fffBBB', *v))
        for t in faces:
            f.write(struct.pack('<Biii', 3, *t))


if __name__ == '__main__':
    main()
