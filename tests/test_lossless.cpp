// Lossless for every mesh (codec/src/lossless): messy meshes encode by default and a full
// decode gives back exactly the input — vertex count, oriented faces as a multiset
// (duplicates and faces repeating a vertex included), every vertex on its grid position —
// while clean meshes give the same bytes as with `strict` (format version 1/3).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <numeric>
#include <random>

#include "format/file_format.h"
#include "lossless/lossless_record.h"
#include "mesh/corner_table.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/mesh_gen.h"
#include "support/messy_mesh.h"

namespace pomar {
namespace {

using gen::detail::add_face;
using gen::detail::add_vertex;
using Tri = std::array<uint32_t, 3>;

/// The smallest of a face's three rotations (a face repeating a vertex included).
Tri rotation(uint32_t a, uint32_t b, uint32_t c) {
  return std::min({Tri{a, b, c}, Tri{b, c, a}, Tri{c, a, b}});
}

/// The oriented faces of `m` as a sorted multiset, vertices renamed by `name`.
template <class Name> std::vector<Tri> faces(const Mesh &m, Name name) {
  std::vector<Tri> out;
  for (size_t f = 0; f < m.triangle_count(); ++f) {
    const uint32_t *t = &m.triangles[3 * f];
    out.push_back(rotation(name(t[0]), name(t[1]), name(t[2])));
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Encodes `input` with `options`, decodes it fully and checks that it is the input:
/// decoded vertex i is input vertex decoded_to_input[i] (a permutation; the identity with
/// keep_order), on its grid position, and the faces are the input's. Returns the report.
EncodeReport expect_exact(const Mesh &input, EncodeOptions options = {}) {
  EncodeReport report;
  const std::vector<uint8_t> file = encode(input, options, &report);
  const FileInfo info = inspect(file.data(), file.size());
  const Mesh out = decode(file.data(), file.size());
  EXPECT_EQ(out.vertex_count(), input.vertex_count());
  EXPECT_EQ(out.triangle_count(), input.triangle_count());
  const std::vector<uint32_t> &map = report.decoded_to_input;
  EXPECT_EQ(map.size(), out.vertex_count());
  if (map.size() != out.vertex_count() || out.vertex_count() != input.vertex_count())
    return report;
  std::vector<uint32_t> sorted = map;
  std::sort(sorted.begin(), sorted.end());
  for (uint32_t v = 0; v < sorted.size(); ++v)
    EXPECT_EQ(sorted[v], v) << "decoded_to_input is not a permutation";
  for (size_t i = 0; i < out.vertex_count(); ++i) {
    if (options.keep_order) {
      EXPECT_EQ(map[i], i);
    }
    for (int k = 0; k < 3; ++k) {
      const float want =
          info.grid.dequantize(k, info.grid.quantize(k, input.positions[3 * map[i] + k]));
      EXPECT_EQ(out.positions[3 * i + k], want) << "vertex " << i << " axis " << k;
    }
  }
  EXPECT_EQ(faces(out, [&](uint32_t v) { return map[v]; }),
            faces(input, [](uint32_t v) { return v; }));
  EXPECT_EQ(info.version, 5u);
  EXPECT_EQ(info.lossless_bytes, report.lossless.bytes);
  EXPECT_EQ(info.input_vertices, input.vertex_count());
  EXPECT_EQ(info.input_faces, input.triangle_count());
  return report;
}

/// A closed sphere with every kind of defect added: a second sphere glued at one vertex
/// (pinch), a fin on an edge (three faces), a flipped face, duplicates (exact, rotated and
/// reversed), faces repeating a vertex, unreferenced vertices (one outside the box).
Mesh messy_sphere(int subdivisions) {
  Mesh m = gen::icosphere(subdivisions);
  const uint32_t nv = static_cast<uint32_t>(m.vertex_count());
  const Mesh other = gen::icosphere(1);
  const uint32_t base = nv;
  for (size_t i = 0; i < other.positions.size(); ++i)
    m.positions.push_back(other.positions[i] * 0.3f + (i % 3 == 0 ? 1.3f : 0.f));
  for (size_t c = 0; c < other.triangles.size(); ++c) { // glued at the sphere's vertex 0
    const uint32_t v = other.triangles[c];
    m.triangles.push_back(v == 0 ? 0 : base + v);
  }
  const uint32_t *t0 = &m.triangles[0];
  const uint32_t a = t0[0], b = t0[1];
  const uint32_t fin = add_vertex(m, 0.0, 0.0, 2.0);
  add_face(m, a, b, fin);                                    // a fin: edge (a, b) has 3 faces
  std::swap(m.triangles[3 * 7 + 1], m.triangles[3 * 7 + 2]); // a flipped face
  const Tri f9 = {m.triangles[27], m.triangles[28], m.triangles[29]};
  add_face(m, f9[0], f9[1], f9[2]); // exact duplicate
  add_face(m, f9[1], f9[2], f9[0]); // rotated duplicate
  add_face(m, f9[0], f9[1], f9[2]); // and another
  add_face(m, f9[0], f9[2], f9[1]); // reversed duplicate
  add_face(m, 3, 3, 5);             // faces repeating a vertex
  add_face(m, 6, 4, 6);
  add_face(m, 8, 8, 8);
  const uint32_t lonely = add_vertex(m, 0.5, 0.5, 0.5); // only in a degenerate face
  add_face(m, lonely, 2, lonely);
  add_vertex(m, 5.0, -7.0, 3.0); // unreferenced, outside the faces' box
  add_vertex(m, 0.1, 0.2, 0.3);  // unreferenced
  return m;
}

TEST(Lossless, EachKindOfDefectRoundTripsExactly) {
  struct Case {
    const char *name;
    Mesh mesh;
  };
  Mesh duplicates = gen::tetrahedron();
  add_face(duplicates, 0, 1, 2);
  add_face(duplicates, 1, 2, 0);
  Mesh opposite = gen::tetrahedron();
  add_face(opposite, 0, 2, 1);
  Mesh degenerate = gen::tetrahedron();
  add_face(degenerate, 0, 0, 1);
  add_face(degenerate, 2, 3, 3);
  add_face(degenerate, 1, 1, 1);
  Mesh isolated = gen::tetrahedron();
  add_vertex(isolated, 9, 9, 9);
  add_vertex(isolated, -3, 0.25, 1);
  add_vertex(isolated, 0, 0, 0);        // on an existing vertex's position
  Mesh coincident = gen::tetrahedron(); // a fan pinched at a vertex with a twin position
  add_vertex(coincident, 0, 0, 0);
  const Case cases[] = {
      {"non-manifold edge", gen::nonmanifold_edge()},
      {"non-manifold vertex", gen::nonmanifold_vertex()},
      {"flipped face", gen::flipped_face()},
      {"face repeating a vertex", gen::repeated_vertex_face()},
      {"Moebius strip", gen::moebius(12)},
      {"Klein bottle", gen::klein_bottle(6, 5)},
      {"duplicate faces", duplicates},
      {"opposite duplicate", opposite},
      {"degenerate faces", degenerate},
      {"unreferenced vertices", isolated},
      {"coincident unreferenced vertex", coincident},
      {"everything at once", messy_sphere(2)},
  };
  for (const Case &c : cases) {
    SCOPED_TRACE(c.name);
    const EncodeReport r = expect_exact(c.mesh);
    EXPECT_TRUE(r.lossless.stored);
    EXPECT_FALSE(r.lossless.summary().empty());
  }
}

TEST(Lossless, ReportCountsWhatWasStored) {
  const EncodeReport r = expect_exact(messy_sphere(2));
  EXPECT_EQ(r.lossless.duplicate_faces, 3u);
  EXPECT_EQ(r.lossless.degenerate_faces, 4u);
  // 3 unreferenced (the small sphere's vertex 0, replaced by the pinch, and 2 added) + 1
  // that only a face repeating a vertex uses.
  EXPECT_EQ(r.lossless.unreferenced_vertices, 4u);
  EXPECT_EQ(r.unreferenced_vertices, 3u);
  EXPECT_GE(r.lossless.vertices_split, 1u);
  EXPECT_GE(r.lossless.edges_cut, 1u);
  EXPECT_GE(r.lossless.faces_flipped, 1u);
  EXPECT_GT(r.lossless.bytes, 0u);
  EXPECT_LT(r.lossless.bytes, 80u);
  EXPECT_NE(r.lossless.summary().find("3 duplicate faces"), std::string::npos)
      << r.lossless.summary();
}

TEST(Lossless, LargeMessyMeshesRoundTripClusteredAndProgressive) {
  const Mesh m = messy_sphere(5); // 10k vertices: clustered by default
  EncodeOptions progressive;
  progressive.progressive = true;
  for (const EncodeOptions &o : {EncodeOptions(), progressive}) {
    const EncodeReport r = expect_exact(m, o);
    EXPECT_EQ(r.info.clustered(), !o.progressive);
    // Cheap: a few bytes per defect, nothing per clean vertex.
    EXPECT_LT(r.lossless.bytes, 120u);
  }
}

TEST(Lossless, RandomSoupsAndGluedDisksRoundTripExactly) {
  for (uint32_t seed = 1; seed <= 100; ++seed) {
    for (int kind = 0; kind < 2; ++kind) {
      const Mesh m =
          kind == 0 ? gen::soup(seed, 6 + seed % 20, 4 + (seed * 7) % 60) : gen::glued_disk(seed);
      SCOPED_TRACE("seed " + std::to_string(seed) + " kind " + std::to_string(kind));
      bool any = false;
      for (size_t c = 0; c < m.triangles.size(); c += 3)
        any |= m.triangles[c] != m.triangles[c + 1] && m.triangles[c + 1] != m.triangles[c + 2] &&
               m.triangles[c] != m.triangles[c + 2];
      if (!any) { // nothing to code: a clear error
        EXPECT_THROW(encode(m), Error);
        continue;
      }
      EncodeOptions o;
      o.keep_order = seed % 3 == 0;
      expect_exact(m, o);
    }
  }
}

// Stray points (or --keep-order) on a valid surface: the lossless stage codes the mesh as it
// is, with no cut; on a messy one, or one whose only stray point is a vertex a degenerate
// face uses, it cuts. Both ways the decode is the input, and each kind of change is counted
// where the cut made it.
TEST(Lossless, StrayPointsOnValidAndMessySurfacesRoundTripExactly) {
  Mesh clean = gen::icosphere(3);
  add_vertex(clean, 4.0, -1.0, 0.5);
  add_vertex(clean, 0.0, 0.0, 0.0);
  for (bool keep_order : {false, true}) {
    EncodeOptions o;
    o.keep_order = keep_order;
    const EncodeReport r = expect_exact(clean, o);
    EXPECT_EQ(r.lossless.unreferenced_vertices, 2u) << keep_order;
    EXPECT_EQ(r.lossless.vertices_split + r.lossless.edges_cut + r.lossless.faces_flipped +
                  r.lossless.duplicate_faces + r.lossless.degenerate_faces,
              0u)
        << keep_order;
  }
  EncodeOptions keep;
  keep.keep_order = true;
  const EncodeReport kept = expect_exact(gen::icosphere(2), keep); // no stray point at all
  EXPECT_EQ(kept.lossless.unreferenced_vertices + kept.lossless.vertices_split, 0u);
  Mesh messy = clean;
  std::swap(messy.triangles[4], messy.triangles[5]); // one face flipped
  const EncodeReport flipped = expect_exact(messy, keep);
  EXPECT_EQ(flipped.lossless.faces_flipped, 1u);
  EXPECT_EQ(flipped.lossless.unreferenced_vertices, 2u);
  Mesh degenerate = clean; // the second stray point used by a face repeating a vertex
  add_face(degenerate, uint32_t(clean.vertex_count() - 1), 0, uint32_t(clean.vertex_count() - 1));
  const EncodeReport d = expect_exact(degenerate);
  EXPECT_EQ(d.lossless.degenerate_faces, 1u);
  EXPECT_EQ(d.lossless.unreferenced_vertices, 2u);
}

TEST(Lossless, KeepOrderRestoresTheInputNumbering) {
  Mesh clean = gen::icosphere(4);
  EncodeOptions keep;
  keep.keep_order = true;
  const EncodeReport r = expect_exact(clean, keep);
  EXPECT_TRUE(r.lossless.stored);
  EXPECT_TRUE(r.lossless.keep_order);
  // The order costs far less than log2(n!) bits when neighbours follow each other.
  const double n = double(clean.vertex_count());
  const double log2_factorial = std::lgamma(n + 1) / std::log(2.0);
  EXPECT_LT(8.0 * double(r.lossless.bytes), log2_factorial);
  const EncodeReport messy = expect_exact(messy_sphere(3), keep);
  EXPECT_TRUE(messy.lossless.keep_order);
}

TEST(Lossless, CleanMeshesGiveTheSameBytesAsStrict) {
  EncodeOptions strict;
  strict.strict = true;
  for (const Mesh &m : {gen::icosphere(2), gen::torus(40, 20), gen::icosphere(5)}) {
    EncodeReport r;
    const std::vector<uint8_t> a = encode(m, {}, &r), b = encode(m, strict);
    EXPECT_EQ(a, b);
    EXPECT_FALSE(r.lossless.stored);
    EXPECT_EQ(r.lossless.summary(), "");
    const FileInfo info = inspect(a.data(), a.size());
    EXPECT_EQ(info.version, 5u);
    EXPECT_EQ(info.lossless_bytes, 0u);
  }
}

TEST(Lossless, StrictRefusesMessyMeshesAndDropsUnreferencedVertices) {
  EncodeOptions strict;
  strict.strict = true;
  EXPECT_THROW(encode(gen::nonmanifold_edge(), strict), Error);
  EXPECT_THROW(encode(messy_sphere(1), strict), Error);
  Mesh isolated = gen::tetrahedron();
  add_vertex(isolated, 9, 9, 9);
  EncodeReport r;
  const std::vector<uint8_t> file = encode(isolated, strict, &r);
  EXPECT_EQ(r.unreferenced_vertices, 1u);
  EXPECT_FALSE(r.lossless.stored);
  EXPECT_EQ(decode(file.data(), file.size()).vertex_count(), 4u);
}

TEST(Lossless, WhatCannotBeCodedIsStillAClearError) {
  auto message = [](const Mesh &m, EncodeOptions o = {}) -> std::string {
    try {
      encode(m, o);
    } catch (const Error &e) {
      return e.what();
    }
    return "";
  };
  Mesh nan = messy_sphere(1);
  nan.positions.back() = std::nanf(""); // an unreferenced vertex
  EXPECT_NE(message(nan).find("non-finite"), std::string::npos) << message(nan);
  Mesh bad_index = messy_sphere(1);
  bad_index.triangles[5] = 100000;
  EXPECT_NE(message(bad_index).find("vertex 100000"), std::string::npos) << message(bad_index);
  EXPECT_NE(message(Mesh{}).find("no triangles"), std::string::npos);
  Mesh only_degenerate = gen::tetrahedron();
  only_degenerate.triangles = {0, 0, 1, 2, 3, 3};
  EXPECT_NE(message(only_degenerate).find("no valid triangle"), std::string::npos)
      << message(only_degenerate);
  EncodeOptions bits;
  bits.bits = 30;
  EXPECT_NE(message(messy_sphere(1), bits).find("bits"), std::string::npos)
      << message(messy_sphere(1), bits);
}

TEST(Lossless, CoarserLevelsAndSelectiveDecodesShowTheCutMesh) {
  const Mesh m = messy_sphere(5);
  const std::vector<uint8_t> file = encode(m);
  const FileInfo info = inspect(file.data(), file.size());
  ASSERT_TRUE(info.clustered());
  for (int level : {0, int(info.global_levels), int(info.levels.size()) - 1}) {
    const Mesh coarse = decode(file.data(), file.size(), level);
    CornerTable ct;
    EXPECT_NO_THROW(build_corner_table(coarse.triangles.data(), coarse.triangle_count(),
                                       coarse.vertex_count(), ct))
        << "level " << level;
  }
  // Selective decode of everything at the finest level: the cut mesh (info's counts).
  SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()));
  d.want_all(d.finest_level());
  d.update();
  EXPECT_EQ(d.mesh().vertex_count(), info.vertices);
  EXPECT_EQ(d.mesh().triangle_count(), info.faces);
  // ... and exact_mesh() is the input, as decode() gives it.
  const Mesh full = decode(file.data(), file.size());
  EXPECT_EQ(d.exact_mesh().positions, full.positions);
  EXPECT_EQ(d.exact_mesh().triangles, full.triangles);
  EXPECT_EQ(full.vertex_count(), m.vertex_count());
  // A region at a coarser level: exact_mesh() is the cut mesh.
  SelectiveDecoder part(std::make_unique<MemorySource>(file.data(), file.size()));
  part.want_cluster(0, part.finest_level());
  part.update();
  EXPECT_EQ(part.exact_mesh().positions, part.mesh().positions);
}

TEST(Lossless, DamagedRecordIsAnErrorNotAWrongMesh) {
  const std::vector<uint8_t> file = encode(messy_sphere(2));
  const FileLayout layout = read_layout(file.data(), file.size());
  const int li = find_section(layout, kLosslessTag); // (beside the BLKO and CERR sections)
  ASSERT_GE(li, 0);
  const SectionEntry &s = layout.header.sections[size_t(li)];
  EXPECT_EQ(s.flags, kSectionRequired);
  for (uint64_t i = 0; i < s.bytes; ++i) {
    std::vector<uint8_t> copy = file;
    copy[layout.section_offset[size_t(li)] + i] ^= 0x20;
    EXPECT_THROW(decode(copy.data(), copy.size()), Error) << "byte " << i;
  }
}

TEST(Lossless, SkipDamagedGivesTheCutMeshWhenTheRecordIsDamaged) {
  const Mesh m = messy_sphere(2);
  for (bool progressive : {false, true}) {
    EncodeOptions o;
    o.progressive = progressive;
    EncodeReport er;
    std::vector<uint8_t> file = encode(m, o, &er);
    const FileLayout layout = read_layout(file.data(), file.size());
    const int li = find_section(layout, kLosslessTag);
    ASSERT_GE(li, 0);
    file[layout.section_offset[size_t(li)] + 1] ^= 0x40;
    DecodeOptions d;
    d.skip_damaged = true;
    DecodeReport r;
    const Mesh out = decode(file.data(), file.size(), d, &r);
    ASSERT_EQ(r.damaged.size(), 1u);
    EXPECT_EQ(r.damaged[0].block, "lossless record");
    EXPECT_NE(r.damaged[0].problem.find("the mesh is the coded one"), std::string::npos);
    EXPECT_EQ(out.vertex_count(), er.info.vertices); // the cut mesh
    EXPECT_THROW(decode(file.data(), file.size()), Error);
  }
}

TEST(Lossless, RecordReaderRejectsGarbage) {
  // Bodies that pass the section checksum but hold nonsense (a hostile file): always a
  // clear error or a mesh, never a crash. The decoded mesh here is a small sphere.
  const Mesh d = gen::icosphere(1);
  uint64_t state = 1;
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<uint8_t> body(1 + trial % 40);
    for (uint8_t &b : body) {
      state = gen::detail::mix64(state + 0x9E3779B97F4A7C15ull);
      b = static_cast<uint8_t>(state);
    }
    body[0] &= 1;
    try {
      const LosslessRecord r = read_lossless_record(body.data(), body.size(), d, 12);
      Quantizer g;
      g.bits = 12;
      apply_lossless_record(Mesh(d), r, g);
    } catch (const Error &) {
    }
  }
}

// apply_lossless_record works in the decoded mesh's own arrays, so it checks what a record
// can get wrong before it touches them: a record that does not fit throws with the mesh as
// it was (a skip_damaged decode then gives that mesh, the cut one).
TEST(Lossless, ARecordThatDoesNotFitLeavesTheDecodedMeshAsItWas) {
  Mesh d = gen::icosphere(1);
  VertexAttribute scalar;
  scalar.kind = AttributeKind::Scalar;
  scalar.name = "quality";
  scalar.components = 1;
  scalar.values.assign(d.vertex_count(), 0.5f);
  d.attributes.push_back(scalar);
  Quantizer g;
  g.bits = 12;
  LosslessRecord extra_without_values; // a vertex no face uses, and no value of `quality`
  extra_without_values.extra_q = {1, 2, 3};
  LosslessRecord short_order; // an order of the wrong length
  short_order.order = {0, 1};
  for (const LosslessRecord &r : {extra_without_values, short_order}) {
    Mesh decoded = d;
    EXPECT_THROW(apply_lossless_record(std::move(decoded), r, g), Error);
    EXPECT_EQ(decoded.positions, d.positions);
    EXPECT_EQ(decoded.triangles, d.triangles);
    ASSERT_EQ(decoded.attributes.size(), 1u);
    EXPECT_EQ(decoded.attributes[0].values, scalar.values);
  }
  Mesh decoded = d; // and a record that fits consumes it
  const Mesh out = apply_lossless_record(std::move(decoded), LosslessRecord(), g);
  EXPECT_EQ(out.positions, d.positions);
  EXPECT_EQ(out.triangle_count(), d.triangle_count());
}

} // namespace
} // namespace pomar

