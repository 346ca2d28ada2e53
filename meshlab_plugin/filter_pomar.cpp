// MeshLab 2020.09 filter plugin for layers opened from .pomar files: see filter_pomar.h.
#include "filter_pomar.h"
#include "pomar_layer.h"

#include <pomar/pomar.h>
#include <pomar/random_access.h>
#include <pomar/vcg_adapter.h>

#include <QFile>
#include <QFileInfo>
#include <QtGlobal>

#include <vcg/complex/algorithms/update/selection.h>
#include <vcg/complex/allocate.h>
#include <vcg/space/color4.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <set>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

const char *const kClusterAttr = pomar::meshlab::kClusterAttribute;
const char *const kLevelAttr = pomar::meshlab::kLevelAttribute;
const char *const kSourceAttr = pomar::meshlab::kSourceAttribute;
/// TargetLevel default when the file is unknown: "the finest level" after clamping.
const int kFinestPlaceholder = 99;
/// Decoders kept at once (each holds its current mesh).
const size_t kMaxSessions = 4;

// ---------------------------------------------------------------- mesh signature

/// What identifies a mesh produced by a decoder: counts plus a hash of the positions (bit
/// patterns) and the triangles, both in order. A layer that still has the signature of the
/// decoder's last output can be refined on top of the decoder's state.
struct Signature {
  uint64_t vn = 0, fn = 0, hash = 0;
  bool operator==(const Signature &o) const { return vn == o.vn && fn == o.fn && hash == o.hash; }
  bool operator!=(const Signature &o) const { return !(*this == o); }
};

class Hasher {
public:
  void add(uint32_t w) {
    h_ = (h_ ^ w) * 0x100000001b3ULL;
    h_ ^= h_ >> 29;
  }
  void add(float f) {
    uint32_t w;
    std::memcpy(&w, &f, sizeof w);
    add(w);
  }
  uint64_t value() const { return h_; }

private:
  uint64_t h_ = 0xcbf29ce484222325ULL;
};

Signature signatureOf(const pomar::Mesh &mesh) {
  Hasher h;
  for (float x : mesh.positions)
    h.add(x);
  for (uint32_t i : mesh.triangles)
    h.add(i);
  return {mesh.vertex_count(), mesh.triangle_count(), h.value()};
}

/// The same for a MeshLab mesh: live elements only, vertices renumbered in order (what
/// pomar::from_vcg would give, without dropping unreferenced vertices).
Signature signatureOf(const CMeshO &m) {
  constexpr uint32_t kNone = UINT32_MAX;
  std::vector<uint32_t> index(m.vert.size(), kNone);
  Hasher h;
  uint64_t vn = 0, fn = 0;
  for (size_t v = 0; v < m.vert.size(); ++v) {
    if (m.vert[v].IsD())
      continue;
    index[v] = uint32_t(vn++);
    for (int a = 0; a < 3; ++a)
      h.add(float(m.vert[v].cP()[a]));
  }
  for (const CFaceO &f : m.face) {
    if (f.IsD())
      continue;
    ++fn;
    for (int k = 0; k < f.VN(); ++k) {
      const size_t v = pomar::vertex_position(m, f.cV(k));
      h.add(v < index.size() ? index[v] : kNone);
    }
  }
  return {vn, fn, h.value()};
}

// ---------------------------------------------------------------- attributes

bool sourceOf(CMeshO &m, std::string &path) {
  auto h = vcg::tri::Allocator<CMeshO>::FindPerMeshAttribute<std::string>(m, kSourceAttr);
  if (!vcg::tri::Allocator<CMeshO>::IsValidHandle(m, h) || h().empty())
    return false;
  path = h();
  return true;
}

/// Whether the layer was opened with "Skip damaged blocks".
bool skipsDamage(CMeshO &m) {
  auto h = vcg::tri::Allocator<CMeshO>::FindPerMeshAttribute<int>(
      m, pomar::meshlab::kSkipDamagedAttribute);
  return vcg::tri::Allocator<CMeshO>::IsValidHandle(m, h) && h() != 0;
}

/// The per-vertex cluster and level attributes of a layer as integers; false (with `why`)
/// if they are missing or hold values that are not cluster ids / levels of this file.
/// `clusters` = 0 for a pure progressive file (no cluster ids needed).
/// used[v]: a live face uses vertex v.
std::vector<char> usedVertices(const CMeshO &m) {
  std::vector<char> used(m.vert.size(), 0);
  const CVertexO *first = m.vert.empty() ? nullptr : &m.vert[0];
  for (const CFaceO &f : m.face)
    if (!f.IsD())
      for (int k = 0; k < 3; ++k)
        if (f.cV(k) >= first && f.cV(k) < first + m.vert.size())
          used[size_t(f.cV(k) - first)] = 1;
  return used;
}

