"""The Python module: round trips on numpy arrays, levels, info, files, selective decoding,
errors for bad input, the GIL released, no growth in memory under repeated calls."""
import gc
import json
import os
import warnings
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import pomar

SAMPLES = os.environ.get("POMAR_SAMPLES", os.path.join(os.path.dirname(__file__), "../../samples"))
BUNNY = os.path.join(SAMPLES, "bunny.ply")


def torus(rings=40, sides=24, big=1.0, small=0.3):
    """A closed manifold torus: float32 (rings*sides, 3), uint32 (2*rings*sides, 3)."""
    u = np.linspace(0, 2 * np.pi, rings, endpoint=False)[:, None]
    v = np.linspace(0, 2 * np.pi, sides, endpoint=False)[None, :]
    x = (big + small * np.cos(v)) * np.cos(u)
    y = (big + small * np.cos(v)) * np.sin(u)
    z = small * np.sin(v) * np.ones_like(u)
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(np.float32)
    i, j = np.meshgrid(np.arange(rings), np.arange(sides), indexing="ij")
    a = i * sides + j
    b = ((i + 1) % rings) * sides + j
    c = ((i + 1) % rings) * sides + (j + 1) % sides
    d = i * sides + (j + 1) % sides
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                            np.stack([a, c, d], -1).reshape(-1, 3)]).astype(np.uint32)
    return vertices, faces


def sorted_triangles(vertices, faces):
    """Triangles as sorted rows of corner positions (rotated to start at the smallest
    corner, orientation kept): comparable whatever the vertex numbering."""
    corners = vertices[faces]  # (m, 3, 3)
    keys = [tuple(map(tuple, tri)) for tri in corners]
    out = []
    for k in keys:
        r = k.index(min(k))
        out.append(k[r:] + k[:r])
    return sorted(out)


@pytest.fixture(scope="module")
def bunny():
    return pomar.read(BUNNY)


def test_version():
    assert pomar.__version__.count(".") == 2


def test_round_trip_arrays_lossless_on_the_grid():
    vertices, faces = torus()
    data = pomar.encode(vertices, faces, bits=16)
    assert isinstance(data, bytes)
    mesh = pomar.decode(data)
    assert mesh.vertices.dtype == np.float32 and mesh.vertices.shape == vertices.shape
    assert mesh.faces.dtype == np.uint32 and mesh.faces.shape == faces.shape
    step = 2.6 / (2**16 - 1)  # the grid spans the bounding cube (extent 2.6)
    # Same triangles: re-encode the decoded mesh and get it back bit for bit.
    again = pomar.decode(pomar.encode(mesh, bits=16))
    assert sorted_triangles(again.vertices, again.faces) == sorted_triangles(mesh.vertices, mesh.faces)
    # Positions within half a grid step of the input (decoded_to_input is unknown here:
    # compare each decoded vertex with its nearest input vertex).
    d = np.abs(mesh.vertices[:, None, :] - vertices[None, :, :]).max(-1).min(-1)
    assert d.max() <= 0.5 * step * 1.01


def test_decoded_arrays_are_not_copies():
    """decode() hands over the library's buffers: the arrays do not own a copy, they keep
    the C++ storage alive (their base), and stay valid after everything else is gone."""
    vertices, faces = torus()
    mesh = pomar.decode(pomar.encode(vertices, faces))
    for array in (mesh.vertices, mesh.faces):
        assert not array.flags.owndata and array.base is not None
        assert array.flags.c_contiguous and array.flags.writeable
    v = mesh.vertices
    del mesh
    gc.collect()
    assert np.isfinite(v).all() and v.shape == vertices.shape


def test_levels_and_info(bunny):
    data = pomar.encode(bunny)
    info = pomar.info(data)
    # What a full decode gives (the bunny's unreferenced vertices included); "vertices" and
    # "faces" count the coded mesh.
    assert info["input_vertices"] == len(bunny.vertices) and info["input_faces"] == len(bunny.faces)
    assert info["level_count"] == len(info["levels"]) - 1
    base = pomar.decode(data, level=0)
    assert len(base.vertices) == info["base_vertices"]
    counts = [len(pomar.decode(data, level=l).vertices) for l in (0, 3, info["level_count"])]
    assert counts == sorted(counts) and counts[-1] == info["input_vertices"]
    assert len(pomar.decode(data, level=5).faces) == info["levels"][5]["faces"]
    # bytearray and memoryview work as well as bytes.
    assert len(pomar.decode(bytearray(data), 2).faces) == len(pomar.decode(memoryview(data), 2).faces)


@pytest.mark.skipif(not os.path.exists(os.environ.get("POMAR_TOOL", "")), reason="pomar tool not built")
def test_info_matches_the_tool(tmp_path, bunny):
    path = tmp_path / "bunny.pomar"
    pomar.write(path, bunny)
    out = subprocess.run([os.environ["POMAR_TOOL"], "info", str(path), "--json"],
                         check=True, capture_output=True, text=True).stdout
    tool = json.loads(out)
    mine = pomar.info(path.read_bytes())
    assert mine.keys() == tool.keys()
    for key in tool:
        if isinstance(tool[key], float):
            assert mine[key] == pytest.approx(tool[key]), key
        elif key in ("bbox_min", "grid_max"):
            assert mine[key] == pytest.approx(tool[key]), key
        else:
            assert mine[key] == tool[key], key


def test_files(tmp_path, bunny):
    for name in ("b.ply", "b.obj", "b.off", "b.stl"):
        pomar.write(tmp_path / name, bunny)
        back = pomar.read(tmp_path / name)
        assert len(back.faces) == len(bunny.faces), name
    pomar.write(tmp_path / "a.ply", bunny, binary=False)
    assert np.array_equal(pomar.read(tmp_path / "a.ply").vertices, bunny.vertices)
    pomar.write(str(tmp_path / "b.pomar"), bunny, bits=14)
    assert pomar.info((tmp_path / "b.pomar").read_bytes())["bits"] == 14
    assert len(pomar.read(tmp_path / "b.pomar", level=0).vertices) < len(bunny.vertices)
    assert len(pomar.read(tmp_path / "b.pomar").vertices) == len(bunny.vertices)
    with pytest.raises(TypeError, match="pomar files only"):
        pomar.write(tmp_path / "c.ply", bunny, bits=14)


