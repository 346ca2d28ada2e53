// Tests for pomar/mesh_io.h: lossless round trips in every format, the importer traps
// (OBJ faces, PLY tristrips, STL welding, unreferenced vertices) and error reporting.
#include <pomar/mesh_io.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/io_common.h"
#include "support/mesh_gen.h"
#include "support/temp_dir.h"

#include <pomar/vcg_adapter.h>
#include <wrap/io_trimesh/export_stl.h>
#include <wrap/io_trimesh/import_ply.h>

// vcglib's PLY importer never frees the index list of a tristrip (plylib allocates it);
// keep LeakSanitizer builds of this test green.
extern "C" const char *__lsan_default_suppressions() { return "leak:cb_read_list_\n"; }

namespace {

using pomar::AttributeKind;
using pomar::LoadReport;
using pomar::Mesh;
using pomar::VertexAttribute;

// ------------------------------------------------------------------------------------
// Helpers
// ------------------------------------------------------------------------------------

/// A fresh directory under ::testing::TempDir(), removed with its files afterwards.
class MeshIoTest : public pomar::test::TempDirTest {};

std::string read_text(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The message of the pomar::Error that `f` throws (fails the test if it does not).
template <class F> std::string error_of(F f) {
  try {
    f();
  } catch (const pomar::Error &e) {
    return e.what();
  } catch (const std::exception &e) {
    ADD_FAILURE() << "expected pomar::Error, got: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected pomar::Error, nothing thrown";
  return "";
}

std::string load_error(const std::string &path) {
  return error_of([&] { pomar::load_mesh(path); });
}

bool same_bits(const std::vector<float> &a, const std::vector<float> &b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

/// Eight vertices with awkward floats, each first used in index order by the triangles
/// (so STL's welding gives back the same numbering).
Mesh awkward_mesh() {
  Mesh m;
  m.positions = {0.1f,         1e-7f,
                 123456.789f, // 0
                 -0.0f,        0.0f,
                 1.0f, // 1
                 1e-40f,       -3.4028235e38f,
                 0.333333343f, // 2 (denormal, -FLT_MAX)
                 16777216.0f,  -1.17549435e-38f,
                 2.71828175f, // 3
                 -7.5f,        1.0e30f,
                 -2.0e-30f, // 4
                 3.14159274f,  -0.0f,
                 -0.0f, // 5
                 1.4e-45f,     65504.0f,
                 -123.456f, // 6 (smallest denormal)
                 0.5f,         0.25f,
                 -1e-7f}; // 7
  m.triangles = {0, 1, 2, 0, 2, 3, 3, 2, 4, 4, 5, 6, 6, 7, 0, 7, 1, 5};
  return m;
}

/// A mesh with random finite float bit patterns over the whole range.
Mesh random_mesh(size_t vertices, uint32_t seed) {
  std::mt19937 rng(seed);
  Mesh m;
  while (m.positions.size() < 3 * vertices) {
    const uint32_t bits = rng();
    float f;
    std::memcpy(&f, &bits, sizeof f);
    if (std::isfinite(f))
      m.positions.push_back(f);
  }
  for (uint32_t v = 0; v + 2 < vertices; ++v)
    m.triangles.insert(m.triangles.end(), {v, v + 1, v + 2});
  return m;
}

const char *const kTetraPly = "ply\nformat ascii 1.0\nelement vertex 4\n"
                              "property float x\nproperty float y\nproperty float z\n"
                              "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                              "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

// ------------------------------------------------------------------------------------
// Lossless round trips
// ------------------------------------------------------------------------------------

struct Case {
  const char *name;
  bool binary;
};

class RoundTrip : public MeshIoTest, public ::testing::WithParamInterface<Case> {};

TEST_P(RoundTrip, AwkwardFloatsAreBitIdentical) {
  const Mesh in = awkward_mesh();
  const std::string file = path(GetParam().name);
  pomar::save_mesh(file, in, GetParam().binary);
  LoadReport report;
  const Mesh out = pomar::load_mesh(file, &report);
  EXPECT_TRUE(same_bits(in.positions, out.positions));
  EXPECT_EQ(in.triangles, out.triangles);
  EXPECT_EQ(report.unreferenced_vertices, 0u);
  EXPECT_EQ(report.polygons_triangulated, 0u);
  EXPECT_TRUE(report.ignored_attributes.empty());
}

TEST_P(RoundTrip, RandomFloatsAreBitIdentical) {
  const Mesh in = random_mesh(3000, 1234);
  const std::string file = path(GetParam().name);
  pomar::save_mesh(file, in, GetParam().binary);
  const Mesh out = pomar::load_mesh(file);
  ASSERT_EQ(in.positions.size(), out.positions.size());
  for (size_t i = 0; i < in.positions.size(); ++i)
    ASSERT_EQ(std::memcmp(&in.positions[i], &out.positions[i], sizeof(float)), 0)
        << "value " << i << ": wrote " << in.positions[i] << ", read " << out.positions[i];
  EXPECT_EQ(in.triangles, out.triangles);
}

INSTANTIATE_TEST_SUITE_P(AllFormats, RoundTrip,
                         ::testing::Values(Case{"m.ply", true}, Case{"m_ascii.ply", false},
                                           Case{"m.obj", true}, Case{"m.off", true},
                                           Case{"m.stl", true}, Case{"m_ascii.stl", false}),
                         [](const ::testing::TestParamInfo<Case> &info) {
                           std::string n = info.param.name;
                           for (char &c : n)
                             if (c == '.')
                               c = '_';
                           return n;
                         });

TEST_F(MeshIoTest, ReportDescribesFile) {
  pomar::save_mesh(path("a.ply"), awkward_mesh());
  LoadReport r;
  pomar::load_mesh(path("a.ply"), &r);
  EXPECT_EQ(r.format, "ply");
  EXPECT_EQ(r.file_vertices, 8u);
  EXPECT_EQ(r.file_faces, 6u);
}

TEST_F(MeshIoTest, ExtensionIsCaseInsensitive) {
  pomar::save_mesh(path("UPPER.PLY"), awkward_mesh());
  LoadReport r;
  EXPECT_EQ(pomar::load_mesh(path("UPPER.PLY"), &r).triangle_count(), 6u);
  EXPECT_EQ(r.format, "ply");
  EXPECT_TRUE(read_text(path("UPPER.PLY")).find("binary_little_endian") != std::string::npos);
}

TEST_F(MeshIoTest, AsciiPlyIsAscii) {
  pomar::save_mesh(path("a.ply"), awkward_mesh(), false);
  EXPECT_EQ(read_text(path("a.ply")).compare(0, 21, "ply\nformat ascii 1.0\n"), 0);
}

// ------------------------------------------------------------------------------------
// OBJ
// ------------------------------------------------------------------------------------

TEST_F(MeshIoTest, ObjTetrahedronKeepsAllFourFaces) {
  const std::string file = write("tetra.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                              "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  LoadReport r;
  const Mesh m = pomar::load_mesh(file, &r);
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}));
  EXPECT_EQ(r.file_faces, 4u);
  EXPECT_EQ(r.format, "obj");
}

TEST_F(MeshIoTest, ObjQuadIsFanTriangulated) {
  const std::string file = write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  LoadReport r;
  const Mesh m = pomar::load_mesh(file, &r);
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(r.polygons_triangulated, 1u);
  EXPECT_EQ(r.file_faces, 1u);
}

TEST_F(MeshIoTest, ObjRelativeIndicesSlashesGroupsAndAttributes) {
  const std::string file =
      write("rel.obj", "mtllib x.mtl\r\no a\r\nv 0 0 0 1 0 0\r\nv 1 0 0 1 0 0\r\n"
                       "v 0 1 0 1 0 0\r\nvn 0 0 1\r\nvt 0 0\r\n"
                       "g first\r\nusemtl red\r\nf -3/1/1 -2/1/1 -1/1/1\r\n"
                       "v 1 1 0 1 0 0\r\ng second\r\nf 2//1 4//1 3//1\r\n");
  LoadReport r;
  const Mesh m = pomar::load_mesh(file, &r);
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2}));
  // Vertex colours and the one normal every corner uses are kept; the texture coordinate
  // is missing on the second face's corners, and the material library is not there.
  EXPECT_EQ(r.ignored_attributes,
            (std::vector<std::string>{"texture coordinates (not given for every corner)",
                                      "materials (material library 'x.mtl' not found)"}));
  ASSERT_EQ(m.attributes.size(), 2u);
  EXPECT_EQ(m.find(AttributeKind::Colour)->colour,
            (std::vector<uint8_t>{255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0}));
  EXPECT_EQ(m.find(AttributeKind::Normal)->values,
            (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}));
}

