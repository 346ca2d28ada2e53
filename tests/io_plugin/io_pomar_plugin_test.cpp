// In-process tests of the MeshLab IO plugin libio_pomar.so: loads it with QPluginLoader as
// MeshLab's PluginManager does and drives open()/save() with the parameters MeshLab would
// pass, including the pre-open choices meshlabserver cannot reach ("Base clustered mesh",
// "Global level N"), the per-vertex/per-mesh attributes and the save parameters.
// No X display needed: nothing here touches OpenGL or widgets.
#include <gtest/gtest.h>

#include <array>
#include <map>

#include <QCoreApplication>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QPluginLoader>
#include <QStringList>
#include <QTemporaryDir>

#include <common/interfaces.h>
#include <common/meshmodel.h>

#include <pomar/pomar.h>
#include <pomar/random_access.h>
#include <pomar/vcg_adapter.h>

#include <vcg/complex/algorithms/update/normal.h>

#include "support/mesh_attributes.h"
#include "support/mesh_gen.h"

#include "support/mesh_compare.h"
#include "support/meshlab_layer.h"
#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace {

// ---------------------------------------------------------------- helpers

QStringList g_warnings; // qWarning() lines of the plugin

void captureMessages(QtMsgType type, const QMessageLogContext &, const QString &text) {
  if (type == QtWarningMsg)
    g_warnings << text;
  std::fprintf(stderr, "%s\n", qUtf8Printable(text));
}

MeshIOInterface *plugin() {
  static QPluginLoader loader(QStringLiteral(POMAR_IO_PLUGIN));
  static MeshIOInterface *io = qobject_cast<MeshIOInterface *>(loader.instance());
  if (io == nullptr)
    ADD_FAILURE() << "cannot load " << POMAR_IO_PLUGIN << ": "
                  << loader.errorString().toStdString();
  return io;
}

using Tri = pomar::test::PositionTriangle;
using pomar::test::canonical;

std::vector<uint8_t> readBytes(const QString &path) {
  QFile f(path);
  if (!f.open(QIODevice::ReadOnly))
    return {};
  const QByteArray b = f.readAll();
  return std::vector<uint8_t>(b.begin(), b.end());
}

void writeBytes(const QString &path, const std::vector<uint8_t> &bytes) {
  std::ofstream out(QFile::encodeName(path).toStdString(), std::ios::binary);
  out.write(reinterpret_cast<const char *>(bytes.data()), std::streamsize(bytes.size()));
}

using pomar::test::sourceAttribute;
using pomar::test::vertexAttribute;

class PomarPluginTest : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir_ = new QTemporaryDir();
    input_ = new pomar::Mesh(pomar::gen::noisy_sphere(3000, 7));
    clustered_ = new std::vector<uint8_t>(pomar::encode(*input_));
    pomar::EncodeOptions progressive;
    progressive.progressive = true;
    progressive_ = new std::vector<uint8_t>(pomar::encode(*input_, progressive));
    writeBytes(path("clustered.pomar"), *clustered_);
    writeBytes(path("progressive.pomar"), *progressive_);
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete input_;
    delete clustered_;
    delete progressive_;
  }
  void SetUp() override {
    ASSERT_NE(plugin(), nullptr);
    ASSERT_TRUE(dir_->isValid());
    g_warnings.clear();
    plugin()->clearErrorString();
  }

  void TearDown() override {
    // vcglib 2020.09's ~TriMesh() does not free named attributes (MeshLab leaks them too).
    for (MeshModel *mm : doc_.meshList)
      mm->cm.ClearAttributes();
  }

  static QString path(const QString &name) { return dir_->filePath(name); }

  /// Open like MeshLab: initPreOpenParameter, then the dialog's choices, then open().
  bool openAt(const QString &fileName, int choice, int level = 0, bool skipDamaged = false) {
    mm_ = doc_.addNewMesh(fileName, "test", true);
    RichParameterList par;
    plugin()->initPreOpenParameter("pomar", fileName, par);
    if (choice >= 0)
      par.setValue("OpenAt", EnumValue(choice));
    par.setValue("Level", IntValue(level));
    par.setValue("SkipDamaged", BoolValue(skipDamaged));
    int mask = -1;
    const bool ok = plugin()->open("pomar", fileName, *mm_, mask, par);
    EXPECT_EQ(mask, 0);
    return ok;
  }

  /// A layer holding `mesh`, prepared as MeshLab does after loading it.
  MeshModel *layer(const pomar::Mesh &mesh) {
    MeshModel *mm = doc_.addNewMesh("", "input", true);
    pomar::to_vcg(mesh, mm->cm);
    mm->UpdateBoxAndNormals();
    return mm;
  }

  /// Save with the defaults of initSaveParameter, changed by `edit`.
  template <class Edit>
  bool save(MeshModel &mm, const QString &fileName, Edit edit, int mask = 0) {
    RichParameterList par;
    plugin()->initSaveParameter("pomar", mm, par);
    edit(par);
    return plugin()->save("pomar", fileName, mm, mask, par);
  }
  bool save(MeshModel &mm, const QString &fileName) {
    return save(mm, fileName, [](RichParameterList &) {});
  }

  QStringList dirEntries() const {
    return QDir(dir_->path()).entryList(QDir::Files | QDir::Hidden | QDir::NoDotAndDotDot);
  }

  static QTemporaryDir *dir_;
  static pomar::Mesh *input_;
  static std::vector<uint8_t> *clustered_, *progressive_;
  MeshDocument doc_;
  MeshModel *mm_ = nullptr;
};