bool layerClustersAndLevels(CMeshO &m, uint32_t clusters, int finest, std::vector<int> &cluster,
                            std::vector<int> &level, QString &why) {
  auto ch = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(m, kClusterAttr);
  auto lh = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(m, kLevelAttr);
  if (!vcg::tri::Allocator<CMeshO>::IsValidHandle(m, ch) ||
      !vcg::tri::Allocator<CMeshO>::IsValidHandle(m, lh)) {
    why = "the layer has no per-vertex pomar_cluster / pomar_level attributes";
    return false;
  }
  cluster.assign(m.vert.size(), -1);
  level.assign(m.vert.size(), -1);
  // A vertex no face uses (kept by a lossless file, shown only at full resolution) has
  // neither: it is left at -1 and ignored.
  const std::vector<char> used = usedVertices(m);
  for (size_t v = 0; v < m.vert.size(); ++v) {
    if (m.vert[v].IsD())
      continue;
    const float c = ch[v], l = lh[v];
    if (!used[v] && c == -1.0f && l == -1.0f)
      continue;
    if (clusters > 0) {
      if (!(c >= 0 && c < float(clusters) && c == std::floor(c))) {
        why = QString("vertex %1 has no cluster (pomar_cluster = %2): the layer was opened below "
                      "the base clustered level or edited; apply \"POMAR: Set Level of Detail\" "
                      "first")
                  .arg(v)
                  .arg(double(c));
        return false;
      }
      cluster[v] = int(c);
    }
    if (!(l >= 0 && l <= float(finest) && l == std::floor(l))) {
      why = QString("vertex %1 has no valid level (pomar_level = %2); apply \"POMAR: Set Level "
                    "of Detail\" first")
                .arg(v)
                .arg(double(l));
      return false;
    }
    level[v] = int(l);
  }
  return true;
}

// ---------------------------------------------------------------- colours

uint64_t mix64(uint64_t x) { // splitmix64 finalizer
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// A deterministic, well spread colour per cluster id.
vcg::Color4b clusterColor(uint32_t c) {
  const uint64_t h = mix64(c);
  vcg::Color4b col;
  col.SetHSVColor(float(h & 0xFFFF) / 65536.0f, 0.45f + 0.5f * float((h >> 16) & 0xFF) / 255.0f,
                  0.7f + 0.3f * float((h >> 24) & 0xFF) / 255.0f);
  return col;
}

/// Colour ramp of t in [0,1]: blue (coarse) - cyan - green - yellow - red (fine).
vcg::Color4b levelColor(double t) {
  t = std::min(1.0, std::max(0.0, t));
  vcg::Color4b col;
  col.SetHSVColor(float((1.0 - t) * 2.0 / 3.0), 1.0f, 1.0f);
  return col;
}

// ---------------------------------------------------------------- progress

using pomar::meshlab::ProgressRelay;

} // namespace

// ---------------------------------------------------------------- sessions

struct PomarFilterPlugin::Session {
  std::string path;
  qint64 fileSize = -1, fileTime = 0; ///< to notice a file replaced on disk
  std::unique_ptr<pomar::SelectiveDecoder> decoder;
  bool skipDamaged = false;  ///< decode around damaged blocks (the layer was opened so)
  size_t damageReported = 0; ///< decoder->damaged() entries already logged
  bool pristine = true;      ///< the decoder was never updated (fresh state)
  bool haveSignature = false;
  Signature signature; ///< of the mesh the decoder's current state produced
  uint64_t lastUse = 0;
  // Facts about the file.
  bool clustered = false;
  int base = 0, finest = 0; ///< base clustered level (0 if progressive), full resolution
  uint32_t clusters = 0;

  void open() {
    pomar::SelectiveOptions options;
    options.skip_damaged = skipDamaged;
    decoder = std::make_unique<pomar::SelectiveDecoder>(std::make_unique<pomar::FileSource>(path),
                                                        options);
    damageReported = 0;
    pristine = true;
    haveSignature = false;
    clustered = decoder->info().clustered();
    base = clustered ? decoder->base_clustered_level() : 0;
    finest = decoder->finest_level();
    clusters = clustered ? decoder->cluster_count() : 0;
  }
  void fresh() {
    if (!pristine)
      open();
  }
  int clamp(int level) const { return std::min(finest, std::max(base, level)); }
};

