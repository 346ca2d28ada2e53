#include "mesh/mesh_compare.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace pomar {

namespace {

Position position(const Mesh &m, uint32_t v) {
  return Position{m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
}

} // namespace

PositionTriangle smallest_rotation(const Mesh &m, size_t f, int &rotation) {
  const PositionTriangle t = {position(m, m.triangles[3 * f]), position(m, m.triangles[3 * f + 1]),
                              position(m, m.triangles[3 * f + 2])};
  const PositionTriangle r[3] = {t, {t[1], t[2], t[0]}, {t[2], t[0], t[1]}};
  rotation = int(std::min_element(r, r + 3) - r);
  return r[rotation];
}

std::vector<PositionTriangle> canonical_triangles(const Mesh &m) {
  std::vector<PositionTriangle> out(m.triangle_count());
  int rotation = 0;
  for (size_t f = 0; f < out.size(); ++f)
    out[f] = smallest_rotation(m, f, rotation);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Position> sorted_positions(const Mesh &m) {
  std::vector<Position> out(m.vertex_count());
  for (size_t v = 0; v < out.size(); ++v)
    out[v] = position(m, uint32_t(v));
  std::sort(out.begin(), out.end());
  return out;
}

bool same_geometry(const Mesh &a, const Mesh &b, bool triangles_only) {
  return canonical_triangles(a) == canonical_triangles(b) &&
         (triangles_only ||
          (a.vertex_count() == b.vertex_count() && sorted_positions(a) == sorted_positions(b)));
}

double attribute_error(const VertexAttribute &a, size_t i, const VertexAttribute &b, size_t j,
                       bool exact) {
  const uint32_t n = a.components;
  if (a.kind == AttributeKind::Colour) {
    double e = 0;
    for (uint32_t k = 0; k < n; ++k)
      e = std::max(e, std::fabs(double(a.colour[i * n + k]) - double(b.colour[j * n + k])));
    return e;
  }
  const float *x = &a.values[i * n], *y = &b.values[j * n];
  if (exact && std::memcmp(x, y, 4 * n) == 0)
    return 0;
  if (a.kind == AttributeKind::Normal && !exact) {
    const bool zero_x = x[0] == 0 && x[1] == 0 && x[2] == 0;
    const bool zero_y = y[0] == 0 && y[1] == 0 && y[2] == 0;
    if (zero_x || zero_y) // a zero-length normal comes back as exactly zero
      return zero_x && zero_y ? 0 : HUGE_VAL;
    const double cx = double(x[1]) * y[2] - double(x[2]) * y[1];
    const double cy = double(x[2]) * y[0] - double(x[0]) * y[2];
    const double cz = double(x[0]) * y[1] - double(x[1]) * y[0];
    const double dot = double(x[0]) * y[0] + double(x[1]) * y[1] + double(x[2]) * y[2];
    return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot) * 180.0 / M_PI;
  }
  double e = 0;
  for (uint32_t k = 0; k < n; ++k) {
    const double d = std::fabs(double(x[k]) - double(y[k]));
    e = std::max(e, std::isnan(d) ? HUGE_VAL : d);
  }
  return exact && e == 0 ? HUGE_VAL : e; // bit patterns differ (-0 and 0, NaN payloads)
}

VerticesByPosition vertices_by_position(const Mesh &m) {
  VerticesByPosition at;
  for (uint32_t v = 0; v < m.vertex_count(); ++v)
    at[position(m, v)].push_back(v);
  return at;
}

double worst_attribute_error(const VerticesByPosition &ref_at, const VertexAttribute &a,
                             const Mesh &out, const VertexAttribute &b, bool exact) {
  double worst = 0;
  for (uint32_t v = 0; v < out.vertex_count(); ++v) {
    const auto it = ref_at.find(position(out, v));
    if (it == ref_at.end())
      continue;
    double best = HUGE_VAL;
    for (uint32_t r : it->second)
      best = std::min(best, attribute_error(a, r, b, v, exact));
    worst = std::max(worst, best);
  }
  return worst;
}

std::vector<float> corner_uvs(const Mesh &m) {
  if (!m.corner_texcoords.empty())
    return m.corner_texcoords;
  const VertexAttribute *uv = m.find(AttributeKind::TexCoord);
  std::vector<float> out;
  if (uv && uv->vertex_count() == m.vertex_count())
    for (const uint32_t v : m.triangles)
      out.insert(out.end(), {uv->values[2 * v], uv->values[2 * v + 1]});
  return out;
}

std::string face_material_text(const Mesh &m, size_t f, bool names) {
  if (m.face_materials.empty())
    return "";
  const Material &mat = m.materials[m.face_materials[f]];
  const std::string file = mat.texture >= 0 ? m.texture_files[size_t(mat.texture)] : "";
  return names ? mat.name + "|" + file + "|" + mat.properties : file;
}

CornerDifference compare_corners(const Mesh &ref, const std::vector<float> &ref_uvs,
                                 const Mesh &out, const std::vector<float> &out_uvs, bool exact,
                                 bool names) {
  const bool uvs = !ref_uvs.empty(), materials = !ref.face_materials.empty();
  std::map<PositionTriangle, std::vector<std::pair<size_t, int>>> faces; // (face, rotation)
  for (size_t f = 0; f < ref.triangle_count(); ++f) {
    int rotation = 0;
    const PositionTriangle t = smallest_rotation(ref, f, rotation);
    faces[t].push_back({f, rotation});
  }
  CornerDifference d;
  for (size_t g = 0; g < out.triangle_count(); ++g) {
    int rotation = 0;
    const auto it = faces.find(smallest_rotation(out, g, rotation));
    if (it == faces.end())
      continue;
    double best = HUGE_VAL;
    bool material_ok = !materials;
    for (const auto &[f, r] : it->second) {
      double e = 0;
      for (int k = 0; uvs && k < 3; ++k) {
        const float *a = &ref_uvs[6 * f + 2 * size_t((k + r) % 3)];
        const float *b = &out_uvs[6 * g + 2 * size_t((k + rotation) % 3)];
        for (int c = 0; c < 2; ++c) {
          const double diff = std::fabs(double(a[c]) - double(b[c]));
          e = std::max(e, exact              ? (std::memcmp(a + c, b + c, 4) == 0 ? 0 : HUGE_VAL)
                          : std::isnan(diff) ? HUGE_VAL
                                             : diff);
        }
      }
      best = std::min(best, e);
      material_ok |= face_material_text(ref, f, names) == face_material_text(out, g, names);
    }
    d.worst_uv_error = std::max(d.worst_uv_error, best);
    d.material_mismatches += !material_ok;
  }
  return d;
}

} // namespace pomar
