// A MeshLab layer opened from a .pomar file: what the IO plugin (io_plugin/) and the filter
// plugin (meshlab_plugin/) agree on about it. The names of the attributes the IO plugin
// writes and the filters read, filling a layer from a decoded mesh, the layer's own colours
// while a Show filter paints it, the relay of the codec's progress to MeshLab's callback,
// warnings, and error messages.
//
// Part of the plugins' boundary layer (pomar/meshlab_*.h): compiled only against MeshLab
// 2020.09's headers (MESHLAB_SCALAR=float, cmake/MeshLabPlugin.cmake) and not installed with
// the library.
#pragma once

#include <pomar/pomar.h>
#include <pomar/vcg_adapter.h>

#include <common/interfaces.h>
#include <common/meshmodel.h>
#include <vcg/complex/allocate.h>
#include <vcg/complex/complex.h>

#include <QString>
#include <QtGlobal>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <string>
#include <utility>
#include <vector>

namespace pomar::meshlab {

constexpr const char *kClusterAttribute = "pomar_cluster"; ///< per vertex, float (-1: none)
constexpr const char *kLevelAttribute = "pomar_level";     ///< per vertex, float (-1: unknown)
constexpr const char *kSourceAttribute = "pomar_source";   ///< per mesh, absolute path
/// per mesh, int: 1 if the layer was opened with "Skip damaged blocks" (the filters then
/// decode around damaged blocks too)
constexpr const char *kSkipDamagedAttribute = "pomar_skip_damaged";
/// per vertex, vcg::Color4b: the layer's own colours while "Show Clusters" / "Show Levels"
/// paint the vertices; "Show Original Colours" puts them back, saving uses them.
constexpr const char *kSavedColourAttribute = "pomar_saved_colour";

/// The attributes above: a .pomar file re-creates them, saving does not lose them.
inline bool isPomarAttribute(const std::string &name) {
  for (const char *own : {kClusterAttribute, kLevelAttribute, kSourceAttribute,
                          kSkipDamagedAttribute, kSavedColourAttribute})
    if (name == own)
      return true;
  return false;
}

// ---------------------------------------------------------------- the layer's attributes

/// Writes the attributes of a layer decoded from `source`: per vertex its cluster and the
/// level that created it (-1 where unknown: `cluster` / `level` not one per vertex, as for a
/// pure progressive file's clusters), per mesh the source file and the damage policy.
template <class MeshType>
void setLayerAttributes(MeshType &m, const std::vector<uint32_t> &cluster,
                        const std::vector<uint32_t> &level, const std::string &source,
                        bool skipDamaged) {
  using Alloc = vcg::tri::Allocator<MeshType>;
  auto clusterOf = Alloc::template GetPerVertexAttribute<float>(m, kClusterAttribute);
  auto levelOf = Alloc::template GetPerVertexAttribute<float>(m, kLevelAttribute);
  const bool haveClusters = cluster.size() == m.vert.size();
  const bool haveLevels = level.size() == m.vert.size();
  for (size_t v = 0; v < m.vert.size(); ++v) { // -1: none (UINT32_MAX: a vertex no face uses)
    clusterOf[v] = haveClusters && cluster[v] != UINT32_MAX ? float(cluster[v]) : -1.0f;
    levelOf[v] = haveLevels && level[v] != UINT32_MAX ? float(level[v]) : -1.0f;
  }
  Alloc::template GetPerMeshAttribute<std::string>(m, kSourceAttribute)() = source;
  Alloc::template GetPerMeshAttribute<int>(m, kSkipDamagedAttribute)() = skipDamaged ? 1 : 0;
}

/// The layer's source file (the per-mesh pomar_source attribute); false if it has none.
inline bool sourceOf(CMeshO &m, std::string &path) {
  auto h = vcg::tri::Allocator<CMeshO>::FindPerMeshAttribute<std::string>(m, kSourceAttribute);
  if (!vcg::tri::Allocator<CMeshO>::IsValidHandle(m, h) || h().empty())
    return false;
  path = h();
  return true;
}

/// Whether the layer was opened with "Skip damaged blocks".
inline bool skipsDamage(CMeshO &m) {
  auto h = vcg::tri::Allocator<CMeshO>::FindPerMeshAttribute<int>(m, kSkipDamagedAttribute);
  return vcg::tri::Allocator<CMeshO>::IsValidHandle(m, h) && h() != 0;
}

// ---------------------------------------------------------------- filling a layer

/// Enables the optional CMeshO data that pomar::to_vcg fills from `mesh` (per-vertex and
/// per-wedge texture coordinates): to_vcg writes only where the mesh has room.
inline void enableRoomFor(const pomar::Mesh &mesh, MeshModel &mm) {
  if (mesh.find(pomar::AttributeKind::TexCoord))
    mm.updateDataMask(MeshModel::MM_VERTTEXCOORD);
  if (!mesh.corner_texcoords.empty())
    mm.updateDataMask(MeshModel::MM_WEDGTEXCOORD);
}

/// Replaces the layer's content by `mesh` with the pomar attributes (setLayerAttributes):
/// m.Clear() and m.ClearAttributes() (pomar::to_vcg), the vertices and faces with the decoded
/// attributes (colour, normals, quality, texture coordinates, named floats, each corner's
/// texture coordinates in its wedge with the face's texture). What was written enters the
/// layer's data mask as well (MeshModel::Enable): the GUI picks the rendering (vertex colour,
/// wedge texture, ...) from that mask. Returns to_vcg's mask of what was written.
inline int fillLayer(MeshModel &mm, const pomar::Mesh &mesh, const std::vector<uint32_t> &cluster,
                     const std::vector<uint32_t> &level, const std::string &source,
                     bool skipDamaged) {
  enableRoomFor(mesh, mm);
  const int written = pomar::to_vcg(mesh, mm.cm);
  mm.Enable(written);
  setLayerAttributes(mm.cm, cluster, level, source, skipDamaged);
  return written;
}

// ---------------------------------------------------------------- the layer's own colours

/// The layer's own colours saved by Show Clusters / Show Levels (invalid handle if none).
inline CMeshO::PerVertexAttributeHandle<vcg::Color4b> savedColours(CMeshO &m) {
  return vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<vcg::Color4b>(m,
                                                                           kSavedColourAttribute);
}

/// Before Show Clusters / Show Levels paint the vertices: keep the layer's own colours aside
/// (once: painting twice keeps the first, the user's).
inline void keepOwnColours(CMeshO &m) {
  if (vcg::tri::Allocator<CMeshO>::IsValidHandle(m, savedColours(m)))
    return;
  auto saved =
      vcg::tri::Allocator<CMeshO>::AddPerVertexAttribute<vcg::Color4b>(m, kSavedColourAttribute);
  for (size_t v = 0; v < m.vert.size(); ++v)
    saved[v] = m.vert[v].C();
}

/// Swap the vertex colours with the saved ones (no-op without saved colours).
inline void swapSavedColours(CMeshO &m) {
  auto saved = savedColours(m);
  if (!vcg::tri::Allocator<CMeshO>::IsValidHandle(m, saved))
    return;
  for (size_t v = 0; v < m.vert.size(); ++v)
    std::swap(m.vert[v].C(), saved[v]);
}

// ---------------------------------------------------------------- messages and progress

/// A warning in MeshLab's log (with `logPrefix`) and on stderr ("pomar: "): Log() is a
/// no-op in meshlabserver.
inline void warn(MeshLabInterface &plugin, const char *logPrefix, const QString &text) {
  plugin.Log(GLLogStream::WARNING, qUtf8Printable(logPrefix + text));
  qWarning("pomar: %s", qUtf8Printable(text));
}

/// The message of a failure while working on a file: the codec's message as it is when it
/// names the file already (pomar::Error::path()), else "<context>: <message>".
inline QString errorText(const std::exception &e, const QString &context) {
  const QString what = QString::fromStdString(pomar::printable(e.what())); // (file-derived text)
  const auto *error = dynamic_cast<const pomar::Error *>(&e);
  if (error != nullptr && !error->path().empty())
    return what;
  return QString("%1: %2").arg(context, what);
}

/// Forwards progress to MeshLab's callback at most every 10% (meshlabserver prints the
/// label on every call).
class ProgressRelay {
public:
  ProgressRelay(vcg::CallBackPos *cb, const char *label) : cb_(cb), label_(label) {}
  void report(int pct) {
    if (cb_ != nullptr && pct / 10 != last_ / 10) {
      last_ = pct;
      (*cb_)(pct, label_);
    }
  }
  /// The codec's fraction in [0,1], mapped into [from, to] percent.
  Progress range(int from, int to) {
    if (cb_ == nullptr)
      return {};
    return [this, from, to](double fraction, const char *) {
      const double f = std::isfinite(fraction) ? std::min(1.0, std::max(0.0, fraction)) : 0.0;
      report(from + int(f * (to - from)));
    };
  }
  Progress function() { return range(0, 100); }
  /// The end: 100% with an empty label, which clears the label from MeshLab's status bar
  /// (it would keep showing it). The destructor calls it if nobody did.
  void done() {
    if (cb_ != nullptr && !done_) {
      done_ = true;
      (*cb_)(100, "");
    }
  }
  ~ProgressRelay() { done(); }
  ProgressRelay(const ProgressRelay &) = delete;
  ProgressRelay &operator=(const ProgressRelay &) = delete;

private:
  vcg::CallBackPos *cb_;
  const char *label_;
  int last_ = -100;
  bool done_ = false;
};

} // namespace pomar::meshlab
