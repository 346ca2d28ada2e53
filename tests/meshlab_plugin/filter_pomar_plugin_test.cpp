// In-process tests of the MeshLab filter plugin libfilter_pomar.so: loads it and the IO plugin
// libio_pomar.so with QPluginLoader as MeshLab's PluginManager does, opens .pomar layers with
// the IO plugin and runs the filters as meshlabserver does (initParameterSet, updateDataMask
// of the requirements, applyFilter). Every result is compared with pomar::SelectiveDecoder
// driven directly: refinement on the cached state, rebuilding the state from a layer's
// attributes, coarsening, levels of detail, colours, refusals. No X display needed.
#include <gtest/gtest.h>

#include <QAction>
#include <QCoreApplication>
#include <QFile>
#include <QPluginLoader>
#include <QStringList>
#include <QTemporaryDir>

#include <common/GLLogStream.h>
#include <common/interfaces.h>
#include <common/meshmodel.h>

#include <pomar/pomar.h>
#include <pomar/random_access.h>
#include <pomar/vcg_adapter.h>

#include "support/mesh_gen.h"

#include "support/mesh_compare.h"
#include "support/meshlab_layer.h"
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace {

const char *const kRefine = "POMAR: Refine Selected Clusters";
const char *const kCoarsen = "POMAR: Coarsen Selected Clusters";
const char *const kSetLevel = "POMAR: Set Level of Detail";
const char *const kShowClusters = "POMAR: Show Clusters";
const char *const kShowLevels = "POMAR: Show Levels";
const char *const kShowOriginal = "POMAR: Show Original Colours";

// ---------------------------------------------------------------- plugins

template <class Interface> Interface *instance(QPluginLoader &loader) {
  Interface *p = qobject_cast<Interface *>(loader.instance());
  if (p == nullptr)
    ADD_FAILURE() << "cannot load " << loader.fileName().toStdString() << ": "
                  << loader.errorString().toStdString();
  return p;
}
MeshIOInterface *io() {
  static QPluginLoader loader(QStringLiteral(POMAR_IO_PLUGIN));
  return instance<MeshIOInterface>(loader);
}
MeshFilterInterface *filter() {
  static QPluginLoader loader(QStringLiteral(POMAR_FILTER_PLUGIN));
  return instance<MeshFilterInterface>(loader);
}

QAction *action(const char *name) {
  for (QAction *a : filter()->actions())
    if (a->text() == name)
      return a;
  ADD_FAILURE() << "no filter named " << name;
  return nullptr;
}

// ---------------------------------------------------------------- meshes

using Tri = pomar::test::PositionTriangle;
using pomar::test::canonical;
std::vector<Tri> canonical(const CMeshO &m) { return canonical(pomar::from_vcg(m)); }

using pomar::test::sourceAttribute;
using pomar::test::vertexAttribute;

void writeBytes(const QString &path, const std::vector<uint8_t> &bytes) {
  std::ofstream out(QFile::encodeName(path).toStdString(), std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char *>(bytes.data()), std::streamsize(bytes.size()));
}

std::unique_ptr<pomar::SelectiveDecoder> decoderOf(const std::vector<uint8_t> &file) {
  return std::make_unique<pomar::SelectiveDecoder>(
      std::make_unique<pomar::MemorySource>(file.data(), file.size()));
}

// ---------------------------------------------------------------- fixture

class FilterPomarTest : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir_ = new QTemporaryDir();
    input_ = new pomar::Mesh(pomar::gen::noisy_sphere(12000, 11));
    clustered_ = new std::vector<uint8_t>(pomar::encode(*input_));
    pomar::EncodeOptions progressive;
    progressive.progressive = true;
    progressive_ = new std::vector<uint8_t>(pomar::encode(*input_, progressive));
    writeBytes(path("clustered.pomar"), *clustered_);
    writeBytes(path("progressive.pomar"), *progressive_);
    pomar::Mesh coloured = *input_;
    pomar::VertexAttribute c;
    c.kind = pomar::AttributeKind::Colour;
    c.name = "colour";
    c.components = 3;
    for (size_t v = 0; v < coloured.vertex_count(); ++v)
      for (int k = 0; k < 3; ++k)
        c.colour.push_back(uint8_t(128 + 127 * std::sin(7.0 * coloured.positions[3 * v + k])));
    coloured.attributes.push_back(c);
    writeBytes(path("coloured.pomar"), pomar::encode(coloured));
    info_ = new pomar::FileInfo(pomar::inspect(clustered_->data(), clustered_->size()));
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete input_;
    delete clustered_;
    delete progressive_;
    delete info_;
  }
  void SetUp() override {
    ASSERT_NE(io(), nullptr);
    ASSERT_NE(filter(), nullptr);
    ASSERT_TRUE(dir_->isValid());
    ASSERT_TRUE(info_->clustered());
    ASSERT_GT(info_->clusters, 50u);
    base_ = int(info_->global_levels);
    finest_ = int(info_->levels.size());
    filter()->setLog(&log_);
  }
  void TearDown() override {
    filter()->setLog(nullptr);
    // vcglib 2020.09's ~TriMesh() does not free named attributes (MeshLab leaks them too).
    for (MeshModel *mm : doc_.meshList)
      mm->cm.ClearAttributes();
  }

  static QString path(const QString &name) { return dir_->filePath(name); }

  /// Opens `name` with the IO plugin like meshlabserver (full resolution by default).
  MeshModel *open(const QString &name, int openAt = 0, bool skipDamaged = false) {
    MeshModel *mm = doc_.addNewMesh(path(name), name, true);
    RichParameterList par;
    io()->initPreOpenParameter("pomar", path(name), par);
    par.setValue("OpenAt", EnumValue(openAt));
    par.setValue("SkipDamaged", BoolValue(skipDamaged));
    int mask = 0;
    EXPECT_TRUE(io()->open("pomar", path(name), *mm, mask, par)) << io()->errorMsg().toStdString();
    mm->UpdateBoxAndNormals();
    return mm;
  }

  /// Runs a filter on the current layer as meshlabserver does; `edit` changes the defaults.
  bool apply(const char *name, std::function<void(RichParameterList &)> edit = {},
             vcg::CallBackPos *cb = nullptr) {
    QAction *a = action(name);
    RichParameterList par;
    filter()->initParameterSet(a, doc_, par);
    if (edit)
      edit(par);
    doc_.mm()->updateDataMask(filter()->getRequirements(a));
    log_.Clear();
    return filter()->applyFilter(a, doc_, par, cb);
  }
  bool setLevel(int level) {
    return apply(kSetLevel, [&](RichParameterList &p) { p.setValue("Level", IntValue(level)); });
  }
  bool refine(int level) {
    return apply(kRefine,
                 [&](RichParameterList &p) { p.setValue("TargetLevel", IntValue(level)); });
  }
  bool coarsen(int level) {
    return apply(kCoarsen,
                 [&](RichParameterList &p) { p.setValue("TargetLevel", IntValue(level)); });
  }

  QString logText() const {
    QStringList lines;
    log_.print(lines);
    return lines.join("\n");
  }

  /// Selects the faces with a vertex in one of `clusters` (what a user's brush does).
  static void selectFacesOf(MeshModel &mm, const std::set<int> &clusters) {
    const std::vector<float> cluster = vertexAttribute(mm.cm, "pomar_cluster");
    const CVertexO *first = &mm.cm.vert[0];
    vcg::tri::UpdateSelection<CMeshO>::Clear(mm.cm);
    for (CFaceO &f : mm.cm.face)
      for (int k = 0; k < 3; ++k)
        if (clusters.count(int(cluster[size_t(f.V(k) - first)])))
          f.SetS();
  }
  /// The clusters of the vertices of the selected faces.
  static std::set<int> clustersOfSelection(MeshModel &mm) {
    const std::vector<float> cluster = vertexAttribute(mm.cm, "pomar_cluster");
    const CVertexO *first = &mm.cm.vert[0];
    std::set<int> out;
    for (CFaceO &f : mm.cm.face)
      if (f.IsS())
        for (int k = 0; k < 3; ++k)
          out.insert(int(cluster[size_t(f.V(k) - first)]));
    return out;
  }

  /// The layer keeps its pomar attributes, consistent with the decoder's vertex facts.
  void expectAttributes(MeshModel &mm, const pomar::SelectiveDecoder &d,
                        const QString &file = "clustered.pomar") {
    EXPECT_EQ(sourceAttribute(mm.cm), QFile::encodeName(path(file)).toStdString());
    const std::vector<float> cluster = vertexAttribute(mm.cm, "pomar_cluster");
    const std::vector<float> level = vertexAttribute(mm.cm, "pomar_level");
    ASSERT_EQ(cluster.size(), mm.cm.vert.size());
    ASSERT_EQ(level.size(), mm.cm.vert.size());
    // Same multiset of (position, cluster, level) as the decoder's.
    using Row = std::tuple<float, float, float, int, int>;
    std::vector<Row> got, want;
    for (size_t v = 0; v < mm.cm.vert.size(); ++v) {
      const auto &p = mm.cm.vert[v].cP();
      got.emplace_back(p[0], p[1], p[2], int(cluster[v]), int(level[v]));
    }
    const pomar::Mesh m = d.mesh();
    const std::vector<uint32_t> vc = d.vertex_cluster(), vl = d.vertex_level();
    const bool clustered = d.info().clustered();
    for (size_t v = 0; v < m.vertex_count(); ++v)
      want.emplace_back(m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2],
                        clustered ? int(vc[v]) : -1, int(vl[v]));
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    EXPECT_TRUE(got == want);
  }

  static QTemporaryDir *dir_;
  static pomar::Mesh *input_;
  static std::vector<uint8_t> *clustered_, *progressive_;
  static pomar::FileInfo *info_;
  int base_ = 0, finest_ = 0;
  MeshDocument doc_;
  GLLogStream log_;
};