QTemporaryDir *PomarPluginTest::dir_ = nullptr;
pomar::Mesh *PomarPluginTest::input_ = nullptr;
std::vector<uint8_t> *PomarPluginTest::clustered_ = nullptr;
std::vector<uint8_t> *PomarPluginTest::progressive_ = nullptr;

pomar::FileInfo infoOf(const std::vector<uint8_t> &file) {
  return pomar::inspect(file.data(), file.size());
}

uint32_t verticesAtLevel(const pomar::FileInfo &info, int level) {
  return level == 0 ? info.base_vertices : info.levels[size_t(level) - 1].vertices;
}

// ---------------------------------------------------------------- declarations

TEST_F(PomarPluginTest, FormatsAndCapabilities) {
  for (const auto &list : {plugin()->importFormats(), plugin()->exportFormats()}) {
    ASSERT_EQ(list.size(), 1);
    EXPECT_EQ(list[0].description, "POMAR progressive mesh");
    EXPECT_EQ(list[0].extensions, QStringList{"pomar"});
  }
  QString format = "pomar";
  int capability = -1, defaultBits = -1;
  plugin()->GetExportMaskCapability(format, capability, defaultBits);
  using M = vcg::tri::io::Mask;
  EXPECT_EQ(capability, M::IOM_VERTCOLOR | M::IOM_VERTNORMAL | M::IOM_VERTQUALITY |
                            M::IOM_VERTTEXCOORD | M::IOM_WEDGTEXCOORD);
  EXPECT_EQ(defaultBits,
            M::IOM_VERTCOLOR | M::IOM_VERTQUALITY | M::IOM_VERTTEXCOORD | M::IOM_WEDGTEXCOORD);
}

TEST_F(PomarPluginTest, ParameterDefaults) {
  RichParameterList pre;
  plugin()->initPreOpenParameter("pomar", "x.pomar", pre);
  ASSERT_TRUE(pre.hasParameter("OpenAt"));
  ASSERT_TRUE(pre.hasParameter("Level"));
  EXPECT_EQ(pre.getEnum("OpenAt"), 0); // full resolution
  EXPECT_EQ(pre.getInt("Level"), 0);
  EXPECT_FALSE(pre.getBool("SkipDamaged"));

  MeshModel *mm = doc_.addNewMesh("", "empty", true);
  RichParameterList save;
  plugin()->initSaveParameter("pomar", *mm, save);
  const pomar::EncodeOptions defaults;
  EXPECT_EQ(save.getInt("Bits"), defaults.bits);
  EXPECT_FLOAT_EQ(save.getFloat("ClusterRatio"), float(defaults.cluster_ratio));
  EXPECT_EQ(save.getBool("Progressive"), false);
  EXPECT_EQ(save.getBool("Repair"), false); // repairing is opt-in

  RichParameterList other;
  plugin()->initPreOpenParameter("ply", "x.ply", other);
  plugin()->initSaveParameter("ply", *mm, other);
  EXPECT_TRUE(other.isEmpty());
}

// ---------------------------------------------------------------- open

TEST_F(PomarPluginTest, OpenFullResolutionIsLossless) {
  ASSERT_TRUE(openAt(path("clustered.pomar"), -1)) << plugin()->errorMsg().toStdString();
  const pomar::Mesh got = pomar::from_vcg(mm_->cm);
  EXPECT_EQ(canonical(got), canonical(pomar::decode(clustered_->data(), clustered_->size())));

  const pomar::FileInfo info = infoOf(*clustered_);
  ASSERT_TRUE(info.clustered());
  const std::vector<float> cluster = vertexAttribute(mm_->cm, "pomar_cluster");
  const std::vector<float> level = vertexAttribute(mm_->cm, "pomar_level");
  ASSERT_EQ(cluster.size(), got.vertex_count());
  ASSERT_EQ(level.size(), got.vertex_count());
  std::set<float> clusters(cluster.begin(), cluster.end());
  EXPECT_EQ(clusters.size(), info.clusters); // every cluster keeps at least its root
  EXPECT_EQ(*clusters.begin(), 0.0f);
  EXPECT_EQ(*clusters.rbegin(), float(info.clusters - 1));
  EXPECT_EQ(*std::min_element(level.begin(), level.end()), 0.0f);
  EXPECT_EQ(*std::max_element(level.begin(), level.end()), float(info.levels.size()));
  EXPECT_EQ(sourceAttribute(mm_->cm), QFile::encodeName(path("clustered.pomar")).toStdString());
}

TEST_F(PomarPluginTest, OpenBaseClusteredMesh) {
  ASSERT_TRUE(openAt(path("clustered.pomar"), 1)) << plugin()->errorMsg().toStdString();
  const pomar::FileInfo info = infoOf(*clustered_);
  EXPECT_EQ(uint32_t(mm_->cm.vn), info.clusters);
  const std::vector<float> cluster = vertexAttribute(mm_->cm, "pomar_cluster");
  const std::vector<float> level = vertexAttribute(mm_->cm, "pomar_level");
  EXPECT_EQ(std::set<float>(cluster.begin(), cluster.end()).size(), info.clusters);
  EXPECT_LE(*std::max_element(level.begin(), level.end()), float(info.global_levels));
}

