// The MeshLab filter plugin's decoders (meshlab_plugin/, libfilter_pomar.so): one
// pomar::SelectiveDecoder per .pomar file, kept between filter calls. When the layer is
// still what the decoder produced last (same counts, positions and triangles: its
// Signature), a refinement decodes only what is missing on top of the decoder's state;
// otherwise a fresh decoder is brought to the levels recorded in the layer's pomar_cluster /
// pomar_level attributes first (syncToLayer). replaceLayer puts the decoder's mesh into the
// layer.
//
// Part of the plugins' boundary layer (pomar/meshlab_*.h, see meshlab_layer.h).
#pragma once

#include <pomar/meshlab_layer.h>
#include <pomar/pomar.h>
#include <pomar/random_access.h>
#include <pomar/vcg_adapter.h>

#include <common/meshmodel.h>
#include <vcg/complex/algorithms/update/bounding.h>
#include <vcg/complex/algorithms/update/normal.h>
#include <vcg/complex/algorithms/update/selection.h>
#include <vcg/complex/allocate.h>

#include <QFile>
#include <QFileInfo>
#include <QString>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace pomar::meshlab {

using Clock = std::chrono::steady_clock;

inline double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// ---------------------------------------------------------------- mesh signature

/// What identifies a mesh produced by a decoder: counts plus a hash of the positions (bit
/// patterns) and the triangles, both in order. A layer that still has the signature of the
/// decoder's last output can be refined on top of the decoder's state.
struct Signature {
  uint64_t vn = 0, fn = 0, hash = 0;
  bool operator==(const Signature &o) const { return vn == o.vn && fn == o.fn && hash == o.hash; }
  bool operator!=(const Signature &o) const { return !(*this == o); }
};