PomarFilterPlugin::Session *PomarFilterPlugin::session(const std::string &path, bool skipDamaged,
                                                       QString &error) {
  const QFileInfo fi(QFile::decodeName(path.c_str()));
  if (!fi.exists() || !fi.isFile()) {
    sessions_.erase(path);
    error = QString("the layer's source file %1 does not exist any more").arg(fi.filePath());
    return nullptr;
  }
  const qint64 size = fi.size(), time = fi.lastModified().toMSecsSinceEpoch();
  auto it = sessions_.find(path);
  if (it != sessions_.end() && (it->second->fileSize != size || it->second->fileTime != time ||
                                it->second->skipDamaged != skipDamaged)) {
    sessions_.erase(it); // replaced on disk, or opened with the other damage policy: start over
    it = sessions_.end();
  }
  if (it == sessions_.end()) {
    auto s = std::make_unique<Session>();
    s->path = path;
    s->fileSize = size;
    s->fileTime = time;
    s->skipDamaged = skipDamaged;
    try {
      s->open();
    } catch (const std::exception &e) { // pomar::Error, std::bad_alloc
      error = pomar::meshlab::errorText(e, "cannot read " + fi.filePath());
      return nullptr;
    }
    while (sessions_.size() >= kMaxSessions) {
      auto oldest = sessions_.begin();
      for (auto i = sessions_.begin(); i != sessions_.end(); ++i)
        if (i->second->lastUse < oldest->second->lastUse)
          oldest = i;
      sessions_.erase(oldest);
    }
    it = sessions_.emplace(path, std::move(s)).first;
  }
  it->second->lastUse = ++clock_;
  return it->second.get();
}