TEST_F(PomarPluginTest, OpenGlobalLevels) {
  const pomar::FileInfo info = infoOf(*clustered_);
  const int base = int(info.global_levels), finest = int(info.levels.size());
  ASSERT_GT(base, 1);
  ASSERT_GT(finest, base + 1);
  for (int n : {0, base / 2, base, base + 1, finest}) {
    SCOPED_TRACE("level " + std::to_string(n));
    ASSERT_TRUE(openAt(path("clustered.pomar"), 2, n)) << plugin()->errorMsg().toStdString();
    EXPECT_EQ(uint32_t(mm_->cm.vn), verticesAtLevel(info, n));
    EXPECT_EQ(canonical(pomar::from_vcg(mm_->cm)),
              canonical(pomar::decode(clustered_->data(), clustered_->size(), n)));
    const std::vector<float> cluster = vertexAttribute(mm_->cm, "pomar_cluster");
    const std::vector<float> level = vertexAttribute(mm_->cm, "pomar_level");
    ASSERT_EQ(level.size(), size_t(mm_->cm.vn));
    if (n < base) { // decoded by pomar::decode: no per-vertex levels or clusters
      EXPECT_EQ(*std::max_element(cluster.begin(), cluster.end()), -1.0f);
      EXPECT_EQ(*std::max_element(level.begin(), level.end()), -1.0f);
    } else {
      EXPECT_GE(*std::min_element(cluster.begin(), cluster.end()), 0.0f);
      EXPECT_EQ(*std::max_element(level.begin(), level.end()), float(n));
    }
    EXPECT_EQ(sourceAttribute(mm_->cm), QFile::encodeName(path("clustered.pomar")).toStdString());
  }
}

TEST_F(PomarPluginTest, OpenProgressiveFile) {
  const pomar::FileInfo info = infoOf(*progressive_);
  ASSERT_FALSE(info.clustered());
  const int finest = int(info.levels.size());
  ASSERT_GT(finest, 3);
  for (int n : {0, 3, finest}) {
    SCOPED_TRACE("level " + std::to_string(n));
    ASSERT_TRUE(openAt(path("progressive.pomar"), 2, n)) << plugin()->errorMsg().toStdString();
    EXPECT_EQ(uint32_t(mm_->cm.vn), verticesAtLevel(info, n));
    EXPECT_EQ(canonical(pomar::from_vcg(mm_->cm)),
              canonical(pomar::decode(progressive_->data(), progressive_->size(), n)));
    const std::vector<float> cluster = vertexAttribute(mm_->cm, "pomar_cluster");
    const std::vector<float> level = vertexAttribute(mm_->cm, "pomar_level");
    EXPECT_EQ(std::set<float>(cluster.begin(), cluster.end()), std::set<float>{-1.0f});
    EXPECT_EQ(*std::max_element(level.begin(), level.end()), float(n));
  }
  // Full resolution (the default) and "base clustered" (= the base mesh: no clusters).
  ASSERT_TRUE(openAt(path("progressive.pomar"), 0));
  EXPECT_EQ(uint32_t(mm_->cm.vn), info.vertices);
  ASSERT_TRUE(openAt(path("progressive.pomar"), 1));
  EXPECT_EQ(uint32_t(mm_->cm.vn), info.base_vertices);
}

TEST_F(PomarPluginTest, BareFileNameIsResolvedAgainstTheWorkingDirectory) {
  const QString old = QDir::currentPath();
  ASSERT_TRUE(QDir::setCurrent(dir_->path())); // what the GUI does before open()
  const bool ok = openAt("clustered.pomar", 0);
  QDir::setCurrent(old);
  ASSERT_TRUE(ok) << plugin()->errorMsg().toStdString();
  EXPECT_EQ(sourceAttribute(mm_->cm), QFile::encodeName(path("clustered.pomar")).toStdString());
}

TEST_F(PomarPluginTest, OpenErrors) {
  const int finest = int(infoOf(*clustered_).levels.size());
  EXPECT_FALSE(openAt(path("clustered.pomar"), 2, finest + 1));
  EXPECT_TRUE(plugin()->errorMsg().contains("does not exist"))
      << plugin()->errorMsg().toStdString();
  EXPECT_EQ(mm_->cm.vn, 0);
  EXPECT_FALSE(openAt(path("clustered.pomar"), 2, -1));
  EXPECT_TRUE(plugin()->errorMsg().contains("does not exist"));

  EXPECT_FALSE(openAt(path("missing.pomar"), 0));
  EXPECT_TRUE(plugin()->errorMsg().contains("missing.pomar")) << plugin()->errorMsg().toStdString();

  std::vector<uint8_t> cut(clustered_->begin(), clustered_->begin() + clustered_->size() / 2);
  writeBytes(path("cut.pomar"), cut);
  EXPECT_FALSE(openAt(path("cut.pomar"), 0));
  EXPECT_TRUE(plugin()->errorMsg().contains("truncated")) << plugin()->errorMsg().toStdString();
  EXPECT_EQ(mm_->cm.vn, 0);
  EXPECT_FALSE(g_warnings.isEmpty()); // also on stderr: meshlabserver does not print errorMsg()

  // With "Skip damaged blocks" the half that arrived opens, coarser where blocks are missing.
  g_warnings.clear();
  ASSERT_TRUE(openAt(path("cut.pomar"), 0, 0, true)) << plugin()->errorMsg().toStdString();
  EXPECT_GT(mm_->cm.vn, 0);
  EXPECT_LT(size_t(mm_->cm.vn), size_t(infoOf(*clustered_).vertices));
  EXPECT_TRUE(g_warnings.join("\n").contains("damaged block"))
      << g_warnings.join("\n").toStdString();
  pomar::DecodeOptions o;
  o.skip_damaged = true;
  const pomar::Mesh expected = pomar::decode(cut.data(), cut.size(), o);
  EXPECT_EQ(size_t(mm_->cm.vn), expected.vertex_count());
  EXPECT_EQ(size_t(mm_->cm.fn), expected.triangle_count());
  QFile::remove(path("cut.pomar"));
}

