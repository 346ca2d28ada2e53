// Vertices no triangle uses: counting and dropping them (pomar.h).
#include <algorithm>
#include <vector>

#include "attributes/vertex_rows.h"
#include "mesh/corner_table.h"
#include "pomar/pomar.h"

namespace pomar {

size_t drop_unreferenced_vertices(Mesh &mesh) {
  const size_t nv = mesh.vertex_count();
  std::vector<uint32_t> index(nv, kNone);
  for (uint32_t v : mesh.triangles)
    if (v < nv)
      index[v] = 0;
  std::vector<float> kept;
  uint32_t next = 0;
  for (size_t v = 0; v < nv; ++v) {
    if (index[v] == kNone)
      continue;
    index[v] = next++;
    kept.insert(kept.end(), &mesh.positions[3 * v], &mesh.positions[3 * v] + 3);
  }
  for (uint32_t &v : mesh.triangles)
    if (v < nv)
      v = index[v];
  mesh.positions.swap(kept);
  for (VertexAttribute &a : mesh.attributes) { // the attributes of the kept vertices
    const size_t size = a.kind == AttributeKind::Colour ? a.colour.size() : a.values.size();
    if (size != nv * a.components)
      continue; // not one value per vertex: left for validation to name
    keep_vertex_rows(a, nv, [&](size_t v) { return index[v] != kNone; });
  }
  return nv - next;
}

} // namespace pomar