TEST_F(MeshIoTest, ObjAttributesRoundTrip) {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.5f, 9, 9, 9};
  m.triangles = {0, 1, 2, 1, 3, 2};
  VertexAttribute c;
  c.kind = AttributeKind::Colour;
  c.name = "colour";
  c.components = 3;
  c.colour = {1, 2, 3, 250, 251, 252, 9, 8, 7, 128, 0, 255, 5, 5, 5};
  VertexAttribute n;
  n.kind = AttributeKind::Normal;
  n.name = "normal";
  n.components = 3;
  n.values = {0, 0, 1, 0.6f, 0, 0.8f, -1, 0, 0, 0.1f, 0.2f, 0.3f, 1, 1, 1};
  VertexAttribute uv;
  uv.kind = AttributeKind::TexCoord;
  uv.name = "texcoord";
  uv.components = 2;
  uv.values = {0, 0, 1, 0, 0, 1, 0.333333343f, 0.7f, 5, 5};
  m.attributes = {c, n, uv};
  save_mesh(path("attr.obj"), m);
  LoadReport r;
  const Mesh back = load_mesh(path("attr.obj"), &r);
  EXPECT_TRUE(r.ignored_attributes.empty());
  EXPECT_EQ(r.unreferenced_vertices, 1u); // vertex 4: kept (the codec stores such vertices)
  EXPECT_EQ(back.positions, m.positions);
  for (const VertexAttribute &a : m.attributes) {
    const VertexAttribute *b = back.find(a.kind);
    ASSERT_NE(b, nullptr) << a.name;
    ASSERT_EQ(b->vertex_count(), 5u) << a.name;
    // Colours are per vertex in OBJ ("v x y z r g b"): all come back. Normals and texture
    // coordinates are per corner: vertex 4, which no face uses, has none (zeros).
    EXPECT_EQ(b->colour, a.colour);
    const size_t four = 4 * size_t(a.components);
    if (!a.values.empty()) {
      EXPECT_EQ(std::vector<float>(b->values.begin(), b->values.begin() + four),
                std::vector<float>(a.values.begin(), a.values.begin() + four));
    }
  }
}

TEST_F(MeshIoTest, ObjBadFacesAreErrors) {
  EXPECT_NE(load_error(write("short.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n"))
                .find("line 5: face with 2 vertices"),
            std::string::npos);
  EXPECT_NE(load_error(write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"))
                .find("references vertex 4"),
            std::string::npos);
  EXPECT_NE(
      load_error(write("rel.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n")).find(path("rel.obj")),
      std::string::npos);
  EXPECT_NE(load_error(write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")).find("zero.obj"),
            std::string::npos);
}

TEST_F(MeshIoTest, ObjNonFiniteAndBadCoordinates) {
  const std::string nan_msg =
      load_error(write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_NE(nan_msg.find("vertex 1"), std::string::npos) << nan_msg;
  EXPECT_NE(nan_msg.find("non-finite"), std::string::npos) << nan_msg;
  const std::string bad = load_error(write("bad.obj", "v 0 0 0\nv 1,5 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_NE(bad.find("bad coordinate '1,5'"), std::string::npos) << bad;
}

// ------------------------------------------------------------------------------------
// PLY
// ------------------------------------------------------------------------------------

TEST_F(MeshIoTest, PlyTristrips) {
  // Strip 0 1 2 3 gives (0,1,2) and (2,1,3) (every other triangle flipped to keep the
  // orientation); -1 restarts: strip 1 3 4 gives (1,3,4).
  const std::string file =
      write("strips.ply", "ply\nformat ascii 1.0\nelement vertex 5\n"
                          "property float x\nproperty float y\nproperty float z\n"
                          "element tristrips 1\nproperty list int int vertex_indices\n"
                          "end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 1 0\n"
                          "8 0 1 2 3 -1 1 3 4\n");
  LoadReport r;
  const Mesh m = pomar::load_mesh(file, &r);
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3, 1, 3, 4}));
  EXPECT_EQ(r.file_faces, 3u);
}

TEST_F(MeshIoTest, PlyTristripsBadIndexIsError) {
  const std::string file =
      write("strips.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                          "property float x\nproperty float y\nproperty float z\n"
                          "element tristrips 1\nproperty list int int vertex_indices\n"
                          "end_header\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2 7\n");
  EXPECT_NE(load_error(file).find("references vertex 7"), std::string::npos);
}

TEST_F(MeshIoTest, PlyPolygonsKeptVertexAttributesAndIgnoredFaceAttributes) {
  const std::string file =
      write("quad.ply", "ply\nformat ascii 1.0\nelement vertex 5\n"
                        "property float x\nproperty float y\nproperty float z\n"
                        "property float nx\nproperty float ny\nproperty float nz\n"
                        "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                        "element face 2\nproperty list uchar int vertex_indices\n"
                        "property float quality\nend_header\n"
                        "0 0 0 0 0 1 255 0 0\n1 0 0 0 0 1 255 0 0\n1 1 0 0 0 1 255 0 0\n"
                        "0 1 0 0 0 1 255 0 0\n2 2 2 0 0 1 255 0 0\n"
                        "4 0 1 2 3 0.5\n3 1 4 2 1\n");
  LoadReport r;
  const Mesh m = pomar::load_mesh(file, &r);
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 1, 4, 2}));
  EXPECT_EQ(r.polygons_triangulated, 1u);
  EXPECT_EQ(r.file_faces, 2u);
  // Vertex normals and colours are kept; the face quality is not.
  EXPECT_EQ(r.ignored_attributes, (std::vector<std::string>{"quality"}));
  ASSERT_EQ(m.attributes.size(), 2u);
  const VertexAttribute *c = m.find(AttributeKind::Colour);
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->components, 3u);
  EXPECT_EQ(c->colour,
            (std::vector<uint8_t>{255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0}));
  const VertexAttribute *n = m.find(AttributeKind::Normal);
  ASSERT_NE(n, nullptr);
  EXPECT_EQ(n->values.size(), 15u);
}

/// A PLY file with every kind of vertex attribute, written and read back in both
/// encodings: bit-identical values, names and texture files.
TEST_F(MeshIoTest, PlyAttributesRoundTrip) {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.5f};
  m.triangles = {0, 1, 2, 1, 3, 2};
  VertexAttribute c;
  c.kind = AttributeKind::Colour;
  c.name = "colour";
  c.components = 4;
  c.colour = {1, 2, 3, 4, 250, 251, 252, 0, 9, 8, 7, 6, 128, 0, 255, 255};
  VertexAttribute n;
  n.kind = AttributeKind::Normal;
  n.name = "normal";
  n.components = 3;
  n.values = {0, 0, 1, 0.6f, 0, 0.8f, -1, 0, 0, 0.1f, 0.2f, 0.3f};
  VertexAttribute q;
  q.kind = AttributeKind::Scalar;
  q.name = "quality";
  q.values = {0.1f, 1e-30f, -3, 7};
  VertexAttribute conf = q;
  conf.name = "confidence";
  conf.values = {1, 0.5f, 0.25f, 0.125f};
  VertexAttribute uv;
  uv.kind = AttributeKind::TexCoord;
  uv.name = "texcoord";
  uv.components = 2;
  uv.values = {0, 0, 1, 0, 0, 1, 0.333333343f, 0.7f};
  m.attributes = {c, n, q, conf, uv};
  m.texture_files = {"skin.png", "a b.jpg"};
  for (bool binary : {true, false}) {
    const std::string file = path(binary ? "attr_bin.ply" : "attr_ascii.ply");
    save_mesh(file, m, binary);
    LoadReport r;
    const Mesh back = load_mesh(file, &r);
    EXPECT_TRUE(r.ignored_attributes.empty());
    EXPECT_EQ(back.positions, m.positions);
    EXPECT_EQ(back.triangles, m.triangles);
    EXPECT_EQ(back.texture_files, m.texture_files);
    ASSERT_EQ(back.attributes.size(), m.attributes.size());
    for (const VertexAttribute &a : m.attributes) {
      const VertexAttribute *b = back.find(a.kind, a.name);
      ASSERT_NE(b, nullptr) << a.name;
      EXPECT_EQ(b->components, a.components) << a.name;
      EXPECT_EQ(b->colour, a.colour) << a.name;
      EXPECT_EQ(b->values, a.values) << a.name;
    }
  }
}

