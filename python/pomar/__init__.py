"""pomar: progressive, randomly accessible compression of triangle meshes.

    import numpy as np, pomar
    data = pomar.encode(vertices, faces, bits=12)  # float32 (n, 3), uint32 (m, 3) -> bytes
    mesh = pomar.decode(data, level=5)             # pomar.Mesh: .vertices, .faces
    pomar.info(data)["levels"]                     # the keys of `pomar info --json`
    mesh = pomar.read("bunny.ply")                 # .ply .obj .off .stl .pomar
    mesh.colors, mesh.normals, mesh.scalars        # per-vertex attributes (None / {} if absent)
    pomar.write("bunny.pomar", mesh, bits=14)

Failures of the library raise pomar.Error (str(e) is the message, e.kind what went
wrong); arrays of the wrong dtype or shape raise TypeError / ValueError. encode, decode,
read, write and SelectiveDecoder.update release the GIL while they work.
"""

import os
import warnings

from . import _pomar
from ._pomar import Error, info

__version__ = _pomar.__version__
__all__ = ["Mesh", "Error", "encode", "decode", "info", "read", "write", "SelectiveDecoder"]


class Mesh:
    """A triangle mesh: vertices float32 (n, 3), faces uint32 (m, 3), counter-clockwise
    seen from outside, and optional per-vertex attributes, one row per vertex:

    colors: uint8 (n, 3) RGB or (n, 4) RGBA, or None (always stored exactly)
    normals: float32 (n, 3), or None
    scalars: dict name -> float32 (n,) (MeshLab's "quality", PLY "confidence", ...)
    texcoords: float32 (n, 2) (u, v), or None; texture_files: the images they refer to

    and, for textured meshes (photogrammetry scans, OBJ `f v/vt`, PLY face texcoord):

    corner_texcoords: float32 (m, 3, 2), u, v of each corner of each face, or None
    face_materials: uint32 (m,), each face's index into materials, or None
    materials: list of dicts {"name": str, "texture": int (index into texture_files, -1
        for none), "properties": str (an OBJ material's other MTL lines, as read)}
    texture_images: per texture file, its image file's bytes or None: encode() embeds
        them (one self-contained .pomar), decode() gives them back bit for bit
    attribute_info: of a decoded mesh, one dict per attribute with "kind", "name",
        "components", "bits" (0 = exact), "exact" and "bound" (the largest error against
        the input: normals in degrees, scalars and texcoords absolute per component)
    source: the file read() or a SelectiveDecoder read it from (None otherwise): write()
        refuses to replace that file unless overwrite=True
    """

    __slots__ = ("vertices", "faces", "damaged", "colors", "normals", "scalars", "texcoords",
                 "texture_files", "corner_texcoords", "face_materials", "materials",
                 "texture_images", "attribute_info", "source")

    def __init__(self, vertices, faces, damaged=(), *, colors=None, normals=None, scalars=None,
                 texcoords=None, texture_files=(), corner_texcoords=None, face_materials=None,
                 materials=(), texture_images=(), attribute_info=(), source=None):
        self.vertices = vertices
        self.faces = faces
        #: blocks a decode with skip_damaged=True decoded around: dicts with "block"
        #: ("cluster 17", "level 9"), "problem" and "level_kept"; empty when intact.
        self.damaged = list(damaged)
        self.colors = colors
        self.normals = normals
        self.scalars = dict(scalars or {})
        self.texcoords = texcoords
        self.texture_files = list(texture_files)
        self.corner_texcoords = corner_texcoords
        self.face_materials = face_materials
        self.materials = [dict(m) for m in materials]
        self.texture_images = list(texture_images)
        self.attribute_info = list(attribute_info)
        self.source = source

    def _attributes(self):
        """The attribute fields as the keyword arguments of _pomar's encode/write_mesh."""
        return {key: getattr(self, key, None)
                for key in ("colors", "normals", "scalars", "texcoords", "texture_files",
                            "corner_texcoords", "face_materials", "materials",
                            "texture_images")}

    def __repr__(self):
        kinds = [name for name in ("colors", "normals", "texcoords", "corner_texcoords")
                 if getattr(self, name) is not None]
        if self.materials:
            kinds.append(f"{len(self.materials)} materials")
        kinds += [f"scalar {name!r}" for name in self.scalars]
        extra = f", {', '.join(kinds)}" if kinds else ""
        return f"pomar.Mesh({len(self.vertices)} vertices, {len(self.faces)} faces{extra})"


def _check_threads(threads):
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 0:
        raise ValueError("threads must be an integer >= 0 (0: every core), not %r" % (threads,))