// The warning names the file as it is, whatever it holds: "%1" and "%2" in a path are no
// places for arguments.
TEST_F(PomarPluginTest, DamageWarningKeepsThePathAsItIs) {
  std::vector<uint8_t> cut(clustered_->begin(), clustered_->begin() + clustered_->size() / 2);
  const QString name = path("cut %2 %1 %3.pomar");
  writeBytes(name, cut);
  g_warnings.clear();
  ASSERT_TRUE(openAt(name, 0, 0, true)) << plugin()->errorMsg().toStdString();
  pomar::DecodeOptions o;
  o.skip_damaged = true;
  pomar::DecodeReport report;
  pomar::decode(cut.data(), cut.size(), o, &report);
  ASSERT_FALSE(report.damaged.empty());
  const QString expected = QFileInfo(name).absoluteFilePath() + ": " +
                           QString::number(report.damaged.size()) + " damaged block(s) skipped";
  EXPECT_TRUE(g_warnings.join("\n").contains(expected))
      << "expected: " << expected.toStdString() << "\ngot: " << g_warnings.join("\n").toStdString();
  QFile::remove(name);
}

// ---------------------------------------------------------------- save

TEST_F(PomarPluginTest, SaveWithDefaultsEqualsTheLibrary) {
  MeshModel *mm = layer(*input_);
  ASSERT_TRUE(save(*mm, path("saved.pomar"))) << plugin()->errorMsg().toStdString();
  EXPECT_EQ(readBytes(path("saved.pomar")), *clustered_);
  EXPECT_TRUE(g_warnings.isEmpty()) << g_warnings.join("\n").toStdString();
  QFile::remove(path("saved.pomar"));
}

TEST_F(PomarPluginTest, SaveParameters) {
  MeshModel *mm = layer(*input_);
  ASSERT_TRUE(save(*mm, path("p.pomar"), [](RichParameterList &par) {
    par.setValue("Bits", IntValue(10));
    par.setValue("Progressive", BoolValue(true));
  })) << plugin()->errorMsg().toStdString();
  pomar::EncodeOptions o;
  o.bits = 10;
  o.progressive = true;
  EXPECT_EQ(readBytes(path("p.pomar")), pomar::encode(*input_, o));
  EXPECT_EQ(infoOf(readBytes(path("p.pomar"))).bits, 10);
  EXPECT_FALSE(infoOf(readBytes(path("p.pomar"))).clustered());

  ASSERT_TRUE(save(*mm, path("p.pomar"), [](RichParameterList &par) {
    par.setValue("ClusterRatio", FloatValue(0.05f));
  })); // replaces the existing file
  pomar::EncodeOptions c;
  c.cluster_ratio = 0.05f;
  EXPECT_EQ(readBytes(path("p.pomar")), pomar::encode(*input_, c));
  EXPECT_GT(infoOf(readBytes(path("p.pomar"))).clusters, infoOf(*clustered_).clusters);
  QFile::remove(path("p.pomar"));
}

TEST_F(PomarPluginTest, SaveSkipsDeletedElements) {
  MeshModel *mm = layer(*input_);
  vcg::tri::Allocator<CMeshO>::DeleteFace(mm->cm, mm->cm.face[10]);
  ASSERT_TRUE(save(*mm, path("d.pomar"))) << plugin()->errorMsg().toStdString();
  const std::vector<uint8_t> file = readBytes(path("d.pomar"));
  EXPECT_EQ(infoOf(file).faces, input_->triangle_count() - 1);
  QFile::remove(path("d.pomar"));
}