// A binary little-endian PLY with vertex attributes is read without vcglib (the walk takes
// the positions and triangles too, io/ply_reader.cpp mesh_from_capture): it must give what the
// general path gives for the same values in an ASCII file (vcglib reads its positions and
// triangles): attributes in the same order with the same values (a colour whose alpha is
// 255 everywhere kept as RGB, quality, texture coordinates, named scalars, a double
// converted), the texture file, what is ignored, unreferenced vertices.
TEST_F(MeshIoTest, PlyBinaryAttributesReadWithoutVcglibAsVcglibReadsThem) {
  std::mt19937 rng(29);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  const size_t nv = 301, nf = 290; // vertex 300 unreferenced, at least
  const char *props = "property float intensity\nproperty float x\nproperty uchar red\n"
                      "property uchar green\nproperty uchar blue\nproperty uchar alpha\n"
                      "property float y\nproperty double confidence\nproperty float nx\n"
                      "property float ny\nproperty float nz\nproperty float z\n"
                      "property float quality\nproperty float u\nproperty float v\n"
                      "property int flags\n";
  auto header = [&](const char *format) {
    return std::string("ply\nformat ") + format + " 1.0\ncomment TextureFile skin.png\n" +
           "element vertex " + std::to_string(nv) + "\n" + props + "element face " +
           std::to_string(nf) + "\nproperty list uchar int vertex_indices\nend_header\n";
  };
  std::string binary = header("binary_little_endian"), ascii = header("ascii");
  char buf[64];
  auto f32 = [&](float x) {
    binary.append(reinterpret_cast<const char *>(&x), 4);
    std::snprintf(buf, sizeof buf, "%.9g ", double(x));
    ascii += buf;
  };
  auto f64 = [&](double x) {
    binary.append(reinterpret_cast<const char *>(&x), 8);
    std::snprintf(buf, sizeof buf, "%.17g ", x);
    ascii += buf;
  };
  auto u8 = [&](uint8_t x) {
    binary += char(x);
    ascii += std::to_string(x) + " ";
  };
  auto i32 = [&](int32_t x) {
    binary.append(reinterpret_cast<const char *>(&x), 4);
    ascii += std::to_string(x) + " ";
  };
  for (size_t v = 0; v < nv; ++v) {
    f32(u(rng)); // intensity
    f32(u(rng)); // x
    for (int k = 0; k < 3; ++k)
      u8(uint8_t(rng()));
    u8(255);                     // alpha: 255 everywhere
    f32(v % 7 ? u(rng) : -0.0f); // y
    f64(double(u(rng)) / 3);     // confidence: a double, kept as float
    for (int k = 0; k < 3; ++k)  // nx ny nz
      f32(u(rng));
    f32(u(rng)); // z
    f32(u(rng)); // quality
    f32(u(rng)); // u
    f32(u(rng)); // v
    i32(0);      // flags
    ascii += "\n";
  }
  for (size_t f = 0; f < nf; ++f) {
    u8(3);
    for (int k = 0; k < 3; ++k)
      i32(int32_t((f + k * 97) % 300));
    ascii += "\n";
  }
  LoadReport rb, ra;
  const Mesh b = pomar::load_mesh(write("attr_fast.ply", binary), &rb);
  const Mesh a = pomar::load_mesh(write("attr_general.ply", ascii), &ra);
  EXPECT_TRUE(same_bits(b.positions, a.positions));
  EXPECT_EQ(b.triangles, a.triangles);
  EXPECT_EQ(b.texture_files, a.texture_files);
  EXPECT_EQ(b.texture_files, std::vector<std::string>{"skin.png"});
  ASSERT_EQ(b.attributes.size(), a.attributes.size());
  ASSERT_EQ(b.attributes.size(), 6u); // colour, normal, quality, texcoord, 2 named scalars
  for (size_t i = 0; i < a.attributes.size(); ++i) {
    const VertexAttribute &x = b.attributes[i], &y = a.attributes[i];
    EXPECT_EQ(x.kind, y.kind) << i;
    EXPECT_EQ(x.name, y.name) << i;
    EXPECT_EQ(x.components, y.components) << x.name;
    EXPECT_EQ(x.colour, y.colour) << x.name;
    EXPECT_TRUE(same_bits(x.values, y.values)) << x.name;
  }
  EXPECT_EQ(b.find(AttributeKind::Colour)->components, 4u); // the file's alpha, all 255
  EXPECT_EQ(b.find(AttributeKind::Colour)->colour[3], 255);
  EXPECT_EQ(rb.ignored_attributes, ra.ignored_attributes);
  EXPECT_EQ(rb.unreferenced_vertices, ra.unreferenced_vertices);
  EXPECT_GE(rb.unreferenced_vertices, 1u);
  EXPECT_EQ(rb.file_vertices, ra.file_vertices);
  EXPECT_EQ(rb.file_faces, ra.file_faces);
}

TEST_F(MeshIoTest, PlySixteenBitColourIsNotKeptAndSaysSo) {
  const std::string file =
      write("c16.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                       "property float x\nproperty float y\nproperty float z\n"
                       "property ushort red\nproperty ushort green\n"
                       "property ushort blue\nproperty float intensity\n"
                       "element face 1\nproperty list uchar int vertex_indices\n"
                       "end_header\n0 0 0 65535 0 0 1\n1 0 0 0 65535 0 2\n"
                       "0 1 0 0 0 65535 3\n3 0 1 2\n");
  LoadReport r;
  const Mesh m = load_mesh(file, &r);
  EXPECT_EQ(r.ignored_attributes,
            (std::vector<std::string>{"colors (16-bit channels: pomar keeps 8-bit colour)"}));
  ASSERT_EQ(m.attributes.size(), 1u);
  EXPECT_EQ(m.attributes[0].name, "intensity");
  EXPECT_EQ(m.attributes[0].values, (std::vector<float>{1, 2, 3}));
}

TEST_F(MeshIoTest, PlyUnreferencedVerticesAreKeptAndCounted) {
  const std::string file =
      write("unref.ply", "ply\nformat ascii 1.0\nelement vertex 5\n"
                         "property float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_indices\n"
                         "end_header\n0 0 0\n9 9 9\n1 0 0\n8 8 8\n0 1 0\n3 4 0 2\n");
  LoadReport r;
  const Mesh m = pomar::load_mesh(file, &r);
  EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 9, 9, 9, 1, 0, 0, 8, 8, 8, 0, 1, 0}));
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{4, 0, 2}));
  EXPECT_EQ(r.unreferenced_vertices, 2u);
  EXPECT_EQ(r.file_vertices, 5u);
}

TEST_F(MeshIoTest, UnreferencedVerticesInObjAndOff) {
  LoadReport r;
  const Mesh obj =
      pomar::load_mesh(write("u.obj", "v 9 9 9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 2 3 4\n"), &r);
  EXPECT_EQ(obj.triangles, (std::vector<uint32_t>{1, 2, 3}));
  EXPECT_EQ(obj.vertex_count(), 4u);
  EXPECT_EQ(r.unreferenced_vertices, 1u);
  const Mesh off =
      pomar::load_mesh(write("u.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n9 9 9\n0 1 0\n3 0 1 3\n"), &r);
  EXPECT_EQ(off.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 9, 9, 9, 0, 1, 0}));
  EXPECT_EQ(r.unreferenced_vertices, 1u);
}

TEST_F(MeshIoTest, PlyLastPolygonCornerOutOfRangeIsError) {
  // vcglib does not range-check the last corner of a polygon; we must.
  const std::string file =
      write("bad.ply", "ply\nformat ascii 1.0\nelement vertex 4\n"
                       "property float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\n"
                       "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 100000\n");
  const std::string msg = load_error(file);
  EXPECT_NE(msg.find("references vertex 100000"), std::string::npos) << msg;
  EXPECT_NE(msg.find(file), std::string::npos) << msg;
}

TEST_F(MeshIoTest, PlyHugePolygonIsError) {
  std::string text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                     "property float z\nelement face 1\nproperty list int int vertex_indices\n"
                     "end_header\n0 0 0\n1 0 0\n0 1 0\n600";
  for (int i = 0; i < 600; ++i)
    text += " " + std::to_string(i % 3);
  const std::string msg = load_error(write("huge.ply", text + "\n"));
  EXPECT_NE(msg.find("600 vertices"), std::string::npos) << msg;
}

TEST_F(MeshIoTest, PlyEdgesAreIgnored) {
  const std::string file =
      write("edge.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                        "property float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list uchar int vertex_indices\n"
                        "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
                        "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n0 1\n");
  LoadReport r;
  EXPECT_EQ(pomar::load_mesh(file, &r).triangle_count(), 1u);
  EXPECT_NE(std::find(r.ignored_attributes.begin(), r.ignored_attributes.end(), "edges"),
            r.ignored_attributes.end());
}

