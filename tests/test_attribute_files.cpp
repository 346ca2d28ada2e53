// Attributes in mesh files: OBJ texture names (mtllib + map_Kd) and UVs through .pomar,
// OFF colour and normals written back exactly, what each writer cannot hold named, and
// text files of several 1 MiB chunks written whole, or not at all when a write fails.
#include <pomar/mesh_io.h>
#include <pomar/pomar.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include <csignal>
#include <sys/resource.h>
#include <vector>

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include "support/mesh_attributes.h"
#include "support/mesh_gen.h"
#include "support/temp_dir.h"

namespace pomar {
namespace {

using AttributeFiles = test::TempDirTest;

std::string read_text(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string joined(const std::vector<std::string> &list) {
  std::string out;
  for (const std::string &s : list)
    out += (out.empty() ? "" : " | ") + s;
  return out;
}

/// An n x n grid in the OBJ format with a texture coordinate per vertex ("f a/a b/b c/c"),
/// naming the material library `mtllib` and using material `material`.
std::string uv_grid_obj(int n, const std::string &mtllib, const std::string &material) {
  std::string s = "mtllib " + mtllib + "\n";
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      s += "v " + std::to_string(i) + " " + std::to_string(j) + " " +
           std::to_string(0.1 * ((i * 7 + j * 3) % 5)) + "\n";
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      s += "vt " + std::to_string(i / double(n - 1)) + " " + std::to_string(j / double(n - 1)) +
           "\n";
  s += "usemtl " + material + "\n";
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const std::string a = std::to_string(j * n + i + 1), b = std::to_string(j * n + i + 2),
                        c = std::to_string((j + 1) * n + i + 1),
                        d = std::to_string((j + 1) * n + i + 2);
      s += "f " + a + "/" + a + " " + b + "/" + b + " " + d + "/" + d + "\n";
      s += "f " + a + "/" + a + " " + d + "/" + d + " " + c + "/" + c + "\n";
    }
  return s;
}

TEST_F(AttributeFiles, ObjTextureNamesAndUvsRoundTripThroughPomar) {
  write("tex.mtl", "newmtl skin\nKd 1 1 1\nmap_Kd my skin.png\n");
  const std::string in = write("in.obj", uv_grid_obj(12, "tex.mtl", "skin"));
  LoadReport r;
  const Mesh original = load_mesh(in, &r);
  EXPECT_TRUE(r.ignored_attributes.empty()) << joined(r.ignored_attributes);
  EXPECT_EQ(original.texture_files, std::vector<std::string>{"my skin.png"});
  ASSERT_NE(original.find(AttributeKind::TexCoord), nullptr);

  EncodeOptions exact;
  exact.attributes.exact = true; // UVs bit for bit: the OBJ written back has the input's
  const std::vector<uint8_t> file = encode(original, exact);
  const Mesh decoded = decode(file.data(), file.size());
  EXPECT_EQ(decoded.texture_files, original.texture_files);
  const std::string out = path("out dir.obj"); // a space: the mtllib name is escaped
  save_mesh(out, decoded);
  EXPECT_TRUE(attributes_not_saved(out, decoded).empty());
  const std::string mtl = read_text(path("out dir.mtl"));
  EXPECT_NE(mtl.find("newmtl skin\nKd 1 1 1\nmap_Kd my skin.png\n"), std::string::npos) << mtl;
  const std::string obj = read_text(out);
  EXPECT_NE(obj.find("mtllib out\\ dir.mtl\n"), std::string::npos);
  EXPECT_NE(obj.find("\nusemtl skin\n"), std::string::npos); // the material, kept by the file
  EXPECT_NE(obj.find("\nvt "), std::string::npos);

  LoadReport back_report;
  const Mesh back = load_mesh(out, &back_report);
  EXPECT_TRUE(back_report.ignored_attributes.empty()) << joined(back_report.ignored_attributes);
  EXPECT_EQ(back.texture_files, original.texture_files);
  EXPECT_EQ(back.positions, decoded.positions);
  EXPECT_EQ(back.triangles, decoded.triangles);
  ASSERT_NE(back.find(AttributeKind::TexCoord), nullptr);
  EXPECT_EQ(back.find(AttributeKind::TexCoord)->values,
            decoded.find(AttributeKind::TexCoord)->values);
  // The decoded mesh is the input (up to the 12-bit grid): same UVs per input vertex.
  const std::vector<uint8_t> again = encode(back, exact);
  EXPECT_EQ(decode(again.data(), again.size()).texture_files, original.texture_files);
}

TEST_F(AttributeFiles, ObjMaterialsAreKeptAndMissingLibrariesNamed) {
  // Missing library: its contents are lost, and said so; the usemtl name is kept.
  LoadReport r;
  const Mesh lost = load_mesh(write("a.obj", uv_grid_obj(4, "nowhere.mtl", "m")), &r);
  EXPECT_NE(joined(r.ignored_attributes).find("material library 'nowhere.mtl' not found"),
            std::string::npos)
      << joined(r.ignored_attributes);
  ASSERT_EQ(lost.materials.size(), 1u);
  EXPECT_EQ(lost.materials[0].name, "m");
  EXPECT_EQ(lost.materials[0].texture, -1);
  // Other properties and two materials: all kept, per face, and nothing named.
  write("two.mtl", "newmtl m\nKa 0.2 0.2 0.2\nKd 1 1 1\nillum 2\nmap_Kd a.png\n"
                   "newmtl n\nmap_Kd b.png\n");
  std::string text = uv_grid_obj(4, "two.mtl", "m");
  text.insert(text.rfind("f "), "usemtl n\n");
  const Mesh m = load_mesh(write("b.obj", text), &r);
  EXPECT_EQ(m.texture_files, (std::vector<std::string>{"a.png", "b.png"}));
  EXPECT_TRUE(r.ignored_attributes.empty()) << joined(r.ignored_attributes);
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].name, "m");
  EXPECT_EQ(m.materials[0].properties, "Ka 0.2 0.2 0.2\nKd 1 1 1\nillum 2\n");
  EXPECT_EQ(m.materials[0].texture, 0);
  EXPECT_EQ(m.materials[1].texture, 1);
  ASSERT_EQ(m.face_materials.size(), m.triangle_count());
  EXPECT_EQ(m.face_materials.back(), 1u);
  EXPECT_EQ(std::count(m.face_materials.begin(), m.face_materials.end(), 0u),
            long(m.triangle_count() - 1));
  // A library that is a directory, a device or a /proc file (which could block) is not read.
  ASSERT_EQ(mkdir(path("dir.mtl").c_str(), 0700), 0);
  for (const char *name : {"dir.mtl", "/dev/zero", "/proc/self/status"}) {
    load_mesh(write("c.obj", uv_grid_obj(4, name, "m")), &r);
    EXPECT_NE(joined(r.ignored_attributes)
                  .find("'" + std::string(name) + "' not a regular file of 1 byte to 64 MiB"),
              std::string::npos)
        << joined(r.ignored_attributes);
  }
}

