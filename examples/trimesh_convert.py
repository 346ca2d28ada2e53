import numpy as np
import pomar
import trimesh  # not a dependency of pomar: any library with vertex/face arrays works

tm = trimesh.load("samples/bunny.ply", process=False)
data = pomar.encode(tm.vertices.astype(np.float32), tm.faces.astype(np.uint32))
mesh = pomar.decode(data, level=10)
back = trimesh.Trimesh(vertices=mesh.vertices, faces=mesh.faces, process=False)