/// Header for a PLY file with three float vertices and one face list of the given type.
std::string ply_header(const std::string &format, const std::string &face_list) {
  return "ply\nformat " + format +
         " 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty " +
         face_list + " vertex_indices\nend_header\n";
}

template <class T> std::string bytes_of(T v, bool big_endian) {
  std::string b(reinterpret_cast<const char *>(&v), sizeof v);
  if (big_endian)
    std::reverse(b.begin(), b.end());
  return b;
}

TEST_F(MeshIoTest, PlyBinaryBigEndianAndIndexTypes) {
  std::string body;
  for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f})
    body += bytes_of(f, true);
  std::string faces = bytes_of<uint8_t>(3, true);
  for (uint32_t i : {0u, 1u, 2u})
    faces += bytes_of(i, true);
  const Mesh m = pomar::load_mesh(
      write("be.ply", ply_header("binary_big_endian", "list uchar uint") + body + faces));
  EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{0, 1, 2}));

  // plylib reads a ushort count of a uint list as one byte: refused rather than misread.
  faces = bytes_of<uint16_t>(3, true);
  for (uint32_t i : {0u, 1u, 2u})
    faces += bytes_of(i, true);
  const std::string msg = load_error(
      write("be2.ply", ply_header("binary_big_endian", "list ushort uint") + body + faces));
  EXPECT_NE(msg.find("misreads"), std::string::npos) << msg;
}

/// A fast reading path gives what the general one gives: the same floats bit for bit, the
/// same faces and the same report (two unreferenced vertices in the tests' files).
void expect_same_load(const Mesh &fast, const LoadReport &fast_report, const Mesh &general,
                      const LoadReport &general_report) {
  EXPECT_TRUE(same_bits(fast.positions, general.positions));
  EXPECT_EQ(fast.triangles, general.triangles);
  EXPECT_EQ(fast_report.unreferenced_vertices, 2u);
  EXPECT_EQ(fast_report.unreferenced_vertices, general_report.unreferenced_vertices);
  EXPECT_EQ(fast_report.file_vertices, general_report.file_vertices);
  EXPECT_EQ(fast_report.file_faces, general_report.file_faces);
  EXPECT_EQ(fast_report.ignored_attributes, general_report.ignored_attributes);
}

// ASCII PLY of float x, y, z and uchar-counted int faces is read without vcglib
// (io/ply_simple_read.cpp, read_simple_ascii): it must give the floats fscanf gives
// (vcglib's general path, taken here for the same data by an extra empty element) for
// every way of writing a number, decline what it does not take ('+', hex, overflow, junk:
// the general path decides) and count unreferenced vertices the same.
// parse_float (every general reader's decimal numbers: PLY ASCII walk, OFF, ASCII STL)
// takes plain decimal text through from_chars and the rest through strtof: it must give
// strtof's float, bit for bit, and accept and refuse what strtof does, for every way of
// writing a number (long mantissas, halfway cases, denormals, overflow, signs, hex, nan).
TEST(ParseFloat, GivesStrtofsFloatBitForBit) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-160, 130);
  const char *formats[] = {"%.9g", "%.17g", "%.3f", "%e", "%.1e", "%g", "%.30e", "%.45f"};
  std::vector<std::string> tokens = {
      "0",     "-0",    "0.0",   "5.",       ".5",           "-.5",          "1e39",
      "-1e39", "1e-46", "1e-50", "1e-40",    "3.4028235e38", "3.4028236e38", "+1",
      "0x1p3", "nan",   "inf",   "-inf",     "1.5f",         "1e",           "1e+",
      "--1",   "1..2",  "e5",    "00012.50", "1E+0005",      "-2.50E+1",     "."};
  tokens.push_back(std::string("0.") + std::string(60, '0') + "1");
  tokens.push_back(std::string(70, '9') + ".5");
  char buf[128];
  for (int i = 0; i < 20000; ++i) {
    std::snprintf(buf, sizeof buf, formats[i % 8], std::ldexp(mantissa(rng), exponent(rng)));
    tokens.push_back(buf);
  }
  for (int i = 0; i < 2000; ++i) { // halfway between two neighbouring floats, and next to it
    const float f = std::ldexp(float(mantissa(rng)), exponent(rng) / 2);
    const double half = (double(f) + double(std::nextafter(f, 2 * f + 1))) / 2;
    std::snprintf(buf, sizeof buf, "%.40g", half);
    tokens.push_back(buf);
    std::snprintf(buf, sizeof buf, "%.17g", half);
    tokens.push_back(buf);
  }
  size_t plain = 0;
  for (const std::string &t : tokens) {
    char *end = nullptr;
    const float expected = std::strtof(t.c_str(), &end);
    const bool expected_ok =
        !t.empty() && t.find_first_of("xX") == std::string::npos && end == t.c_str() + t.size();
    float got = 12345.f;
    const bool ok = pomar::io::parse_float(t, got);
    EXPECT_EQ(ok, expected_ok) << t;
    if (ok && expected_ok) {
      uint32_t a, b;
      std::memcpy(&a, &got, 4);
      std::memcpy(&b, &expected, 4);
      EXPECT_EQ(a, b) << t;
    }
    plain += pomar::io::plain_decimal(t.data(), t.data() + t.size());
  }
  EXPECT_GT(plain, tokens.size() * 9 / 10); // the fast branch was what was tested
}

TEST_F(MeshIoTest, PlyAsciiFastPathReadsWhatVcglibReads) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-45, 38);
  const char *formats[] = {"%.9g", "%.3f", "%e", "%.20g", "%.1e", "%g"};
  std::string vertices;
  const size_t nv = 303;
  char buf[64];
  for (size_t i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) {
      const double x = std::ldexp(mantissa(rng), exponent(rng) / 4);
      std::snprintf(buf, sizeof buf, formats[(i + k) % 6], x);
      vertices += buf;
      vertices += k < 2 ? (i % 7 ? " " : "\t ") : (i % 5 ? "\n" : "\r\n");
    }
  }
  std::string faces;
  const size_t nf = 299; // vertices 301 and 302 unreferenced
  for (size_t f = 0; f < nf; ++f)
    faces +=
        "3 " + std::to_string(f) + " " + std::to_string(f + 1) + " " + std::to_string(f + 2) + "\n";
  auto header = [&](const std::string &extra) {
    return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(nv) +
           "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
           std::to_string(nf) + "\nproperty list uchar int vertex_indices\n" + extra +
           "end_header\n";
  };
  LoadReport fast_report, general_report;
  const Mesh fast =
      pomar::load_mesh(write("fast.ply", header("") + vertices + faces), &fast_report);
  const Mesh general = pomar::load_mesh(
      write("general.ply", header("element material 0\nproperty float shine\n") + vertices + faces),
      &general_report);
  expect_same_load(fast, fast_report, general, general_report);
  // Odd numbers, first coordinate of the file: read as the general path reads them; what the
  // fast path declines fails as the general path fails.
  for (const std::string &odd :
       {std::string("-0"), std::string(".5"), std::string("5."), std::string("1e-40"),
        std::string("-3.4028234e38"), std::string("-2.50E+1"),
        std::string("0.") + std::string(44, '0') + "1",
        std::string("123456789012345678901234567890"), std::string("+1"), std::string("0x1p3"),
        std::string("1e39"), std::string("1.5f"), std::string("nan")}) {
    const std::string v = odd + vertices.substr(vertices.find(' '));
    const std::string a = write("odd_fast.ply", header("") + v + faces);
    const std::string b =
        write("odd_general.ply", header("element material 0\nproperty float shine\n") + v + faces);
    std::string error_a, error_b;
    Mesh ma, mb;
    try {
      ma = pomar::load_mesh(a);
    } catch (const pomar::Error &e) {
      error_a = e.what();
    }
    try {
      mb = pomar::load_mesh(b);
    } catch (const pomar::Error &e) {
      error_b = e.what();
    }
    EXPECT_EQ(error_a.empty(), error_b.empty()) << odd << ": " << error_a << " / " << error_b;
    EXPECT_TRUE(same_bits(ma.positions, mb.positions)) << odd;
  }
}