QTemporaryDir *FilterPomarTest::dir_ = nullptr;
pomar::Mesh *FilterPomarTest::input_ = nullptr;
std::vector<uint8_t> *FilterPomarTest::clustered_ = nullptr;
std::vector<uint8_t> *FilterPomarTest::progressive_ = nullptr;
pomar::FileInfo *FilterPomarTest::info_ = nullptr;

// ---------------------------------------------------------------- declarations

TEST_F(FilterPomarTest, FiltersAndClasses) {
  QStringList names;
  for (QAction *a : filter()->actions())
    names << a->text();
  EXPECT_EQ(names, QStringList({kRefine, kCoarsen, kSetLevel, kShowClusters, kShowLevels,
                                kShowOriginal}));
  for (QAction *a : filter()->actions()) {
    EXPECT_NE(filter()->getClass(a), MeshFilterInterface::Generic) << a->text().toStdString();
    EXPECT_EQ(filter()->filterArity(a), MeshFilterInterface::SINGLE_MESH);
    EXPECT_FALSE(filter()->filterInfo(a).isEmpty());
  }
  EXPECT_TRUE(filter()->getClass(action(kRefine)) & MeshFilterInterface::Remeshing);
  EXPECT_TRUE(filter()->getClass(action(kCoarsen)) & MeshFilterInterface::Remeshing);
  EXPECT_TRUE(filter()->getClass(action(kSetLevel)) & MeshFilterInterface::Remeshing);
  EXPECT_TRUE(filter()->getClass(action(kShowClusters)) & MeshFilterInterface::VertexColoring);
  EXPECT_TRUE(filter()->getClass(action(kShowLevels)) & MeshFilterInterface::VertexColoring);
  for (const char *f : {kRefine, kCoarsen, kSetLevel})
    EXPECT_EQ(filter()->postCondition(action(f)), int(MeshModel::MM_GEOMETRY_AND_TOPOLOGY_CHANGE));
  for (const char *f : {kShowClusters, kShowLevels, kShowOriginal}) {
    EXPECT_EQ(filter()->postCondition(action(f)), int(MeshModel::MM_VERTCOLOR));
    EXPECT_EQ(filter()->getRequirements(action(f)), int(MeshModel::MM_VERTCOLOR));
  }
}