TEST_F(AttributeFiles, TextureNamesWithLineBreaksAreRefused) {
  Mesh m = gen::noisy_sphere(50, 1, 0.1);
  m.texture_files = {"a\nb.png"};
  EXPECT_THROW(save_mesh(path("x.obj"), m), Error);
  EXPECT_THROW(save_mesh(path("x.ply"), m), Error);
}

TEST_F(AttributeFiles, OffColourAndNormalsAreWrittenAndReadBackExactly) {
  for (const int has : {int(kColour), kColour | kAlpha, int(kNormals), kColour | kNormals}) {
    const Mesh m = with_attributes(gen::noisy_sphere(300, 2, 0.1), has);
    const std::string out = path("m.off");
    save_mesh(out, m);
    EXPECT_TRUE(attributes_not_saved(out, m).empty());
    const std::string head = read_text(out).substr(0, 6);
    EXPECT_EQ(head.substr(0, head.find('\n')),
              std::string(has & kColour ? "C" : "") + (has & kNormals ? "N" : "") + "OFF");
    LoadReport r;
    const Mesh back = load_mesh(out, &r);
    EXPECT_TRUE(r.ignored_attributes.empty()) << joined(r.ignored_attributes);
    EXPECT_EQ(back.positions, m.positions);
    EXPECT_EQ(back.triangles, m.triangles);
    ASSERT_EQ(back.attributes.size(), m.attributes.size()) << has;
    for (size_t i = 0; i < m.attributes.size(); ++i) {
      EXPECT_EQ(back.attributes[i].kind, m.attributes[i].kind);
      EXPECT_EQ(back.attributes[i].components, m.attributes[i].components);
      EXPECT_EQ(back.attributes[i].colour, m.attributes[i].colour);
      EXPECT_EQ(back.attributes[i].values, m.attributes[i].values);
    }
  }
}