// OBJ of positions and faces only is read without tinyobjloader (io/obj_io.cpp,
// read_simple_obj): it must give tinyobjloader's floats (its own decimal sum, not a correctly
// rounded conversion) for every way of writing a number, triangulate polygons as the general
// path does, keep faces in file order across o/g/s lines, and decline what it does not take.
// The general path reads the same data when an unknown keyword line ("mg 1", which the scan
// and tinyobjloader skip) makes the fast path decline.
TEST_F(MeshIoTest, ObjFastPathReadsWhatTinyobjloaderReads) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-45, 38);
  // (%.20g: fraction digits past the 8th, where tinyobjloader calls std::pow.)
  const char *formats[] = {"%.9g", "%.3f", "%e", "%.20g", "%.1e", "%g", "%.12f"};
  const size_t nv = 407;
  std::string body = "# made by the test\n";
  char buf[64];
  for (size_t i = 0; i < nv; ++i) {
    body += i % 11 ? "v " : "v\t ";
    for (int k = 0; k < 3; ++k) {
      std::snprintf(buf, sizeof buf, formats[(i + k) % 7],
                    std::ldexp(mantissa(rng), exponent(rng) / 4));
      body += buf;
      body += k < 2 ? (i % 7 ? " " : "\t ") : (i % 5 ? "\n" : "\r\n");
    }
    if (i == 100)
      body += "o part\ng group one\ns 1\n\n";
  }
  // Triangles, quads and pentagons (fan-triangulated); the last two vertices unreferenced.
  for (size_t f = 0; f + 6 < nv; f += 3) {
    const size_t n = 3 + (f / 3) % 3;
    body += "f";
    for (size_t c = 0; c < n; ++c)
      body += " " + std::to_string(f + c + 1);
    body += f % 2 ? "\n" : " \r\n";
    if (f == 201)
      body += "g another\ns off\n# a comment\n";
  }
  body += "f 403 404 405\n";
  LoadReport fast_report, general_report;
  const Mesh fast = pomar::load_mesh(write("fast.obj", body), &fast_report);
  const Mesh general = pomar::load_mesh(write("general.obj", body + "mg 1\n"), &general_report);
  expect_same_load(fast, fast_report, general, general_report);
  EXPECT_EQ(fast_report.polygons_triangulated, general_report.polygons_triangulated);
  EXPECT_GT(fast_report.polygons_triangulated, 80u);
  // Odd numbers as the first coordinate, and lines the fast path declines: read as the
  // general path reads them, or failing as it fails.
  const std::string rest = body.substr(body.find('\n', body.find("v ")));
  for (const std::string &first :
       {std::string("v -0 0 0"),
        std::string("v .5 0 0"),
        std::string("v 5. 0 0"),
        std::string("v 1e-40 0 0"),
        std::string("v -3.4028234e38 0 0"),
        std::string("v -2.50E+1 1.e5 0"),
        std::string("v -282.72e8 341.93550e5 -310.65e6"), // (not correctly rounded)
        std::string("v 0.") + std::string(44, '0') + "1 0 0",
        std::string("v 123456789012345678901234567890 0 0"),
        std::string("v +1 0 0"),
        std::string("v 0x1p3 0 0"),
        std::string("v 1e39 0 0"),
        std::string("v 1.5f 0 0"),
        std::string("v nan 0 0"),
        std::string("v 1 2"),
        std::string("v 1 2 3 4"),
        std::string("v 1 2 3 # c"),
        std::string("v 1 2 3\nf 1 2"),
        std::string("v 1 2 3\nf 1 2 0"),
        std::string("v 1 2 3\nf 1 2 999"),
        std::string("v 1 2 3\nf -1 -2 -3"),
        std::string("v 1 2 3\nf 1/1 2/2 3/3"),
        std::string("v 1 2 3\nvn 0 0 1"),
        std::string("v 1 2 3\nl 1 2")}) {
    const std::string text = "# x\n" + first + rest;
    std::string error_a, error_b;
    Mesh ma, mb;
    try {
      ma = pomar::load_mesh(write("odd_fast.obj", text));
    } catch (const pomar::Error &e) {
      error_a = e.what();
    }
    try {
      mb = pomar::load_mesh(write("odd_general.obj", text + "mg 1\n"));
    } catch (const pomar::Error &e) {
      error_b = e.what();
    }
    EXPECT_EQ(error_a.empty(), error_b.empty()) << first << ": " << error_a << " / " << error_b;
    EXPECT_TRUE(same_bits(ma.positions, mb.positions)) << first;
    EXPECT_EQ(ma.triangles, mb.triangles) << first;
  }
}

TEST_F(MeshIoTest, PlyFaceListTypeVcglibCannotReadIsError) {
  const std::string data = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string msg = load_error(write("t.ply", ply_header("ascii", "list ushort int") + data));
  EXPECT_NE(msg.find("without a vertex index list of a type vcglib reads"), std::string::npos)
      << msg;
}

TEST_F(MeshIoTest, PlyMalformedAsciiNumberIsError) {
  // fscanf would read "0-5" as 0 and -5, shifting everything after it.
  const std::string file =
      write("m.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                     "property float y\nproperty float z\nelement face 1\n"
                     "property list uchar int vertex_indices\nproperty float q\n"
                     "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 0-5\n");
  EXPECT_NE(load_error(file).find("bad number '0-5'"), std::string::npos);
}

TEST_F(MeshIoTest, PlyEdgeWithoutVertexPropertiesIsError) {
  const std::string file =
      write("e.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                     "property float y\nproperty float z\nelement face 1\n"
                     "property list uchar int vertex_indices\nelement edge 1\n"
                     "property int a\nproperty int b\nend_header\n"
                     "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n0 1\n");
  EXPECT_NE(load_error(file).find("edge element"), std::string::npos);
}

TEST_F(MeshIoTest, PlyNaNNamesVertex) {
  const std::string file =
      write("nan.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                       "property float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\n"
                       "end_header\n0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n");
  const std::string msg = load_error(file);
  EXPECT_NE(msg.find("vertex 2 has a non-finite coordinate"), std::string::npos) << msg;
}

TEST_F(MeshIoTest, PlyTruncatedIsError) {
  pomar::save_mesh(path("full.ply"), awkward_mesh());
  const std::string bytes = read_text(path("full.ply"));
  const std::string file = write("cut.ply", bytes.substr(0, bytes.size() - 5));
  EXPECT_NE(load_error(file).find("truncated"), std::string::npos);
}

// ------------------------------------------------------------------------------------
// OFF
// ------------------------------------------------------------------------------------

// A plain OFF file ("OFF", counts, x y z lines, "3 a b c" lines) is read without vcglib
// (io/off_io.cpp, read_simple_off): the same floats as vcglib's atof-then-float, the same
// faces and report as the general path, taken here for the same data by a comment line.
TEST_F(MeshIoTest, OffFastPathReadsWhatVcglibReads) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-60, 60);
  const char *formats[] = {"%.17g", "%.3f", "%e", "%.9g", "%.1e", "%g"};
  const size_t nv = 204, nf = 200; // vertices 202 and 203 unreferenced
  std::string body;
  char buf[64];
  for (size_t i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) {
      std::snprintf(buf, sizeof buf, formats[(i + k) % 6],
                    std::ldexp(mantissa(rng), exponent(rng) / 3));
      body += buf;
      body += k < 2 ? (i % 3 ? " " : " \t") : "\n";
    }
  for (size_t f = 0; f < nf; ++f)
    body +=
        "3 " + std::to_string(f) + " " + std::to_string(f + 2) + " " + std::to_string(f + 1) + "\n";
  const std::string counts = std::to_string(nv) + " " + std::to_string(nf) + " 0\n";
  // (The fast path declines a keyword line "OFF " with a space, which vcglib reads as "OFF":
  // the general path then reads the same data.)
  LoadReport fast_report, general_report;
  const Mesh fast = pomar::load_mesh(write("fast.off", "OFF\n" + counts + body), &fast_report);
  const Mesh general =
      pomar::load_mesh(write("general.off", "OFF \n" + counts + body), &general_report);
  expect_same_load(fast, fast_report, general, general_report);
  // Blank and comment lines anywhere before the faces end (skipped by vcglib's line reader,
  // and by the fast path).
  std::string spaced = "# made by hand\nOFF\n\n" + counts + "\n# vertices\n";
  for (size_t at = 0, line = 0; at < body.size(); ++line) {
    const size_t end = body.find('\n', at) + 1;
    spaced += body.substr(at, end - at) + (line % 50 == 7 ? "\n#\n" : "");
    at = end;
  }
  LoadReport spaced_report, spaced_general_report;
  const Mesh spaced_fast = pomar::load_mesh(write("spaced.off", spaced), &spaced_report);
  const Mesh spaced_general = pomar::load_mesh(
      write("spaced_general.off", "# made by hand\nOFF \n" + spaced.substr(spaced.find("OFF") + 4)),
      &spaced_general_report);
  expect_same_load(spaced_fast, spaced_report, spaced_general, spaced_general_report);
  expect_same_load(spaced_fast, spaced_report, fast, fast_report);
  // CRLF line ends (and a last line of only CR), which the fast path takes too, read as
  // vcglib reads them.
  std::string crlf;
  for (char c : "OFF\n" + counts + body)
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  LoadReport crlf_report, crlf_general_report;
  const Mesh crlf_fast = pomar::load_mesh(write("crlf.off", crlf + "\r\n"), &crlf_report);
  const Mesh crlf_general = pomar::load_mesh(
      write("crlf_general.off", "OFF \r\n" + crlf.substr(5) + "\r\n"), &crlf_general_report);
  expect_same_load(crlf_fast, crlf_report, crlf_general, crlf_general_report);
  expect_same_load(crlf_fast, crlf_report, fast, fast_report);
  // Doubles that round differently straight to float and through double (vcglib's way).
  const std::string tricky = "OFF\n3 1 0\n1.00000005960464477539062500000001 0 0\n"
                             "0 0.100000001490116119384765625000001 0\n0 0 1e-44\n3 0 1 2\n";
  const Mesh t_fast = pomar::load_mesh(write("t_fast.off", tricky));
  const Mesh t_general = pomar::load_mesh(write("t_general.off", "OFF\n#\n" + tricky.substr(4)));
  EXPECT_TRUE(same_bits(t_fast.positions, t_general.positions));
}