TEST_F(FilterPomarTest, ParameterDefaults) {
  // A .pomar layer: the file's levels.
  open("clustered.pomar");
  RichParameterList refinePar, coarsenPar, levelPar, showPar;
  filter()->initParameterSet(action(kRefine), doc_, refinePar);
  filter()->initParameterSet(action(kCoarsen), doc_, coarsenPar);
  filter()->initParameterSet(action(kSetLevel), doc_, levelPar);
  filter()->initParameterSet(action(kShowClusters), doc_, showPar);
  filter()->initParameterSet(action(kShowLevels), doc_, showPar);
  EXPECT_EQ(refinePar.size(), 1);
  EXPECT_EQ(refinePar.getInt("TargetLevel"), finest_);
  EXPECT_EQ(coarsenPar.size(), 1);
  EXPECT_EQ(coarsenPar.getInt("TargetLevel"), base_);
  EXPECT_EQ(levelPar.size(), 1);
  EXPECT_EQ(levelPar.getInt("Level"), base_);
  EXPECT_TRUE(showPar.isEmpty());

  // Any other layer: "finest" placeholders.
  MeshModel *plain = doc_.addNewMesh("", "plain", true);
  pomar::to_vcg(*input_, plain->cm);
  RichParameterList r, c, l;
  filter()->initParameterSet(action(kRefine), doc_, r);
  filter()->initParameterSet(action(kCoarsen), doc_, c);
  filter()->initParameterSet(action(kSetLevel), doc_, l);
  EXPECT_EQ(r.getInt("TargetLevel"), 99);
  EXPECT_EQ(c.getInt("TargetLevel"), 0);
  EXPECT_EQ(l.getInt("Level"), -1);
}

// ---------------------------------------------------------------- levels of detail