TEST_F(PomarPluginTest, SaveWarnsAboutWhatIsNotKept) {
  MeshModel *mm = layer(*input_);
  mm->updateDataMask(MeshModel::MM_VERTCOLOR);
  for (auto &v : mm->cm.vert)
    v.C() = vcg::Color4b::White;
  mm->cm.vert[5].C() = vcg::Color4b::Red;
  vcg::tri::Allocator<CMeshO>::GetPerVertexAttribute<int>(mm->cm, "my_label");
  ASSERT_TRUE(save(*mm, path("w.pomar"))) << plugin()->errorMsg().toStdString(); // mask 0
  const QString all = g_warnings.join("\n");
  EXPECT_TRUE(all.contains("per-vertex colors (tick Color")) << all.toStdString();
  EXPECT_TRUE(all.contains("my_label")) << all.toStdString(); // not a float: not kept
  EXPECT_FALSE(all.contains("per-vertex normals")) << all.toStdString(); // MeshLab's own
  EXPECT_EQ(readBytes(path("w.pomar")), *clustered_);         // and the file is the same

  // Normals that are not MeshLab's angle-weighted ones are named too.
  g_warnings.clear();
  for (auto &v : mm->cm.vert)
    v.N() = vcg::Point3f(0, 0, 1);
  ASSERT_TRUE(save(*mm, path("w.pomar")));
  EXPECT_TRUE(g_warnings.join("\n").contains("per-vertex normals"));
  QFile::remove(path("w.pomar"));
}

// Save with the mask of the save dialog / meshlabserver -m, open again: the attributes come
// back exactly (colour, float attribute) or within their bound (quality), and the open mask
// tells MeshLab to show the colours.
TEST_F(PomarPluginTest, SaveAndOpenKeepAttributes) {
  using M = vcg::tri::io::Mask;
  MeshModel *mm = layer(*input_);
  mm->updateDataMask(MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY);
  auto weight = vcg::tri::Allocator<CMeshO>::GetPerVertexAttribute<float>(mm->cm, "my_weight");
  for (size_t v = 0; v < mm->cm.vert.size(); ++v) {
    mm->cm.vert[v].C() = vcg::Color4b((v * 7) & 255, (v * 13) & 255, (v * 29) & 255, 255);
    mm->cm.vert[v].Q() = float(v) * 0.25f;
    weight[v] = 1.0f / float(v + 1);
  }
  ASSERT_TRUE(save(*mm, path("a.pomar"), [](RichParameterList &) {},
                   M::IOM_VERTCOLOR | M::IOM_VERTQUALITY))
      << plugin()->errorMsg().toStdString();
  EXPECT_FALSE(g_warnings.join("\n").contains("colors")) << g_warnings.join("\n").toStdString();
  const pomar::FileInfo info = infoOf(readBytes(path("a.pomar")));
  ASSERT_EQ(info.attributes.size(), 3u);

  MeshModel *back = doc_.addNewMesh("", "back", false);
  int mask = 0;
  RichParameterList par;
  plugin()->initPreOpenParameter("pomar", path("a.pomar"), par);
  ASSERT_TRUE(plugin()->open("pomar", path("a.pomar"), *back, mask, par, nullptr, nullptr))
      << plugin()->errorMsg().toStdString();
  EXPECT_TRUE(mask & M::IOM_VERTCOLOR);
  EXPECT_TRUE(mask & M::IOM_VERTQUALITY);
  // Match vertices by position on the file's grid (the file renumbers them).
  std::map<std::array<float, 3>, size_t> at;
  auto snap = [&](int axis, float x) {
    return info.grid.dequantize(axis, info.grid.quantize(axis, x));
  };
  for (size_t v = 0; v < mm->cm.vert.size(); ++v) {
    const auto &p = mm->cm.vert[v].P();
    at[{snap(0, p[0]), snap(1, p[1]), snap(2, p[2])}] = v;
  }
  auto backWeight = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(back->cm, "my_weight");
  ASSERT_TRUE(vcg::tri::Allocator<CMeshO>::IsValidHandle(back->cm, backWeight));
  const double qBound = info.attributes[1].bound;
  size_t matched = 0;
  for (size_t v = 0; v < back->cm.vert.size(); ++v) {
    const auto &p = back->cm.vert[v].P();
    const auto it = at.find({p[0], p[1], p[2]});
    ASSERT_NE(it, at.end());
    ++matched;
    EXPECT_EQ(back->cm.vert[v].C(), mm->cm.vert[it->second].C());
    EXPECT_NEAR(back->cm.vert[v].Q(), mm->cm.vert[it->second].Q(), qBound);
    EXPECT_NEAR(backWeight[v], weight[it->second], info.attributes[2].bound);
  }
  EXPECT_GT(matched, 0u);

  // Without the Color tick the colours are not saved, and the warning says how to keep them.
  g_warnings.clear();
  ASSERT_TRUE(save(*mm, path("a.pomar"), [](RichParameterList &) {}, M::IOM_VERTQUALITY));
  EXPECT_TRUE(g_warnings.join("\n").contains("per-vertex colors (tick Color"));
  EXPECT_EQ(infoOf(readBytes(path("a.pomar"))).attributes.size(), 2u);
  QFile::remove(path("a.pomar"));
}

