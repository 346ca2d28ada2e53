// What the MeshLab filter plugin's filters do (meshlab_plugin/, libfilter_pomar.so) on a layer
// opened from a .pomar file: refine or coarsen the clusters of the selection, set one level of
// detail, colour the vertices by cluster or by level and put the layer's colours back. Each
// returns "" when done, or why it refused (the plugin's errorMessage); they log what they did
// through the plugin (MeshLabInterface::Log) and throw pomar::Error or std::bad_alloc when the
// decoder fails (the session is then no longer usable).
//
// Part of the plugins' boundary layer (pomar/meshlab_*.h, see meshlab_layer.h).
#pragma once

#include <pomar/meshlab_layer.h>
#include <pomar/meshlab_session.h>
#include <pomar/pomar.h>
#include <pomar/random_access.h>
#include <pomar/vcg_adapter.h>

#include <common/interfaces.h>
#include <common/meshmodel.h>
#include <vcg/complex/allocate.h>
#include <vcg/space/color4.h>

#include <QFile>
#include <QString>
#include <QStringList>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

namespace pomar::meshlab {

// ---------------------------------------------------------------- colours

namespace filter_detail {

inline uint64_t mix64(uint64_t x) { // splitmix64 finalizer
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

} // namespace filter_detail

/// A deterministic, well spread colour per cluster id.
inline vcg::Color4b clusterColor(uint32_t c) {
  const uint64_t h = filter_detail::mix64(c);
  vcg::Color4b col;
  col.SetHSVColor(float(h & 0xFFFF) / 65536.0f, 0.45f + 0.5f * float((h >> 16) & 0xFF) / 255.0f,
                  0.7f + 0.3f * float((h >> 24) & 0xFF) / 255.0f);
  return col;
}

/// Colour ramp of t in [0,1]: blue (coarse) - cyan - green - yellow - red (fine).
inline vcg::Color4b levelColor(double t) {
  t = std::min(1.0, std::max(0.0, t));
  vcg::Color4b col;
  col.SetHSVColor(float((1.0 - t) * 2.0 / 3.0), 1.0f, 1.0f);
  return col;
}

// ---------------------------------------------------------------- messages

/// Why a filter refuses a layer without a pomar_source attribute.
inline QString notAPomarLayer(const QString &filter, const QString &layer) {
  return QString("\"%1\" works only on a layer opened from a .pomar file; layer \"%2\" has no "
                 "pomar_source attribute (open the .pomar file itself; duplicated layers and "
                 "other formats lose it)")
      .arg(filter, layer);
}

/// Blocks the decoder skipped since the last report (layers opened with "Skip damaged
/// blocks"): one warning listing them.
inline void warnAboutNewDamage(MeshLabInterface &plugin, Session &s) {
  const std::vector<pomar::DamagedBlock> &damaged = s.decoder->damaged();
  if (damaged.size() <= s.damageReported)
    return;
  const QString text =
      QString("%1: %2 damaged block(s) skipped, the mesh stays coarser there:\n%3")
          .arg(QFile::decodeName(s.path.c_str()))
          .arg(damaged.size() - s.damageReported)
          .arg(QString::fromStdString(pomar::describe_damage(damaged, s.damageReported)));
  s.damageReported = damaged.size();
  warn(plugin, "POMAR: ", text);
}

// ---------------------------------------------------------------- refine / coarsen

/// The clusters a refine or coarsen works on.
struct ClusterSelection {
  std::vector<char> chosen; ///< per cluster
  size_t count = 0;         ///< clusters chosen
  size_t faces = 0;         ///< selected faces they come from, or
  size_t vertices = 0;      ///< with no face selected, selected vertices
};

namespace filter_detail {

/// The clusters of the selected faces (or, with no face selected, of the selected vertices)
/// and the clusters linked to them (rooted at copies of one texture seam vertex, of which a
/// layer at full resolution shows one): the level map gives linked clusters one level, so
/// coarsening one without its twin would leave both where they are.
inline ClusterSelection selectedClusters(const CMeshO &m, const std::vector<int> &cluster,
                                         Session &s) {
  ClusterSelection out;
  std::vector<char> &chosen = out.chosen;
  chosen.assign(s.clusters, 0);
  for (const CFaceO &f : m.face) {
    if (f.IsD() || !f.IsS())
      continue;
    ++out.faces;
    for (int k = 0; k < f.VN(); ++k) {
      const size_t v = pomar::vertex_position(m, f.cV(k));
      if (v < cluster.size() && cluster[v] >= 0)
        chosen[size_t(cluster[v])] = 1;
    }
  }
  if (out.faces == 0)
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (!m.vert[v].IsD() && m.vert[v].IsS() && cluster[v] >= 0) {
        ++out.vertices;
        chosen[size_t(cluster[v])] = 1;
      }
  std::vector<uint32_t> linkStart, link;
  s.decoder->cluster_links(linkStart, link);
  const std::vector<char> selected = chosen;
  for (uint32_t c = 0; c < s.clusters; ++c)
    if (selected[c])
      for (uint32_t i = linkStart[c]; i < linkStart[c + 1]; ++i)
        chosen[link[i]] = 1;
  out.count = size_t(std::count(chosen.begin(), chosen.end(), 1));
  return out;
}

/// Refine: the chosen clusters up to `target` (the level map completes the rest). Coarsen:
/// the current level map, lowered to `target` for the chosen clusters.
inline void requestLevels(pomar::SelectiveDecoder &d, bool refine, const std::vector<char> &chosen,
                          int target) {
  if (refine) {
    for (uint32_t c = 0; c < chosen.size(); ++c)
      if (chosen[c])
        d.want_cluster(c, target);
    return;
  }
  std::vector<int> wanted = d.levels();
  for (uint32_t c = 0; c < chosen.size(); ++c)
    if (chosen[c])
      wanted[c] = std::min(wanted[c], target);
  d.set_wanted(wanted);
}

} // namespace filter_detail

/// "POMAR: Refine Selected Clusters" (refine) and "POMAR: Coarsen Selected Clusters": the
/// clusters of the selection go up (down) to `requested`, clamped to the file's levels;
/// afterwards the selection is the faces whose three vertices are in those clusters.
inline QString refineOrCoarsen(MeshLabInterface &plugin, bool refine, MeshModel &mm, Session &s,
                               int requested, vcg::CallBackPos *cb) {
  const auto t0 = Clock::now();
  const char *verb = refine ? "refine" : "coarsen";
  if (!s.clustered)
    return QString("%1 is a pure progressive file: it has no clusters to %2; use \"POMAR: "
                   "Set Level of Detail\"")
        .arg(QFile::decodeName(s.path.c_str()), verb);
  CMeshO &m = mm.cm;
  std::vector<int> cluster, level;
  QString why;
  if (!layerClustersAndLevels(m, s.clusters, s.finest, cluster, level, why))
    return QString("cannot %1: %2").arg(verb, why);
  const ClusterSelection selection = filter_detail::selectedClusters(m, cluster, s);
  if (selection.count == 0)
    return QString("nothing selected: select the faces of the region to %1 first").arg(verb);
  const int target = s.clamp(requested);
  if (target != requested)
    plugin.Log("POMAR: target level %d clamped to %d (this file has levels %d..%d)", requested,
               target, s.base, s.finest);

  ProgressRelay progress(cb, refine ? "POMAR: refining" : "POMAR: coarsening");
  progress.report(0);
  QString how;
  if (!syncToLayer(s, m, progress, how, why))
    return QString("cannot %1: %2").arg(verb, why);
  pomar::SelectiveDecoder &d = *s.decoder;
  const std::vector<int> before = d.levels();
  const uint64_t bytes0 = d.bytes_read();
  const auto t1 = Clock::now();
  filter_detail::requestLevels(d, refine, selection.chosen, target);
  d.update(progress.range(50, 95));
  const double decodeMs = msSince(t1);
  const std::vector<int> &after = d.levels();
  size_t changed = 0, reached = 0;
  for (uint32_t c = 0; c < s.clusters; ++c) {
    changed += after[c] != before[c];
    reached += selection.chosen[c] && after[c] == target;
  }
  replaceLayer(s, mm, &selection.chosen);
  progress.done();

  const size_t count = selection.count;
  const bool byFaces = selection.faces > 0;
  plugin.Log(
      "POMAR: %s %zu clusters in %.1f ms (to level %d, from %zu selected %s; %s; decode %.1f "
      "ms): %zu clusters changed level, %zu of the %zu at level %d%s; %d vertices, %d faces; "
      "read %.1f KB more of the file (%u cluster blocks so far)",
      refine ? "refined" : "coarsened", count, msSince(t0), target,
      byFaces ? selection.faces : selection.vertices, byFaces ? "faces" : "vertices",
      qUtf8Printable(how), decodeMs, changed, reached, count, target,
      reached < count ? (refine ? " (the others were finer already)"
                                : " (the level map keeps neighbouring clusters at most one level "
                                  "apart)")
                      : "",
      m.vn, m.fn, double(d.bytes_read() - bytes0) / 1024.0, d.blocks_read());
  return QString();
}

// ---------------------------------------------------------------- set level of detail

/// "POMAR: Set Level of Detail": every cluster at `requested` (-1 or above the finest: full
/// resolution; below the base clustered level: the base clustered mesh).
inline QString setLevel(MeshLabInterface &plugin, MeshModel &mm, Session &s, int requested,
                        vcg::CallBackPos *cb) {
  const auto t0 = Clock::now();
  int level = requested < 0 || requested > s.finest ? s.finest : requested;
  if (level < s.base) {
    plugin.Log("POMAR: level %d is below the base clustered level: using %d (levels %d..%d)",
               requested, s.base, s.base, s.finest);
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
  s.willUpdate();
  d.update(progress.range(0, 95));
  const double decodeMs = msSince(t0);
  replaceLayer(s, mm, nullptr);
  progress.done();
  plugin.Log("POMAR: set level of detail %d%s in %.1f ms (decode %.1f ms): %d vertices, %d "
             "faces; read %.1f KB more of the file",
             level,
             level == s.finest ? " (full resolution)"
             : level == s.base ? " (base clustered)"
                               : "",
             msSince(t0), decodeMs, mm.cm.vn, mm.cm.fn, double(d.bytes_read() - bytes0) / 1024.0);
  return QString();
}

// ---------------------------------------------------------------- show filters

/// "POMAR: Show Clusters": a colour per cluster id (grey for a vertex no face uses), the
/// layer's own colours kept aside.
inline QString showClusters(MeshLabInterface &plugin, MeshModel &mm) {
  CMeshO &m = mm.cm;
  auto ch = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(m, kClusterAttribute);
  if (!vcg::tri::Allocator<CMeshO>::IsValidHandle(m, ch))
    return "the layer has no per-vertex pomar_cluster attribute";
  const std::vector<char> used = usedVertices(m);
  for (size_t v = 0; v < m.vert.size(); ++v) {
    if (m.vert[v].IsD() || (!used[v] && ch[v] == -1.0f)) // a vertex no face uses: no cluster
      continue;
    const float c = ch[v];
    if (!(c >= 0 && c == std::floor(c) && c < 16777216.0f))
      return QString("vertex %1 has no cluster (pomar_cluster = %2): a pure progressive "
                     "file, or a layer opened below the base clustered level")
          .arg(v)
          .arg(double(c));
  }
  mm.updateDataMask(MeshModel::MM_VERTCOLOR);
  keepOwnColours(m);
  std::set<int> seen;
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
  plugin.Log("POMAR: coloured %zu clusters", seen.size());
  return QString();
}

namespace filter_detail {

/// Paints each vertex with the level of its cluster (a pure progressive file: the layer's one
/// level); returns the number of clusters per level (for a pure progressive file, 1 at its
/// level).
inline std::vector<size_t> paintLevels(CMeshO &m, const Session &s, const std::vector<int> &cluster,
                                       const std::vector<int> &level) {
  const int span = std::max(1, s.finest - s.base);
  std::vector<size_t> histogram(size_t(s.finest + 1), 0);
  if (s.clustered) {
    const std::vector<int> &levels = s.decoder->levels();
    for (int l : levels)
      ++histogram[size_t(l)];
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (!m.vert[v].IsD() && cluster[v] >= 0) // (not a vertex no face uses)
        m.vert[v].C() = levelColor(double(levels[size_t(cluster[v])] - s.base) / span);
    return histogram;
  }
  int uniform = 0;
  for (size_t v = 0; v < m.vert.size(); ++v)
    if (!m.vert[v].IsD())
      uniform = std::max(uniform, level[v]);
  histogram[size_t(uniform)] = 1;
  for (CVertexO &v : m.vert)
    if (!v.IsD())
      v.C() = levelColor(double(uniform) / span);
  return histogram;
}

} // namespace filter_detail

/// "POMAR: Show Levels": the level of each vertex's cluster, blue (base clustered level) to
/// red (finest), the layer's own colours kept aside.
inline QString showLevels(MeshLabInterface &plugin, MeshModel &mm, Session &s) {
  const auto t0 = Clock::now();
  CMeshO &m = mm.cm;
  std::vector<int> cluster, level;
  QString how, why;
  if (!layerClustersAndLevels(m, s.clusters, s.finest, cluster, level, why))
    return QString("cannot show the levels: %1").arg(why);
  ProgressRelay progress(nullptr, "");
  if (!syncToLayer(s, m, progress, how, why))
    return QString("cannot show the levels: %1").arg(why);
  mm.updateDataMask(MeshModel::MM_VERTCOLOR);
  keepOwnColours(m);
  const std::vector<size_t> histogram = filter_detail::paintLevels(m, s, cluster, level);
  QStringList parts;
  for (size_t l = 0; l < histogram.size(); ++l)
    if (histogram[l] > 0)
      parts << QString("level %1: %2").arg(l).arg(histogram[l]);
  plugin.Log("POMAR: levels shown (blue = level %d, red = level %d) in %.1f ms; %s %s; %s", s.base,
             s.finest, msSince(t0), s.clustered ? "clusters per level:" : "pure progressive file,",
             qUtf8Printable(parts.join(", ")), qUtf8Printable(how));
  return QString();
}

/// "POMAR: Show Original Colours": the colours the layer had before Show Clusters / Show
/// Levels.
inline QString showOriginalColours(MeshLabInterface &plugin, MeshModel &mm) {
  CMeshO &m = mm.cm;
  auto saved = savedColours(m);
  if (!vcg::tri::Allocator<CMeshO>::IsValidHandle(m, saved)) {
    plugin.Log("POMAR: the layer shows its own colours already");
    return QString();
  }
  for (size_t v = 0; v < m.vert.size(); ++v)
    m.vert[v].C() = saved[v];
  vcg::tri::Allocator<CMeshO>::DeletePerVertexAttribute(m, saved);
  plugin.Log("POMAR: original colours restored");
  return QString();
}

} // namespace pomar::meshlab