namespace {

/// Brings the session's decoder to the state of the layer, unless it is there already:
/// a fresh decoder, the wanted levels from the layer's attributes (per cluster: the highest
/// level of its vertices), update(). Returns false (with `why`) if the layer has no usable
/// attributes. `how` says what happened, for the log.
bool syncToLayer(PomarFilterPlugin::Session &s, CMeshO &m, ProgressRelay &progress, QString &how,
                 QString &why) {
  const Signature current = signatureOf(m);
  if (s.haveSignature && s.signature == current) {
    how = "incremental, on the cached decoder state";
    return true;
  }
  const auto t0 = Clock::now();
  std::vector<int> cluster, level;
  if (!layerClustersAndLevels(m, s.clusters, s.finest, cluster, level, why))
    return false;
  s.fresh();
  if (s.clustered) {
    std::vector<int> wanted(s.clusters, s.base);
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (!m.vert[v].IsD() && cluster[v] >= 0)
        wanted[size_t(cluster[v])] = std::max(wanted[size_t(cluster[v])], level[v]);
    s.decoder->set_wanted(wanted);
  } else {
    int uniform = 0;
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (!m.vert[v].IsD())
        uniform = std::max(uniform, level[v]);
    s.decoder->clear_wanted();
    s.decoder->want_all(uniform);
  }
  s.pristine = false;
  s.haveSignature = false;
  s.decoder->update(progress.range(0, 50));
  s.signature = signatureOf(s.decoder->exact_mesh());
  s.haveSignature = true;
  how = QString("decoder state rebuilt from the layer's attributes in %1 ms")
            .arg(msSince(t0), 0, 'f', 1);
  if (s.signature != current)
    how += QString("; note: the layer (%1 vertices, %2 faces) differs from what the file decodes "
                   "to at its levels (%3 vertices, %4 faces), edits are replaced")
               .arg(current.vn)
               .arg(current.fn)
               .arg(s.signature.vn)
               .arg(s.signature.fn);
  return true;
}

/// Before Show Clusters / Show Levels paint the vertices: keep the layer's own colours aside
/// (once: painting twice keeps the first, the user's).
void keepOwnColours(CMeshO &m) {
  if (vcg::tri::Allocator<CMeshO>::IsValidHandle(m, pomar::meshlab::savedColours(m)))
    return;
  auto saved = vcg::tri::Allocator<CMeshO>::AddPerVertexAttribute<vcg::Color4b>(
      m, pomar::meshlab::kSavedColourAttribute);
  for (size_t v = 0; v < m.vert.size(); ++v)
    saved[v] = m.vert[v].C();
}

/// Replaces the layer's content by the decoder's current mesh (every cluster at the finest
/// level: exactly what was saved, a lossless record undone; otherwise the coded, cut mesh),
/// with the pomar attributes (-1 for a vertex no face uses); selects the vertices of the
/// clusters marked in `select` (if given) and the faces whose three vertices are selected.
void replaceMesh(PomarFilterPlugin::Session &s, MeshModel &mm, const std::vector<char> *select) {
  std::vector<uint32_t> from; // vertex of the decoder's mesh() each vertex comes from
  const pomar::Mesh mesh = s.decoder->exact_mesh(&from);
  const std::vector<uint32_t> cluster = s.decoder->vertex_cluster();
  const std::vector<uint32_t> level = s.decoder->vertex_level();
  // The attributes of each vertex of `mesh` (UINT32_MAX: a vertex no face uses).
  std::vector<uint32_t> clusterOf(mesh.vertex_count(), UINT32_MAX), levelOf = clusterOf;
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    if (from[v] < level.size()) {
      clusterOf[v] = s.clustered ? cluster[from[v]] : UINT32_MAX;
      levelOf[v] = level[from[v]];
    }
  CMeshO &m = mm.cm;
  // The decoded attributes of these vertices go with them (colour, normals, quality,
  // texture coordinates, named floats); texture coordinates are optional in CMeshO.
  if (mesh.find(pomar::AttributeKind::TexCoord))
    mm.updateDataMask(MeshModel::MM_VERTTEXCOORD);
  // Clear() + ClearAttributes() (saved colours of Show Clusters included), then the new
  // vertices and faces with their attributes.
  const int written = pomar::to_vcg(mesh, m);
  const bool ownColour = written & vcg::tri::io::Mask::IOM_VERTCOLOR;
  const bool ownQuality = written & vcg::tri::io::Mask::IOM_VERTQUALITY;
  const bool ownNormals = written & vcg::tri::io::Mask::IOM_VERTNORMAL;
  // The decoded colour, quality and texture coordinates enter the layer's data mask, which the
  // GUI renders from (vertex colour shown as soon as the layer is refreshed).
  mm.Enable(written);
  pomar::meshlab::setLayerAttributes(m, s.clustered ? clusterOf : std::vector<uint32_t>(), levelOf,
                                     s.path, s.skipDamaged);
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    if (!ownColour)
      m.vert[v].C() = vcg::Color4b(vcg::Color4b::White);
    if (!ownQuality)
      m.vert[v].Q() = 0;
    if (select != nullptr && s.clustered && clusterOf[v] != UINT32_MAX && (*select)[clusterOf[v]])
      m.vert[v].SetS();
  }
  const bool faceColor = vcg::tri::HasPerFaceColor(m);
  for (CFaceO &f : m.face) {
    if (faceColor)
      f.C() = vcg::Color4b(vcg::Color4b::White);
    if (select != nullptr && f.V(0)->IsS() && f.V(1)->IsS() && f.V(2)->IsS())
      f.SetS();
  }
  m.svn = int(vcg::tri::UpdateSelection<CMeshO>::VertexCount(m));
  m.sfn = int(vcg::tri::UpdateSelection<CMeshO>::FaceCount(m));
  if (ownNormals) { // the file's normals, not recomputed ones
    vcg::tri::UpdateBounding<CMeshO>::Box(m);
    if (m.fn > 0)
      vcg::tri::UpdateNormal<CMeshO>::PerFaceNormalized(m);
  } else {
    mm.UpdateBoxAndNormals();
  }
  s.signature = signatureOf(mesh);
  s.haveSignature = true;
}

} // namespace

// ---------------------------------------------------------------- declarations

PomarFilterPlugin::PomarFilterPlugin() {
  typeList << FP_REFINE_SELECTED << FP_COARSEN_SELECTED << FP_SET_LEVEL << FP_SHOW_CLUSTERS
           << FP_SHOW_LEVELS << FP_SHOW_ORIGINAL_COLOURS;
  for (FilterIDType id : types())
    actionList << new QAction(filterName(id), this);
}

PomarFilterPlugin::~PomarFilterPlugin() = default;

QString PomarFilterPlugin::pluginName() const { return "FilterPomar"; }

QString PomarFilterPlugin::filterName(FilterIDType filter) const {
  switch (filter) {
  case FP_REFINE_SELECTED:
    return "POMAR: Refine Selected Clusters";
  case FP_COARSEN_SELECTED:
    return "POMAR: Coarsen Selected Clusters";
  case FP_SET_LEVEL:
    return "POMAR: Set Level of Detail";
  case FP_SHOW_CLUSTERS:
    return "POMAR: Show Clusters";
  case FP_SHOW_LEVELS:
    return "POMAR: Show Levels";
  case FP_SHOW_ORIGINAL_COLOURS:
    return "POMAR: Show Original Colours";
  }
  return "Unknown POMAR filter";
}