namespace pomar {
namespace {

// Attributes ride through the lossless stage: cut copies carry their vertex's values, and
// vertices no face uses (which the levels never code) get theirs back bit for bit from the
// record; with keep_order too.
TEST(Lossless, AttributesOfEveryVertexComeBackWithTheMessyMesh) {
  Mesh m = messy_sphere(2);
  const size_t nv = m.vertex_count();
  VertexAttribute colour, normal, quality;
  colour.kind = AttributeKind::Colour;
  colour.name = "colour";
  colour.components = 4;
  normal.kind = AttributeKind::Normal;
  normal.name = "normal";
  normal.components = 3;
  quality.kind = AttributeKind::Scalar;
  quality.name = "quality";
  for (size_t v = 0; v < nv; ++v) {
    for (int k = 0; k < 4; ++k)
      colour.colour.push_back(static_cast<uint8_t>(v * 37 + k * 91));
    const float x = m.positions[3 * v], y = m.positions[3 * v + 1], z = m.positions[3 * v + 2];
    const float len = std::sqrt(x * x + y * y + z * z);
    normal.values.insert(normal.values.end(), {x / len, y / len, z / len});
    quality.values.push_back(0.001f * float(v) - 0.25f);
  }
  m.attributes = {colour, normal, quality};
  for (bool keep_order : {false, true}) {
    EncodeOptions o;
    o.keep_order = keep_order;
    const EncodeReport r = expect_exact(m, o);
    ASSERT_GT(r.lossless.unreferenced_vertices, 0u);
    EncodeReport again;
    const std::vector<uint8_t> file = encode(m, o, &again);
    const Mesh out = decode(file.data(), file.size());
    ASSERT_EQ(out.vertex_count(), nv);
    DecodeOptions none; // the attributes read past: the same mesh, record undone
    none.attributes = AttributeMask::none();
    const Mesh plain = decode(file.data(), file.size(), none);
    EXPECT_EQ(plain.positions, out.positions);
    EXPECT_EQ(plain.triangles, out.triangles);
    EXPECT_TRUE(plain.attributes.empty());
    const VertexAttribute *c = out.find(AttributeKind::Colour);
    const VertexAttribute *n = out.find(AttributeKind::Normal);
    const VertexAttribute *q = out.find(AttributeKind::Scalar, "quality");
    ASSERT_TRUE(c && n && q);
    ASSERT_EQ(c->vertex_count(), nv);
    ASSERT_EQ(n->vertex_count(), nv);
    ASSERT_EQ(q->vertex_count(), nv);
    for (size_t i = 0; i < nv; ++i) {
      const uint32_t v = again.decoded_to_input[i];
      for (int k = 0; k < 4; ++k)
        EXPECT_EQ(c->colour[4 * i + k], colour.colour[4 * v + k]) << "vertex " << v;
      double dot = 0;
      for (int k = 0; k < 3; ++k)
        dot += double(n->values[3 * i + k]) * normal.values[3 * v + k];
      EXPECT_GT(dot, std::cos(n->bound * M_PI / 180.0) - 1e-6) << "vertex " << v;
      EXPECT_NEAR(q->values[i], quality.values[v], q->bound + 1e-7) << "vertex " << v;
    }
  }
}

} // namespace
} // namespace pomar