// MeshLab's GUI renders a layer from its data mask (MeshModel::hasDataMask), not from the
// mask open() returns: each attribute read (and only those) is enabled on the layer, as
// MeshModel::Enable does for the stock readers.
TEST_F(PomarPluginTest, OpenEnablesWhatItReadsOnTheLayer) {
  using M = vcg::tri::io::Mask;
  const int kKept = M::IOM_VERTCOLOR | M::IOM_VERTNORMAL | M::IOM_VERTQUALITY | M::IOM_VERTTEXCOORD;
  struct Case {
    int has;      ///< pomar::with_attributes's
    int mask;     ///< the mask open() returns
    int dataMask; ///< the optional data enabled on the layer (MeshModel::MM_*)
  };
  using MM = MeshModel;
  for (const Case &c :
       {Case{pomar::kColour, M::IOM_VERTCOLOR, MM::MM_VERTCOLOR},
        Case{pomar::kColour | pomar::kAlpha | pomar::kNormals, M::IOM_VERTCOLOR | M::IOM_VERTNORMAL,
             MM::MM_VERTCOLOR},
        Case{pomar::kScalars, M::IOM_VERTQUALITY, MM::MM_VERTQUALITY},
        Case{pomar::kTexcoords, M::IOM_VERTTEXCOORD, MM::MM_VERTTEXCOORD},
        Case{pomar::kAll, kKept, MM::MM_VERTCOLOR | MM::MM_VERTQUALITY | MM::MM_VERTTEXCOORD},
        Case{0, 0, 0}}) {
    SCOPED_TRACE(c.has);
    const pomar::Mesh mesh = pomar::with_attributes(pomar::gen::noisy_sphere(400, 3), c.has);
    const std::vector<uint8_t> bytes = pomar::encode(mesh);
    {
      std::ofstream out(QFile::encodeName(path("attrs.pomar")).toStdString(), std::ios::binary);
      out.write(reinterpret_cast<const char *>(bytes.data()), std::streamsize(bytes.size()));
    }
    MeshModel *mm = doc_.addNewMesh(path("attrs.pomar"), "attrs", true);
    ASSERT_FALSE(mm->hasDataMask(MM::MM_VERTCOLOR)); // a new layer: only what is always on
    RichParameterList par;
    plugin()->initPreOpenParameter("pomar", path("attrs.pomar"), par);
    int mask = 0;
    ASSERT_TRUE(plugin()->open("pomar", path("attrs.pomar"), *mm, mask, par))
        << plugin()->errorMsg().toStdString();
    EXPECT_EQ(mask, c.mask);
    for (int bit : {MM::MM_VERTCOLOR, MM::MM_VERTQUALITY, MM::MM_VERTTEXCOORD})
      EXPECT_EQ(mm->hasDataMask(bit), bool(c.dataMask & bit)) << "MeshModel data bit " << bit;
    EXPECT_TRUE(mm->hasDataMask(MM::MM_VERTNORMAL)); // always on in MeshLab
    EXPECT_EQ(bool(c.dataMask & MM::MM_VERTTEXCOORD), vcg::tri::HasPerVertexTexCoord(mm->cm));
    mm->cm.ClearAttributes();
    doc_.delMesh(mm);
  }
  QFile::remove(path("attrs.pomar"));
}

/// A sphere with per-corner texture coordinates and two textures, a chart per half: a seam
/// around the equator.
pomar::Mesh texturedSphere() {
  pomar::Mesh mesh = pomar::gen::noisy_sphere(400, 3);
  const size_t nf = mesh.triangle_count();
  mesh.texture_files = {"a.png", "b.png"};
  mesh.materials = {{"a", 0, "Kd 1 1 1\n"}, {"b", 1, ""}};
  for (size_t f = 0; f < nf; ++f) {
    const float *p0 = &mesh.positions[3 * mesh.triangles[3 * f]];
    const bool top = p0[2] >= 0;
    mesh.face_materials.push_back(top ? 0 : 1);
    for (int k = 0; k < 3; ++k) {
      const float *p = &mesh.positions[3 * mesh.triangles[3 * f + size_t(k)]];
      mesh.corner_texcoords.push_back(0.25f * p[0] + (top ? 0.25f : 0.75f));
      mesh.corner_texcoords.push_back(0.25f * p[1] + 0.5f);
    }
  }
  return mesh;
}

/// The faces of a layer as their wedge texture coordinates, starting at the smallest, and
/// texture index, as a multiset (a full decode gives the faces back as a multiset; positions
/// are quantized).
std::multiset<std::array<float, 7>> wedgeFaces(const CMeshO &m) {
  std::multiset<std::array<float, 7>> out;
  for (const CFaceO &f : m.face) {
    if (f.IsD())
      continue;
    std::array<std::pair<float, float>, 3> c;
    for (int k = 0; k < 3; ++k)
      c[size_t(k)] = {f.cWT(k).U(), f.cWT(k).V()};
    const size_t first = size_t(std::min_element(c.begin(), c.end()) - c.begin());
    std::array<float, 7> row{};
    for (size_t k = 0; k < 3; ++k) {
      row[2 * k] = c[(first + k) % 3].first;
      row[2 * k + 1] = c[(first + k) % 3].second;
    }
    row[6] = f.cWT(0).N();
    out.insert(row);
  }
  return out;
}