QString PomarFilterPlugin::filterInfo(FilterIDType filter) const {
  const QString common =
      "<br><br>Works on a layer opened from a <i>.pomar</i> file (the file must still exist). "
      "Random access follows the POMAR paper: <i>Maglo, Grimstead, Hudelot</i>, "
      "<b>\"POMAR: Compression of progressive oriented meshes accessible randomly\"</b>, "
      "Computers &amp; Graphics 37(6), 2013.";
  switch (filter) {
  case FP_REFINE_SELECTED:
    return "Decodes the clusters of the selected faces up to <i>Target level</i> (default: the "
           "file's finest level), reading only their blocks of the file. Neighbouring clusters "
           "are refined just enough that adjacent clusters differ by at most one level. "
           "Clusters already finer stay as they are. Afterwards the selection is the faces "
           "whose vertices all belong to the requested clusters, so you can refine again or "
           "invert the selection." +
           common;
  case FP_COARSEN_SELECTED:
    return "Brings the clusters of the selected faces down to <i>Target level</i> (default: "
           "the base clustered level); the other clusters keep their levels, and neighbours of "
           "finer clusters stay at most one level coarser than them. Afterwards the selection "
           "is the faces of the coarsened clusters." +
           common;
  case FP_SET_LEVEL:
    return "Decodes the whole mesh at one level of detail: every cluster at <i>Level</i> "
           "(-1 or more than the finest level: full resolution; for a clustered file, levels "
           "below the base clustered level give the base clustered mesh)." +
           common;
  case FP_SHOW_CLUSTERS:
    return "Colours every vertex by its random-access cluster (a fixed colour per cluster id). "
           "The layer's own colours are kept aside: <i>Show Original Colours</i> puts them "
           "back, saving as .pomar saves them, and refining or coarsening restores the file's "
           "colours." +
           common;
  case FP_SHOW_LEVELS:
    return "Colours every vertex by the level of its cluster in the current level map: blue = "
           "the base clustered level (coarse) to red = the finest level (full resolution). "
           "The layer's own colours are kept aside as for <i>Show Clusters</i>." +
           common;
  case FP_SHOW_ORIGINAL_COLOURS:
    return "Puts back the vertex colours the layer had before <i>Show Clusters</i> or "
           "<i>Show Levels</i> (nothing to do if neither was applied since the last refine)." +
           common;
  }
  return QString();
}

MeshFilterInterface::FilterClass PomarFilterPlugin::getClass(QAction *a) {
  switch (ID(a)) {
  case FP_REFINE_SELECTED:
  case FP_COARSEN_SELECTED:
    return FilterClass(Remeshing | Selection);
  case FP_SET_LEVEL:
    return Remeshing;
  case FP_SHOW_CLUSTERS:
  case FP_SHOW_LEVELS:
  case FP_SHOW_ORIGINAL_COLOURS:
    return VertexColoring;
  }
  return Remeshing; // never Generic: MeshLab refuses to load a plugin with a Generic filter
}

MeshFilterInterface::FILTER_ARITY PomarFilterPlugin::filterArity(QAction *) const {
  return SINGLE_MESH;
}

int PomarFilterPlugin::getRequirements(QAction *a) {
  switch (ID(a)) {
  case FP_SHOW_CLUSTERS:
  case FP_SHOW_LEVELS:
  case FP_SHOW_ORIGINAL_COLOURS:
    return MeshModel::MM_VERTCOLOR;
  default:
    return MeshModel::MM_NONE;
  }
}

int PomarFilterPlugin::getPreConditions(QAction *a) const {
  switch (ID(a)) {
  case FP_REFINE_SELECTED:
  case FP_COARSEN_SELECTED:
    return MeshModel::MM_FACENUMBER;
  default:
    return MeshModel::MM_NONE;
  }
}

int PomarFilterPlugin::postCondition(QAction *a) const {
  switch (ID(a)) {
  case FP_SHOW_CLUSTERS:
  case FP_SHOW_LEVELS:
  case FP_SHOW_ORIGINAL_COLOURS:
    return MeshModel::MM_VERTCOLOR;
  default: // the mesh is replaced (includes the selection flags)
    return MeshModel::MM_GEOMETRY_AND_TOPOLOGY_CHANGE;
  }
}

