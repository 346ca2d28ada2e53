// The lossless stage (see lossless_stage.h): pomar::encode() cuts a messy mesh with
// make_manifold, codes the cut mesh with the manifold encoder and stores what the cut
// changed; a full decode undoes it.
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

/// True if every vertex is used by a face (indices out of range are left to the encoder,
/// which names them).
bool all_vertices_used(const Mesh &mesh) {
  const size_t nv = mesh.vertex_count();
  std::vector<uint8_t> used(nv, 0);
  for (uint32_t v : mesh.triangles)
    if (v < nv)
      used[v] = 1;
  return std::find(used.begin(), used.end(), 0) == used.end();
}

/// True when the manifold encoder takes `mesh` as it is: a valid corner table (manifold,
/// oriented, no face repeating a vertex, no duplicate).
bool valid_topology(const Mesh &mesh) {
  try {
    CornerTable ct;
    build_corner_table(mesh.triangles.data(), mesh.triangle_count(), mesh.vertex_count(), ct);
  } catch (const Error &) {
    return false;
  }
  return true;
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

LosslessRecord build_lossless_record(const Mesh &input, const Mesh &cut, const RepairMap &map,
                                     const std::vector<uint32_t> &decoded_to_cut,
                                     const Quantizer &grid, bool keep_order, Mesh &decoded,
                                     std::vector<uint32_t> &output_to_input) {
  const uint32_t nv = static_cast<uint32_t>(input.vertex_count());
  const uint32_t nd = static_cast<uint32_t>(decoded_to_cut.size());
  auto input_of_cut = [&](uint32_t c) { return c < nv ? c : map.copy_of[c - nv]; };
  LosslessRecord r;

  // Vertices: the first decoded vertex of an input vertex represents it, later ones are
  // copies; then the input vertices no decoded vertex is.
  std::vector<uint32_t> first(nv, kNone), input_to_output(nv, kNone);
  std::vector<uint32_t> cut_to_decoded(cut.vertex_count(), kNone);
  output_to_input.clear();
  for (uint32_t d = 0; d < nd; ++d) {
    const uint32_t c = decoded_to_cut[d], v = input_of_cut(c);
    cut_to_decoded[c] = d;
    if (first[v] != kNone) {
      r.copies.push_back({d, first[v]});
      continue;
    }
    first[v] = d;
    input_to_output[v] = static_cast<uint32_t>(output_to_input.size());
    output_to_input.push_back(v);
  }
  // The others, sorted by grid position (their output order is free: the deltas from one
  // to the next are then smaller; keep_order restores the input order anyway).
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
  // Their attributes, as the input has them (the levels never code these vertices).
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
  if (!faces_changed) {
    if (keep_order)
      r.order = output_to_input;
    return r;
  }
  const std::vector<uint32_t> order = canonical_face_order(decoded.triangles);
  std::vector<uint32_t> rank(nf);
  for (uint32_t i = 0; i < nf; ++i)
    rank[order[i]] = i;
  for (uint32_t f = 0; f < nf; ++f)
    if (map.flipped[f])
      r.flipped.push_back(rank[f]);
  std::sort(r.flipped.begin(), r.flipped.end());

  // Removed input faces: repeating a vertex, or an exact duplicate of a kept face (the one
  // with the same rotated vertices in input numbering).
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
  if (keep_order)
    r.order = output_to_input;
  return r;
}

namespace {

/// encode(), given the mesh (`owned`, the same mesh) or not (nullptr): a clean mesh given is
/// freed once the manifold encoder has quantized it.
std::vector<uint8_t> encode_any(const Mesh &mesh, const EncodeOptions &options,
                                EncodeReport *report, Mesh *owned) {
  bool released = false;
  std::function<void()> release;
  if (owned)
    release = [&] {
      *owned = Mesh();
      released = true;
    };
  // Per-corner values are coded as the seam cut (lossless/seam_cut.h), whose copies the
  // record welds back: such a mesh always has a record.
  const bool corners = has_corner_values(mesh) && options.attributes.keep.texcoords;
  if (corners)
    validate_corner_values(mesh, options.attributes.exact);
  if (options.strict && corners)
    throw Error(Error::Kind::Usage,
                "per-corner texture coordinates and face materials are kept with a lossless "
                "record, which strict mode does not write: encode without strict (--strict), "
                "or drop the texture coordinates");
  if (options.strict)
    return encode_manifold(mesh, options, report, nullptr, release);

  // False once the topology is known to be one the manifold encoder does not take as it is.
  bool valid = true;
  if (!options.keep_order && !corners && all_vertices_used(mesh)) {
    // Most meshes are clean: code them as they are (the file is then byte for byte what
    // strict gives). The manifold encoder checks the topology early (its corner table),
    // before it releases the mesh: if the table refuses the mesh (TopologyError), the mesh
    // is cut; if the encoder refuses it for another reason, the topology is checked here,
    // and only an invalid one is cut.
    try {
      return encode_manifold(mesh, options, report, nullptr, release, false);
    } catch (const TopologyError &) { // (its corner table refused the mesh)
      if (released)
        throw;
      valid = false;
    } catch (const Error &) {
      if (released || mesh.triangles.size() % 3 || valid_topology(mesh))
        throw; // not a matter of topology: the error stands
      valid = false;
    }
  }

  const size_t nv = mesh.vertex_count();
  check_encode_input(mesh, options); // unreferenced vertices included
  Mesh cut;
  const Mesh *coded = &cut; // what the manifold encoder codes: the cut (the mesh itself if
                            // no cut and no attribute to neutralise: no copy)
  RepairMap map;
  RepairReport repair;
  SeamCut seams;
  LosslessHook hook;
  hook.grid = make_quantizer(mesh.positions.data(), nv, options.bits);
  LosslessRecord record;
  Mesh decoded;
  std::vector<uint32_t> output_to_input;
  hook.record = [&](const std::vector<uint32_t> &decoded_to_cut) {
    record = build_lossless_record(mesh, *coded, map, decoded_to_cut, hook.grid, options.keep_order,
                                   decoded, output_to_input);
    return write_lossless_record(record, std::move(decoded));
  };
  // The cut (make_manifold) and the record's coding. On a mesh whose topology may be valid
  // (unreferenced vertices, or the order kept) the cut is first taken to be the mesh itself:
  // make_manifold leaves such a mesh as it is, and the manifold encoder's corner table says
  // whether it is (a scan's stray points then cost no topology analysis); if the encoder
  // refuses it and the topology is the reason, the mesh is cut after all.
  const auto cut_and_encode = [&](bool cut_needed) {
    map = RepairMap();
    repair = RepairReport();
    decoded = Mesh();
    coded = &cut;
    if (cut_needed) {
      cut = mesh;
      repair = cut_to_manifold(cut, &map); // checks the indices
    } else {
      map.face_origin.resize(mesh.triangle_count());
      std::iota(map.face_origin.begin(), map.face_origin.end(), 0u);
      map.flipped.assign(mesh.triangle_count(), 0);
      if (mesh.attributes.empty())
        coded = &mesh;
      else
        cut = mesh;
    }
    hook.locked.clear();
    hook.twin.clear();
    hook.origin.clear();
    hook.materials.clear();
    if (corners) { // the cut's faces get their corners' values, then it is cut at its seams
      if (coded != &cut) {
        cut = mesh;
        coded = &cut;
      }
      corner_values_of_cut(mesh, map, cut);
      seams = cut_at_seams(cut, map, static_cast<uint32_t>(nv));
      hook.locked = std::move(seams.locked);
      hook.twin = std::move(seams.twin);
      hook.origin = std::move(seams.origin);
      MaterialTable materials;
      materials.corner_texcoords = !mesh.corner_texcoords.empty();
      materials.face_materials = !mesh.face_materials.empty();
      materials.materials = mesh.materials;
      hook.materials = write_materials(materials);
    }
    if (coded == &cut)
      usable_attributes_for_unused_vertices(cut);
    if (coded->triangle_count() == 0)
      throw Error(Error::Kind::InvalidMesh, "the mesh has no valid triangle: all " +
                                                std::to_string(mesh.triangle_count()) +
                                                " faces repeat a vertex");
    const auto encode_once = [&](const EncodeOptions &o) {
      if (!cut_needed) // (the topology is not known to be valid: a refusal is not named)
        return encode_manifold(*coded, o, report, &hook, {}, false);
      try { // (the encoder's corner table checks the cut, see repair/cut.h)
        return encode_manifold(cut, o, report, &hook);
      } catch (const TopologyError &e) {
        throw still_invalid(e);
      }
    };
    hook.wedge_from_positions = true;
    std::vector<uint8_t> file = encode_once(options);
    if (corners && !mesh.corner_texcoords.empty() && !options.attributes.exact) {
      // The positions predict the (u, v) of charts that map the surface affinely far better
      // than the neighbours' mean, which does better on charts that do not: both files,
      // the smaller kept (bench/README.md, "Textured scans"). The cut, the decimation, the
      // numbering and so the record are the same; only the wedge residuals differ.
      EncodeReport first;
      if (report)
        first = *report;
      EncodeOptions quiet = options;
      quiet.progress = nullptr;
      hook.wedge_from_positions = false;
      std::vector<uint8_t> mean = encode_once(quiet);
      if (mean.size() < file.size())
        file.swap(mean);
      else if (report)
        *report = std::move(first);
    }
    return file;
  };
  std::vector<uint8_t> file;
  if (valid) {
    try {
      file = cut_and_encode(false);
    } catch (const TopologyError &) {
      valid = false;
    } catch (const Error &) {
      if (mesh.triangles.size() % 3 || valid_topology(mesh))
        throw; // not a matter of topology: the error stands
      valid = false;
    }
  }
  if (!valid)
    file = cut_and_encode(true);
  if (report) {
    LosslessReport &l = report->lossless;
    l = LosslessReport();
    l.stored = true;
    l.vertex_copies = record.copies.size();
    l.vertices_split = repair.vertices_split;
    l.edges_cut = repair.edges_cut;
    l.faces_flipped = record.flipped.size();
    for (const auto &d : record.duplicates)
      l.duplicate_faces += d.second;
    l.degenerate_faces = record.degenerate.size();
    l.unreferenced_vertices = record.extra_q.size() / 3;
    l.keep_order = options.keep_order;
    l.seam_edges = seams.seam_edges;
    l.wedge_copies = seams.wedge_copies;
    l.bytes = report->info.lossless_bytes;
    report->info.input_vertices = nv;
    report->info.input_faces = mesh.triangle_count();
    report->input_vertices = nv;
    std::vector<uint8_t> used(nv, 0);
    for (uint32_t v : mesh.triangles)
      used[v] = 1;
    report->unreferenced_vertices =
        static_cast<size_t>(std::count(used.begin(), used.end(), uint8_t(0)));
    if (options.keep_order) {
      report->decoded_to_input.resize(nv);
      for (uint32_t v = 0; v < nv; ++v)
        report->decoded_to_input[v] = v;
    } else {
      report->decoded_to_input = output_to_input;
    }
  }
  return file;
}

} // namespace

std::vector<uint8_t> encode(const Mesh &mesh, const EncodeOptions &options, EncodeReport *report) {
  return encode_any(mesh, options, report, nullptr);
}

std::vector<uint8_t> encode(Mesh &&mesh, const EncodeOptions &options, EncodeReport *report) {
  struct LeaveEmpty { // whether encode returns or throws
    Mesh &mesh;
    ~LeaveEmpty() { mesh = Mesh(); }
  } leave_empty{mesh};
  return encode_any(mesh, options, report, &mesh);
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