TEST_F(FilterPomarTest, SetLevelOfDetail) {
  MeshModel *mm = open("clustered.pomar");
  auto d = decoderOf(*clustered_);

  ASSERT_TRUE(setLevel(base_)) << filter()->errorMsg().toStdString();
  EXPECT_EQ(mm->cm.vn, int(info_->clusters));
  EXPECT_EQ(canonical(mm->cm), canonical(d->mesh()));
  expectAttributes(*mm, *d);
  EXPECT_TRUE(
      logText().contains(QString("POMAR: set level of detail %1 (base clustered)").arg(base_)));

  const int mid = (base_ + finest_) / 2;
  ASSERT_TRUE(setLevel(mid));
  d->want_all(mid);
  d->update();
  EXPECT_EQ(canonical(mm->cm), canonical(d->mesh()));
  expectAttributes(*mm, *d);

  // -1 and anything above the finest level: full resolution = the lossless decode.
  for (int level : {-1, finest_ + 5}) {
    ASSERT_TRUE(setLevel(level));
    EXPECT_EQ(canonical(mm->cm), canonical(pomar::decode(clustered_->data(), clustered_->size())));
    EXPECT_TRUE(logText().contains("(full resolution)"));
  }
  // Below the base clustered level: clamped to it (going coarser re-decodes).
  ASSERT_TRUE(setLevel(0));
  EXPECT_EQ(mm->cm.vn, int(info_->clusters));
  EXPECT_TRUE(logText().contains("below the base clustered level"));
  EXPECT_EQ(mm->cm.vn, int(mm->cm.vert.size()));
  EXPECT_EQ(mm->cm.fn, int(mm->cm.face.size()));
}

// ---------------------------------------------------------------- refine

TEST_F(FilterPomarTest, RefineSelectedClustersMatchesTheLibrary) {
  MeshModel *mm = open("clustered.pomar");
  ASSERT_TRUE(setLevel(base_));
  const std::set<int> first = {0, 7, 23};
  selectFacesOf(*mm, first);
  const std::set<int> requested = clustersOfSelection(*mm); // includes the 1-ring's clusters
  ASSERT_GT(requested.size(), first.size());

  std::vector<std::pair<int, const char *>> progress;
  static std::vector<std::pair<int, const char *>> *sink;
  sink = &progress;
  vcg::CallBackPos *cb = [](const int pos, const char *text) {
    sink->emplace_back(pos, text);
    return true;
  };
  ASSERT_TRUE(apply(kRefine, {}, cb)) << filter()->errorMsg().toStdString(); // default: finest
  auto d = decoderOf(*clustered_);
  for (int c : requested)
    d->want_cluster(uint32_t(c), finest_);
  d->update();
  EXPECT_EQ(canonical(mm->cm), canonical(d->mesh()));
  expectAttributes(*mm, *d);
  EXPECT_TRUE(logText().contains(QString("POMAR: refined %1 clusters in ").arg(requested.size())))
      << logText().toStdString();
  EXPECT_TRUE(logText().contains("incremental, on the cached decoder state"));
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.back().first, 100);

  // The selection: the faces whose three vertices are in the requested clusters.
  const std::vector<float> cluster = vertexAttribute(mm->cm, "pomar_cluster");
  const CVertexO *v0 = &mm->cm.vert[0];
  size_t selected = 0;
  for (const CFaceO &f : mm->cm.face) {
    bool inside = true;
    for (int k = 0; k < 3; ++k)
      inside = inside && requested.count(int(cluster[size_t(f.cV(k) - v0)])) > 0;
    EXPECT_EQ(f.IsS(), inside);
    selected += f.IsS();
  }
  EXPECT_GT(selected, 0u);
  for (size_t v = 0; v < mm->cm.vert.size(); ++v)
    EXPECT_EQ(mm->cm.vert[v].IsS(), requested.count(int(cluster[v])) > 0);

  // Refine again elsewhere, to an intermediate level: a delta on the same state.
  selectFacesOf(*mm, {40, 41});
  const std::set<int> second = clustersOfSelection(*mm);
  const int mid = base_ + 3;
  ASSERT_TRUE(refine(mid));
  for (int c : second)
    d->want_cluster(uint32_t(c), mid);
  d->update();
  EXPECT_EQ(canonical(mm->cm), canonical(d->mesh()));
  expectAttributes(*mm, *d);
  EXPECT_TRUE(logText().contains("incremental, on the cached decoder state"));
  EXPECT_EQ(clustersOfSelection(*mm).size() > 0, true);

  // TargetLevel above the finest level is clamped.
  selectFacesOf(*mm, {40});
  const std::set<int> third = clustersOfSelection(*mm);
  ASSERT_TRUE(refine(99));
  EXPECT_TRUE(logText().contains(QString("target level 99 clamped to %1").arg(finest_)));
  for (int c : third)
    d->want_cluster(uint32_t(c), finest_);
  d->update();
  EXPECT_EQ(canonical(mm->cm), canonical(d->mesh()));
}