namespace pomar {
namespace {

/// The canonical order by its definition: face indices sorted by (rotated triple, index).
std::vector<uint32_t> canonical_order_by_definition(const std::vector<uint32_t> &t) {
  const uint32_t nf = static_cast<uint32_t>(t.size() / 3);
  std::vector<std::array<uint32_t, 3>> key(nf);
  for (uint32_t f = 0; f < nf; ++f) {
    const uint32_t *v = &t[3 * size_t(f)];
    // (Rotated to a smallest vertex; for a face repeating its smallest one, the rule of
    // the record's format, which the decoder must follow too.)
    const int k = v[0] < v[1] ? (v[0] < v[2] ? 0 : 2) : (v[1] < v[2] ? 1 : 2);
    key[f] = {v[k], v[(k + 1) % 3], v[(k + 2) % 3]};
  }
  std::vector<uint32_t> order(nf);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return key[a] != key[b] ? key[a] < key[b] : a < b; });
  return order;
}

// canonical_face_order buckets the faces by smallest vertex when the ids are about as many
// as the faces (buckets of many faces, 3 and 100; of a few, 1000 and 4000) and sorts triples
// otherwise: each must give the defined order, duplicate faces (same triple, any rotation)
// by index.
TEST(Lossless, CanonicalFaceOrderIsTheSortedRotatedTriples) {
  std::mt19937 rng(7);
  for (uint32_t top : {3u, 100u, 1000u, 4000u, (1u << 21) - 1, 1u << 21, 0xFFFFFFFEu}) {
    std::uniform_int_distribution<uint32_t> id(0, top);
    std::vector<uint32_t> t;
    for (int f = 0; f < 5000; ++f) {
      if (f % 7 == 3 && t.size() >= 3) { // a duplicate of an earlier face, rotated
        const size_t g = 3 * (rng() % (t.size() / 3)), r = rng() % 3;
        for (size_t k = 0; k < 3; ++k)
          t.push_back(t[g + (k + r) % 3]);
        continue;
      }
      for (int k = 0; k < 3; ++k)
        t.push_back(id(rng));
    }
    t.push_back(top), t.push_back(0), t.push_back(top); // (the largest id is used)
    EXPECT_EQ(canonical_face_order(t), canonical_order_by_definition(t)) << "ids up to " << top;
  }
  EXPECT_TRUE(canonical_face_order({}).empty());
}

} // namespace
} // namespace pomar
