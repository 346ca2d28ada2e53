import pomar

mesh = pomar.read("samples/bunny.ply")           # .ply .obj .off .stl .pomar
data = pomar.encode(mesh.vertices, mesh.faces, bits=12)  # float32 (n,3), uint32 (m,3) -> bytes
info = pomar.info(data)                          # the keys of `pomar info --json`
coarse = pomar.decode(data, level=5)             # pomar.Mesh: .vertices, .faces
full = pomar.decode(data)                        # full resolution
d = pomar.SelectiveDecoder(data)                 # or a path
d.want_sphere(full.vertices[0], 0.02); d.update()  # finest level around a point
print(info["level_count"], len(coarse.vertices), len(full.vertices), len(d.mesh().vertices), d.bytes_read)