void PomarFilterPlugin::initParameterSet(QAction *a, MeshModel &m, RichParameterList &par) {
  Session *s = nullptr;
  std::string path;
  QString ignored;
  const int id = ID(a);
  if ((id == FP_REFINE_SELECTED || id == FP_COARSEN_SELECTED || id == FP_SET_LEVEL) &&
      sourceOf(m.cm, path))
    s = session(path, skipsDamage(m.cm), ignored); // cheap: header and global part
  const QString range =
      s != nullptr ? QString(" This file: levels %1 (base clustered mesh) to %2 (full resolution).")
                         .arg(s->base)
                         .arg(s->finest)
                   : QString();
  switch (id) {
  case FP_REFINE_SELECTED:
    par.addParam(RichInt("TargetLevel", s != nullptr ? s->finest : kFinestPlaceholder,
                         "Target level",
                         "Level the clusters of the selected faces are refined to (clamped to "
                         "the file's levels; higher than the finest = the finest)." +
                             range));
    break;
  case FP_COARSEN_SELECTED:
    par.addParam(RichInt("TargetLevel", s != nullptr ? s->base : 0, "Target level",
                         "Level the clusters of the selected faces are coarsened to (clamped to "
                         "the file's levels; lower than the base clustered level = the base "
                         "clustered level)." +
                             range));
    break;
  case FP_SET_LEVEL:
    par.addParam(RichInt("Level", s != nullptr ? s->base : -1, "Level",
                         "Level of every cluster: -1 (or more than the finest level) = full "
                         "resolution; below the base clustered level = the base clustered "
                         "mesh." +
                             range));
    break;
  default:
    break;
  }
}

bool PomarFilterPlugin::fail(const QString &text) {
  errorMessage = text;
  pomar::meshlab::warn(*this, "POMAR: ", text);
  return false;
}

// ---------------------------------------------------------------- apply

bool PomarFilterPlugin::applyFilter(QAction *a, MeshDocument &md, const RichParameterList &par,
                                    vcg::CallBackPos *cb) {
  MeshModel *mm = md.mm();
  if (mm == nullptr)
    return fail("no current layer");
  std::string path;
  if (!sourceOf(mm->cm, path))
    return fail(QString("\"%1\" works only on a layer opened from a .pomar file; layer \"%2\" "
                        "has no pomar_source attribute (open the .pomar file itself; duplicated "
                        "layers and other formats lose it)")
                    .arg(filterName(a), mm->label()));
  const int id = ID(a);
  if (id == FP_SHOW_CLUSTERS)
    return showClusters(*mm);
  if (id == FP_SHOW_ORIGINAL_COLOURS)
    return showOriginalColours(*mm);

  QString error;
  Session *s = session(path, skipsDamage(mm->cm), error);
  if (s == nullptr)
    return fail(error);
  try {
    bool ok = false;
    switch (id) {
    case FP_REFINE_SELECTED:
      ok = refineOrCoarsen(true, *mm, *s, par.getInt("TargetLevel"), cb);
      break;
    case FP_COARSEN_SELECTED:
      ok = refineOrCoarsen(false, *mm, *s, par.getInt("TargetLevel"), cb);
      break;
    case FP_SET_LEVEL:
      ok = setLevel(*mm, *s, par.getInt("Level"), cb);
      break;
    case FP_SHOW_LEVELS:
      return showLevels(*mm, s);
    default:
      return fail("unknown filter");
    }
    warnAboutNewDamage(*s);
    return ok;
  } catch (const std::exception &e) { // pomar::Error (damaged file), std::bad_alloc
    // The decoder may be half way through an update: forget it. The layer is unchanged
    // (it is replaced only after a successful update).
    sessions_.erase(path);
    return fail(pomar::meshlab::errorText(e, QFile::decodeName(path.c_str())));
  }
}

/// Blocks the decoder skipped since the last report (layers opened with "Skip damaged
/// blocks"): one warning listing them.
void PomarFilterPlugin::warnAboutNewDamage(Session &s) {
  const std::vector<pomar::DamagedBlock> &damaged = s.decoder->damaged();
  if (damaged.size() <= s.damageReported)
    return;
  const QString text =
      QString("%1: %2 damaged block(s) skipped, the mesh stays coarser there:\n%3")
          .arg(QFile::decodeName(s.path.c_str()))
          .arg(damaged.size() - s.damageReported)
          .arg(QString::fromStdString(pomar::describe_damage(damaged, s.damageReported)));
  s.damageReported = damaged.size();
  pomar::meshlab::warn(*this, "POMAR: ", text);
}

