// The per-vertex rows of an attribute, kept for a subset of the vertices (dropping
// unreferenced vertices, keeping one representative of copied vertices).
#pragma once

#include <cstddef>

#include "pomar/attributes.h"

namespace pomar {

/// Keep, in order, the rows of the vertices v in [0, nv) for which keep(v) is true; keep is
/// called once per vertex, in increasing v (it may keep state). The attribute must have
/// nv rows.
template <class Keep> void keep_vertex_rows(VertexAttribute &a, size_t nv, Keep &&keep) {
  const size_t n = a.components;
  auto compact = [&](auto &values) {
    size_t out = 0;
    for (size_t v = 0; v < nv; ++v)
      if (keep(v))
        for (size_t k = 0; k < n; ++k)
          values[out++] = values[v * n + k];
    values.resize(out);
  };
  if (a.kind == AttributeKind::Colour)
    compact(a.colour);
  else
    compact(a.values);
}

} // namespace pomar