class SignatureHasher {
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

inline Signature signatureOf(const pomar::Mesh &mesh) {
  SignatureHasher h;
  for (float x : mesh.positions)
    h.add(x);
  for (uint32_t i : mesh.triangles)
    h.add(i);
  return {mesh.vertex_count(), mesh.triangle_count(), h.value()};
}

/// The same for a MeshLab mesh: live elements only, vertices renumbered in order (what
/// pomar::from_vcg would give, without dropping unreferenced vertices).
inline Signature signatureOf(const CMeshO &m) {
  constexpr uint32_t kNone = UINT32_MAX;
  std::vector<uint32_t> index(m.vert.size(), kNone);
  SignatureHasher h;
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

// ---------------------------------------------------------------- the layer's levels

/// used[v]: a live face uses vertex v.
inline std::vector<char> usedVertices(const CMeshO &m) {
  std::vector<char> used(m.vert.size(), 0);
  const CVertexO *first = m.vert.empty() ? nullptr : &m.vert[0];
  for (const CFaceO &f : m.face)
    if (!f.IsD())
      for (int k = 0; k < 3; ++k)
        if (f.cV(k) >= first && f.cV(k) < first + m.vert.size())
          used[size_t(f.cV(k) - first)] = 1;
  return used;
}

/// The per-vertex cluster and level attributes of a layer as integers (-1 for a vertex no
/// face uses); false (with `why`) if they are missing or hold values that are not cluster
/// ids / levels of this file. `clusters` = 0 for a pure progressive file (no cluster ids
/// needed).
inline bool layerClustersAndLevels(CMeshO &m, uint32_t clusters, int finest,
                                   std::vector<int> &cluster, std::vector<int> &level,
                                   QString &why) {
  auto ch = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(m, kClusterAttribute);
  auto lh = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(m, kLevelAttribute);
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

// ---------------------------------------------------------------- sessions

/// One decoder per .pomar file.
struct Session {
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

  /// A fresh decoder of the file; throws pomar::Error if it cannot be read.
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
  /// A fresh decoder unless the current one was never updated.
  void fresh() {
    if (!pristine)
      open();
  }
  int clamp(int level) const { return std::min(finest, std::max(base, level)); }
  /// Forget the signature before an update: the decoder's state is about to change.
  void willUpdate() {
    pristine = false;
    haveSignature = false;
  }
};

/// The sessions of the files filters worked on, at most kMaxSessions (each holds its
/// decoder's current mesh; the least recently used goes first).
class Sessions {
public:
  static constexpr size_t kMaxSessions = 4;

  /// The session of `path`, created (or re-created when the file changed on disk, or the
  /// layer asks for the other damage policy) if needed; nullptr with `error` set when the
  /// file cannot be read.
  Session *get(const std::string &path, bool skipDamaged, QString &error) {
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
      sessions_.erase(it); // replaced on disk, or opened with the other damage policy
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
        error = errorText(e, "cannot read " + fi.filePath());
        return nullptr;
      }
      evictOldest(kMaxSessions - 1);
      it = sessions_.emplace(path, std::move(s)).first;
    }
    it->second->lastUse = ++clock_;
    return it->second.get();
  }

  /// Drops the session of `path` (its decoder may be half way through an update).
  void forget(const std::string &path) { sessions_.erase(path); }

private:
  void evictOldest(size_t keep) {
    while (sessions_.size() > keep) {
      auto oldest = sessions_.begin();
      for (auto i = sessions_.begin(); i != sessions_.end(); ++i)
        if (i->second->lastUse < oldest->second->lastUse)
          oldest = i;
      sessions_.erase(oldest);
    }
  }

  std::map<std::string, std::unique_ptr<Session>> sessions_;
  uint64_t clock_ = 0; ///< for evicting the least recently used session
};

// ---------------------------------------------------------------- decoder <-> layer

/// Brings the session's decoder to the state of the layer, unless it is there already:
/// a fresh decoder, the wanted levels from the layer's attributes (per cluster: the highest
/// level of its vertices), update(). Returns false (with `why`) if the layer has no usable
/// attributes. `how` says what happened, for the log.
inline bool syncToLayer(Session &s, CMeshO &m, ProgressRelay &progress, QString &how,
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
  s.willUpdate();
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

namespace session_detail {

/// Per vertex of the decoder's exact mesh (`from`: the vertex of its mesh() each comes from),
/// the cluster (UINT32_MAX for a pure progressive file) and the level; UINT32_MAX for a
/// vertex no face uses.
inline void exactVertexClustersAndLevels(const Session &s, const std::vector<uint32_t> &from,
                                         size_t vertices, std::vector<uint32_t> &clusterOf,
                                         std::vector<uint32_t> &levelOf) {
  const std::vector<uint32_t> cluster = s.decoder->vertex_cluster();
  const std::vector<uint32_t> level = s.decoder->vertex_level();
  clusterOf.assign(vertices, UINT32_MAX);
  levelOf = clusterOf;
  for (size_t v = 0; v < vertices; ++v)
    if (from[v] < level.size()) {
      clusterOf[v] = s.clustered ? cluster[from[v]] : UINT32_MAX;
      levelOf[v] = level[from[v]];
    }
}

/// After fillLayer: white vertex colours and zero quality where the file has none, white face
/// colours; with `select`, the vertices of the clusters marked in it and the faces whose three
/// vertices are selected.
inline void resetColoursAndSelect(CMeshO &m, int written, const Session &s,
                                  const std::vector<uint32_t> &clusterOf,
                                  const std::vector<char> *select) {
  const bool ownColour = written & vcg::tri::io::Mask::IOM_VERTCOLOR;
  const bool ownQuality = written & vcg::tri::io::Mask::IOM_VERTQUALITY;
  for (size_t v = 0; v < clusterOf.size(); ++v) {
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
}

} // namespace session_detail

/// Replaces the layer's content by the decoder's current mesh (every cluster at the finest
/// level: exactly what was saved, a lossless record undone; otherwise the coded, cut mesh),
/// with the pomar attributes (-1 for a vertex no face uses) and the decoded per-vertex and
/// per-wedge data enabled on the layer (fillLayer; the saved colours of Show Clusters go with
/// the old attributes); selects the vertices of the clusters marked in `select` (if given)
/// and the faces whose three vertices are selected. The file's normals are kept, others are
/// computed from the geometry.
inline void replaceLayer(Session &s, MeshModel &mm, const std::vector<char> *select) {
  std::vector<uint32_t> from; // vertex of the decoder's mesh() each vertex comes from
  const pomar::Mesh mesh = s.decoder->exact_mesh(&from);
  std::vector<uint32_t> clusterOf, levelOf;
  session_detail::exactVertexClustersAndLevels(s, from, mesh.vertex_count(), clusterOf, levelOf);
  CMeshO &m = mm.cm;
  const int written = fillLayer(mm, mesh, s.clustered ? clusterOf : std::vector<uint32_t>(),
                                levelOf, s.path, s.skipDamaged);
  session_detail::resetColoursAndSelect(m, written, s, clusterOf, select);
  if (written & vcg::tri::io::Mask::IOM_VERTNORMAL) { // the file's normals, not recomputed ones
    vcg::tri::UpdateBounding<CMeshO>::Box(m);
    if (m.fn > 0)
      vcg::tri::UpdateNormal<CMeshO>::PerFaceNormalized(m);
  } else {
    mm.UpdateBoxAndNormals();
  }
  s.signature = signatureOf(mesh);
  s.haveSignature = true;
}

} // namespace pomar::meshlab