def encode(vertices, faces=None, *, bits=12, clusters=0, cluster_ratio=0.01,
           progressive=False, memory_limit=None, progress=None, colors=None, normals=None,
           scalars=None, texcoords=None, texture_files=None, normal_bits=9, scalar_bits=16,
           texcoord_bits=12, exact_attributes=False, strict=False, keep_order=False,
           threads=0, stored_errors=True, block_order="spatial"):
    """Compress a triangle mesh into .pomar bytes.

    vertices: float32 array (n, 3), faces: uint32 array (m, 3), both C-contiguous; or a
    pomar.Mesh as the only argument (its attributes are encoded; the attribute keywords
    replace a field). Per-vertex attributes as the fields of pomar.Mesh: colors (exact),
    normals (octahedral, normal_bits 4..16 a coordinate: 9 keeps them within 0.33 degrees),
    scalars (dict, scalar_bits 1..24 over each one's range), texcoords (texcoord_bits
    1..24 over the range of u and of v); exact_attributes=True stores every float bit for
    bit (NaN and infinities included, which are an error otherwise).
    bits: quantization grid of the positions, 4..24. The file is random
    access (about cluster_ratio x vertices clusters, or `clusters`) unless progressive=True.
    memory_limit: bytes or "512M" / "auto" / "none" (default: the memory available).
    progress: None or a callable(fraction, stage) called now and then (Ctrl-C interrupts
    the call in any case; an exception raised by progress stops it and propagates).
    Messy meshes (non-manifold, inconsistently oriented, duplicate or degenerate faces,
    unreferenced vertices) are stored losslessly; strict=True refuses them instead
    (pomar.Error, kind "invalid_mesh") and drops unreferenced vertices. keep_order=True
    also stores the input vertex numbering (a full decode gives the vertices back in the
    input order). threads: for the encoder's parallel steps, 0 = every core this process
    may use (the bytes do not depend on it).
    Random-access files also store, by default, a geometric error per cluster and level
    (stored_errors=False leaves it out: about 3% smaller, and SelectiveDecoder.want_view
    estimates the errors from edge lengths) and their cluster blocks in the spatial
    (Morton) order of the clusters (block_order="id": in cluster id order).
    """
    _check_threads(threads)
    if block_order not in ("spatial", "id"):
        raise ValueError("block_order must be 'spatial' or 'id' (got %r)" % (block_order,))
    given = {"colors": colors, "normals": normals, "scalars": scalars, "texcoords": texcoords,
             "texture_files": texture_files}
    attributes = {}
    if isinstance(vertices, Mesh):
        if faces is not None:
            raise TypeError("encode(mesh) takes no faces argument")
        attributes = Mesh._attributes(vertices)
        vertices, faces = vertices.vertices, vertices.faces
    elif faces is None:
        raise TypeError("encode() needs faces (or a pomar.Mesh)")
    attributes.update({key: value for key, value in given.items() if value is not None})
    return _pomar.encode(vertices, faces, bits, clusters, cluster_ratio, progressive,
                         memory_limit, progress, attributes, normal_bits, scalar_bits,
                         texcoord_bits, exact_attributes, bool(strict), bool(keep_order),
                         threads, bool(stored_errors), block_order == "spatial")


def _mesh(vertices, faces, damaged, attributes):
    return Mesh(vertices, faces, damaged, **attributes)


def decode(data, level=None, *, skip_damaged=False, memory_limit=None, progress=None,
           attributes=True, threads=0):
    """Decode .pomar bytes (bytes, bytearray, memoryview) to a Mesh after `level`
    refinement levels (0 = base mesh, None = full resolution), with the file's per-vertex
    attributes (attributes=False: positions and faces only) and their precision in
    mesh.attribute_info.

    skip_damaged=True decodes around damaged or missing blocks instead of raising (a
    damaged global level stops before it, a damaged cluster stays coarse) and lists them
    in mesh.damaged; damage in the header, base mesh or tables still raises pomar.Error.
    progress: as for encode(). threads: for the clusters of a random-access file, 0 = every
    core this process may use (the mesh does not depend on it)."""
    _check_threads(threads)
    vertices, faces, damaged, fields = _pomar.decode(data, level, skip_damaged, memory_limit,
                                                     progress, attributes, threads)
    return _mesh(vertices, faces, damaged, fields)