TEST_F(FilterPomarTest, RefiningEverythingEqualsTheLosslessDecode) {
  MeshModel *mm = open("clustered.pomar");
  ASSERT_TRUE(setLevel(base_));
  vcg::tri::UpdateSelection<CMeshO>::FaceAll(mm->cm);
  ASSERT_TRUE(refine(finest_));
  EXPECT_EQ(canonical(mm->cm), canonical(pomar::decode(clustered_->data(), clustered_->size())));
  EXPECT_EQ(size_t(vcg::tri::UpdateSelection<CMeshO>::FaceCount(mm->cm)), mm->cm.face.size());
}

// ---------------------------------------------------------------- rebuilding the state

TEST_F(FilterPomarTest, StateIsRebuiltFromTheLayersAttributes) {
  // Layer A: base clustered mesh + a refined region; the plugin's decoder is in that state.
  MeshModel *a = open("clustered.pomar");
  ASSERT_TRUE(setLevel(base_));
  selectFacesOf(*a, {3, 4});
  const std::set<int> regionA = clustersOfSelection(*a);
  ASSERT_TRUE(refine(finest_));
  const std::vector<Tri> afterA = canonical(a->cm);

  // Layer B (same file, opened at full resolution): its first filter finds a decoder that
  // does not match it, so the state is rebuilt from B's attributes; then it coarsens.
  MeshModel *b = open("clustered.pomar");
  ASSERT_EQ(doc_.mm(), b);
  selectFacesOf(*b, {10, 11, 12});
  const std::set<int> regionB = clustersOfSelection(*b);
  ASSERT_TRUE(coarsen(base_)) << filter()->errorMsg().toStdString();
  EXPECT_TRUE(logText().contains("decoder state rebuilt from the layer's attributes"))
      << logText().toStdString();
  EXPECT_FALSE(logText().contains("differs from what the file decodes"));
  EXPECT_TRUE(logText().contains(QString("POMAR: coarsened %1 clusters").arg(regionB.size())));
  auto db = decoderOf(*clustered_);
  db->want_all(finest_);
  db->update();
  std::vector<int> wanted = db->levels();
  for (int c : regionB)
    wanted[size_t(c)] = base_;
  db->set_wanted(wanted);
  db->update();
  EXPECT_EQ(canonical(b->cm), canonical(db->mesh()));
  expectAttributes(*b, *db);
  // The level map keeps neighbours one level apart: the region is coarser than the rest.
  EXPECT_LT(b->cm.vn, int(info_->vertices));

  // Back to layer A: rebuilt from A's attributes, then refined further.
  doc_.setCurrentMesh(a->id());
  EXPECT_EQ(canonical(a->cm), afterA); // untouched by B's filters
  selectFacesOf(*a, {30});
  const std::set<int> more = clustersOfSelection(*a);
  ASSERT_TRUE(refine(finest_));
  EXPECT_TRUE(logText().contains("decoder state rebuilt from the layer's attributes"));
  EXPECT_FALSE(logText().contains("differs from what the file decodes"));
  auto da = decoderOf(*clustered_);
  for (int c : regionA)
    da->want_cluster(uint32_t(c), finest_);
  da->update();
  for (int c : more)
    da->want_cluster(uint32_t(c), finest_);
  da->update();
  EXPECT_EQ(canonical(a->cm), canonical(da->mesh()));
  expectAttributes(*a, *da);
}

TEST_F(FilterPomarTest, AnEditedLayerIsRebuiltAndItsEditsReplaced) {
  MeshModel *mm = open("clustered.pomar");
  ASSERT_TRUE(setLevel(base_));
  mm->cm.vert[5].P()[0] += 0.25f; // same counts, different positions
  selectFacesOf(*mm, {1});
  const std::set<int> region = clustersOfSelection(*mm);
  ASSERT_TRUE(refine(finest_));
  EXPECT_TRUE(logText().contains("differs from what the file decodes")) << logText().toStdString();
  auto d = decoderOf(*clustered_);
  for (int c : region)
    d->want_cluster(uint32_t(c), finest_);
  d->update();
  EXPECT_EQ(canonical(mm->cm), canonical(d->mesh()));
}

TEST_F(FilterPomarTest, CoarsenTheWholeMeshGivesTheBaseClusteredMesh) {
  MeshModel *mm = open("clustered.pomar");
  vcg::tri::UpdateSelection<CMeshO>::FaceAll(mm->cm);
  ASSERT_TRUE(coarsen(0)); // clamped to the base clustered level
  EXPECT_TRUE(logText().contains(QString("target level 0 clamped to %1").arg(base_)));
  EXPECT_EQ(mm->cm.vn, int(info_->clusters));
  auto d = decoderOf(*clustered_);
  EXPECT_EQ(canonical(mm->cm), canonical(d->mesh()));
}

