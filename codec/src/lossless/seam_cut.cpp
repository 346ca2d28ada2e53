// Texture seams: the seam cut (encoder) and the wedge values back into corners (decoder).
#include "lossless/seam_cut.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include "mesh/corner_table.h"
#include "mesh/radix_sort.h"

namespace pomar {

const char *const kWedgeTexcoord = "pomar:corner texcoord";
const char *const kWedgeMaterial = "pomar:face material";

bool internal_attribute_name(const std::string &name) { return name.rfind("pomar:", 0) == 0; }

bool keeps_attribute(const std::string &name, AttributeKind kind, const AttributeMask &mask) {
  if (kind == AttributeKind::Scalar && name == kWedgeMaterial)
    return mask.texcoords;
  return mask.keeps(kind);
}

bool has_corner_values(const Mesh &mesh) {
  return !mesh.corner_texcoords.empty() || !mesh.face_materials.empty();
}

void validate_corner_values(const Mesh &mesh, bool exact) {
  const size_t nf = mesh.triangle_count();
  auto invalid = [](const std::string &what) { throw Error(Error::Kind::InvalidMesh, what); };
  if (!mesh.corner_texcoords.empty() && mesh.corner_texcoords.size() != 6 * nf)
    invalid("per-corner texture coordinates: " + std::to_string(mesh.corner_texcoords.size()) +
            " values for " + std::to_string(nf) + " triangles (6 a triangle)");
  if (!mesh.face_materials.empty() && mesh.face_materials.size() != nf)
    invalid("face materials: " + std::to_string(mesh.face_materials.size()) + " for " +
            std::to_string(nf) + " triangles");
  for (size_t f = 0; f < mesh.face_materials.size(); ++f)
    if (mesh.face_materials[f] >= mesh.materials.size())
      invalid("face " + std::to_string(f) + " has material " +
              std::to_string(mesh.face_materials[f]) + "; the mesh has " +
              std::to_string(mesh.materials.size()) + " materials");
  for (const Material &m : mesh.materials)
    if (m.texture >= 0 && size_t(m.texture) >= mesh.texture_files.size())
      invalid("material '" + m.name + "' names texture " + std::to_string(m.texture) +
              "; the mesh has " + std::to_string(mesh.texture_files.size()) + " texture files");
  for (const VertexAttribute &a : mesh.attributes)
    if (internal_attribute_name(a.name))
      invalid("attribute '" + a.name + "': names starting with 'pomar:' are the codec's own");
  if (!exact)
    for (size_t i = 0; i < mesh.corner_texcoords.size(); ++i)
      if (!std::isfinite(mesh.corner_texcoords[i]))
        invalid("texture coordinate of corner " + std::to_string(i / 2 % 3) + " of face " +
                std::to_string(i / 6) + " is " +
                (std::isnan(mesh.corner_texcoords[i]) ? "NaN" : "infinite") +
                " (--exact-attributes keeps such values bit for bit)");
}

namespace {

/// Union-find over the corners (path halving).
uint32_t find(std::vector<uint32_t> &parent, uint32_t c) {
  while (parent[c] != c)
    c = parent[c] = parent[parent[c]];
  return c;
}

} // namespace

void corner_values_of_cut(const Mesh &input, const RepairMap &map, Mesh &cut) {
  const size_t nf = cut.triangle_count();
  if (map.face_origin.size() != nf || map.flipped.size() != nf)
    throw Error(Error::Kind::Internal, "internal lossless error: the cut's face map does not fit");
  cut.corner_texcoords.clear();
  cut.face_materials.clear();
  if (!input.corner_texcoords.empty()) {
    cut.corner_texcoords.resize(6 * nf);
    for (size_t f = 0; f < nf; ++f) {
      const float *from = &input.corner_texcoords[6 * size_t(map.face_origin[f])];
      float *to = &cut.corner_texcoords[6 * f];
      static constexpr int kKept[3] = {0, 1, 2}, kFlipped[3] = {0, 2, 1};
      const int *order = map.flipped[f] ? kFlipped : kKept;
      for (int k = 0; k < 3; ++k) {
        to[2 * k] = from[2 * order[k]];
        to[2 * k + 1] = from[2 * order[k] + 1];
      }
    }
  }
  if (!input.face_materials.empty()) {
    cut.face_materials.resize(nf);
    for (size_t f = 0; f < nf; ++f)
      cut.face_materials[f] = input.face_materials[map.face_origin[f]];
  }
}

namespace {

uint32_t next_corner(uint32_t c) { return c - c % 3 + (c + 1) % 3; }

/// Whether corners a and b (at the same vertex) have the same value, bit for bit.
bool same_corner_values(const Mesh &mesh, uint32_t a, uint32_t b) {
  if (!mesh.corner_texcoords.empty() &&
      std::memcmp(&mesh.corner_texcoords[2 * size_t(a)], &mesh.corner_texcoords[2 * size_t(b)],
                  2 * sizeof(float)) != 0)
    return false;
  return mesh.face_materials.empty() || mesh.face_materials[a / 3] == mesh.face_materials[b / 3];
}

/// The wedges: union-find `parent` joins the corners of a vertex that stay together in the
/// cut. Counts and locks the seam edges' vertices; marks the mesh boundary's vertices.
void join_wedges(const Mesh &mesh, std::vector<uint32_t> &parent, SeamCut &cut,
                 std::vector<uint8_t> &seam_edges_at, std::vector<uint8_t> &on_boundary) {
  const std::vector<uint32_t> &V = mesh.triangles;
  const uint32_t nc = static_cast<uint32_t>(V.size());
  // The edges, each as (smaller, larger vertex) with the corner that starts it in its face:
  // sorted, the two faces of an interior edge are neighbours (the mesh is manifold).
  std::vector<Keyed> edges(nc);
  for (uint32_t c = 0; c < nc; ++c) {
    const uint32_t a = V[c], b = V[next_corner(c)];
    edges[c] = {uint64_t(std::min(a, b)) << 32 | std::max(a, b), c};
  }
  std::sort(edges.begin(), edges.end(), [](const Keyed &x, const Keyed &y) {
    return x.key != y.key ? x.key < y.key : x.id < y.id;
  });
  parent.resize(nc);
  std::iota(parent.begin(), parent.end(), 0u);
  for (uint32_t i = 0; i < nc; ++i) {
    if (i + 1 == nc || edges[i].key != edges[i + 1].key) { // a boundary edge
      on_boundary[V[edges[i].id]] = on_boundary[V[next_corner(edges[i].id)]] = 1;
      continue;
    }
    // Face f has a -> b starting at corner cf, face g has b -> a starting at cg.
    const uint32_t cf = edges[i].id, cg = edges[i + 1].id;
    const uint32_t f_a = cf, f_b = next_corner(cf), g_b = cg, g_a = next_corner(cg);
    // The faces stay neighbours in the cut only if they agree at both ends: a seam edge
    // becomes two boundary edges (joining the corners at the end where they agree would
    // leave the faces sharing a vertex and no edge there: a vertex of two fans).
    const bool seam = !same_corner_values(mesh, f_a, g_a) || !same_corner_values(mesh, f_b, g_b);
    if (!seam) {
      parent[find(parent, f_a)] = find(parent, g_a);
      parent[find(parent, f_b)] = find(parent, g_b);
    } else {
      ++cut.seam_edges;
      for (uint32_t v : {V[cf], V[next_corner(cf)]}) {
        cut.locked[v] = 1;
        seam_edges_at[v] = uint8_t(std::min(255, seam_edges_at[v] + 1));
      }
    }
    ++i;
  }
  // Mesh boundary edges are not seams: the wedges they separate are already apart.
}

/// One vertex per wedge: the wedge of the vertex's first corner keeps it, the others get
/// copies, numbered in corner order (cut vertex nv + i copies vertex copy_source[i]).
/// Returns the cut's triangles.
std::vector<uint32_t> number_wedges(const std::vector<uint32_t> &V, uint32_t nv,
                                    std::vector<uint32_t> &parent,
                                    std::vector<uint32_t> &copy_source) {
  const uint32_t nc = static_cast<uint32_t>(V.size());
  std::vector<uint32_t> vertex_of_root(nc, kNone), first_root(nv, kNone);
  std::vector<uint32_t> triangles(nc);
  for (uint32_t c = 0; c < nc; ++c) {
    const uint32_t r = find(parent, c), v = V[c];
    if (vertex_of_root[r] == kNone) {
      if (first_root[v] == kNone) {
        first_root[v] = r;
        vertex_of_root[r] = v;
      } else {
        vertex_of_root[r] = nv + static_cast<uint32_t>(copy_source.size());
        copy_source.push_back(v);
      }
    }
    triangles[c] = vertex_of_root[r];
  }
  return triangles;
}

/// The wedge values of every vertex of the cut (a vertex no face uses: zeros).
void wedge_values(const Mesh &mesh, const std::vector<uint32_t> &triangles, uint32_t total,
                  VertexAttribute &uv, VertexAttribute &material) {
  uv.kind = AttributeKind::TexCoord;
  uv.name = kWedgeTexcoord;
  uv.components = 2;
  uv.values.assign(2 * size_t(total), 0.0f);
  material.kind = AttributeKind::Scalar;
  material.name = kWedgeMaterial;
  material.components = 1;
  material.values.assign(total, 0.0f);
  const bool has_uv = !mesh.corner_texcoords.empty(), has_mat = !mesh.face_materials.empty();
  for (uint32_t c = 0; c < triangles.size(); ++c) {
    const uint32_t w = triangles[c];
    if (has_uv)
      std::memcpy(&uv.values[2 * size_t(w)], &mesh.corner_texcoords[2 * size_t(c)],
                  2 * sizeof(float));
    if (has_mat)
      material.values[w] = static_cast<float>(mesh.face_materials[c / 3]);
  }
}

/// The copies: positions and attributes of the vertex they copy.
void append_copies(Mesh &mesh, const std::vector<uint32_t> &copy_source) {
  mesh.positions.reserve(mesh.positions.size() + 3 * copy_source.size());
  for (uint32_t s : copy_source)
    for (int k = 0; k < 3; ++k)
      mesh.positions.push_back(mesh.positions[3 * size_t(s) + k]);
  for (VertexAttribute &a : mesh.attributes) {
    const size_t n = a.components;
    for (uint32_t s : copy_source) {
      if (a.kind == AttributeKind::Colour)
        for (size_t k = 0; k < n; ++k)
          a.colour.push_back(a.colour[s * n + k]);
      else
        for (size_t k = 0; k < n; ++k)
          a.values.push_back(a.values[s * n + k]);
    }
  }
}

/// The copies' locks and origins; a simple seam vertex (one copy, two seam edges, not on the
/// boundary) and its copy become twins, unlocked.
void twin_seam_vertices(uint32_t nv, const std::vector<uint32_t> &copy_source,
                        const std::vector<uint8_t> &seam_edges_at,
                        const std::vector<uint8_t> &on_boundary, SeamCut &cut) {
  const uint32_t total = nv + static_cast<uint32_t>(copy_source.size());
  cut.locked.resize(total, 0);
  cut.twin.assign(total, kNone);
  cut.origin.resize(total);
  std::iota(cut.origin.begin(), cut.origin.begin() + nv, 0u);
  std::vector<uint32_t> copies(nv, 0), last_copy(nv, kNone);
  for (uint32_t i = 0; i < copy_source.size(); ++i) {
    const uint32_t s = copy_source[i];
    cut.locked[nv + i] = cut.locked[s];
    cut.origin[nv + i] = s;
    ++copies[s];
    last_copy[s] = nv + i;
  }
  for (uint32_t v = 0; v < nv; ++v)
    if (copies[v] == 1 && seam_edges_at[v] == 2 && !on_boundary[v]) { // a simple seam vertex
      cut.twin[v] = last_copy[v];
      cut.twin[last_copy[v]] = v;
      cut.locked[v] = cut.locked[last_copy[v]] = 0;
      cut.twins += 2;
    }
}

} // namespace

SeamCut cut_at_seams(Mesh &mesh, RepairMap &map, uint32_t input_vertices) {
  const uint32_t nv = static_cast<uint32_t>(mesh.vertex_count());
  const bool has_uv = !mesh.corner_texcoords.empty(), has_mat = !mesh.face_materials.empty();
  SeamCut cut;
  cut.locked.assign(nv, 0);
  std::vector<uint8_t> seam_edges_at(nv, 0), on_boundary(nv, 0);
  std::vector<uint32_t> parent;
  join_wedges(mesh, parent, cut, seam_edges_at, on_boundary);
  std::vector<uint32_t> copy_source;
  std::vector<uint32_t> triangles = number_wedges(mesh.triangles, nv, parent, copy_source);
  cut.wedge_copies = copy_source.size();
  const uint32_t total = nv + static_cast<uint32_t>(copy_source.size());
  VertexAttribute uv, material;
  wedge_values(mesh, triangles, total, uv, material);
  append_copies(mesh, copy_source);
  twin_seam_vertices(nv, copy_source, seam_edges_at, on_boundary, cut);
  // Cut vertex v (v < nv) stands for input vertex v (< input_vertices) or for the copy
  // map.copy_of[v - input_vertices]; so does each of its wedge copies.
  if (map.copy_of.size() + input_vertices != nv)
    throw Error(Error::Kind::Internal, "internal lossless error: the seam cut's map does not fit");
  for (uint32_t s : copy_source)
    map.copy_of.push_back(s < input_vertices ? s : map.copy_of[s - input_vertices]);

  mesh.triangles.swap(triangles);
  if (has_uv)
    mesh.attributes.push_back(std::move(uv));
  if (has_mat)
    mesh.attributes.push_back(std::move(material));
  mesh.corner_texcoords.clear();
  mesh.corner_texcoords.shrink_to_fit();
  mesh.face_materials.clear();
  mesh.face_materials.shrink_to_fit();
  return cut;
}

void corners_from_wedges(Mesh &mesh) {
  const size_t nv = mesh.vertex_count(), nc = mesh.triangles.size();
  for (size_t i = 0; i < mesh.attributes.size();) {
    VertexAttribute &a = mesh.attributes[i];
    const bool uv = a.kind == AttributeKind::TexCoord && a.name == kWedgeTexcoord;
    const bool mat = a.kind == AttributeKind::Scalar && a.name == kWedgeMaterial;
    if (!uv && !mat) {
      ++i;
      continue;
    }
    if (a.vertex_count() != nv)
      throw Error(Error::Kind::Internal, "internal error: the wedge values do not fit the mesh");
    if (uv) {
      mesh.corner_texcoords.resize(2 * nc);
      for (size_t c = 0; c < nc; ++c)
        std::memcpy(&mesh.corner_texcoords[2 * c], &a.values[2 * size_t(mesh.triangles[c])],
                    2 * sizeof(float));
      mesh.corner_texcoord_bits = a.bits;
      mesh.corner_texcoord_bound = a.bound;
    } else {
      mesh.face_materials.resize(nc / 3);
      for (size_t f = 0; f < nc / 3; ++f) {
        const float m = a.values[mesh.triangles[3 * f]];
        const float r = std::nearbyint(m);
        // (The grid of the material codes is at most one unit a step: within half of it.)
        if (!(r >= 0) || r >= float(mesh.materials.size()) || std::fabs(m - r) >= 0.5f)
          throw Error(Error::Kind::DamagedFile,
                      "damaged .pomar file: face " + std::to_string(f) + " has material " +
                          std::to_string(m) + "; the file has " +
                          std::to_string(mesh.materials.size()) + " materials");
        mesh.face_materials[f] = static_cast<uint32_t>(r);
      }
    }
    mesh.attributes.erase(mesh.attributes.begin() + long(i));
  }
}

} // namespace pomar