def read(path, level=None):
    """Read a mesh file: .ply .obj .off .stl (positions, triangles, the per-vertex
    colours, normals, scalars and texture coordinates the readers know, per-corner texture
    coordinates and materials: OBJ + MTL, PLY face texcoord/texnumber), or .pomar (decoded
    after `level` levels, None = all)."""
    path = os.fspath(path)
    if path.lower().endswith(".pomar"):
        with open(path, "rb") as f:
            mesh = decode(f.read(), level)
    else:
        if level is not None:
            raise ValueError("level applies to .pomar files only")
        vertices, faces, _report, fields = _pomar.read_mesh(path)
        mesh = _mesh(vertices, faces, (), fields)
    mesh.source = path
    return mesh


def _refuse_source(path, mesh):
    """pomar.Error (kind "usage") if `path` is the file `mesh` was read from (the same
    file, also through links)."""
    source = getattr(mesh, "source", None)
    if source is None:
        return
    try:
        same = os.path.samefile(path, source)
    except OSError:  # one of them does not exist (yet)
        return
    if same:
        error = Error(f"{path} is the file the mesh was read from ({source}): it would be "
                      "overwritten; choose another file (or pass overwrite=True)")
        error.kind, error.path, error.level, error.cluster = "usage", path, None, None
        raise error


def write(path, mesh, *, binary=True, overwrite=False, **encode_options):
    """Write a Mesh, replacing `path` atomically: .ply .stl (binary unless binary=False),
    .obj .off, or .pomar (encode_options as for encode(), e.g. bits=14). PLY and .pomar
    keep every attribute (PLY of the materials only each face's texture); OBJ colour (RGB),
    normals, texture coordinates (per vertex or per corner), materials and texture files
    (a .mtl beside the file); OFF colour and normals; STL none. What a format cannot hold
    is named in one UserWarning. The file the mesh was read from (mesh.source: a coarse
    level, a region, a mesh decoded around damage) is not replaced: pomar.Error, kind
    "usage", unless overwrite=True."""
    path = os.fspath(path)
    if not overwrite:
        _refuse_source(path, mesh)
    if path.lower().endswith(".pomar"):
        _pomar.write_bytes(path, encode(mesh, **encode_options))
        return
    if encode_options:
        raise TypeError(f"options {sorted(encode_options)} apply to .pomar files only")
    lost = _pomar.write_mesh(path, mesh.vertices, mesh.faces, binary, Mesh._attributes(mesh))
    if lost:
        where = (".obj keeps them" if path.lower().endswith(".ply")
                 else ".ply keeps every attribute")
        warnings.warn(f"{path} cannot hold {', '.join(lost)}: not written ({where})",
                      stacklevel=2)


class SelectiveDecoder(_pomar.SelectiveDecoder):
    """Random access to a clustered .pomar file (a path or its bytes): decode the base
    clustered mesh, then refine chosen regions, reading only the blocks they need.

        d = pomar.SelectiveDecoder("dragon.pomar")
        d.want_sphere((0.01, 0.12, 0.0), 0.02)  # level=None: finest; or want_cluster/box
        d.update()
        part = d.mesh()                          # + d.vertex_cluster(), d.vertex_level()
        d.bytes_read

    View-dependent decoding: d.want_view(eye, view_proj, fov_y, width, height, near,
    pixel_error) then d.update() refines every cluster in the view frustum until its error
    (the file's stored bound, or the longest edge of a file without one) projects to at
    most pixel_error pixels; view_proj is a 4x4 view-projection matrix, column-major (16
    numbers, OpenGL clip volume), fov_y in radians, width and height in pixels.
    d.view_levels(...) (same arguments) returns those levels without asking for them;
    d.cluster_error(c, level) is the stored bound (-1 without one, has_cluster_errors).

    memory_limit (as for decode()) is checked by the constructor for the base clustered
    mesh and by update() for each level map before it is decoded (pomar.Error, kind
    "memory_limit", the mesh as it was).

    One thread at a time per decoder (calls from several threads wait for each other);
    update() decodes the clusters of a level on `threads` threads of its own (keyword of
    the constructor, 0 = every core this process may use; the mesh does not depend on it).
    """

    def __init__(self, source, *, skip_damaged=False, memory_limit=None, threads=0):
        _check_threads(threads)
        super().__init__(source, skip_damaged=skip_damaged, memory_limit=memory_limit,
                         threads=threads)
        self._path = os.fspath(source) if isinstance(source, (str, os.PathLike)) else None

    def mesh(self):
        """The current mesh (after the last update()); its source is the file read, if
        the decoder was given a path."""
        vertices, faces, fields = self.mesh_arrays()
        mesh = _mesh(vertices, faces, (), fields)
        mesh.source = self._path
        return mesh