TEST_F(AttributeFiles, OffColourSurvivesOffPomarOffPomar) {
  // A COFF file as a user has it, through pomar twice: the colours never change.
  std::string text = "COFF\n";
  const Mesh sphere = gen::noisy_sphere(400, 3, 0.1);
  text += std::to_string(sphere.vertex_count()) + " " + std::to_string(sphere.triangle_count()) +
          " 0\n";
  for (size_t v = 0; v < sphere.vertex_count(); ++v)
    text += std::to_string(sphere.positions[3 * v]) + " " +
            std::to_string(sphere.positions[3 * v + 1]) + " " +
            std::to_string(sphere.positions[3 * v + 2]) + " " + std::to_string(v * 7 % 256) + " " +
            std::to_string(v * 13 % 256) + " " + std::to_string(v * 31 % 256) + "\n";
  for (size_t t = 0; t < sphere.triangle_count(); ++t)
    text += "3 " + std::to_string(sphere.triangles[3 * t]) + " " +
            std::to_string(sphere.triangles[3 * t + 1]) + " " +
            std::to_string(sphere.triangles[3 * t + 2]) + "\n";
  const Mesh input = load_mesh(write("in.off", text));
  ASSERT_NE(input.find(AttributeKind::Colour), nullptr);
  EncodeOptions in_order;
  in_order.keep_order = true; // the input's vertex numbering: colours compare vertex by vertex
  const std::vector<uint8_t> a = encode(input, in_order);
  save_mesh(path("mid.off"), decode(a.data(), a.size()));
  const Mesh mid = load_mesh(path("mid.off"));
  const std::vector<uint8_t> b = encode(mid, in_order);
  const Mesh last = decode(b.data(), b.size());
  ASSERT_NE(last.find(AttributeKind::Colour), nullptr);
  EXPECT_EQ(last.find(AttributeKind::Colour)->colour, input.find(AttributeKind::Colour)->colour);
  EXPECT_EQ(last.positions, mid.positions); // on the grid since the first encode
}

TEST_F(AttributeFiles, WritersNameWhatTheyCannotHold) {
  const Mesh m = with_attributes(gen::noisy_sphere(100, 4, 0.1), kAll);
  EXPECT_TRUE(attributes_not_saved("x.ply", m).empty());
  EXPECT_EQ(joined(attributes_not_saved("x.stl", m)),
            "colours | normals | scalars 'quality', 'confidence' | texture coordinates | texture "
            "file names");
  EXPECT_EQ(joined(attributes_not_saved("x.off", m)),
            "scalars 'quality', 'confidence' | texture coordinates | texture file names");
  EXPECT_EQ(joined(attributes_not_saved("x.obj", m)),
            "the alpha of the colours | scalars 'quality', 'confidence'");
  Mesh plain = gen::noisy_sphere(100, 4, 0.1);
  for (const char *ext : {".ply", ".obj", ".off", ".stl"})
    EXPECT_TRUE(attributes_not_saved(std::string("x") + ext, plain).empty());
}

/// `sphere` as an ASCII PLY with colours red green blue alpha, every alpha 255; with `quad`,
/// plus a separate quad (a polygon: the reader takes the vcglib path, not the capture).
std::string opaque_rgba_ply(const Mesh &sphere, bool quad) {
  const size_t nv = sphere.vertex_count(), nf = sphere.triangle_count();
  std::string s = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(nv + (quad ? 4 : 0)) +
                  "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
                  "property uchar green\nproperty uchar blue\nproperty uchar alpha\n"
                  "element face " +
                  std::to_string(nf + (quad ? 1 : 0)) +
                  "\nproperty list uchar int vertex_indices\nend_header\n";
  for (size_t v = 0; v < nv + (quad ? 4 : 0); ++v) {
    const float x = v < nv ? sphere.positions[3 * v] : 3.0f + float((v - nv) % 2);
    const float y = v < nv ? sphere.positions[3 * v + 1] : float((v - nv) / 2);
    const float z = v < nv ? sphere.positions[3 * v + 2] : 0.0f;
    s += std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + " " +
         std::to_string(v * 7 % 256) + " " + std::to_string(v * 13 % 256) + " " +
         std::to_string(v * 31 % 256) + " 255\n";
  }
  for (size_t t = 0; t < nf; ++t)
    s += "3 " + std::to_string(sphere.triangles[3 * t]) + " " +
         std::to_string(sphere.triangles[3 * t + 1]) + " " +
         std::to_string(sphere.triangles[3 * t + 2]) + "\n";
  if (quad)
    s += "4 " + std::to_string(nv) + " " + std::to_string(nv + 1) + " " + std::to_string(nv + 3) +
         " " + std::to_string(nv + 2) + "\n";
  return s;
}

