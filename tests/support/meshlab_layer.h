// Reading back what the pomar MeshLab plugins store on a layer (plugin tests only).
#pragma once

#include <common/meshmodel.h>
#include <vcg/complex/allocate.h>

#include <string>
#include <vector>

#include <pomar/meshlab_layer.h> // the attribute names

namespace pomar::test {

/// A per-vertex float attribute of the layer (empty if it has none).
inline std::vector<float> vertexAttribute(CMeshO &m, const char *name) {
  std::vector<float> out;
  auto h = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(m, name);
  if (!vcg::tri::Allocator<CMeshO>::IsValidHandle(m, h))
    return out;
  for (size_t v = 0; v < m.vert.size(); ++v)
    out.push_back(h[v]);
  return out;
}

/// The source path the IO plugin stored, or "<none>".
inline std::string sourceAttribute(CMeshO &m) {
  auto h = vcg::tri::Allocator<CMeshO>::FindPerMeshAttribute<std::string>(
      m, pomar::meshlab::kSourceAttribute);
  return vcg::tri::Allocator<CMeshO>::IsValidHandle(m, h) ? h() : std::string("<none>");
}

} // namespace pomar::test
