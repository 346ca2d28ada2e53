"""pomar: progressive, randomly accessible compression of triangle meshes.

    import numpy as np, pomar
    data = pomar.encode(vertices, faces, bits=12)  # float32 (n, 3), uint32 (m, 3) -> bytes
    mesh = pomar.decode(data, level=5)             # pomar.Mesh: .vertices, .faces
    pomar.info(data)["levels"]                     # the keys of `pomar info --json`
    mesh = pomar.read("bunny.ply")                 # .ply .obj .off .stl .pomar
    pomar.write("bunny.pomar", mesh, bits=14)

Failures of the library raise pomar.Error (str(e) is the message, e.kind what went
wrong); arrays of the wrong dtype or shape raise TypeError / ValueError. encode, decode,
read, write and SelectiveDecoder.update release the GIL while they work.
"""

import os

from . import _pomar
from ._pomar import Error, info

__version__ = _pomar.__version__
__all__ = ["Mesh", "Error", "encode", "decode", "info", "read", "write", "SelectiveDecoder"]


class Mesh:
    """A triangle mesh: vertices float32 (n, 3), faces uint32 (m, 3), counter-clockwise
    seen from outside. Per-vertex attributes (issue 12) will be further fields, None when
    a mesh has none."""

    __slots__ = ("vertices", "faces", "damaged")

    def __init__(self, vertices, faces, damaged=()):
        self.vertices = vertices
        self.faces = faces
        #: blocks a decode with skip_damaged=True decoded around: dicts with "block"
        #: ("cluster 17", "level 9"), "problem" and "level_kept"; empty when intact.
        self.damaged = list(damaged)

    def __repr__(self):
        return f"pomar.Mesh({len(self.vertices)} vertices, {len(self.faces)} faces)"


def encode(vertices, faces=None, *, bits=12, clusters=0, cluster_ratio=0.01,
           progressive=False, memory_limit=None, progress=None):
    """Compress a manifold, consistently oriented triangle mesh into .pomar bytes.

    vertices: float32 array (n, 3), faces: uint32 array (m, 3), both C-contiguous; or a
    pomar.Mesh as the only argument. bits: quantization grid, 4..24. The file is random
    access (about cluster_ratio x vertices clusters, or `clusters`) unless progressive=True.
    memory_limit: bytes or "512M" / "auto" / "none" (default: the memory available).
    progress: None or a callable(fraction, stage) called now and then (Ctrl-C interrupts
    the call in any case; an exception raised by progress stops it and propagates).
    """
    if isinstance(vertices, Mesh):
        if faces is not None:
            raise TypeError("encode(mesh) takes no faces argument")
        vertices, faces = vertices.vertices, vertices.faces
    elif faces is None:
        raise TypeError("encode() needs faces (or a pomar.Mesh)")
    return _pomar.encode(vertices, faces, bits, clusters, cluster_ratio, progressive,
                         memory_limit, progress)


def decode(data, level=None, *, skip_damaged=False, memory_limit=None, progress=None):
    """Decode .pomar bytes (bytes, bytearray, memoryview) to a Mesh after `level`
    refinement levels (0 = base mesh, None = full resolution).

    skip_damaged=True decodes around damaged or missing blocks instead of raising (a
    damaged global level stops before it, a damaged cluster stays coarse) and lists them
    in mesh.damaged; damage in the header, base mesh or tables still raises pomar.Error.
    progress: as for encode()."""
    return Mesh(*_pomar.decode(data, level, skip_damaged, memory_limit, progress))


def read(path, level=None):
    """Read a mesh file: .ply .obj .off .stl (positions and triangles; what else the file
    carries is dropped), or .pomar (decoded after `level` levels, None = all)."""
    path = os.fspath(path)
    if path.lower().endswith(".pomar"):
        with open(path, "rb") as f:
            return decode(f.read(), level)
    if level is not None:
        raise ValueError("level applies to .pomar files only")
    vertices, faces, _report = _pomar.read_mesh(path)
    return Mesh(vertices, faces)


def write(path, mesh, *, binary=True, **encode_options):
    """Write a Mesh, replacing `path` atomically: .ply .stl (binary unless binary=False),
    .obj .off, or .pomar (encode_options as for encode(), e.g. bits=14)."""
    path = os.fspath(path)
    if path.lower().endswith(".pomar"):
        _pomar.write_bytes(path, encode(mesh, **encode_options))
        return
    if encode_options:
        raise TypeError(f"options {sorted(encode_options)} apply to .pomar files only")
    _pomar.write_mesh(path, mesh.vertices, mesh.faces, binary)


class SelectiveDecoder(_pomar.SelectiveDecoder):
    """Random access to a clustered .pomar file (a path or its bytes): decode the base
    clustered mesh, then refine chosen regions, reading only the blocks they need.

        d = pomar.SelectiveDecoder("dragon.pomar")
        d.want_sphere((0.01, 0.12, 0.0), 0.02)  # level=None: finest; or want_cluster/box
        d.update()
        part = d.mesh()                          # + d.vertex_cluster(), d.vertex_level()
        d.bytes_read

    One thread at a time per decoder (calls from several threads wait for each other).
    """

    def mesh(self):
        """The current mesh (after the last update())."""
        return Mesh(*self.mesh_arrays())