def test_write_refuses_the_file_the_mesh_was_read_from(tmp_path, bunny):
    assert bunny.source == BUNNY
    for name, level in (("a.ply", None), ("a.pomar", 0)):
        path = tmp_path / name
        pomar.write(path, bunny)
        before = path.read_bytes()
        mesh = pomar.read(path, level)  # a .pomar at level 0: the base mesh
        assert mesh.source == str(path)
        link = tmp_path / ("link-" + name)
        link.symlink_to(path)
        hard = tmp_path / ("hard-" + name)
        os.link(path, hard)
        for target in (path, str(path), link, hard):
            with pytest.raises(pomar.Error, match="the file the mesh was read from") as e:
                pomar.write(target, mesh)
            assert e.value.kind == "usage" and e.value.path == os.fspath(target)
        assert path.read_bytes() == before
        assert not [p for p in os.listdir(tmp_path) if ".tmp." in p]
        other = tmp_path / ("other-" + name)
        pomar.write(other, mesh)  # another file: written
        assert pomar.read(other, level).faces.shape == mesh.faces.shape
        mesh.source = None  # a mesh of no file: written anywhere
        pomar.write(path, mesh)
        path.write_bytes(before)
        mesh.source = str(path)
        pomar.write(path, mesh, overwrite=True)  # asked for
        assert len(pomar.read(path).faces) == len(mesh.faces)
        if level == 0:
            assert path.read_bytes() != before
    # A selective decoder's mesh comes from its file.
    path = tmp_path / "s.pomar"
    pomar.write(path, bunny)
    d = pomar.SelectiveDecoder(path)
    d.want_cluster(0)
    d.update()
    part = d.mesh()
    assert part.source == str(path)
    with pytest.raises(pomar.Error, match="read from"):
        pomar.write(path, part)
    assert pomar.SelectiveDecoder(path.read_bytes()).mesh().source is None


def test_selective_decoder(tmp_path, bunny):
    data = pomar.encode(bunny)
    path = tmp_path / "bunny.pomar"
    path.write_bytes(data)
    for source in (path, str(path), data):
        d = pomar.SelectiveDecoder(source)
        info = d.info
        assert d.cluster_count == info["clusters"] > 1
        base = d.mesh()
        assert len(base.vertices) > 0
        d.want_cluster(0)
        d.update()
        one = d.mesh()
        assert len(one.vertices) > len(base.vertices)
        assert d.blocks_read >= 1 and d.bytes_read < info["total_bytes"]
        assert d.levels[0] == d.finest_level
        assert d.vertex_cluster().shape == (len(one.vertices),)
        assert d.vertex_level().max() == d.finest_level
        lo = np.array(info["bbox_min"], np.float32)
        d.want_box(lo, lo + 0.1, level=d.base_clustered_level + 1)
        d.want_sphere(tuple(lo), 0.05)
        d.update()
        d.want_all()
        d.update()
        full = d.mesh()
        assert len(full.vertices) == info["vertices"] and d.damaged == []
        # Everything but the stored errors (CERR), which only a view reads.
        cerr = [s["bytes"] for s in pomar.info(data)["sections"] if s["name"] == "CERR"]
        assert len(cerr) == 1
        assert d.bytes_read == info["total_bytes"] - cerr[0]
        assert d.cluster_error(0, d.base_clustered_level) > 0
        assert d.bytes_read == info["total_bytes"]


def test_selective_decoder_checks_each_update_against_memory_limit(bunny):
    data = pomar.encode(bunny)
    # 12 MiB holds the base clustered mesh (8.0 MiB on one thread) and one cluster's
    # neighbourhood, not the whole mesh at full resolution (15.2 MiB; the C++ tests check
    # the estimates).
    d = pomar.SelectiveDecoder(data, memory_limit="12M", threads=1)
    base = len(d.mesh().vertices)
    d.want_all()
    with pytest.raises(pomar.Error) as e:
        d.update()
    assert e.value.kind == "memory_limit"
    assert "refine the clusters asked for" in str(e.value)
    assert len(d.mesh().vertices) == base  # nothing decoded
    d = pomar.SelectiveDecoder(data, memory_limit="12M", threads=1)
    d.want_cluster(0)
    d.update()
    assert len(d.mesh().vertices) > base


def test_bad_arrays_raise_clear_errors():
    vertices, faces = torus()
    with pytest.raises(TypeError, match=r"vertices must have dtype float32, not float64.*astype"):
        pomar.encode(vertices.astype(np.float64), faces)
    with pytest.raises(TypeError, match=r"faces must have dtype uint32, not int64"):
        pomar.encode(vertices, faces.astype(np.int64))
    with pytest.raises(ValueError, match=r"vertices must have shape \(n, 3\), not \(960, 2\)"):
        pomar.encode(vertices[:, :2].copy(), faces)
    with pytest.raises(ValueError, match="not C-contiguous"):
        pomar.encode(np.asfortranarray(vertices), faces)
    with pytest.raises(ValueError, match="not C-contiguous"):
        pomar.encode(vertices, faces[::2])
    with pytest.raises(TypeError, match="numpy array"):
        pomar.encode(vertices.tolist(), faces)
    bad = faces.copy()
    bad[3, 1] = len(vertices)  # a face referring to a vertex that does not exist
    with pytest.raises(pomar.Error) as e:
        pomar.encode(vertices, bad)
    assert e.value.kind == "invalid_mesh" and str(len(vertices)) in str(e.value)
    nan = vertices.copy()
    nan[7, 2] = np.nan
    with pytest.raises(pomar.Error) as e:
        pomar.encode(nan, faces)
    assert e.value.kind == "invalid_mesh"
    with pytest.raises(ValueError, match="bits must be between 4 and 24, not 40"):
        pomar.encode(vertices, faces, bits=40)
    data = pomar.encode(vertices, faces)
    levels = pomar.info(data)["level_count"]
    for level in (-1, levels + 1):
        with pytest.raises(ValueError, match=rf"level {level} does not exist: the file has levels 0..{levels}"):
            pomar.decode(data, level)
    d = pomar.SelectiveDecoder(data)
    with pytest.raises(ValueError, match=rf"cluster {d.cluster_count} does not exist"):
        d.want_cluster(d.cluster_count)
    with pytest.raises(ValueError, match="level 99 does not exist"):
        d.want_all(99)
    with pytest.raises(TypeError, match="center must be 3 numbers"):
        d.want_sphere((1, 2), 0.1)