/// Every colour of `m` is RGBA with alpha 255.
void expect_opaque_rgba(const Mesh &m, const char *what) {
  const VertexAttribute *c = m.find(AttributeKind::Colour);
  ASSERT_NE(c, nullptr) << what;
  ASSERT_EQ(c->components, 4u) << what;
  ASSERT_EQ(c->colour.size(), 4 * m.vertex_count()) << what;
  for (size_t v = 0; v < m.vertex_count(); ++v)
    ASSERT_EQ(c->colour[4 * v + 3], 255) << what << ": vertex " << v;
}

// A PLY with an alpha property gives RGBA colours also when every alpha is 255: on both
// read paths, through the PLY (binary and ASCII) and OFF writers, and through .pomar in
// both layouts at every level. OBJ, which has no alpha, names it.
TEST_F(AttributeFiles, PlyAlphaIsKeptWhenEveryAlphaIs255) {
  const Mesh sphere = gen::noisy_sphere(600, 3, 0.1);
  for (bool quad : {false, true}) {
    SCOPED_TRACE(quad ? "with a quad" : "triangles");
    LoadReport r;
    const Mesh m = load_mesh(write("in.ply", opaque_rgba_ply(sphere, quad)), &r);
    EXPECT_TRUE(r.ignored_attributes.empty()) << joined(r.ignored_attributes);
    EXPECT_EQ(r.polygons_triangulated, quad ? 1u : 0u);
    expect_opaque_rgba(m, "read");
    EXPECT_EQ(m.find(AttributeKind::Colour)->colour[4 * 5], 5 * 7 % 256);
    for (const bool binary : {true, false}) {
      save_mesh(path("out.ply"), m, binary);
      EXPECT_NE(read_text(path("out.ply")).find("property uchar alpha\n"), std::string::npos);
      const Mesh back = load_mesh(path("out.ply"));
      expect_opaque_rgba(back, "PLY written back");
      EXPECT_EQ(back.find(AttributeKind::Colour)->colour, m.find(AttributeKind::Colour)->colour);
    }
    save_mesh(path("out.off"), m);
    EXPECT_TRUE(attributes_not_saved(path("out.off"), m).empty());
    const Mesh off = load_mesh(path("out.off"));
    expect_opaque_rgba(off, "OFF written back");
    EXPECT_EQ(off.find(AttributeKind::Colour)->colour, m.find(AttributeKind::Colour)->colour);
    EXPECT_EQ(joined(attributes_not_saved(path("out.obj"), m)), "the alpha of the colours");
    for (const bool progressive : {true, false}) {
      SCOPED_TRACE(progressive ? "progressive" : "clustered");
      EncodeOptions o;
      o.progressive = progressive;
      o.keep_order = true; // colours compare vertex by vertex
      const std::vector<uint8_t> file = encode(m, o);
      const Mesh full = decode(file.data(), file.size());
      expect_opaque_rgba(full, "full decode");
      EXPECT_EQ(full.find(AttributeKind::Colour)->colour, m.find(AttributeKind::Colour)->colour);
      const FileInfo info = inspect(file.data(), file.size());
      ASSERT_EQ(info.attributes.size(), 1u);
      EXPECT_EQ(info.attributes[0].components, 4u);
      for (int level = 0; level < int(info.levels.size()); ++level)
        expect_opaque_rgba(decode(file.data(), file.size(), level),
                           ("level " + std::to_string(level)).c_str());
    }
  }
}

// Every property of the vertex and face elements that is not kept is named in the warning;
// an unknown vertex scalar is kept by its name.
TEST_F(AttributeFiles, PlyPropertiesNotKeptAreNamed) {
  const std::string file = write(
      "p.ply", "ply\nformat ascii 1.0\nelement vertex 4\n"
               "property float x\nproperty float y\nproperty float z\n"
               "property uchar red\nproperty uchar green\nproperty uchar blue\n"
               "property int flags\nproperty list uchar int neighbours\nproperty float wetness\n"
               "element face 2\nproperty list uchar int vertex_indices\nproperty int material\n"
               "property list uchar float corner_weights\nproperty float quality\nend_header\n"
               "0 0 0 1 2 3 0 1 1 0.5\n1 0 0 1 2 3 0 1 2 0.25\n0 1 0 1 2 3 0 1 3 0.125\n"
               "1 1 0 1 2 3 0 1 0 2\n"
               "3 0 1 2 7 3 1 1 1 0.5\n3 1 3 2 8 3 1 1 1 0.5\n");
  LoadReport r;
  const Mesh m = load_mesh(file, &r);
  EXPECT_EQ(r.ignored_attributes,
            (std::vector<std::string>{"flags", "vertex list property 'neighbours'", "quality",
                                      "face property 'material'",
                                      "face list property 'corner_weights'"}));
  ASSERT_NE(m.find(AttributeKind::Scalar, "wetness"), nullptr);
  EXPECT_EQ(m.find(AttributeKind::Scalar, "wetness")->values,
            (std::vector<float>{0.5f, 0.25f, 0.125f, 2.0f}));
  ASSERT_NE(m.find(AttributeKind::Colour), nullptr);
  EXPECT_EQ(m.find(AttributeKind::Colour)->components, 3u);
}