bool PomarFilterPlugin::refineOrCoarsen(bool refine, MeshModel &mm, Session &s, int requested,
                                        vcg::CallBackPos *cb) {
  const auto t0 = Clock::now();
  const char *verb = refine ? "refine" : "coarsen";
  if (!s.clustered)
    return fail(QString("%1 is a pure progressive file: it has no clusters to %2; use \"POMAR: "
                        "Set Level of Detail\"")
                    .arg(QFile::decodeName(s.path.c_str()), verb));
  CMeshO &m = mm.cm;
  std::vector<int> cluster, level;
  QString why;
  if (!layerClustersAndLevels(m, s.clusters, s.finest, cluster, level, why))
    return fail(QString("cannot %1: %2").arg(verb, why));

  // The clusters of the selected faces (or, with no face selected, of the selected vertices).
  std::vector<char> chosen(s.clusters, 0);
  size_t faces = 0;
  for (const CFaceO &f : m.face) {
    if (f.IsD() || !f.IsS())
      continue;
    ++faces;
    for (int k = 0; k < f.VN(); ++k) {
      const size_t v = pomar::vertex_position(m, f.cV(k));
      if (v < cluster.size() && cluster[v] >= 0)
        chosen[size_t(cluster[v])] = 1;
    }
  }
  size_t vertices = 0;
  if (faces == 0)
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (!m.vert[v].IsD() && m.vert[v].IsS() && cluster[v] >= 0) {
        ++vertices;
        chosen[size_t(cluster[v])] = 1;
      }
  const size_t count = size_t(std::count(chosen.begin(), chosen.end(), 1));
  if (count == 0)
    return fail(QString("nothing selected: select the faces of the region to %1 first").arg(verb));

  const int target = s.clamp(requested);
  if (target != requested)
    Log("POMAR: target level %d clamped to %d (this file has levels %d..%d)", requested, target,
        s.base, s.finest);

  ProgressRelay progress(cb, refine ? "POMAR: refining" : "POMAR: coarsening");
  progress.report(0);
  QString how;
  if (!syncToLayer(s, m, progress, how, why))
    return fail(QString("cannot %1: %2").arg(verb, why));
  pomar::SelectiveDecoder &d = *s.decoder;
  const std::vector<int> before = d.levels();
  const uint64_t bytes0 = d.bytes_read();
  const auto t1 = Clock::now();
  if (refine) {
    for (uint32_t c = 0; c < s.clusters; ++c)
      if (chosen[c])
        d.want_cluster(c, target);
  } else {
    std::vector<int> wanted = before;
    for (uint32_t c = 0; c < s.clusters; ++c)
      if (chosen[c])
        wanted[c] = std::min(wanted[c], target);
    d.set_wanted(wanted);
  }
  d.update(progress.range(50, 95));
  const double decodeMs = msSince(t1);
  const std::vector<int> &after = d.levels();
  size_t changed = 0, reached = 0;
  for (uint32_t c = 0; c < s.clusters; ++c) {
    changed += after[c] != before[c];
    reached += chosen[c] && after[c] == target;
  }
  replaceMesh(s, mm, &chosen);
  progress.done();

  const double ms = msSince(t0);
  Log("POMAR: %s %zu clusters in %.1f ms (to level %d, from %zu selected %s; %s; decode %.1f "
      "ms): %zu clusters changed level, %zu of the %zu at level %d%s; %d vertices, %d faces; "
      "read %.1f KB more of the file (%u cluster blocks so far)",
      refine ? "refined" : "coarsened", count, ms, target, faces > 0 ? faces : vertices,
      faces > 0 ? "faces" : "vertices", qUtf8Printable(how), decodeMs, changed, reached, count,
      target,
      reached < count ? (refine ? " (the others were finer already)"
                                : " (the level map keeps neighbouring clusters at most one level "
                                  "apart)")
                      : "",
      m.vn, m.fn, double(d.bytes_read() - bytes0) / 1024.0, d.blocks_read());
  return true;
}

bool PomarFilterPlugin::setLevel(MeshModel &mm, Session &s, int requested, vcg::CallBackPos *cb) {
  const auto t0 = Clock::now();
  int level = requested < 0 || requested > s.finest ? s.finest : requested;
  if (level < s.base) {
    Log("POMAR: level %d is below the base clustered level: using %d (levels %d..%d)", requested,
        s.base, s.base, s.finest);
    level = s.base;
  }
  ProgressRelay progress(cb, "POMAR: setting the level of detail");
  progress.report(0);
  // Any state of the decoder will do: the request fixes every cluster's level.
  pomar::SelectiveDecoder &d = *s.decoder;
  const uint64_t bytes0 = d.bytes_read();
  if (s.clustered) {
    d.set_wanted(std::vector<int>(s.clusters, level));
  } else {
    d.clear_wanted();
    d.want_all(level);
  }
  s.pristine = false;
  s.haveSignature = false;
  d.update(progress.range(0, 95));
  const double decodeMs = msSince(t0);
  replaceMesh(s, mm, nullptr);
  progress.done();
  Log("POMAR: set level of detail %d%s in %.1f ms (decode %.1f ms): %d vertices, %d faces; read "
      "%.1f KB more of the file",
      level,
      level == s.finest ? " (full resolution)"
      : level == s.base ? " (base clustered)"
                        : "",
      msSince(t0), decodeMs, mm.cm.vn, mm.cm.fn, double(d.bytes_read() - bytes0) / 1024.0);
  return true;
}

