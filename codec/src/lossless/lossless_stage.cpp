// The lossless stage (see lossless_stage.h): the cut of a messy mesh (make_manifold, then
// its texture seams) that pomar::encode (encode/encode.cpp) codes with the manifold encoder,
// the record of what the cut changed, and a full decode's undoing of it.
#include "lossless/lossless_stage.h"

#include <algorithm>
#include <array>
#include <numeric>
#include <string>

#include "attributes/material_section.h"
#include "format/file_format.h"
#include "geometry/quantize.h"
#include "lossless/seam_cut.h"
#include "mesh/corner_table.h"
#include "repair/cut.h"

namespace pomar {

namespace {

using Key = std::array<uint32_t, 3>;

/// The rotation of a face starting at its smallest vertex.
Key rotated(const uint32_t *v) {
  const int k = v[0] < v[1] ? (v[0] < v[2] ? 0 : 2) : (v[1] < v[2] ? 1 : 2);
  return {v[k], v[(k + 1) % 3], v[(k + 2) % 3]};
}

bool repeats_vertex(const uint32_t *v) { return v[0] == v[1] || v[1] == v[2] || v[0] == v[2]; }

/// A face repeating a vertex as (a, b): the face is (a, a, b) up to rotation.
std::array<uint32_t, 2> degenerate_form(uint32_t x, uint32_t y, uint32_t z) {
  if (x == y)
    return {x, z};
  if (y == z)
    return {y, x};
  return {z, y}; // z == x: (z, x, y) = (z, z, y)
}

/// The levels code only vertices a face uses; the record keeps the others' attributes bit
/// for bit. So that the attribute checks of the coded mesh do not refuse values the levels
/// never see (an OBJ vertex without a normal, a NaN), such vertices get a neutral value in
/// the copy that is coded.
void usable_attributes_for_unused_vertices(Mesh &cut) {
  const size_t nv = cut.vertex_count();
  std::vector<uint8_t> used(nv, 0);
  for (uint32_t v : cut.triangles)
    if (v < nv) // (an index out of range is the manifold encoder's to name)
      used[v] = 1;
  for (VertexAttribute &a : cut.attributes) {
    if (a.kind == AttributeKind::Colour || a.values.size() != nv * a.components)
      continue;
    for (size_t v = 0; v < nv; ++v)
      if (!used[v])
        for (uint32_t k = 0; k < a.components; ++k)
          a.values[v * a.components + k] = a.kind == AttributeKind::Normal && k == 2 ? 1.0f : 0.0f;
  }
}

std::string plural(size_t n, const char *one, const char *many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

} // namespace

bool all_vertices_used(const Mesh &mesh) {
  const size_t nv = mesh.vertex_count();
  std::vector<uint8_t> used(nv, 0);
  for (uint32_t v : mesh.triangles)
    if (v < nv)
      used[v] = 1;
  return std::find(used.begin(), used.end(), 0) == used.end();
}

bool valid_topology(const Mesh &mesh) {
  try {
    CornerTable ct;
    build_corner_table(mesh.triangles.data(), mesh.triangle_count(), mesh.vertex_count(), ct);
  } catch (const Error &) {
    return false;
  }
  return true;
}

std::string LosslessReport::summary() const {
  if (!stored)
    return "";
  std::vector<std::string> kept;
  if (faces_flipped)
    kept.push_back(plural(faces_flipped, "flipped face", "flipped faces"));
  if (duplicate_faces)
    kept.push_back(plural(duplicate_faces, "duplicate face", "duplicate faces"));
  if (degenerate_faces)
    kept.push_back(plural(degenerate_faces, "face repeating a vertex", "faces repeating a vertex"));
  if (unreferenced_vertices)
    kept.push_back(plural(unreferenced_vertices, "unreferenced vertex", "unreferenced vertices"));
  if (keep_order)
    kept.push_back("the vertex order");
  std::string s;
  if (vertices_split || edges_cut) {
    s = "non-manifold: ";
    if (vertices_split)
      s += plural(vertices_split, "vertex", "vertices") + (edges_cut ? " and " : "");
    if (edges_cut)
      s += plural(edges_cut, "edge", "edges");
    s += " stored as cuts";
  }
  for (size_t i = 0; i < kept.size(); ++i)
    s += (i == 0 ? (s.empty() ? "" : "; ") : i + 1 == kept.size() ? " and " : ", ") + kept[i];
  if (!kept.empty())
    s += " kept";
  if (seam_edges || wedge_copies)
    s += (s.empty() ? "" : "; ") + plural(seam_edges, "texture seam edge", "texture seam edges") +
         " (" + plural(wedge_copies, "vertex copy", "vertex copies") + " welded on decoding)";
  return s + " (" + plural(bytes, "byte", "bytes") + ")";
}

namespace {

/// The first decoded vertex of an input vertex represents it, later ones are copies (added
/// to r.copies); numbers the represented input vertices in output order.
void number_decoded_vertices(const RepairMap &map, uint32_t nv,
                             const std::vector<uint32_t> &decoded_to_cut, LosslessRecord &r,
                             std::vector<uint32_t> &input_to_output,
                             std::vector<uint32_t> &cut_to_decoded,
                             std::vector<uint32_t> &output_to_input) {
  const uint32_t nd = static_cast<uint32_t>(decoded_to_cut.size());
  std::vector<uint32_t> first(nv, kNone);
  output_to_input.clear();
  for (uint32_t d = 0; d < nd; ++d) {
    const uint32_t c = decoded_to_cut[d], v = c < nv ? c : map.copy_of[c - nv];
    cut_to_decoded[c] = d;
    if (first[v] != kNone) {
      r.copies.push_back({d, first[v]});
      continue;
    }
    first[v] = d;
    input_to_output[v] = static_cast<uint32_t>(output_to_input.size());
    output_to_input.push_back(v);
  }
}

/// The input vertices no decoded vertex is, sorted by grid position (their output order is
/// free: the deltas from one to the next are then smaller; keep_order restores the input
/// order anyway), numbered after the others, with their attributes as the input has them
/// (the levels never code these vertices).
void number_extra_vertices(const Mesh &input, const Quantizer &grid, LosslessRecord &r,
                           std::vector<uint32_t> &input_to_output,
                           std::vector<uint32_t> &output_to_input) {
  const uint32_t nv = static_cast<uint32_t>(input.vertex_count());
  std::vector<std::pair<Key, uint32_t>> extra;
  for (uint32_t v = 0; v < nv; ++v)
    if (input_to_output[v] == kNone) {
      Key q;
      for (int k = 0; k < 3; ++k)
        q[k] = grid.quantize(k, input.positions[3 * size_t(v) + k]);
      extra.push_back({q, v});
    }
  std::sort(extra.begin(), extra.end());
  for (const auto &[q, v] : extra) {
    input_to_output[v] = static_cast<uint32_t>(output_to_input.size());
    output_to_input.push_back(v);
    r.extra_q.insert(r.extra_q.end(), q.begin(), q.end());
  }
  if (!extra.empty())
    for (const VertexAttribute &a : input.attributes) {
      VertexAttribute x;
      x.kind = a.kind;
      x.name = a.name;
      x.components = a.components;
      const size_t n = a.components;
      for (const auto &e : extra) {
        const size_t v = e.second;
        if (a.kind == AttributeKind::Colour)
          x.colour.insert(x.colour.end(), &a.colour[v * n], &a.colour[v * n] + n);
        else
          x.values.insert(x.values.end(), &a.values[v * n], &a.values[v * n] + n);
      }
      r.extra_attributes.push_back(std::move(x));
    }
}

/// The removed input faces: repeating a vertex (r.degenerate), or an exact duplicate of a
/// kept face, the one with the same rotated vertices in input numbering (r.duplicates, by
/// the kept face's `rank` in D's canonical order).
void removed_faces(const Mesh &input, const RepairMap &map, uint32_t nf,
                   const std::vector<uint32_t> &rank, const std::vector<uint32_t> &input_to_output,
                   LosslessRecord &r) {
  const uint32_t input_faces = static_cast<uint32_t>(input.triangle_count());
  std::vector<uint8_t> kept(input_faces, 0);
  std::vector<std::pair<Key, uint32_t>> kept_keys(nf);
  for (uint32_t f = 0; f < nf; ++f) {
    kept[map.face_origin[f]] = 1;
    kept_keys[f] = {rotated(&input.triangles[3 * size_t(map.face_origin[f])]), f};
  }
  std::sort(kept_keys.begin(), kept_keys.end());
  std::vector<uint32_t> extra_copies(nf, 0);
  for (uint32_t g = 0; g < input_faces; ++g) {
    if (kept[g])
      continue;
    const uint32_t *t = &input.triangles[3 * size_t(g)];
    if (repeats_vertex(t)) {
      r.degenerate.push_back(
          degenerate_form(input_to_output[t[0]], input_to_output[t[1]], input_to_output[t[2]]));
      continue;
    }
    const Key key = rotated(t);
    auto it = std::lower_bound(kept_keys.begin(), kept_keys.end(), std::make_pair(key, 0u));
    if (it == kept_keys.end() || it->first != key)
      throw Error(Error::Kind::Internal,
                  "internal lossless error: a removed face is neither degenerate nor a duplicate");
    ++extra_copies[rank[it->second]];
  }
  for (uint32_t i = 0; i < nf; ++i)
    if (extra_copies[i])
      r.duplicates.push_back({i, extra_copies[i]});
  std::sort(r.degenerate.begin(), r.degenerate.end());
}

} // namespace

LosslessRecord build_lossless_record(const Mesh &input, const Mesh &cut, const RepairMap &map,
                                     const std::vector<uint32_t> &decoded_to_cut,
                                     const Quantizer &grid, bool keep_order, Mesh &decoded,
                                     std::vector<uint32_t> &output_to_input) {
  const uint32_t nv = static_cast<uint32_t>(input.vertex_count());
  const uint32_t nd = static_cast<uint32_t>(decoded_to_cut.size());
  LosslessRecord r;
  std::vector<uint32_t> input_to_output(nv, kNone), cut_to_decoded(cut.vertex_count(), kNone);
  number_decoded_vertices(map, nv, decoded_to_cut, r, input_to_output, cut_to_decoded,
                          output_to_input);
  number_extra_vertices(input, grid, r, input_to_output, output_to_input);

  // D itself (what write_lossless_record reads of it: the positions to place vertex
  // copies, the faces to apply the record before coding the input's order), and where
  // each cut face comes in D's canonical order (to name flipped and duplicated faces). A
  // cut that only left vertices unreferenced needs neither (a scan's stray points).
  const uint32_t nf = static_cast<uint32_t>(cut.triangle_count());
  const uint32_t input_faces = static_cast<uint32_t>(input.triangle_count());
  const bool faces_changed = nf != input_faces || std::find(map.flipped.begin(), map.flipped.end(),
                                                            1) != map.flipped.end();
  if (!r.copies.empty() || keep_order) {
    decoded.positions.resize(3 * size_t(nd));
    for (uint32_t d = 0; d < nd; ++d)
      for (int k = 0; k < 3; ++k)
        decoded.positions[3 * size_t(d) + k] =
            grid.dequantize(k, grid.quantize(k, cut.positions[3 * size_t(decoded_to_cut[d]) + k]));
  }
  if (faces_changed || keep_order) {
    decoded.triangles.resize(cut.triangles.size());
    for (size_t c = 0; c < cut.triangles.size(); ++c)
      decoded.triangles[c] = cut_to_decoded[cut.triangles[c]];
  }
  if (faces_changed) {
    const std::vector<uint32_t> order = canonical_face_order(decoded.triangles);
    std::vector<uint32_t> rank(nf);
    for (uint32_t i = 0; i < nf; ++i)
      rank[order[i]] = i;
    for (uint32_t f = 0; f < nf; ++f)
      if (map.flipped[f])
        r.flipped.push_back(rank[f]);
    std::sort(r.flipped.begin(), r.flipped.end());
    removed_faces(input, map, nf, rank, input_to_output, r);
  }
  if (keep_order)
    r.order = output_to_input;
  return r;
}

void start_lossless_cut(const Mesh &mesh, const EncodeOptions &options, LosslessCut &c) {
  c.hook.grid = make_quantizer(mesh.positions.data(), mesh.vertex_count(), options.bits);
  const bool keep_order = options.keep_order;
  c.hook.record = [&mesh, &c, keep_order](const std::vector<uint32_t> &decoded_to_cut) {
    c.record = build_lossless_record(mesh, *c.coded, c.map, decoded_to_cut, c.hook.grid, keep_order,
                                     c.decoded, c.output_to_input);
    return write_lossless_record(c.record, std::move(c.decoded));
  };
}

void cut_for_encoding(const Mesh &mesh, bool cut_needed, bool corners, LosslessCut &c) {
  c.map = RepairMap();
  c.repair = RepairReport();
  c.decoded = Mesh();
  c.coded = &c.cut;
  if (cut_needed) {
    c.cut = mesh;
    c.repair = cut_to_manifold(c.cut, &c.map); // checks the indices
  } else {
    c.map.face_origin.resize(mesh.triangle_count());
    std::iota(c.map.face_origin.begin(), c.map.face_origin.end(), 0u);
    c.map.flipped.assign(mesh.triangle_count(), 0);
    if (mesh.attributes.empty())
      c.coded = &mesh;
    else
      c.cut = mesh;
  }
  c.hook.locked.clear();
  c.hook.twin.clear();
  c.hook.origin.clear();
  c.hook.materials.clear();
  if (corners) { // the cut's faces get their corners' values, then it is cut at its seams
    if (c.coded != &c.cut) {
      c.cut = mesh;
      c.coded = &c.cut;
    }
    corner_values_of_cut(mesh, c.map, c.cut);
    c.seams = cut_at_seams(c.cut, c.map, static_cast<uint32_t>(mesh.vertex_count()));
    c.hook.locked = std::move(c.seams.locked);
    c.hook.twin = std::move(c.seams.twin);
    c.hook.origin = std::move(c.seams.origin);
    MaterialTable materials;
    materials.corner_texcoords = !mesh.corner_texcoords.empty();
    materials.face_materials = !mesh.face_materials.empty();
    materials.materials = mesh.materials;
    c.hook.materials = write_materials(materials);
  }
  if (c.coded == &c.cut)
    usable_attributes_for_unused_vertices(c.cut);
  if (c.coded->triangle_count() == 0)
    throw Error(Error::Kind::InvalidMesh, "the mesh has no valid triangle: all " +
                                              std::to_string(mesh.triangle_count()) +
                                              " faces repeat a vertex");
}

namespace {

/// The lossless record's body (its checksum checked) and size, or nullptr if there is none.
const uint8_t *lossless_body(const uint8_t *data, const FileLayout &layout, uint64_t &bytes) {
  const int i = find_section(layout, kLosslessTag);
  if (i < 0)
    return nullptr;
  bytes = layout.header.sections[i].bytes;
  return section_body(data, layout, static_cast<size_t>(i));
}

} // namespace

void lossless_info(const uint8_t *data, const FileLayout &layout, FileInfo &info) {
  uint64_t bytes = 0;
  if (const uint8_t *body = lossless_body(data, layout, bytes)) {
    const LosslessCounts n = read_lossless_counts(body, bytes);
    info.input_vertices = n.vertices(layout.header.vertices);
    info.input_faces = n.faces(layout.header.faces);
  }
}

void undo_cut(const uint8_t *data, const FileLayout &layout, Mesh &decoded,
              std::vector<uint32_t> *source) {
  uint64_t bytes = 0;
  if (const uint8_t *body = lossless_body(data, layout, bytes)) {
    const LosslessRecord r = read_lossless_record(body, bytes, decoded, layout.header.grid.bits);
    decoded = apply_lossless_record(std::move(decoded), r, layout.header.grid, source);
  } else if (source) {
    source->resize(decoded.vertex_count());
    for (uint32_t v = 0; v < source->size(); ++v)
      (*source)[v] = v;
  }
}

} // namespace pomar