// ---------------------------------------------------------------- colours

/// Refining keeps the file's colours on the vertices it decodes; Show Clusters / Show Levels
/// keep the layer's colours aside and Show Original Colours puts them back.
TEST_F(FilterPomarTest, AttributesSurviveRefineAndShowFilters) {
  const std::vector<uint8_t> bytes = [] {
    std::ifstream in(QFile::encodeName(path("coloured.pomar")).toStdString(), std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
  }();
  const pomar::Mesh full = pomar::decode(bytes.data(), bytes.size());
  std::map<std::array<float, 3>, std::array<uint8_t, 3>> colourAt;
  const pomar::VertexAttribute *c = full.find(pomar::AttributeKind::Colour);
  ASSERT_NE(c, nullptr);
  for (size_t v = 0; v < full.vertex_count(); ++v)
    colourAt[{full.positions[3 * v], full.positions[3 * v + 1], full.positions[3 * v + 2]}] = {
        c->colour[3 * v], c->colour[3 * v + 1], c->colour[3 * v + 2]};
  auto expectFileColours = [&](MeshModel &mm) {
    for (const CVertexO &v : mm.cm.vert) {
      const auto it = colourAt.find({v.cP()[0], v.cP()[1], v.cP()[2]});
      ASSERT_NE(it, colourAt.end());
      ASSERT_EQ(v.cC()[0], it->second[0]);
      ASSERT_EQ(v.cC()[1], it->second[1]);
      ASSERT_EQ(v.cC()[2], it->second[2]);
    }
  };
  MeshModel *mm = open("coloured.pomar", 1); // base clustered mesh
  expectFileColours(*mm);
  // The GUI draws vertex colours only when they are in the layer's data mask: opening puts
  // them there, and so does a refine, which replaces the layer's content with a decode.
  EXPECT_TRUE(mm->hasDataMask(MeshModel::MM_VERTCOLOR));
  mm->clearDataMask(MeshModel::MM_VERTCOLOR);
  selectFacesOf(*mm, {0, 1, 2});
  ASSERT_TRUE(refine(info_->levels.size())) << filter()->errorMsg().toStdString();
  expectFileColours(*mm);
  EXPECT_TRUE(mm->hasDataMask(MeshModel::MM_VERTCOLOR));
  ASSERT_TRUE(apply(kShowClusters)) << filter()->errorMsg().toStdString();
  ASSERT_TRUE(apply(kShowLevels)) << filter()->errorMsg().toStdString();
  ASSERT_TRUE(apply(kShowOriginal)) << filter()->errorMsg().toStdString();
  expectFileColours(*mm); // the user's colours, not those of the first Show
  ASSERT_TRUE(apply(kShowClusters));
  ASSERT_TRUE(setLevel(-1)); // a refine puts the file's colours on the new mesh
  expectFileColours(*mm);
  EXPECT_EQ(mm->cm.vn, int(full.vertex_count()));
}

TEST_F(FilterPomarTest, ShowClustersAndLevels) {
  MeshModel *mm = open("clustered.pomar");
  ASSERT_TRUE(apply(kShowClusters)) << filter()->errorMsg().toStdString();
  EXPECT_TRUE(mm->hasDataMask(MeshModel::MM_VERTCOLOR));
  EXPECT_TRUE(logText().contains(QString("POMAR: coloured %1 clusters").arg(info_->clusters)));
  const std::vector<float> cluster = vertexAttribute(mm->cm, "pomar_cluster");
  std::map<int, vcg::Color4b> colourOf;
  std::set<std::array<int, 3>> distinct;
  for (size_t v = 0; v < mm->cm.vert.size(); ++v) {
    const vcg::Color4b c = mm->cm.vert[v].C();
    auto it = colourOf.emplace(int(cluster[v]), c).first;
    EXPECT_TRUE(it->second == c) << "cluster " << cluster[v] << " has two colours";
    distinct.insert({c[0], c[1], c[2]});
  }
  EXPECT_GE(distinct.size() * 100, size_t(info_->clusters) * 95);
  // Deterministic: the same colours again.
  std::vector<vcg::Color4b> before;
  for (const CVertexO &v : mm->cm.vert)
    before.push_back(v.cC());
  ASSERT_TRUE(apply(kShowClusters));
  for (size_t v = 0; v < mm->cm.vert.size(); ++v)
    EXPECT_TRUE(mm->cm.vert[v].cC() == before[v]);

  const vcg::Color4b blue(0, 0, 255, 255), red(255, 0, 0, 255);
  auto count = [&](const vcg::Color4b &c) {
    size_t n = 0;
    for (const CVertexO &v : mm->cm.vert)
      n += v.cC() == c;
    return n;
  };
  // Full resolution: every cluster at the finest level (a freshly opened layer: rebuilt).
  ASSERT_TRUE(apply(kShowLevels));
  EXPECT_EQ(count(red), mm->cm.vert.size());
  // Base clustered mesh: all blue.
  ASSERT_TRUE(setLevel(base_));
  ASSERT_TRUE(apply(kShowLevels));
  EXPECT_EQ(count(blue), mm->cm.vert.size());
  EXPECT_TRUE(logText().contains(QString("level %1: %2").arg(base_).arg(info_->clusters)));
  // A refined region: red there, blue far away, ramp colours in between.
  selectFacesOf(*mm, {0});
  ASSERT_TRUE(refine(finest_));
  for (const CVertexO &v : mm->cm.vert)
    EXPECT_TRUE(v.cC() == vcg::Color4b(vcg::Color4b::White)); // replaced mesh: no stale colours
  ASSERT_TRUE(apply(kShowLevels));
  EXPECT_GT(count(red), 0u);
  EXPECT_LT(count(red), mm->cm.vert.size());
}

// ---------------------------------------------------------------- progressive files

TEST_F(FilterPomarTest, PureProgressiveFile) {
  MeshModel *mm = open("progressive.pomar");
  const pomar::FileInfo info = pomar::inspect(progressive_->data(), progressive_->size());
  ASSERT_FALSE(info.clustered());
  RichParameterList par;
  filter()->initParameterSet(action(kSetLevel), doc_, par);
  EXPECT_EQ(par.getInt("Level"), 0);

  ASSERT_TRUE(setLevel(5)) << filter()->errorMsg().toStdString();
  EXPECT_EQ(canonical(mm->cm),
            canonical(pomar::decode(progressive_->data(), progressive_->size(), 5)));
  auto d = decoderOf(*progressive_);
  d->want_all(5);
  d->update();
  expectAttributes(*mm, *d, "progressive.pomar");
  ASSERT_TRUE(setLevel(2)); // coarser
  EXPECT_EQ(canonical(mm->cm),
            canonical(pomar::decode(progressive_->data(), progressive_->size(), 2)));
  ASSERT_TRUE(setLevel(-1));
  EXPECT_EQ(canonical(mm->cm),
            canonical(pomar::decode(progressive_->data(), progressive_->size())));

  ASSERT_TRUE(apply(kShowLevels)) << filter()->errorMsg().toStdString();
  EXPECT_TRUE(mm->cm.vert[0].cC() == vcg::Color4b(255, 0, 0, 255));

  vcg::tri::UpdateSelection<CMeshO>::FaceAll(mm->cm);
  for (const char *f : {kRefine, kCoarsen}) {
    EXPECT_FALSE(apply(f));
    EXPECT_TRUE(filter()->errorMsg().contains("pure progressive file")) << f;
    EXPECT_TRUE(logText().contains("pure progressive file")) << f;
  }
  EXPECT_FALSE(apply(kShowClusters));
  EXPECT_TRUE(filter()->errorMsg().contains("has no cluster"));
}

// ---------------------------------------------------------------- refusals

TEST_F(FilterPomarTest, LayersNotFromAPomarFileAreRefused) {
  MeshModel *plain = doc_.addNewMesh("", "plain", true);
  pomar::to_vcg(*input_, plain->cm);
  plain->UpdateBoxAndNormals();
  vcg::tri::UpdateSelection<CMeshO>::FaceAll(plain->cm);
  const std::vector<Tri> before = canonical(plain->cm);
  for (const char *f : {kRefine, kCoarsen, kSetLevel, kShowClusters, kShowLevels}) {
    EXPECT_FALSE(apply(f)) << f;
    EXPECT_TRUE(filter()->errorMsg().contains("works only on a layer opened from a .pomar file"))
        << filter()->errorMsg().toStdString();
    EXPECT_TRUE(logText().contains("works only on a layer opened from a .pomar file")) << f;
  }
  EXPECT_EQ(canonical(plain->cm), before);
}

TEST_F(FilterPomarTest, NothingSelected) {
  MeshModel *mm = open("clustered.pomar");
  ASSERT_TRUE(setLevel(base_));
  vcg::tri::UpdateSelection<CMeshO>::Clear(mm->cm);
  const int vn = mm->cm.vn;
  for (const char *f : {kRefine, kCoarsen}) {
    EXPECT_FALSE(apply(f));
    EXPECT_TRUE(filter()->errorMsg().contains("nothing selected")) << f;
  }
  EXPECT_EQ(mm->cm.vn, vn);
  // With no face selected, the selected vertices are used.
  mm->cm.vert[0].SetS();
  ASSERT_TRUE(refine(finest_));
  EXPECT_TRUE(logText().contains("from 1 selected vertices")) << logText().toStdString();
  EXPECT_GT(mm->cm.vn, vn);
}

TEST_F(FilterPomarTest, LayerOpenedBelowTheBaseClusteredLevel) {
  // The IO plugin's "Global level N" below the base clustered level has no clusters.
  MeshModel *mm = doc_.addNewMesh(path("clustered.pomar"), "low", true);
  RichParameterList par;
  io()->initPreOpenParameter("pomar", path("clustered.pomar"), par);
  par.setValue("OpenAt", EnumValue(2));
  par.setValue("Level", IntValue(1));
  int mask = 0;
  ASSERT_TRUE(io()->open("pomar", path("clustered.pomar"), *mm, mask, par));
  vcg::tri::UpdateSelection<CMeshO>::FaceAll(mm->cm);
  EXPECT_FALSE(refine(finest_));
  EXPECT_TRUE(filter()->errorMsg().contains("Set Level of Detail"))
      << filter()->errorMsg().toStdString();
  EXPECT_FALSE(apply(kShowClusters));
  // Setting a level of detail works and brings the clusters back.
  ASSERT_TRUE(setLevel(base_));
  EXPECT_EQ(mm->cm.vn, int(info_->clusters));
  vcg::tri::UpdateSelection<CMeshO>::FaceAll(mm->cm);
  ASSERT_TRUE(refine(finest_));
  EXPECT_EQ(canonical(mm->cm), canonical(pomar::decode(clustered_->data(), clustered_->size())));
}

TEST_F(FilterPomarTest, MissingAndDamagedFiles) {
  // Deleted after opening.
  writeBytes(path("gone.pomar"), *clustered_);
  MeshModel *gone = open("gone.pomar");
  ASSERT_TRUE(QFile::remove(path("gone.pomar")));
  EXPECT_FALSE(setLevel(base_));
  EXPECT_TRUE(filter()->errorMsg().contains("does not exist any more"))
      << filter()->errorMsg().toStdString();
  EXPECT_EQ(gone->cm.vn, int(info_->vertices));

  // A damaged cluster block: the base clustered mesh opens, refining reads the block and fails;
  // the layer is left as it was.
  std::vector<uint8_t> bad = *clustered_;
  bad[bad.size() * 3 / 4] ^= 0x5A;
  writeBytes(path("bad.pomar"), bad);
  MeshModel *mm = open("bad.pomar", 1); // base clustered mesh
  ASSERT_EQ(mm->cm.vn, int(info_->clusters));
  const std::vector<Tri> before = canonical(mm->cm);
  vcg::tri::UpdateSelection<CMeshO>::FaceAll(mm->cm);
  EXPECT_FALSE(refine(finest_));
  EXPECT_TRUE(filter()->errorMsg().contains("damaged .pomar file"))
      << filter()->errorMsg().toStdString();
  EXPECT_TRUE(logText().contains("damaged .pomar file"));
  EXPECT_EQ(canonical(mm->cm), before);

  // Opened with "Skip damaged blocks", the same refinement succeeds around the damage, with
  // a warning; the result is what the library gives with skip_damaged.
  MeshModel *skip = open("bad.pomar", 1, true);
  vcg::tri::UpdateSelection<CMeshO>::FaceAll(skip->cm);
  ASSERT_TRUE(refine(finest_)) << filter()->errorMsg().toStdString();
  EXPECT_TRUE(logText().contains("damaged block")) << logText().toStdString();
  pomar::SelectiveOptions options;
  options.skip_damaged = true;
  pomar::SelectiveDecoder d(std::make_unique<pomar::MemorySource>(bad.data(), bad.size()), options);
  d.want_all(finest_);
  d.update();
  ASSERT_FALSE(d.damaged().empty());
  EXPECT_EQ(canonical(skip->cm), canonical(d.mesh()));
  EXPECT_LT(skip->cm.vn, int(info_->vertices));
  EXPECT_GT(skip->cm.vn, int(info_->clusters));
  // The layer keeps its policy: coarsening and refining again work around the damage.
  ASSERT_TRUE(setLevel(base_)) << filter()->errorMsg().toStdString();
  EXPECT_EQ(skip->cm.vn, int(info_->clusters));
  ASSERT_TRUE(setLevel(finest_)) << filter()->errorMsg().toStdString();
  EXPECT_EQ(canonical(skip->cm), canonical(d.mesh()));
}

} // namespace

int main(int argc, char **argv) {
  QCoreApplication app(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