TEST_F(MeshIoTest, OffQuadAndPolygon) {
  const std::string file = write("poly.off", "OFF\n# comment\n6 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                                             "2 0 0\n2 1 0\n4 0 1 2 3\n5 1 4 5 2 0\n");
  LoadReport r;
  const Mesh m = pomar::load_mesh(file, &r);
  EXPECT_EQ(m.triangle_count(), 2u + 3u);
  EXPECT_EQ(r.polygons_triangulated, 2u);
  EXPECT_EQ(r.file_faces, 2u);
}

TEST_F(MeshIoTest, OffWithNormalsColorsAndTexCoords) {
  // NOFF makes vcglib store normals whether or not the mesh type has them.
  LoadReport r;
  const Mesh m =
      pomar::load_mesh(write("n.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n"
                                      "3 0 1 2\n"),
                       &r);
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_TRUE(r.ignored_attributes.empty()); // per-vertex normals are kept
  ASSERT_NE(m.find(AttributeKind::Normal), nullptr);
  EXPECT_EQ(m.find(AttributeKind::Normal)->values, (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}));
  const Mesh c = pomar::load_mesh(write("c.off", "STCOFF 3 1 0\n0 0 0 255 0 0 255 0.5 0.5\n"
                                                 "1 0 0 255 0 0 255 1 0\n0 1 0 9 9 9 9 0 1\n"
                                                 "3 0 1 2 255 0 0\n"),
                                  &r);
  EXPECT_EQ(c.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  // Vertex colours (RGBA: an alpha is not 255) are kept; the face colour and the texture
  // coordinates (which vcglib's importer does not store) are not.
  EXPECT_EQ(r.ignored_attributes, (std::vector<std::string>{"colors", "texture coordinates"}));
  ASSERT_NE(c.find(AttributeKind::Colour), nullptr);
  EXPECT_EQ(c.find(AttributeKind::Colour)->colour,
            (std::vector<uint8_t>{255, 0, 0, 255, 255, 0, 0, 255, 9, 9, 9, 9}));
  EXPECT_EQ(c.find(AttributeKind::TexCoord), nullptr);
}

TEST_F(MeshIoTest, OffTruncatedFaceListIsError) {
  // vcglib reads a token of an empty line here (out of bounds); we must stop first.
  const std::string msg =
      load_error(write("cut.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
}

TEST_F(MeshIoTest, OffBadIndexAndNaN) {
  EXPECT_NE(load_error(write("i.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"))
                .find("references vertex '3'"),
            std::string::npos);
  const std::string msg =
      load_error(write("n.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n"));
  EXPECT_NE(msg.find("vertex 1 has a non-finite coordinate"), std::string::npos) << msg;
}

// ------------------------------------------------------------------------------------
// STL
// ------------------------------------------------------------------------------------

std::string binary_stl(const std::vector<std::vector<float>> &facets) {
  std::string s(80, ' ');
  const uint32_t n = static_cast<uint32_t>(facets.size());
  s.append(reinterpret_cast<const char *>(&n), 4);
  for (const auto &f : facets) {
    const float normal[3] = {0, 0, 0};
    s.append(reinterpret_cast<const char *>(normal), 12);
    s.append(reinterpret_cast<const char *>(f.data()), 36);
    s.append(2, '\0');
  }
  return s;
}

const std::vector<std::vector<float>> kTetraFacets = {{0, 0, 0, 0, 1, 0, 1, 0, 0},
                                                      {0, 0, 0, 1, 0, 0, 0, 0, 1},
                                                      {0, 0, 0, 0, 0, 1, 0, 1, 0},
                                                      {1, 0, 0, 0, 1, 0, 0, 0, 1}};

TEST_F(MeshIoTest, StlBinaryIsWelded) {
  LoadReport r;
  const Mesh m = pomar::load_mesh(write("t.stl", binary_stl(kTetraFacets)), &r);
  EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1}));
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 1, 2, 1, 3}));
  EXPECT_EQ(r.welded_vertices, 8u);
  EXPECT_EQ(r.file_vertices, 12u);
  EXPECT_EQ(r.file_faces, 4u);
}

// Welding keeps the first occurrence of each position (its bits: -0 where it came first)
// in the order of first occurrences: checked against a plain reference on a binary STL of
// 30,000 facets drawn from 5,000 points, some of them -0/+0 twins.
TEST_F(MeshIoTest, StlWeldingMatchesReference) {
  std::mt19937 rng(23);
  std::vector<std::array<float, 3>> points(5000);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (size_t i = 0; i < points.size(); ++i)
    for (float &c : points[i])
      c = i % 10 == 3 ? (rng() % 2 ? 0.0f : -0.0f) : u(rng); // zeros of both signs
  std::vector<std::vector<float>> facets(30000);
  for (auto &f : facets)
    for (int k = 0; k < 3; ++k) {
      const auto &p = points[rng() % points.size()];
      f.insert(f.end(), p.begin(), p.end());
    }
  // Reference: positions compared as floats (so -0 == +0), first occurrence kept.
  std::vector<float> positions;
  std::vector<uint32_t> triangles;
  std::vector<std::array<float, 3>> kept;
  for (const auto &f : facets)
    for (int k = 0; k < 3; ++k) {
      const std::array<float, 3> p = {f[3 * k], f[3 * k + 1], f[3 * k + 2]};
      size_t id = 0;
      while (id < kept.size() &&
             !(kept[id][0] == p[0] && kept[id][1] == p[1] && kept[id][2] == p[2]))
        ++id;
      if (id == kept.size()) {
        kept.push_back(p);
        positions.insert(positions.end(), p.begin(), p.end());
      }
      triangles.push_back(static_cast<uint32_t>(id));
    }
  LoadReport r;
  const Mesh m = pomar::load_mesh(write("w.stl", binary_stl(facets)), &r);
  EXPECT_TRUE(same_bits(m.positions, positions));
  EXPECT_EQ(m.triangles, triangles);
  EXPECT_EQ(r.welded_vertices, 3 * facets.size() - kept.size());
}

// ASCII STL is read in chunks of 4 MiB (tokens and "endloop" words cut by a chunk's end):
// a 12 MB file must give the mesh its binary twin gives, and the size check the facet
// count.
TEST_F(MeshIoTest, StlAsciiOverSeveralChunksReadsAsBinary) {
  const pomar::Mesh m = pomar::gen::noisy_sphere(24000, 3);
  pomar::save_mesh(path("a.stl"), m, false);
  pomar::save_mesh(path("b.stl"), m, true);
  EXPECT_GT(read_text(path("a.stl")).size(), size_t(10) << 20);
  uint64_t seen_faces = 0;
  LoadReport ra, rb;
  const Mesh a = pomar::load_mesh(path("a.stl"), &ra, [&](uint64_t, uint64_t faces) {
    seen_faces = std::max(seen_faces, faces);
  });
  const Mesh b = pomar::load_mesh(path("b.stl"), &rb);
  EXPECT_EQ(seen_faces, m.triangle_count());
  EXPECT_TRUE(same_bits(a.positions, b.positions));
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.triangle_count(), m.triangle_count());
  EXPECT_EQ(ra.welded_vertices, rb.welded_vertices);
}

