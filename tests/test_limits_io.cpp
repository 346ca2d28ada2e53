// load_mesh's size check (pomar/mesh_io.h SizeCheck): it sees the counts each format's
// header gives before the mesh is read, and its error is reported with the file's path.
#include <pomar/limits.h>
#include <pomar/mesh_io.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "support/mesh_gen.h"
#include "support/temp_dir.h"

namespace pomar {
namespace {

using SizeCheckTest = test::TempDirTest;

/// The counts the check was called with, in order.
struct Calls {
  std::vector<std::pair<uint64_t, uint64_t>> seen;
  SizeCheck record() {
    return [this](uint64_t v, uint64_t f) { seen.emplace_back(v, f); };
  }
};

TEST_F(SizeCheckTest, SeesTheCountsOfEveryFormat) {
  const Mesh cube = gen::icosphere(1); // 42 vertices, 80 triangles
  struct Case {
    const char *name;
    bool binary;
    std::vector<std::pair<uint64_t, uint64_t>> expected;
  } cases[] = {
      {"m.ply", true, {{42, 80}}},  {"m.off", false, {{42, 80}}}, {"m.obj", false, {{42, 80}}},
      {"m.stl", true, {{40, 80}}}, // STL: half a vertex per facet, what welding keeps
      {"a.stl", false, {{40, 80}}}, {"a.ply", false, {{42, 80}}},
  };
  for (const Case &c : cases) {
    save_mesh(path(c.name), cube, c.binary);
    Calls calls;
    LoadReport report;
    bool text_at_check = false; // what a per-format estimate sees when the check runs
    const Mesh m = load_mesh(path(c.name), &report, [&](uint64_t v, uint64_t f) {
      text_at_check = report.text;
      calls.record()(v, f);
    });
    EXPECT_EQ(m.triangle_count(), 80u) << c.name;
    EXPECT_EQ(calls.seen, c.expected) << c.name;
    EXPECT_EQ(text_at_check, !c.binary) << c.name;
    EXPECT_EQ(report.text, !c.binary) << c.name;
  }
}

TEST_F(SizeCheckTest, ObjEstimateFollowsTheReaderThatTakesTheFile) {
  // One tetrahedron as plain OBJ (pomar's own reader), with relative indices and with a
  // normal per corner (both tinyobjloader's): the check sees the reader's decision, and with
  // it the estimate of that reader's peak.
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
  struct Case {
    const char *name, *text;
    EncodeInput expected;
  } cases[] = {
      {"plain.obj", "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n", EncodeInput::ObjPlain},
      {"relative.obj", "f -4 -2 -3\nf -4 -3 -1\nf -3 -2 -1\nf -2 -4 -1\n", EncodeInput::Obj},
      {"normals.obj",
       "vn 0 0 1\nf 1//1 3//1 2//1\nf 1//1 2//1 4//1\nf 2//1 3//1 4//1\n"
       "f 3//1 1//1 4//1\n",
       EncodeInput::ObjAttributes},
  };
  std::vector<uint64_t> estimates;
  for (const Case &c : cases) {
    LoadReport report;
    EncodeInput seen = EncodeInput::Mesh;
    uint64_t estimate = 0;
    const Mesh m = load_mesh(write(c.name, v + c.text), &report, [&](uint64_t nv, uint64_t nf) {
      seen = encode_input(report);
      estimate = encode_memory_estimate(nv, nf, seen);
    });
    EXPECT_EQ(m.triangle_count(), 4u) << c.name;
    EXPECT_EQ(seen, c.expected) << c.name;
    estimates.push_back(estimate);
  }
  // Plain OBJ has the light readers' estimate (as PLY), tinyobjloader's are larger.
  EXPECT_EQ(estimates[0], encode_memory_estimate(4, 4, EncodeInput::PlyBinary));
  EXPECT_LT(estimates[0], estimates[1]);
  EXPECT_LT(estimates[1], estimates[2]);
  // So a limit that fits the plain file's estimate loads it and refuses the others.
  for (size_t i = 0; i < 3; ++i) {
    LoadReport report;
    const auto load = [&] {
      load_mesh(path(cases[i].name), &report, [&](uint64_t nv, uint64_t nf) {
        check_encode_memory(nv, nf, estimates[0], 0, 0, 1, encode_input(report));
      });
    };
    if (i == 0) {
      EXPECT_NO_THROW(load());
    } else {
      try {
        load();
        ADD_FAILURE() << cases[i].name << " fits";
      } catch (const Error &e) {
        EXPECT_EQ(e.kind(), Error::Kind::MemoryLimit) << e.what();
      }
    }
  }
}

TEST_F(SizeCheckTest, ObjNormalsPerCornerAddToTheEstimate) {
  // One tetrahedron with a normal and a texture coordinate per vertex, and with one of each
  // per corner (12 of each: the values the reader holds beyond its row).
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
  std::string per_vertex = v, per_corner = v;
  for (int i = 0; i < 4; ++i)
    per_vertex += "vn 0 0 1\nvt 0 0\n";
  for (int i = 0; i < 12; ++i)
    per_corner += "vn 0 0 1\nvt 0 0\n";
  const int tris[4][3] = {{1, 3, 2}, {1, 2, 4}, {2, 3, 4}, {3, 1, 4}};
  for (int t = 0; t < 4; ++t) {
    per_vertex += "f";
    per_corner += "f";
    for (int k = 0; k < 3; ++k) {
      const std::string a = std::to_string(tris[t][k]), c = std::to_string(3 * t + k + 1);
      per_vertex += " " + a + "/" + a + "/" + a;
      per_corner += " " + a + "/" + c + "/" + c;
    }
    per_vertex += "\n";
    per_corner += "\n";
  }
  uint64_t extra[2] = {0, 0}, lines[2] = {0, 0};
  const std::string names[2] = {"per_vertex.obj", "per_corner.obj"};
  const std::string texts[2] = {per_vertex, per_corner};
  for (int i = 0; i < 2; ++i) {
    LoadReport report;
    load_mesh(write(names[i], texts[i]), &report, [&](uint64_t nv, uint64_t) {
      EXPECT_EQ(encode_input(report), EncodeInput::ObjAttributes) << names[i];
      lines[i] = report.obj_value_lines;
      extra[i] = encode_input_extra(report, nv);
    });
  }
  EXPECT_EQ(lines[0], 8u);
  EXPECT_EQ(lines[1], 24u);
  EXPECT_EQ(extra[0], 0u); // one of each per vertex: the row holds them
  EXPECT_EQ(extra[1], (24u - 8u) * 32u);
  // A limit at the row's estimate takes the per-vertex file and refuses the other.
  const uint64_t limit = encode_memory_estimate(4, 4, EncodeInput::ObjAttributes);
  for (int i = 0; i < 2; ++i) {
    LoadReport report;
    const auto load = [&] {
      load_mesh(path(names[i]), &report, [&](uint64_t nv, uint64_t nf) {
        check_encode_memory(nv, nf, limit, 0, 0, 1, encode_input(report),
                            encode_input_extra(report, nv));
      });
    };
    if (i == 0) {
      EXPECT_NO_THROW(load());
    } else {
      try {
        load();
        ADD_FAILURE() << names[i] << " fits";
      } catch (const Error &e) {
        EXPECT_EQ(e.kind(), Error::Kind::MemoryLimit) << e.what();
      }
    }
  }
  // Other readers hold nothing beyond their rows.
  LoadReport ply;
  ply.format = "ply";
  ply.obj_value_lines = 1000;
  EXPECT_EQ(encode_input_extra(ply, 4), 0u);
}

TEST_F(SizeCheckTest, PolygonsAreCheckedAgainWithTheirTriangles) {
  const std::string ply =
      write("quads.ply", "ply\nformat ascii 1.0\nelement vertex 5\n"
                         "property float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_indices\n"
                         "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 2 0\n"
                         "5 0 1 2 3 4\n");
  Calls calls;
  load_mesh(ply, nullptr, calls.record());
  const std::vector<std::pair<uint64_t, uint64_t>> expected = {{5, 1}, {5, 3}};
  EXPECT_EQ(calls.seen, expected);
}

TEST_F(SizeCheckTest, RefusalNamesThePathAndComesBeforeTheBody) {
  // A header promising 2^31 - 1 vertices over a 12-byte body: the check refuses from the
  // header; without a check the structure walk reports the truncation. Neither allocates
  // for the promised vertices.
  const std::string ply = write("huge.ply", std::string("ply\nformat binary_little_endian 1.0\n"
                                                        "element vertex 2147483647\n"
                                                        "property float x\nproperty float y\n"
                                                        "property float z\nelement face 1\n"
                                                        "property list uchar int vertex_indices\n"
                                                        "end_header\n") +
                                                std::string(12, '\0'));
  try {
    load_mesh(ply, nullptr, [](uint64_t v, uint64_t f) { check_encode_memory(v, f, 1ull << 30); });
    ADD_FAILURE() << "no error";
  } catch (const Error &e) {
    EXPECT_EQ(std::string(e.what()).rfind(ply + ": not enough memory to encode 2,147,483,647 "
                                                "vertices and 1 faces: needs about ",
                                          0),
              0u)
        << e.what();
  }
  try {
    load_mesh(ply);
    ADD_FAILURE() << "no error";
  } catch (const Error &e) {
    EXPECT_EQ(std::string(e.what()), ply + ": truncated PLY file (vertex 0 of 2147483647)");
  }
}

TEST_F(SizeCheckTest, OffAndStlHeadersAreCheckedBeforeTheBody) {
  const std::string off = write("huge.off", "OFF\n1000000000 2000000000 0\n0 0 0\n");
  Calls calls;
  auto refuse = [&](uint64_t v, uint64_t f) {
    calls.seen.emplace_back(v, f);
    throw Error("refused");
  };
  EXPECT_THROW(load_mesh(off, nullptr, refuse), Error);
  std::string stl(84, '\0'); // binary STL header promising 3 facets, with all 3
  stl[80] = 3;
  stl += std::string(150, '\0');
  const std::string stl_path = write("three.stl", stl);
  EXPECT_THROW(load_mesh(stl_path, nullptr, refuse), Error);
  const std::vector<std::pair<uint64_t, uint64_t>> expected = {{1000000000, 2000000000}, {1, 3}};
  EXPECT_EQ(calls.seen, expected);
}

} // namespace
} // namespace pomar