/// `m` written to `name` in each text format (and binary PLY with attributes): files of
/// several MiB, which the writers hand to the file in 1 MiB chunks.
TEST_F(AttributeFiles, FilesOfManyChunksReadBackExactly) {
  const Mesh plain = gen::noisy_sphere(40000, 5, 0.1);
  const struct {
    const char *name;
    int has;
    bool binary;
  } cases[] = {{"a.ply", kAll, false}, {"b.ply", kAll, true},
               {"p.ply", 0, false},    {"m.off", kColour | kNormals, false},
               {"p.off", 0, false},    {"m.obj", kColour | kNormals | kTexcoords, false},
               {"p.obj", 0, false},    {"p.stl", 0, false}};
  for (const auto &c : cases) {
    const Mesh m = c.has ? with_attributes(plain, c.has) : plain;
    const std::string out = path(c.name);
    save_mesh(out, m, c.binary);
    EXPECT_GT(read_text(out).size(), 2u << 20) << c.name;
    const Mesh back = load_mesh(out);
    if (std::string(c.name) == "p.stl") { // corners welded back, in order of first use
      EXPECT_EQ(back.triangle_count(), m.triangle_count());
      EXPECT_EQ(back.vertex_count(), m.vertex_count());
      continue;
    }
    EXPECT_EQ(back.positions, m.positions) << c.name;
    EXPECT_EQ(back.triangles, m.triangles) << c.name;
    ASSERT_EQ(back.attributes.size(), m.attributes.size()) << c.name;
    for (const VertexAttribute &a : m.attributes) { // the readers' order may differ
      const VertexAttribute *same = nullptr;
      for (const VertexAttribute &r : back.attributes)
        if (r.kind == a.kind && (a.kind != AttributeKind::Scalar || r.name == a.name))
          same = &r;
      ASSERT_NE(same, nullptr) << c.name << " " << a.name;
      EXPECT_EQ(same->colour, a.colour) << c.name << " " << a.name;
      EXPECT_EQ(same->values, a.values) << c.name << " " << a.name;
    }
  }
  for (const std::string &n : list_dir())
    EXPECT_EQ(n.find(".tmp."), std::string::npos) << n;
}

/// A write that fails after some chunks have reached the disk (here: a file size limit of
/// 1.5 MiB, so the second chunk fails) is an I/O error naming the file; the file keeps its
/// old contents and no temporary file is left.
TEST_F(AttributeFiles, WriteFailingAfterSomeChunksKeepsTheOldFile) {
  const Mesh m = with_attributes(gen::noisy_sphere(40000, 5, 0.1), kColour | kNormals);
  struct rlimit old;
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  for (const char *name : {"a.ply", "b.ply", "m.off", "m.obj", "m.stl"}) {
    const std::string out = write(name, "old");
    const bool binary = std::string(name) == "b.ply";
    struct rlimit small = old;
    small.rlim_cur = 3u << 19;
    void (*previous)(int) = std::signal(SIGXFSZ, SIG_IGN); // write() fails with EFBIG instead
    ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
    std::string message;
    Error::Kind kind = Error::Kind::Internal;
    std::string where;
    try {
      save_mesh(out, m, binary);
    } catch (const Error &e) {
      message = e.what(), kind = e.kind(), where = e.path();
    }
    ::setrlimit(RLIMIT_FSIZE, &old);
    std::signal(SIGXFSZ, previous);
    EXPECT_EQ(kind, Error::Kind::Io) << name << ": " << message;
    EXPECT_EQ(where, out) << message;
    EXPECT_NE(message.find("cannot write"), std::string::npos) << message;
    EXPECT_EQ(read_text(out), "old") << name;
  }
  for (const std::string &n : list_dir())
    EXPECT_EQ(n.find(".tmp."), std::string::npos) << n;
}

} // namespace
} // namespace pomar