bool PomarFilterPlugin::showClusters(MeshModel &mm) {
  CMeshO &m = mm.cm;
  auto ch = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(m, kClusterAttr);
  if (!vcg::tri::Allocator<CMeshO>::IsValidHandle(m, ch))
    return fail("the layer has no per-vertex pomar_cluster attribute");
  std::set<int> seen;
  const std::vector<char> used = usedVertices(m);
  for (size_t v = 0; v < m.vert.size(); ++v) {
    if (m.vert[v].IsD() || (!used[v] && ch[v] == -1.0f)) // a vertex no face uses: no cluster
      continue;
    const float c = ch[v];
    if (!(c >= 0 && c == std::floor(c) && c < 16777216.0f))
      return fail(QString("vertex %1 has no cluster (pomar_cluster = %2): a pure progressive "
                          "file, or a layer opened below the base clustered level")
                      .arg(v)
                      .arg(double(c)));
  }
  mm.updateDataMask(MeshModel::MM_VERTCOLOR);
  keepOwnColours(m);
  for (size_t v = 0; v < m.vert.size(); ++v) {
    if (m.vert[v].IsD())
      continue;
    if (ch[v] < 0) { // a vertex no face uses
      m.vert[v].C() = vcg::Color4b(vcg::Color4b::Gray);
      continue;
    }
    m.vert[v].C() = clusterColor(uint32_t(ch[v]));
    seen.insert(int(ch[v]));
  }
  Log("POMAR: coloured %zu clusters", seen.size());
  return true;
}

bool PomarFilterPlugin::showLevels(MeshModel &mm, Session *s) {
  const auto t0 = Clock::now();
  CMeshO &m = mm.cm;
  std::vector<int> cluster, level;
  QString how, why;
  if (!layerClustersAndLevels(m, s->clusters, s->finest, cluster, level, why))
    return fail(QString("cannot show the levels: %1").arg(why));
  ProgressRelay progress(nullptr, "");
  if (!syncToLayer(*s, m, progress, how, why))
    return fail(QString("cannot show the levels: %1").arg(why));
  mm.updateDataMask(MeshModel::MM_VERTCOLOR);
  keepOwnColours(m);
  const int span = std::max(1, s->finest - s->base);
  std::vector<size_t> histogram(size_t(s->finest + 1), 0);
  if (s->clustered) {
    const std::vector<int> &levels = s->decoder->levels();
    for (int l : levels)
      ++histogram[size_t(l)];
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (!m.vert[v].IsD() && cluster[v] >= 0) // (not a vertex no face uses)
        m.vert[v].C() = levelColor(double(levels[size_t(cluster[v])] - s->base) / span);
  } else {
    int uniform = 0;
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (!m.vert[v].IsD())
        uniform = std::max(uniform, level[v]);
    histogram[size_t(uniform)] = 1;
    for (CVertexO &v : m.vert)
      if (!v.IsD())
        v.C() = levelColor(double(uniform) / span);
  }
  QStringList parts;
  for (size_t l = 0; l < histogram.size(); ++l)
    if (histogram[l] > 0)
      parts << QString("level %1: %2").arg(l).arg(histogram[l]);
  Log("POMAR: levels shown (blue = level %d, red = level %d) in %.1f ms; %s %s; %s", s->base,
      s->finest, msSince(t0), s->clustered ? "clusters per level:" : "pure progressive file,",
      qUtf8Printable(parts.join(", ")), qUtf8Printable(how));
  return true;
}

bool PomarFilterPlugin::showOriginalColours(MeshModel &mm) {
  CMeshO &m = mm.cm;
  auto saved = pomar::meshlab::savedColours(m);
  if (!vcg::tri::Allocator<CMeshO>::IsValidHandle(m, saved)) {
    Log("POMAR: the layer shows its own colours already");
    return true;
  }
  for (size_t v = 0; v < m.vert.size(); ++v)
    m.vert[v].C() = saved[v];
  vcg::tri::Allocator<CMeshO>::DeletePerVertexAttribute(m, saved);
  Log("POMAR: original colours restored");
  return true;
}

// One heavy translation unit instead of two (AUTOMOC compiles this in place of mocs_compilation).
#include "moc_filter_pomar.cpp"