TEST_F(MeshIoTest, StlAsciiIsWeldedAndMinusZeroEqualsZero) {
  const std::string file =
      write("t.stl", "solid t\n"
                     "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                     "vertex 0 1 0\nendloop\nendfacet\n"
                     "facet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\n"
                     "vertex -0 1 -0\nendloop\nendfacet\nendsolid t\n");
  LoadReport r;
  const Mesh m = pomar::load_mesh(file, &r);
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2}));
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(r.welded_vertices, 2u);
}

TEST_F(MeshIoTest, StlAsciiWithNonAsciiName) {
  // vcglib alone would take this for binary (a byte > 127 after the first 84 bytes).
  std::string text = "solid " + std::string(90, 'x') + " W\xc3\xbcrfel\n";
  text += "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
          "endloop\nendfacet\nendsolid\n";
  EXPECT_EQ(pomar::load_mesh(write("u.stl", text)).triangle_count(), 1u);
}

TEST_F(MeshIoTest, StlBrokenFiles) {
  std::string cut = binary_stl(kTetraFacets);
  cut[84] = char(0xff); // still looks binary
  EXPECT_NE(load_error(write("cut.stl", cut.substr(0, cut.size() - 10))).find("truncated"),
            std::string::npos);
  // vcglib would loop forever looking for the end of the first line.
  EXPECT_NE(load_error(write("noline.stl", std::string(200, 'a'))).find("line breaks"),
            std::string::npos);
  EXPECT_NE(load_error(write("short.stl", "solid x\nendsolid x\n")).find("too short"),
            std::string::npos);
  EXPECT_NE(load_error(write("text.stl", std::string(100, 'x') + "\nhello world\n"))
                .find("contains no triangles"),
            std::string::npos);
  auto nan_facets = kTetraFacets;
  nan_facets[1][4] = NAN;
  const std::string msg = load_error(write("nan.stl", binary_stl(nan_facets)));
  EXPECT_NE(msg.find("vertex 4 (facet 1) has a non-finite coordinate"), std::string::npos) << msg;
}

// ------------------------------------------------------------------------------------
// General errors
// ------------------------------------------------------------------------------------

TEST_F(MeshIoTest, MissingFileNamesPath) {
  for (const char *name : {"missing.ply", "missing.obj", "missing.off", "missing.stl"}) {
    const std::string msg = load_error(path(name));
    EXPECT_NE(msg.find(path(name)), std::string::npos) << msg;
    EXPECT_NE(msg.find("No such file"), std::string::npos) << msg;
  }
}

TEST_F(MeshIoTest, DirectoryIsError) {
  ASSERT_EQ(mkdir(path("d.ply").c_str(), 0700), 0);
  EXPECT_NE(load_error(path("d.ply")).find("is a directory"), std::string::npos);
  EXPECT_NE(error_of([&] { pomar::read_file(path("d.ply")); }).find("is a directory"),
            std::string::npos);
  rmdir(path("d.ply").c_str());
}

TEST_F(MeshIoTest, UnknownExtensionListsSupported) {
  const std::string msg = load_error(write("mesh.xyz", "1 2 3\n"));
  EXPECT_NE(msg.find(".xyz"), std::string::npos) << msg;
  EXPECT_NE(msg.find(".ply, .obj, .off, .stl"), std::string::npos) << msg;
  EXPECT_NE(error_of([&] { pomar::save_mesh(path("out.xyz"), awkward_mesh()); }).find(".xyz"),
            std::string::npos);
  EXPECT_NE(load_error(path("noext")).find("no file extension"), std::string::npos);
}

TEST_F(MeshIoTest, GarbageAndEmptyFiles) {
  std::mt19937 rng(7);
  std::string garbage;
  for (int i = 0; i < 4000; ++i)
    garbage.push_back(static_cast<char>(rng()));
  for (const char *name : {"g.ply", "g.obj", "g.off", "g.stl"}) {
    const std::string msg = load_error(write(name, garbage));
    EXPECT_NE(msg.find(path(name)), std::string::npos) << msg;
    const std::string empty = std::string("empty_") + name;
    const std::string msg2 = load_error(write(empty, ""));
    EXPECT_NE(msg2.find(path(empty)), std::string::npos) << msg2;
  }
  EXPECT_NE(load_error(write("e.obj", "# nothing\n")).find("contains no triangles"),
            std::string::npos);
  EXPECT_NE(load_error(write("e.off", "OFF\n0 0 0\n")).find("contains no triangles"),
            std::string::npos);
  EXPECT_NE(load_error(write("e.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
                                      "property float y\nproperty float z\nend_header\n"))
                .find("contains no triangles"),
            std::string::npos);
  EXPECT_NE(load_error(write("h.ply", "ply\nformat ascii 1.0\nelement vertex\nend_header\n"))
                .find("invalid PLY header"),
            std::string::npos);
}

/// Truncated and bit-flipped versions of valid files must load or throw pomar::Error,
/// never crash, hang or throw anything else.
TEST_F(MeshIoTest, DamagedFilesNeverCrash) {
  const Mesh mesh = random_mesh(40, 99);
  std::mt19937 rng(3);
  for (const Case c : {Case{"d.ply", true}, Case{"d_ascii.ply", false}, Case{"d.obj", true},
                       Case{"d.off", true}, Case{"d_ascii.stl", false}}) {
    pomar::save_mesh(path(c.name), mesh, c.binary);
    const std::string good = read_text(path(c.name));
    for (int trial = 0; trial < 150; ++trial) {
      std::string bad = good;
      if (trial % 2)
        bad.resize(rng() % bad.size());
      for (int flips = trial % 4; flips > 0 && !bad.empty(); --flips)
        bad[rng() % bad.size()] = static_cast<char>(rng());
      write(c.name, bad);
      try {
        pomar::load_mesh(path(c.name));
      } catch (const pomar::Error &) {
      }
    }
  }
}

TEST_F(MeshIoTest, TetrahedronPlyLoads) {
  EXPECT_EQ(pomar::load_mesh(write("t.ply", kTetraPly)).triangle_count(), 4u);
}

// ------------------------------------------------------------------------------------
// Writing
// ------------------------------------------------------------------------------------

TEST_F(MeshIoTest, SaveReplacesAtomicallyAndLeavesNoTemporaryFiles) {
  for (const char *name : {"x.ply", "x.stl", "x.obj", "x.off"}) {
    write(name, "old contents");
    pomar::save_mesh(path(name), awkward_mesh());
    EXPECT_EQ(pomar::load_mesh(path(name)).triangle_count(), 6u);
  }
  for (const std::string &n : list_dir())
    EXPECT_EQ(n.find(".tmp."), std::string::npos) << n;
}

TEST_F(MeshIoTest, SaveRejectsInvalidMeshAndKeepsDestination) {
  write("keep.ply", "old");
  Mesh bad = awkward_mesh();
  bad.triangles.back() = 99;
  EXPECT_NE(error_of([&] { pomar::save_mesh(path("keep.ply"), bad); }).find("references vertex 99"),
            std::string::npos);
  Mesh nan = awkward_mesh();
  nan.positions[4] = NAN;
  EXPECT_NE(error_of([&] { pomar::save_mesh(path("keep.ply"), nan); }).find("vertex 1"),
            std::string::npos);
  EXPECT_EQ(read_text(path("keep.ply")), "old");
  EXPECT_EQ(list_dir().size(), 1u);
}

TEST_F(MeshIoTest, SaveIntoMissingDirectoryNamesPath) {
  for (bool binary : {true, false}) {
    const std::string target = path("no/such/dir/m.ply");
    const std::string msg = error_of([&] { pomar::save_mesh(target, awkward_mesh(), binary); });
    EXPECT_NE(msg.find(target), std::string::npos) << msg;
  }
  const std::string target = path("no/such/dir/m.stl");
  EXPECT_NE(error_of([&] { pomar::save_mesh(target, awkward_mesh()); }).find(target),
            std::string::npos);
}

TEST_F(MeshIoTest, WriteAndReadFile) {
  const std::string data = std::string("abc\0def", 7);
  pomar::write_file_atomic(path("f.bin"), data.data(), data.size());
  const std::vector<uint8_t> back = pomar::read_file(path("f.bin"));
  EXPECT_EQ(std::string(back.begin(), back.end()), data);
  const std::string msg = error_of([&] { pomar::read_file(path("nope.bin")); });
  EXPECT_NE(msg.find(path("nope.bin")), std::string::npos);
  EXPECT_NE(msg.find("No such file or directory"), std::string::npos);
  EXPECT_TRUE(pomar::read_file(write("empty.bin", "")).empty());
}

} // namespace