def test_damaged_and_wrong_data_raise_clear_errors(tmp_path):
    vertices, faces = torus()
    data = bytearray(pomar.encode(vertices, faces))
    data[len(data) // 2] ^= 0x40
    with pytest.raises(pomar.Error) as e:
        pomar.decode(bytes(data))
    assert e.value.kind == "damaged_file"
    around = pomar.decode(bytes(data), skip_damaged=True)
    assert around.damaged and around.damaged[0]["problem"]
    assert 0 < len(around.faces) and pomar.decode(pomar.encode(vertices, faces)).damaged == []
    with pytest.raises(pomar.Error) as e:
        pomar.info(b"not a pomar file")
    assert e.value.kind == "damaged_file"
    with pytest.raises(pomar.Error):
        pomar.decode(bytes(data[:100]))
    with pytest.raises(TypeError, match="not a path"):
        pomar.decode("bunny.pomar")
    with pytest.raises(TypeError, match="bytes-like"):
        pomar.decode(12)
    with pytest.raises(pomar.Error) as e:
        pomar.read(tmp_path / "missing.ply")
    assert e.value.kind == "io" and "missing.ply" in str(e.value)
    assert e.value.path.endswith("missing.ply") and e.value.level is None
    with pytest.raises(pomar.Error) as e:
        pomar.SelectiveDecoder(tmp_path / "missing.pomar")
    with pytest.raises(pomar.Error) as e:
        pomar.encode(vertices, faces, memory_limit=1000)
    assert e.value.kind == "memory_limit"
    with pytest.raises(pomar.Error) as e:
        pomar.encode(vertices, faces, memory_limit="lots")
    assert e.value.kind == "usage"



def test_a_damaged_attr_section_is_a_damaged_file(tmp_path):
    vertices, faces = torus()
    colors = (np.arange(3 * len(vertices)) % 256).astype(np.uint8).reshape(-1, 3)
    data = bytearray(pomar.encode(vertices, faces, colors=colors))
    i = pomar.info(bytes(data))
    offset = i["header_bytes"] + i["base_bytes"]  # the section bodies, in table order
    for s in i["sections"]:
        if s["name"] == "ATTR":
            break
        offset += s["bytes"]
    else:
        pytest.fail("no ATTR section in a file with colours")
    data[offset + s["bytes"] // 2] ^= 0x10
    for read in (lambda: pomar.decode(bytes(data)), lambda: pomar.info(bytes(data)),
                 lambda: pomar.decode(bytes(data), skip_damaged=True),
                 lambda: pomar.SelectiveDecoder(bytes(data)).update()):
        with pytest.raises(pomar.Error) as e:
            read()
        assert e.value.kind == "damaged_file" and "ATTR" in str(e.value)

def test_gil_released_during_encode_and_decode():
    """Another Python thread runs while encode/decode work. With a 0.5 s switch interval a
    thread holding the GIL keeps it through a call shorter than that (these take a few
    ms), so the counter could not move during the call if the GIL were held. The counter
    gives the GIL up after every tick (time.sleep(0) releases it): the calls take it back
    for each progress report (to look for Ctrl-C), and a counter that held it would make
    each of those wait for the switch interval, about two minutes in all; a call that held
    the GIL still stops the counter, which then waits for the GIL through the whole call."""
    vertices, faces = torus(100, 50)
    ticks = 0
    stop = threading.Event()

    def count():
        nonlocal ticks
        while not stop.is_set():
            ticks += 1
            time.sleep(0)

    moved = []

    def work():
        # Five rounds: a thread holding the GIL through a call stops the counter for the
        # whole call, every time; on a loaded machine the counter may simply not be scheduled
        # during one short call, so one round alone would be flaky.
        moved.extend([0, 0])
        for _ in range(5):
            before = ticks
            data = pomar.encode(vertices, faces)
            middle = ticks
            pomar.decode(data)
            moved[0] += middle - before
            moved[1] += ticks - middle

    interval = sys.getswitchinterval()
    sys.setswitchinterval(0.5)
    try:
        counter = threading.Thread(target=count)
        counter.start()
        worker = threading.Thread(target=work)
        worker.start()
        worker.join()
        stop.set()
        counter.join()
    finally:
        sys.setswitchinterval(interval)
    assert len(moved) == 2 and moved[0] > 0 and moved[1] > 0, moved


def test_threads_share_one_decoder(bunny):
    data = pomar.encode(bunny)
    d = pomar.SelectiveDecoder(data)
    errors = []

    def work(c):
        try:
            d.want_cluster(c)
            d.update()
            d.mesh()
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    threads = [threading.Thread(target=work, args=(c,)) for c in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_no_growth_under_repeated_calls(bunny):
    data = pomar.encode(bunny)
    for _ in range(5):  # warm up the allocator
        pomar.decode(data)
    gc.collect()
    before = rss_bytes()
    for _ in range(25):
        mesh = pomar.decode(data)
        pomar.info(data)
        pomar.SelectiveDecoder(data).mesh()
        try:
            pomar.decode(data[:200])
        except pomar.Error:
            pass
    del mesh
    gc.collect()
    # One decoded bunny is about 0.8 MB; leaking it on every call would add ~20 MB.
    assert rss_bytes() - before < 8 * 2**20


def test_trimesh_example(monkeypatch):
    """examples/trimesh_convert.py (quoted in the README), when trimesh is installed."""
    pytest.importorskip("trimesh")
    import runpy
    repo = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    monkeypatch.chdir(repo)
    result = runpy.run_path("examples/trimesh_convert.py")
    assert len(result["back"].faces) == len(result["mesh"].faces)


def test_selective_requests_by_vertices_and_faces(bunny):
    d = pomar.SelectiveDecoder(pomar.encode(bunny))
    base = d.mesh()
    d.want_vertices(np.arange(0, len(base.vertices), 50, dtype=np.uint32))
    d.want_faces([0, 1, 2], level=d.base_clustered_level + 1)
    d.update()
    assert (d.levels > d.base_clustered_level).sum() >= 2
    d.clear_wanted()
    d.update()
    assert len(d.mesh().vertices) == len(base.vertices)
    wanted = np.full(d.cluster_count, d.base_clustered_level, np.int32)
    wanted[3] = d.finest_level
    d.set_wanted(wanted)
    assert d.wanted[3] == d.finest_level
    d.update()
    assert d.levels[3] == d.finest_level
    with pytest.raises(ValueError, match="one level per cluster"):
        d.set_wanted([0])


def test_selective_decoder_around_damage(bunny):
    data = bytearray(pomar.encode(bunny))
    data[len(data) - 100] ^= 0x5A  # inside the last cluster blocks
    strict = pomar.SelectiveDecoder(bytes(data))
    strict.want_all()
    with pytest.raises(pomar.Error) as e:
        strict.update()
    assert e.value.kind == "damaged_file" and "cluster" in str(e.value)
    assert e.value.cluster is not None and e.value.path is None
    lenient = pomar.SelectiveDecoder(bytes(data), skip_damaged=True)
    lenient.want_all()
    lenient.update()
    assert lenient.damaged and lenient.damaged[0]["block"].startswith("cluster")
    assert len(lenient.mesh().vertices) < lenient.info["vertices"]


def test_progress_callback_and_interruption(bunny):
    seen = []
    data = pomar.encode(bunny, progress=lambda fraction, stage: seen.append((stage, fraction)))
    assert {"encode"} <= {stage for stage, _ in seen}
    fractions = [f for stage, f in seen if stage == "encode"]
    assert fractions == sorted(fractions) and fractions[-1] == pytest.approx(1.0)
    seen.clear()
    pomar.decode(data, progress=lambda fraction, stage: seen.append(stage))
    assert "decode" in seen

    class Stop(Exception):
        pass

    def stop(fraction, stage):
        if fraction > 0.3:
            raise Stop(stage)

    with pytest.raises(Stop):
        pomar.encode(bunny, progress=stop)
    with pytest.raises(Stop):
        pomar.decode(data, progress=stop)
    with pytest.raises(TypeError, match="callable"):
        pomar.decode(data, progress=3)
    assert len(pomar.decode(data).faces) == len(bunny.faces)  # nothing left behind


# Per-vertex attributes.

def torus_attributes(vertices, alpha=False):
    """Colours, unit normals, two scalars and texture coordinates for torus() vertices."""
    n = len(vertices)
    rng = np.random.default_rng(16)
    colors = rng.integers(0, 256, size=(n, 4 if alpha else 3), dtype=np.uint8)
    ring = vertices.copy()
    ring[:, 2] = 0
    ring /= np.linalg.norm(ring, axis=1, keepdims=True)
    normals = vertices - ring  # from the tube's centre line (big = 1) to the surface
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    scalars = {"quality": rng.uniform(-3, 5, n).astype(np.float32),
               "confidence": rng.uniform(0, 1, n).astype(np.float32)}
    texcoords = rng.uniform(0, 1, (n, 2)).astype(np.float32)
    return colors, normals.astype(np.float32), scalars, texcoords


def input_index(decoded, vertices):
    """For each decoded vertex, the input vertex nearest to it (the order may differ)."""
    d = np.abs(decoded[:, None, :] - vertices[None, :, :]).max(-1)
    return d.argmin(-1)


def test_attribute_round_trip_within_the_bounds():
    vertices, faces = torus()
    for alpha in (False, True):
        colors, normals, scalars, texcoords = torus_attributes(vertices, alpha)
        data = pomar.encode(vertices, faces, bits=16, colors=colors, normals=normals,
                            scalars=scalars, texcoords=texcoords, texture_files=["skin.png"])
        mesh = pomar.decode(data)
        k = input_index(mesh.vertices, vertices)
        assert len(set(k.tolist())) == len(vertices)
        assert mesh.colors.dtype == np.uint8 and mesh.colors.shape == colors.shape
        assert np.array_equal(mesh.colors, colors[k])  # colours are exact, RGB and RGBA
        info = {a["name"]: a for a in mesh.attribute_info}
        assert sorted(info) == ["colour", "confidence", "normal", "quality", "texcoord"]
        assert info["colour"]["exact"] and info["colour"]["kind"] == "colour"
        assert info["normal"]["bits"] == 9 and 0 < info["normal"]["bound"] < 0.34
        assert mesh.normals.dtype == np.float32 and mesh.normals.shape == (len(vertices), 3)
        cos = np.clip((mesh.normals * normals[k]).sum(1), -1, 1)
        assert np.degrees(np.arccos(cos)).max() <= info["normal"]["bound"] * 1.0001 + 1e-4
        assert sorted(mesh.scalars) == ["confidence", "quality"]
        for name, values in scalars.items():
            assert mesh.scalars[name].dtype == np.float32 and mesh.scalars[name].shape == (len(vertices),)
            assert info[name]["bits"] == 16 and info[name]["bound"] > 0
            assert np.abs(mesh.scalars[name] - values[k]).max() <= info[name]["bound"] * 1.0001
        assert mesh.texcoords.dtype == np.float32 and mesh.texcoords.shape == (len(vertices), 2)
        assert np.abs(mesh.texcoords - texcoords[k]).max() <= info["texcoord"]["bound"] * 1.0001
        assert mesh.texture_files == ["skin.png"]
        assert "colors" in repr(mesh) and "scalar 'quality'" in repr(mesh)
        # The file's info lists the same attributes.
        assert sorted(a["name"] for a in pomar.info(data)["attributes"]) == sorted(info)
    # Fewer bits: a larger bound, still kept.
    coarse = pomar.decode(pomar.encode(vertices, faces, normals=normals, normal_bits=6,
                                       scalars=scalars, scalar_bits=6, texcoords=texcoords,
                                       texcoord_bits=5))
    k = input_index(coarse.vertices, vertices)
    info = {a["name"]: a for a in coarse.attribute_info}
    assert info["normal"]["bits"] == 6 and info["normal"]["bound"] > 1
    cos = np.clip((coarse.normals * normals[k]).sum(1), -1, 1)
    assert np.degrees(np.arccos(cos)).max() <= info["normal"]["bound"] * 1.0001 + 1e-4
    assert np.abs(coarse.scalars["quality"] - scalars["quality"][k]).max() <= info["quality"]["bound"] * 1.0001
    assert np.abs(coarse.texcoords - texcoords[k]).max() <= info["texcoord"]["bound"] * 1.0001


def test_exact_attributes_bit_for_bit():
    vertices, faces = torus()
    colors, normals, scalars, texcoords = torus_attributes(vertices)
    scalars["quality"][5] = np.nan  # exact mode keeps what quantization refuses
    scalars["quality"][6] = -np.inf
    normals[9] = 0  # a zero-length normal
    with pytest.raises(pomar.Error) as e:
        pomar.encode(vertices, faces, normals=normals, scalars=scalars)
    assert e.value.kind == "invalid_mesh"
    mesh = pomar.Mesh(vertices, faces, colors=colors, normals=normals, scalars=scalars,
                      texcoords=texcoords)
    back = pomar.decode(pomar.encode(mesh, bits=16, exact_attributes=True))
    k = input_index(back.vertices, vertices)
    assert all(a["exact"] and a["bits"] == 0 and a["bound"] == 0 for a in back.attribute_info)
    assert np.array_equal(back.colors, colors[k])
    assert np.array_equal(back.normals.view(np.uint32), normals[k].view(np.uint32))
    for name, values in scalars.items():
        assert np.array_equal(back.scalars[name].view(np.uint32), values[k].view(np.uint32))
    assert np.array_equal(back.texcoords.view(np.uint32), texcoords[k].view(np.uint32))


def test_decode_without_attributes_and_mesh_fields():
    vertices, faces = torus()
    colors, normals, scalars, texcoords = torus_attributes(vertices)
    plain = pomar.decode(pomar.encode(vertices, faces))
    assert plain.colors is None and plain.normals is None and plain.texcoords is None
    assert plain.scalars == {} and plain.texture_files == [] and plain.attribute_info == []
    data = pomar.encode(vertices, faces, colors=colors, scalars=scalars)
    full = pomar.decode(data)
    assert full.colors is not None and sorted(full.scalars) == ["confidence", "quality"]
    assert full.normals is None and full.texcoords is None
    bare = pomar.decode(data, attributes=False)
    assert bare.colors is None and bare.scalars == {} and bare.attribute_info == []
    assert np.array_equal(bare.vertices, full.vertices) and np.array_equal(bare.faces, full.faces)
    # encode(mesh): the mesh's fields, a keyword replacing one of them.
    mesh = pomar.Mesh(vertices, faces, colors=colors)
    again = pomar.decode(pomar.encode(mesh, normals=normals))
    assert again.colors is not None and again.normals is not None
    # Coarser levels carry the attributes of their vertices.
    base = pomar.decode(data, level=0)
    assert len(base.colors) == len(base.vertices) < len(vertices)
    assert len(base.scalars["quality"]) == len(base.vertices)


def test_files_with_attributes(tmp_path):
    vertices, faces = torus()
    colors, normals, scalars, texcoords = torus_attributes(vertices, alpha=True)
    mesh = pomar.Mesh(vertices, faces, colors=colors, normals=normals,
                      scalars={"quality": scalars["quality"]}, texcoords=texcoords,
                      texture_files=["skin.png"])
    for binary in (True, False):
        path = tmp_path / f"t{int(binary)}.ply"
        pomar.write(path, mesh, binary=binary)
        back = pomar.read(path)
        assert np.array_equal(back.vertices, vertices)
        assert np.array_equal(back.colors, colors)
        assert np.array_equal(back.normals, normals)
        assert np.array_equal(back.scalars["quality"], scalars["quality"])
        assert np.array_equal(back.texcoords, texcoords)
        assert back.texture_files == ["skin.png"]
    rgb = pomar.Mesh(vertices, faces, colors=colors[:, :3].copy())
    pomar.write(tmp_path / "rgb.ply", rgb)
    assert np.array_equal(pomar.read(tmp_path / "rgb.ply").colors, colors[:, :3])
    # Formats that cannot hold an attribute say so in one warning; OFF keeps the colours.
    with pytest.warns(UserWarning, match="cannot hold colours, normals, scalars 'quality'"):
        pomar.write(tmp_path / "t.stl", mesh)
    with pytest.warns(UserWarning, match="t.off cannot hold scalars 'quality', texture coord"):
        pomar.write(tmp_path / "t.off", mesh)
    assert np.array_equal(pomar.read(tmp_path / "t.off").colors, colors)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pomar.write(tmp_path / "plain.stl", pomar.Mesh(vertices, faces))
    # OBJ: texture coordinates and the texture file names (a .mtl beside it).
    with pytest.warns(UserWarning, match="the alpha of the colours, scalars 'quality'"):
        pomar.write(tmp_path / "t.obj", mesh)
    back = pomar.read(tmp_path / "t.obj")
    assert np.array_equal(back.texcoords, texcoords) and back.texture_files == ["skin.png"]
    assert (tmp_path / "t.mtl").exists()
    # .pomar files carry them too.
    pomar.write(tmp_path / "t.pomar", mesh, bits=16)
    back = pomar.read(tmp_path / "t.pomar")
    k = input_index(back.vertices, vertices)
    assert np.array_equal(back.colors, colors[k]) and back.texture_files == ["skin.png"]


def test_bad_attributes_raise_clear_errors():
    vertices, faces = torus()
    colors, normals, scalars, texcoords = torus_attributes(vertices)
    n = len(vertices)
    with pytest.raises(TypeError, match=r"colors must have dtype uint8, not float32"):
        pomar.encode(vertices, faces, colors=colors.astype(np.float32))
    with pytest.raises(ValueError, match=r"colors must have shape \(n, 3\) or \(n, 4\), not \(960, 2\)"):
        pomar.encode(vertices, faces, colors=colors[:, :2].copy())
    with pytest.raises(ValueError, match=rf"colors has 10 rows but there are {n} vertices"):
        pomar.encode(vertices, faces, colors=colors[:10].copy())
    with pytest.raises(TypeError, match="normals must be a numpy array of float32"):
        pomar.encode(vertices, faces, normals=normals.tolist())
    with pytest.raises(TypeError, match="normals must have dtype float32, not float64"):
        pomar.encode(vertices, faces, normals=normals.astype(np.float64))
    with pytest.raises(ValueError, match="normals is not C-contiguous"):
        pomar.encode(vertices, faces, normals=np.asfortranarray(normals))
    with pytest.raises(TypeError, match="scalars must be a dict"):
        pomar.encode(vertices, faces, scalars=scalars["quality"])
    with pytest.raises(ValueError, match=r"scalars\['quality'\] must have shape \(n,\), not \(960, 1\)"):
        pomar.encode(vertices, faces, scalars={"quality": scalars["quality"][:, None].copy()})
    with pytest.raises(TypeError, match="scalars' names must be str"):
        pomar.encode(vertices, faces, scalars={3: scalars["quality"]})
    with pytest.raises(ValueError, match="scalar name 'colour' is taken"):
        pomar.encode(vertices, faces, colors=colors, scalars={"colour": scalars["quality"]})
    with pytest.raises(ValueError, match=r"texcoords must have shape \(n, 2\), not \(960, 3\)"):
        pomar.encode(vertices, faces, texcoords=normals)
    with pytest.raises(TypeError, match="texture_files must be a list of str"):
        pomar.encode(vertices, faces, texcoords=texcoords, texture_files="skin.png")
    with pytest.raises(ValueError, match="normal_bits must be between 4 and 16, not 3"):
        pomar.encode(vertices, faces, normals=normals, normal_bits=3)
    with pytest.raises(ValueError, match="scalar_bits must be between 1 and 24, not 25"):
        pomar.encode(vertices, faces, scalar_bits=25)
    with pytest.raises(ValueError, match="colors has 10 rows"):
        pomar.write("never-written.ply", pomar.Mesh(vertices, faces, colors=colors[:10].copy()))
    assert not os.path.exists("never-written.ply")


def test_selective_decoder_carries_attributes():
    vertices, faces = torus(80, 48)
    colors, normals, scalars, _ = torus_attributes(vertices)
    d = pomar.SelectiveDecoder(pomar.encode(vertices, faces, colors=colors, normals=normals,
                                            scalars=scalars, clusters=8))
    d.want_cluster(0)
    d.update()
    part = d.mesh()
    n = len(part.vertices)
    assert part.colors.shape == (n, 3) and part.normals.shape == (n, 3)
    assert part.scalars["quality"].shape == (n,)
    k = input_index(part.vertices, vertices)
    assert np.array_equal(part.colors, colors[k])


def test_messy_meshes_strict_keep_order_and_threads():
    """A non-manifold mesh with a duplicate face and an unreferenced vertex: stored
    losslessly by default (the decode gives back every face and vertex), refused with
    strict=True; keep_order gives the input numbering back; the bytes do not depend on
    threads."""
    vertices, faces = torus()
    # A fin: a third face on the edge (faces[0][0], faces[0][1]) -> non-manifold edge,
    # the same face twice, and one vertex no face uses.
    extra = np.array([[0.0, 0.0, 2.0]], dtype=np.float32)
    vertices = np.concatenate([vertices, extra, extra + 0.5])
    fin = np.array([[faces[0][0], faces[0][1], len(vertices) - 2]], dtype=np.uint32)
    faces = np.concatenate([faces, fin, fin]).astype(np.uint32)
    data = pomar.encode(vertices, faces, bits=16)
    mesh = pomar.decode(data)
    assert len(mesh.vertices) == len(vertices) and len(mesh.faces) == len(faces)
    with pytest.raises(pomar.Error) as e:
        pomar.encode(vertices, faces, bits=16, strict=True)
    assert e.value.kind == "invalid_mesh"
    ordered = pomar.decode(pomar.encode(vertices, faces, bits=16, keep_order=True))
    step = (vertices.max(0) - vertices.min(0)).max() / (2 ** 16 - 1)
    assert np.abs(ordered.vertices - vertices).max() <= step

    def oriented(f):  # each face rotated to start at its smallest index, then sorted
        return sorted(tuple(np.roll(t, -int(np.argmin(t)))) for t in f.tolist())
    assert oriented(ordered.faces) == oriented(faces)
    one = pomar.encode(vertices, faces, bits=16, threads=1)
    assert one == pomar.encode(vertices, faces, bits=16, threads=3) == data
    with pytest.raises(ValueError, match="threads must be an integer >= 0"):
        pomar.encode(vertices, faces, threads=-1)


def test_decode_threads_give_the_same_mesh(bunny):
    """The clusters of a random-access file decode on several threads: the mesh does not
    depend on how many (full and selective decodes)."""
    data = pomar.encode(bunny, cluster_ratio=0.02)
    one = pomar.decode(data, threads=1)
    for t in (2, 7):
        other = pomar.decode(data, threads=t)
        assert np.array_equal(one.vertices, other.vertices)
        assert np.array_equal(one.faces, other.faces)
    meshes = []
    for t in (1, 2, 7):
        d = pomar.SelectiveDecoder(data, threads=t)
        d.want_sphere((-0.06, 0.16, 0.0), 0.03)
        d.update()
        meshes.append(d.mesh())
    for m in meshes[1:]:
        assert np.array_equal(meshes[0].vertices, m.vertices)
        assert np.array_equal(meshes[0].faces, m.faces)
    with pytest.raises(ValueError, match="threads must be an integer >= 0"):
        pomar.decode(data, threads=-1)
    with pytest.raises(ValueError, match="threads must be an integer >= 0"):
        pomar.SelectiveDecoder(data, threads=1.5)


def textured_torus():
    """The torus with a texture coordinate per corner (a seam where u and v wrap) and two
    materials, one per half."""
    vertices, faces = torus(rings=12, sides=8)
    rings, sides = 12, 8
    ring, side = np.divmod(faces.astype(np.int64), sides)
    u = ring / rings
    v = side / sides
    # A corner on the wrap of a face that crosses it gets 1 instead of 0: the seam.
    u = np.where((ring == 0) & (ring.max(axis=1, keepdims=True) == rings - 1), 1.0, u)
    v = np.where((side == 0) & (side.max(axis=1, keepdims=True) == sides - 1), 1.0, v)
    corners = np.ascontiguousarray(np.stack([u, v], axis=-1).astype(np.float32))
    face_materials = (np.arange(len(faces)) % 2).astype(np.uint32)
    materials = [{"name": "skin", "texture": 0, "properties": "Kd 1 1 1\nillum 2\n"},
                 {"name": "plain", "texture": -1, "properties": "Kd 0.5 0.5 0.5\n"}]
    return pomar.Mesh(vertices, faces, corner_texcoords=corners, face_materials=face_materials,
                      materials=materials, texture_files=["skin.png"])


def test_textured_files_round_trip(tmp_path):
    mesh = textured_torus()
    assert mesh.corner_texcoords.shape == (len(mesh.faces), 3, 2)
    for name in ("t.obj", "t.ply", "t_ascii.ply"):
        path = str(tmp_path / name)
        with warnings.catch_warnings():
            warnings.simplefilter("error" if name.endswith(".obj") else "ignore")
            pomar.write(path, mesh, binary=not name.endswith("_ascii.ply"))
        back = pomar.read(path)
        assert np.array_equal(back.vertices, mesh.vertices) and np.array_equal(back.faces,
                                                                                 mesh.faces)
        assert back.corner_texcoords.dtype == np.float32
        assert back.corner_texcoords.shape == (len(mesh.faces), 3, 2)
        assert np.array_equal(back.corner_texcoords, mesh.corner_texcoords), name
        assert back.face_materials.dtype == np.uint32
        textures = [back.materials[i]["texture"] for i in back.face_materials]
        assert textures == [mesh.materials[i]["texture"] for i in mesh.face_materials], name
        assert back.texture_files == ["skin.png"]
        if name.endswith(".obj"):
            assert back.materials == mesh.materials
            assert np.array_equal(back.face_materials, mesh.face_materials)
        else:  # PLY: one material per texture file
            assert back.materials[0] == {"name": "texture_0", "texture": 0, "properties": ""}
    plain = pomar.read(BUNNY)
    assert plain.corner_texcoords is None and plain.face_materials is None
    assert plain.materials == []


def test_textured_sample_and_bad_corner_data(tmp_path):
    sample = pomar.read(os.path.join(SAMPLES, "textured_sphere.obj"))
    assert sample.corner_texcoords.shape == (440, 3, 2)
    assert [m["name"] for m in sample.materials] == ["checker", "cap"]
    assert sample.materials[0]["texture"] == 0 and sample.texture_files == ["textured_sphere.png"]
    assert "Ns 10\n" in sample.materials[0]["properties"]
    assert "2 materials" in repr(sample)
    mesh = textured_torus()
    path = str(tmp_path / "bad.obj")
    with pytest.raises(ValueError, match=r"corner_texcoords must have shape \(m, 3, 2\)"):
        pomar.write(path, pomar.Mesh(mesh.vertices, mesh.faces,
                                     corner_texcoords=mesh.corner_texcoords.reshape(-1, 6)))
    with pytest.raises(TypeError, match="corner_texcoords must have dtype float32"):
        pomar.write(path, pomar.Mesh(mesh.vertices, mesh.faces,
                                     corner_texcoords=mesh.corner_texcoords.astype(np.float64)))
    with pytest.raises(ValueError, match="one row per face"):
        pomar.write(path, pomar.Mesh(mesh.vertices, mesh.faces,
                                     corner_texcoords=mesh.corner_texcoords[:-1].copy()))
    with pytest.raises(ValueError, match="face_materials holds 5 but there are 2 materials"):
        bad = np.full(len(mesh.faces), 5, dtype=np.uint32)
        pomar.write(path, pomar.Mesh(mesh.vertices, mesh.faces, face_materials=bad,
                                     materials=mesh.materials, texture_files=["skin.png"]))
    with pytest.raises(ValueError, match="has texture 0 but there are 0 texture_files"):
        pomar.write(path, pomar.Mesh(mesh.vertices, mesh.faces, materials=mesh.materials))
    with pytest.raises(TypeError, match="a material is a dict"):
        pomar.write(path, pomar.Mesh(mesh.vertices, mesh.faces, materials=[{"colour": 1}]))
    assert not os.path.exists(path)


@pytest.mark.skipif("POMAR_TOOL" not in os.environ, reason="needs the pomar tool")
def test_tool_verify_compares_corners_and_materials(tmp_path):
    """`pomar verify ORIGINAL FILE DECODED`: the decoded mesh file's per-corner texture
    coordinates and materials against the original's, faces matched by their corners."""
    sample = str(tmp_path / "torus.obj")
    pomar.write(sample, textured_torus())
    m = pomar.read(sample)
    data = pomar.encode(m, keep_order=True)  # decoded vertices in the input order
    (tmp_path / "s.pomar").write_bytes(data)
    grid = pomar.decode(data).vertices

    def verify(name, corners, face_materials):
        path = str(tmp_path / name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pomar.write(path, pomar.Mesh(grid, m.faces, corner_texcoords=corners,
                                         face_materials=face_materials, materials=m.materials,
                                         texture_files=m.texture_files))
        return subprocess.run([os.environ["POMAR_TOOL"], "verify", sample,
                               str(tmp_path / "s.pomar"), path], capture_output=True, text=True)

    for name in ("same.obj", "same.ply"):
        run = verify(name, m.corner_texcoords, m.face_materials)
        assert run.returncode == 0, run.stderr
        assert "per-corner texture coordinates: 12 bits, within" in run.stdout
        assert "max error 0\n" in run.stdout
        assert "face materials: 2 materials, the same" in run.stdout
    moved = m.corner_texcoords.copy()
    moved[7, 1, 0] += 0.01
    run = verify("moved.obj", moved, m.face_materials)
    assert run.returncode == 3 and "MISMATCH:  per-corner texture coordinates" in run.stderr
    other = m.face_materials.copy()
    other[0] = 1
    run = verify("other.obj", m.corner_texcoords, other)
    assert run.returncode == 3 and "1 faces differ" in run.stderr


def test_textured_mesh_through_the_codec(tmp_path):
    mesh = textured_torus()
    for exact in (True, False):
        back = pomar.decode(pomar.encode(mesh, exact_attributes=exact, keep_order=True))
        assert back.corner_texcoords.shape == mesh.corner_texcoords.shape
        assert back.materials == mesh.materials and back.texture_files == ["skin.png"]
        info = [a for a in back.attribute_info if a["kind"] == "corner texcoord"]
        assert len(info) == 1 and info[0]["exact"] == exact
        # Faces by their corner vertices (the numbering is kept), corners in that order.
        def faces(m):
            out = {}
            for f, t in enumerate(m.faces.tolist()):
                r = t.index(min(t))
                key = tuple(t[r:] + t[:r])
                out[key] = (np.roll(m.corner_texcoords[f], -r, axis=0), int(m.face_materials[f]))
            return out
        a, b = faces(mesh), faces(back)
        assert a.keys() == b.keys()
        bound = info[0]["bound"]
        for key, (uv, material) in a.items():
            assert material == b[key][1]
            if exact:
                assert np.array_equal(uv, b[key][0])
            else:
                assert np.abs(uv - b[key][0]).max() <= bound


def test_embedded_texture_images_come_back_bit_for_bit():
    mesh = textured_torus()
    png = bytes([0x89]) + b"PNG\r\n\x1a\n" + bytes(range(256))
    mesh.texture_images = [png]
    back = pomar.decode(pomar.encode(mesh))
    assert back.texture_images == [png]
    assert pomar.info(pomar.encode(mesh))["embedded_texture_bytes"] == [len(png)]
    mesh.texture_images = [None]
    assert pomar.decode(pomar.encode(mesh)).texture_images == [None]
    mesh.texture_images = ["not bytes"]
    with pytest.raises(TypeError):
        pomar.encode(mesh)
    mesh.texture_images = [png, png]  # more images than texture files
    with pytest.raises(ValueError):
        pomar.encode(mesh)


@pytest.mark.skipif("POMAR_TOOL" not in os.environ, reason="needs the pomar tool")
def test_tool_encodes_and_verifies_a_textured_obj(tmp_path):
    obj, file = str(tmp_path / "t.obj"), str(tmp_path / "t.pomar")
    pomar.write(obj, textured_torus())
    tool = os.environ["POMAR_TOOL"]
    subprocess.run([tool, "encode", obj, file], check=True, capture_output=True)
    run = subprocess.run([tool, "verify", obj, file], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "per-corner texture coordinates: 12 bits" in run.stdout
    assert "face materials: 2 materials, the same per face" in run.stdout


def _look_at(eye, target, fov_y, width, height, near=0.01, far=100.0):
    """The view-projection matrix of camera.js (lookAt, perspective), column-major."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, [0.0, 1.0, 0.0])
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = s, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    t = 1 / np.tan(fov_y / 2)
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = t * height / width, t
    proj[2, 2], proj[2, 3] = (far + near) / (near - far), 2 * far * near / (near - far)
    proj[3, 2] = -1
    return (proj @ view).T.reshape(-1).astype(np.float32)  # column-major


def _view_levels_in_python(d, eye, view_proj, fov_y, height, near, pixels):
    """SelectiveDecoder.view_levels recomputed from what the module exposes (the stored
    bounds, the current mesh and its clusters): in the frustum, the coarsest level whose
    bound, at the distance to the cluster's box of faces grown by its current bound, is
    within `pixels`."""
    m = d.mesh()
    vc = np.asarray(d.vertex_cluster())
    levels = np.asarray(d.levels)
    n, base, finest = d.cluster_count, d.base_clustered_level, d.finest_level
    lo = np.full((n, 3), np.inf)
    hi = np.full((n, 3), -np.inf)
    for tri in m.faces:
        p = m.vertices[tri].astype(np.float64)
        for v in tri:
            c = vc[v]
            lo[c] = np.minimum(lo[c], p.min(axis=0))
            hi[c] = np.maximum(hi[c], p.max(axis=0))
    mat = np.asarray(view_proj, np.float64).reshape(4, 4).T  # clip = mat @ [x y z 1]
    planes = [mat[3] + sign * mat[axis] for axis in range(3) for sign in (-1, 1)]
    per_unit = height / (2 * np.tan(np.float64(np.float32(fov_y)) / 2))
    out = np.full(n, base)
    for c in range(n):
        grow = d.cluster_error(c, int(levels[c]))
        a, b = lo[c] - grow, hi[c] + grow
        if any(pl[0] * (b[0] if pl[0] >= 0 else a[0]) + pl[1] * (b[1] if pl[1] >= 0 else a[1])
               + pl[2] * (b[2] if pl[2] >= 0 else a[2]) + pl[3] < 0 for pl in planes):
            continue
        gap = np.maximum(np.maximum(a - eye, 0), eye - b)
        to_pixels = per_unit / max(np.float64(np.float32(near)), float(np.linalg.norm(gap)))
        level = base
        while level < finest and d.cluster_error(c, level) * to_pixels > pixels:
            level += 1
        out[c] = level
    return out


def test_stored_errors_and_block_order_are_options():
    vertices, faces = torus(60, 30)
    def names(data):  # besides the blocks' 32-bit checks and the normal predictor
        return sorted(s["name"] for s in pomar.info(data)["sections"]
                      if s["name"] not in ("BCHK", "GEOP"))
    assert names(pomar.encode(vertices, faces)) == ["BLKO", "CERR"]
    assert names(pomar.encode(vertices, faces, stored_errors=False)) == ["BLKO"]
    assert names(pomar.encode(vertices, faces, block_order="id")) == ["CERR"]
    plain = pomar.encode(vertices, faces, stored_errors=False, block_order="id")
    assert names(plain) == []
    assert np.array_equal(pomar.decode(plain).faces, pomar.decode(pomar.encode(vertices, faces)).faces)
    with pytest.raises(ValueError):
        pomar.encode(vertices, faces, block_order="morton")


def test_want_view_uses_the_stored_errors(tmp_path):
    vertices, faces = torus(120, 60)
    # Files store the errors (CERR) by default; stored_errors=False leaves them out.
    data = pomar.encode(vertices, faces, cluster_ratio=0.03)
    d = pomar.SelectiveDecoder(data)
    without = pomar.encode(vertices, faces, cluster_ratio=0.03, stored_errors=False)
    assert not pomar.SelectiveDecoder(without).has_cluster_errors
    assert len(without) < len(data)
    assert d.has_cluster_errors
    base, finest = d.base_clustered_level, d.finest_level
    assert d.cluster_error(0, finest) == 0
    assert d.cluster_error(0, base) >= d.cluster_error(0, base + 1) >= 0
    eye = np.array([1.3, 0.0, 0.45], np.float32)
    view_proj = _look_at(eye, [1.3, 0.0, 0.0], 0.8, 800, 457)
    args = dict(eye=eye, view_proj=view_proj, fov_y=0.8, width=800, height=457, near=0.01,
                pixel_error=3.0)
    for step in range(2):  # from the base clustered mesh, then from what it decoded
        levels = np.asarray(d.view_levels(**args))
        ref = _view_levels_in_python(d, eye.astype(np.float64), view_proj, 0.8, 457, 0.01, 3.0)
        # (float rounding of the box and distances may move a cluster at a threshold)
        assert np.mean(levels == ref) > 0.99, step
        assert levels.max() > base + 1
        d.want_view(**args)
        d.update()
        assert list(d.wanted) == list(levels)
    near_side = np.asarray(d.levels)[: d.cluster_count]
    assert near_side.max() == finest or near_side.max() > base + 2
    with pytest.raises(TypeError):
        d.want_view(eye=eye, view_proj=view_proj[:9], fov_y=0.8, width=800, height=457, near=0.01,
                    pixel_error=3.0)