// A textured file (per-corner texture coordinates, two materials): open enables the wedge
// texture coordinates on the layer, fills them with the corners' values and the face's
// texture, and returns IOM_WEDGTEXCOORD.
TEST_F(PomarPluginTest, OpenTexturedFileFillsTheWedges) {
  const pomar::Mesh mesh = texturedSphere();
  pomar::EncodeOptions exact;
  exact.attributes.exact = true;
  exact.keep_order = true;
  pomar::EncodeReport report;
  const std::vector<uint8_t> bytes = pomar::encode(mesh, exact, &report);
  {
    std::ofstream out(QFile::encodeName(path("tex.pomar")).toStdString(), std::ios::binary);
    out.write(reinterpret_cast<const char *>(bytes.data()), std::streamsize(bytes.size()));
  }
  MeshModel *mm = doc_.addNewMesh(path("tex.pomar"), "tex", true);
  ASSERT_FALSE(mm->hasDataMask(MeshModel::MM_WEDGTEXCOORD));
  RichParameterList par;
  plugin()->initPreOpenParameter("pomar", path("tex.pomar"), par);
  int mask = 0;
  ASSERT_TRUE(plugin()->open("pomar", path("tex.pomar"), *mm, mask, par))
      << plugin()->errorMsg().toStdString();
  EXPECT_TRUE(mask & vcg::tri::io::Mask::IOM_WEDGTEXCOORD);
  EXPECT_TRUE(mm->hasDataMask(MeshModel::MM_WEDGTEXCOORD));
  EXPECT_EQ(mm->cm.textures, mesh.texture_files);
  const pomar::Mesh decoded = pomar::decode(bytes.data(), bytes.size());
  ASSERT_EQ(size_t(mm->cm.fn), decoded.triangle_count());
  for (size_t f = 0; f < decoded.triangle_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(mm->cm.face[f].WT(k).U(), decoded.corner_texcoords[6 * f + 2 * size_t(k)]);
      ASSERT_EQ(mm->cm.face[f].WT(k).V(), decoded.corner_texcoords[6 * f + 2 * size_t(k) + 1]);
      ASSERT_EQ(mm->cm.face[f].WT(k).N(), decoded.materials[decoded.face_materials[f]].texture);
    }
  mm->cm.ClearAttributes();
  doc_.delMesh(mm);
  QFile::remove(path("tex.pomar"));
}

// A layer with wedge texture coordinates (an OBJ in MeshLab) saved with TexCoord ticked under
// Wedge (meshlabserver -m wt): the file keeps them, each face's texture and the texture names,
// and opening it gives the layer back. Without the tick the warning names them.
TEST_F(PomarPluginTest, SaveKeepsWedgeTexcoordsAndTextures) {
  using M = vcg::tri::io::Mask;
  const pomar::Mesh mesh = texturedSphere();
  MeshModel *mm = doc_.addNewMesh("", "tex", true);
  mm->updateDataMask(MeshModel::MM_WEDGTEXCOORD);
  ASSERT_EQ(pomar::to_vcg(mesh, mm->cm) & M::IOM_WEDGTEXCOORD, M::IOM_WEDGTEXCOORD);
  mm->UpdateBoxAndNormals();
  g_warnings.clear();
  ASSERT_TRUE(save(
      *mm, path("w.pomar"),
      [](RichParameterList &par) { par.setValue("ExactAttributes", BoolValue(true)); },
      M::IOM_WEDGTEXCOORD))
      << plugin()->errorMsg().toStdString();
  EXPECT_TRUE(g_warnings.isEmpty()) << g_warnings.join("\n").toStdString();
  const std::vector<uint8_t> bytes = readBytes(path("w.pomar"));
  const pomar::Mesh decoded = pomar::decode(bytes.data(), bytes.size());
  EXPECT_EQ(decoded.corner_texcoords.size(), 6 * mesh.triangle_count());
  EXPECT_EQ(decoded.face_materials.size(), mesh.triangle_count());
  EXPECT_EQ(decoded.texture_files, mesh.texture_files);
  ASSERT_EQ(decoded.materials.size(), 2u);
  EXPECT_EQ(decoded.materials[0].texture, 0);
  EXPECT_EQ(decoded.materials[1].texture, 1);

  MeshModel *back = doc_.addNewMesh(path("w.pomar"), "back", true);
  RichParameterList pre;
  plugin()->initPreOpenParameter("pomar", path("w.pomar"), pre);
  int mask = 0;
  ASSERT_TRUE(plugin()->open("pomar", path("w.pomar"), *back, mask, pre));
  EXPECT_EQ(mask, M::IOM_WEDGTEXCOORD);
  EXPECT_EQ(back->cm.textures, mesh.texture_files);
  EXPECT_TRUE(wedgeFaces(back->cm) == wedgeFaces(mm->cm));

  // Not ticked: not in the file, and the warning says how to keep them.
  g_warnings.clear();
  ASSERT_TRUE(save(
      *mm, path("w.pomar"), [](RichParameterList &) {}, 0));
  const QString all = g_warnings.join("\n");
  EXPECT_TRUE(all.contains("per-wedge texture coordinates (tick TexCoord under Wedge / -m wt)"))
      << all.toStdString();
  EXPECT_TRUE(all.contains("2 texture(s)")) << all.toStdString();
  const std::vector<uint8_t> plain = readBytes(path("w.pomar"));
  EXPECT_TRUE(pomar::decode(plain.data(), plain.size()).corner_texcoords.empty());
  QFile::remove(path("w.pomar"));
}