// save_mesh writes binary PLY from the flat arrays, not through vcglib's exporter: the
// bytes must still be exactly the exporter's (its header, float xyz, uchar 3 + int x3).
TEST_F(MeshIoTest, BinaryPlyHasVcglibsExactBytes) {
  pomar::Mesh m;
  m.positions = {0.f, 1.5f, -2.f, 3.25f, 4.f, 5.f, -0.f, 1e-7f, 6.f, 7.f, 8.f, 9.f};
  m.triangles = {0, 1, 2, 0, 2, 3, 3, 2, 1};
  pomar::save_mesh(path("m.ply"), m, true);
  std::string want = "ply\nformat binary_little_endian 1.0\ncomment VCGLIB generated\n"
                     "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face 3\nproperty list uchar int vertex_indices\nend_header\n";
  want.append(reinterpret_cast<const char *>(m.positions.data()), 4 * m.positions.size());
  for (size_t f = 0; f < 3; ++f) {
    want.push_back(3);
    for (int k = 0; k < 3; ++k) {
      const int32_t v = static_cast<int32_t>(m.triangles[3 * f + k]);
      want.append(reinterpret_cast<const char *>(&v), 4);
    }
  }
  EXPECT_EQ(read_text(path("m.ply")), want);
  EXPECT_EQ(list_dir().size(), 1u); // no temporary file left behind
}

namespace stl_reference { // a vcglib mesh that pomar::to_vcg fills, for vcglib's STL exporter
class V;
class F;
struct Types : vcg::UsedTypes<vcg::Use<V>::AsVertexType, vcg::Use<F>::AsFaceType> {};
class V
    : public vcg::Vertex<Types, vcg::vertex::Coord3f, vcg::vertex::Normal3f, vcg::vertex::Color4b,
                         vcg::vertex::Qualityf, vcg::vertex::TexCoord2f, vcg::vertex::BitFlags> {};
class F : public vcg::Face<Types, vcg::face::VertexRef, vcg::face::BitFlags> {};
class M : public vcg::tri::TriMesh<std::vector<V>, std::vector<F>> {};
} // namespace stl_reference

// PLY files with vertex attributes: the walk takes their positions and triangles
// (io/ply_walker.cpp, PlyCapture) instead of vcglib's importer. For ASCII, binary little- and
// big-endian files of the same values, positions, triangles and unreferenced vertices must
// be what vcglib's importer reads from the same file.
TEST_F(MeshIoTest, PlyCapturedPositionsAndTrianglesAreVcglibs) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  const size_t nv = 203, nf = 190;
  std::vector<float> values(nv * 5);
  for (float &x : values)
    x = u(rng);
  values[7] = -0.0f;
  values[11] = 1e-41f; // a denormal
  for (const char *format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    const bool ascii = std::string(format) == "ascii",
               big = std::string(format) == "binary_big_endian";
    std::string f = std::string("ply\nformat ") + format + " 1.0\nelement vertex " +
                    std::to_string(nv) +
                    "\nproperty float quality\nproperty float z\nproperty float x\n"
                    "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                    "property float y\nproperty float confidence\nelement face " +
                    std::to_string(nf) + "\nproperty list uchar int vertex_indices\nend_header\n";
    char buf[64];
    auto put = [&](const void *p, size_t n) {
      std::string b(static_cast<const char *>(p), n);
      if (big)
        std::reverse(b.begin(), b.end());
      f += b;
    };
    auto f32 = [&](float x) {
      if (ascii) {
        std::snprintf(buf, sizeof buf, "%.9g ", double(x));
        f += buf;
      } else {
        put(&x, 4);
      }
    };
    auto u8 = [&](uint8_t x) {
      if (ascii)
        f += std::to_string(x) + " ";
      else
        f += char(x);
    };
    auto i32 = [&](int32_t x) {
      if (ascii)
        f += std::to_string(x) + " ";
      else
        put(&x, 4);
    };
    for (size_t v = 0; v < nv; ++v) {
      f32(values[5 * v]), f32(values[5 * v + 1]), f32(values[5 * v + 2]);
      u8(uint8_t(v)), u8(uint8_t(2 * v)), u8(uint8_t(3 * v));
      f32(values[5 * v + 3]), f32(values[5 * v + 4]);
      if (ascii)
        f += "\n";
    }
    for (size_t t = 0; t < nf; ++t) {
      u8(3);
      for (int k = 0; k < 3; ++k)
        i32(int32_t((t * 7 + size_t(k) * 61) % 200)); // vertices 200..202 unreferenced
      if (ascii)
        f += "\n";
    }
    const std::string file = write(std::string(format) + ".ply", f);
    LoadReport r;
    const Mesh m = pomar::load_mesh(file, &r);
    stl_reference::M vm;
    int mask = 0;
    ASSERT_EQ(vcg::tri::io::ImporterPLY<stl_reference::M>::Open(vm, file.c_str(), mask), 0)
        << format;
    size_t unreferenced = 0;
    const Mesh ref = pomar::from_vcg(vm, &unreferenced, 0, true);
    EXPECT_TRUE(same_bits(m.positions, ref.positions)) << format;
    EXPECT_EQ(m.triangles, ref.triangles) << format;
    EXPECT_EQ(r.unreferenced_vertices, unreferenced) << format;
    EXPECT_EQ(unreferenced, 3u) << format;
    ASSERT_EQ(m.attributes.size(), 3u) << format; // colour, quality, confidence
  }
}

// save_mesh writes binary STL from the flat arrays too: the bytes must be exactly what
// vcglib's exporter writes, facet normals included (computed in float as vcglib does),
// also for a degenerate facet (zero normal) and over several 1 MiB chunks.
TEST_F(MeshIoTest, BinaryStlHasVcglibsExactBytes) {
  pomar::Mesh m = pomar::gen::noisy_sphere(30000, 7);
  m.positions.insert(m.positions.end(), {0.f, 0.f, 0.f, 1.f, 1.f, 1.f, 2.f, 2.f, 2.f});
  const uint32_t n = static_cast<uint32_t>(m.vertex_count());
  m.triangles.insert(m.triangles.end(), {n - 3, n - 2, n - 1}); // collinear: a zero normal
  stl_reference::M vm;
  pomar::to_vcg(m, vm);
  ASSERT_EQ(vcg::tri::io::ExporterSTL<stl_reference::M>::Save(vm, path("vcg.stl").c_str(), true),
            0);
  pomar::save_mesh(path("m.stl"), m, true);
  const std::string want = read_text(path("vcg.stl")), got = read_text(path("m.stl"));
  EXPECT_EQ(got.size(), 84 + 50 * m.triangle_count());
  EXPECT_TRUE(got == want) << "the files differ";
  EXPECT_EQ(list_dir().size(), 2u); // no temporary file left behind
}

// Binary PLY of float xyz + uchar/int triangles is read without vcglib: unreferenced
// vertices are still dropped and counted, the others keep their order; a file outside that
// case (here: a quad) goes through the general reader.
TEST_F(MeshIoTest, SimpleBinaryPlyKeepsAndCountsUnreferencedVertices) {
  pomar::Mesh m;
  m.positions = {0, 0, 0, 9, 9, 9, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.triangles = {0, 2, 3, 0, 3, 4, 0, 4, 2, 2, 4, 3};
  pomar::save_mesh(path("t.ply"), m, true);
  pomar::LoadReport report;
  const pomar::Mesh back = pomar::load_mesh(path("t.ply"), &report);
  EXPECT_EQ(report.unreferenced_vertices, 1u);
  EXPECT_EQ(report.file_vertices, 5u);
  EXPECT_EQ(report.file_faces, 4u);
  EXPECT_EQ(back.positions, m.positions); // kept: the codec stores them (lossless stage)
  EXPECT_EQ(back.triangles, m.triangles);

  std::string quad = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
                     "property float y\nproperty float z\nelement face 1\n"
                     "property list uchar int vertex_indices\nend_header\n";
  const float xyz[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  quad.append(reinterpret_cast<const char *>(xyz), sizeof xyz);
  quad.push_back(4);
  for (int32_t v = 0; v < 4; ++v)
    quad.append(reinterpret_cast<const char *>(&v), 4);
  const pomar::Mesh two = pomar::load_mesh(write("q.ply", quad), &report);
  EXPECT_EQ(two.triangle_count(), 2u);
  EXPECT_EQ(report.polygons_triangulated, 1u);
}