TEST_F(PomarPluginTest, FailedSaveWritesNothing) {
  const QStringList before = dirEntries();
  pomar::Mesh degenerate = pomar::gen::tetrahedron(); // nothing but faces repeating a vertex
  degenerate.triangles = {0, 0, 1, 2, 3, 3};
  MeshModel *mm = layer(degenerate);
  EXPECT_FALSE(save(*mm, path("bad.pomar")));
  EXPECT_TRUE(plugin()->errorMsg().contains("no valid triangle"))
      << plugin()->errorMsg().toStdString();
  EXPECT_TRUE(g_warnings.join("\n").contains("no valid triangle"));
  EXPECT_EQ(dirEntries(), before);

  // An existing destination is left untouched.
  EXPECT_FALSE(save(*mm, path("clustered.pomar")));
  EXPECT_EQ(readBytes(path("clustered.pomar")), *clustered_);
  EXPECT_EQ(dirEntries(), before);

  // An unwritable destination: the codec succeeds, the write fails.
  MeshModel *good = layer(*input_);
  EXPECT_FALSE(save(*good, path("no_such_dir/x.pomar")));
  EXPECT_TRUE(plugin()->errorMsg().contains("no_such_dir")) << plugin()->errorMsg().toStdString();
  EXPECT_EQ(dirEntries(), before);

  // Invalid parameters are the codec's errors.
  EXPECT_FALSE(save(*good, path("bits.pomar"),
                    [](RichParameterList &par) { par.setValue("Bits", IntValue(30)); }));
  EXPECT_FALSE(plugin()->errorMsg().isEmpty());
  EXPECT_EQ(dirEntries(), before);
}

TEST_F(PomarPluginTest, AnyMeshSavesExactlyAndOpensAsItWas) {
  pomar::Mesh messy = pomar::gen::nonmanifold_edge(); // three faces on edge (0, 1)
  messy.triangles.insert(messy.triangles.end(), {0, 1, 2, 0, 1, 2, 3, 3, 4}); // + duplicate, degenerate
  messy.positions.insert(messy.positions.end(), {7.f, 7.f, 7.f}); // + an unreferenced vertex
  MeshModel *mm = layer(messy);
  ASSERT_TRUE(save(*mm, path("messy.pomar"))) << plugin()->errorMsg().toStdString();
  const std::vector<uint8_t> bytes = readBytes(path("messy.pomar"));
  const pomar::Mesh out = pomar::decode(bytes.data(), bytes.size());
  EXPECT_EQ(out.vertex_count(), messy.vertex_count());
  EXPECT_EQ(out.triangle_count(), messy.triangle_count());
  ASSERT_TRUE(openAt(path("messy.pomar"), -1));
  EXPECT_EQ(mm_->cm.vn, int(messy.vertex_count()));
  EXPECT_EQ(mm_->cm.fn, int(messy.triangle_count()));
  QFile::remove(path("messy.pomar"));
}

TEST_F(PomarPluginTest, RepairOptionSavesANonManifoldMeshAndSaysWhatChanged) {
  MeshModel *mm = layer(pomar::gen::nonmanifold_edge()); // three faces on edge (0, 1)

  // With it: saved, one warning naming every change, the layer left as it was.
  g_warnings.clear();
  ASSERT_TRUE(save(*mm, path("book.pomar"), [](RichParameterList &par) {
    par.setValue("Repair", BoolValue(true));
  })) << plugin()->errorMsg().toStdString();
  const QString all = g_warnings.join("\n");
  EXPECT_TRUE(all.contains("book.pomar: repaired before saving: cut 1 edge shared by more than two "
                           "faces (e.g. edge (0, 1), 3 faces); split 2 non-manifold vertices "
                           "into 6 (e.g. vertex 0 into 3)"))
      << all.toStdString();
  EXPECT_EQ(mm->cm.vn, 5);
  const std::vector<uint8_t> bytes = readBytes(path("book.pomar"));
  const pomar::Mesh out = pomar::decode(bytes.data(), bytes.size());
  EXPECT_EQ(out.vertex_count(), 9u); // three separate triangles
  EXPECT_EQ(out.triangle_count(), 3u);
  QFile::remove(path("book.pomar"));

  // A manifold mesh saved with the option: no warning and the same bytes.
  g_warnings.clear();
  MeshModel *good = layer(*input_);
  ASSERT_TRUE(save(*good, path("r.pomar"),
                   [](RichParameterList &par) { par.setValue("Repair", BoolValue(true)); }));
  EXPECT_TRUE(g_warnings.isEmpty()) << g_warnings.join("\n").toStdString();
  EXPECT_EQ(readBytes(path("r.pomar")), *clustered_);
  QFile::remove(path("r.pomar"));
}

TEST_F(PomarPluginTest, OpenThenSaveRoundTrip) {
  ASSERT_TRUE(openAt(path("clustered.pomar"), 0));
  mm_->UpdateBoxAndNormals();
  ASSERT_TRUE(save(*mm_, path("again.pomar"))) << plugin()->errorMsg().toStdString();
  const std::vector<uint8_t> again = readBytes(path("again.pomar"));
  EXPECT_EQ(canonical(pomar::decode(again.data(), again.size())),
            canonical(pomar::decode(clustered_->data(), clustered_->size())));
  // Our own attributes are not reported as lost data.
  EXPECT_TRUE(g_warnings.isEmpty()) << g_warnings.join("\n").toStdString();
  QFile::remove(path("again.pomar"));
}

} // namespace

int main(int argc, char **argv) {
  QCoreApplication app(argc, argv);
  qInstallMessageHandler(captureMessages);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
