// What the MeshLab IO plugin (io_plugin/, libio_pomar.so) does besides MeshLab's glue: opening
// decodes a .pomar file at the level the "Pre-Open Options" ask for and fills the layer;
// saving takes what the save mask ticks of the layer, names what the file would not keep,
// encodes with the "Additional Parameters" and replaces the destination atomically.
//
// Part of the plugins' boundary layer (pomar/meshlab_*.h, see meshlab_layer.h).
#pragma once

#include <pomar/meshlab_layer.h>
#include <pomar/pomar.h>
#include <pomar/random_access.h>
#include <pomar/repair.h>
#include <pomar/vcg_adapter.h>

#include <common/interfaces.h>
#include <common/meshmodel.h>
#include <wrap/io_trimesh/io_mask.h>

#include <QByteArray>
#include <QFile>
#include <QFileInfo>
#include <QSaveFile>
#include <QString>
#include <QStringList>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace pomar::meshlab {

/// The per-vertex and per-wedge data a .pomar file keeps (vcg::tri::io::Mask bits).
constexpr int kKeptMask = vcg::tri::io::Mask::IOM_VERTCOLOR | vcg::tri::io::Mask::IOM_VERTNORMAL |
                          vcg::tri::io::Mask::IOM_VERTQUALITY |
                          vcg::tri::io::Mask::IOM_VERTTEXCOORD |
                          vcg::tri::io::Mask::IOM_WEDGTEXCOORD;

/// The file name as the codec takes it (QFile's encoding of file names).
inline std::string nativePath(const QString &path) { return QFile::encodeName(path).toStdString(); }

// ---------------------------------------------------------------- open

/// Values of the IO plugin's "OpenAt" pre-open parameter.
enum OpenAt { OPEN_FULL = 0, OPEN_BASE_CLUSTERED = 1, OPEN_GLOBAL_LEVEL = 2 };

/// What the "Pre-Open Options" ask for. meshlabserver passes none of them: full resolution,
/// damaged files refused.
struct OpenRequest {
  int openAt = OPEN_FULL;
  int level = 0; ///< for OPEN_GLOBAL_LEVEL
  bool skipDamaged = false;
};

inline OpenRequest openRequest(const RichParameterList &par) {
  OpenRequest r;
  if (par.hasParameter("OpenAt"))
    r.openAt = par.getEnum("OpenAt");
  if (par.hasParameter("Level"))
    r.level = par.getInt("Level");
  r.skipDamaged = par.hasParameter("SkipDamaged") && par.getBool("SkipDamaged");
  return r;
}

/// A .pomar file decoded for a layer.
struct DecodedFile {
  pomar::Mesh mesh;
  /// Per vertex of `mesh`, its cluster and the level that created it (UINT32_MAX: a vertex
  /// no face uses); empty where unknown (a pure progressive file has no clusters, the plain
  /// decoder below the base clustered mesh knows neither).
  std::vector<uint32_t> vertexCluster, vertexLevel;
  std::vector<pomar::DamagedBlock> damaged; ///< skipped ("Skip damaged blocks")
  int level = 0, finest = 0;                ///< the level opened, the file's finest
  bool clustered = false;                   ///< a random-access file (not pure progressive)
};

namespace io_detail {

/// The level `request` names in the file of `decoder`; throws pomar::Error if there is none.
inline int levelToOpen(const pomar::SelectiveDecoder &decoder, const OpenRequest &request) {
  int level = decoder.finest_level();
  if (request.openAt == OPEN_BASE_CLUSTERED)
    level = decoder.base_clustered_level();
  else if (request.openAt == OPEN_GLOBAL_LEVEL)
    level = request.level;
  pomar::check_level_exists(level, decoder.finest_level());
  return level;
}

/// Below the base clustered mesh only the plain decoder goes; it knows no vertex levels.
inline void decodeBelowBase(const QString &path, const OpenRequest &request,
                            ProgressRelay &progress, DecodedFile &out) {
  QFile file(path);
  QByteArray bytes;
  if (file.open(QIODevice::ReadOnly))
    bytes = file.readAll();
  if (!file.isOpen() || file.error() != QFileDevice::NoError) {
    const std::string native = nativePath(path);
    throw pomar::Error(pomar::Error::Kind::Io,
                       "cannot read " + native + ": " + file.errorString().toStdString())
        .with_path(native);
  }
  pomar::DecodeOptions options;
  options.level = out.level;
  options.skip_damaged = request.skipDamaged;
  options.progress = progress.function();
  pomar::DecodeReport report;
  out.mesh = pomar::decode(reinterpret_cast<const uint8_t *>(bytes.constData()),
                           size_t(bytes.size()), options, &report);
  out.damaged = report.damaged;
}

/// Every cluster at out.level with the selective decoder. At the finest level, intact:
/// exactly what was saved (a lossless record undone); coarser levels show the coded, cut mesh.
inline void decodeSelective(pomar::SelectiveDecoder &decoder, ProgressRelay &progress,
                            DecodedFile &out) {
  decoder.want_all(out.level);
  decoder.update(progress.function());
  std::vector<uint32_t> source;
  out.mesh = decoder.exact_mesh(&source);
  const std::vector<uint32_t> clusters = decoder.vertex_cluster(), levels = decoder.vertex_level();
  for (uint32_t s : source) {
    out.vertexCluster.push_back(s < clusters.size() ? clusters[s] : UINT32_MAX);
    out.vertexLevel.push_back(s < levels.size() ? levels[s] : UINT32_MAX);
  }
  out.damaged = decoder.damaged();
}

} // namespace io_detail

/// Decodes the file at `path` (absolute) as `request` says. Throws pomar::Error (a missing,
/// damaged or truncated file, a level the file does not have) or std::bad_alloc.
inline DecodedFile decodeFile(const QString &path, const OpenRequest &request,
                              ProgressRelay &progress) {
  pomar::SelectiveOptions options;
  options.skip_damaged = request.skipDamaged;
  pomar::SelectiveDecoder decoder(std::make_unique<pomar::FileSource>(nativePath(path)), options);
  DecodedFile out;
  out.clustered = decoder.info().clustered();
  out.finest = decoder.finest_level();
  out.level = io_detail::levelToOpen(decoder, request);
  if (out.clustered && out.level < decoder.base_clustered_level())
    io_detail::decodeBelowBase(path, request, progress, out);
  else
    io_detail::decodeSelective(decoder, progress, out);
  if (!out.clustered)
    out.vertexCluster.clear(); // a progressive file's vertices have no cluster
  return out;
}

/// Replaces the layer's content by the decoded file (fillLayer) and returns the mask open()
/// reports. m.textures are names relative to the file: the GUI loads them after open() with
/// the file's folder as the current directory, as for the stock OBJ and PLY readers.
inline int fillLayer(MeshModel &m, const DecodedFile &file, const QString &path,
                     const OpenRequest &request) {
  return fillLayer(m, file.mesh, file.vertexCluster, file.vertexLevel, nativePath(path),
                   request.skipDamaged) &
         kKeptMask;
}

/// The warning about the blocks "Skip damaged blocks" skipped.
inline QString damageWarning(const QString &path, const std::vector<pomar::DamagedBlock> &damaged) {
  // One arg() call for all three: a chained arg() would read a "%2" in the path (or in the
  // damage text) as a place for the next argument.
  return QString("%1: %2 damaged block(s) skipped, the mesh is coarser there:\n%3")
      .arg(path, QString::number(damaged.size()),
           QString::fromStdString(pomar::describe_damage(damaged)));
}

/// The log line of a successful open.
inline void logOpened(MeshLabInterface &plugin, const QString &path, const DecodedFile &file) {
  plugin.Log("pomar: opened %s at level %d of %d (%s): %zu vertices, %zu faces",
             qUtf8Printable(path), file.level, file.finest,
             file.clustered ? "clustered file" : "progressive file", file.mesh.vertex_count(),
             file.mesh.triangle_count());
}

// ---------------------------------------------------------------- save

/// What the save parameters ("Additional Parameters" of the save dialog) ask for; the
/// library's defaults for those not given.
struct SaveRequest {
  pomar::EncodeOptions options;
  bool repair = false; ///< cut into a manifold mesh first (pomar::make_manifold)
};

inline SaveRequest saveRequest(const RichParameterList &par) {
  SaveRequest r;
  pomar::EncodeOptions &o = r.options;
  if (par.hasParameter("Bits"))
    o.bits = par.getInt("Bits");
  if (par.hasParameter("ClusterRatio"))
    o.cluster_ratio = par.getFloat("ClusterRatio");
  if (par.hasParameter("Progressive"))
    o.progressive = par.getBool("Progressive");
  if (par.hasParameter("NormalBits"))
    o.attributes.normal_bits = par.getInt("NormalBits");
  o.attributes.exact = par.hasParameter("ExactAttributes") && par.getBool("ExactAttributes");
  r.repair = par.hasParameter("Repair") && par.getBool("Repair");
  return r;
}

/// What the layer has of the kept data (MeshModel's data mask), as from_vcg's mask.
inline int layerAttributes(MeshModel &mm) {
  using M = vcg::tri::io::Mask;
  int mask = pomar::kVcgCustomScalars;
  if (mm.hasDataMask(MeshModel::MM_VERTCOLOR))
    mask |= M::IOM_VERTCOLOR;
  if (mm.hasDataMask(MeshModel::MM_VERTNORMAL))
    mask |= M::IOM_VERTNORMAL;
  if (mm.hasDataMask(MeshModel::MM_VERTQUALITY))
    mask |= M::IOM_VERTQUALITY;
  if (mm.hasDataMask(MeshModel::MM_VERTTEXCOORD))
    mask |= M::IOM_VERTTEXCOORD;
  if (mm.hasDataMask(MeshModel::MM_WEDGTEXCOORD))
    mask |= M::IOM_WEDGTEXCOORD;
  return mask;
}

/// What a save takes: the save mask (dialog ticks, meshlabserver -m) limited to what the
/// layer has, plus the named per-vertex floats (from_vcg's mask).
inline int savedAttributes(MeshModel &mm, int saveMask) {
  return layerAttributes(mm) & (saveMask | pomar::kVcgCustomScalars);
}

/// Angle-weighted vertex normals as MeshLab computes them after opening a file
/// (MeshModel::UpdateBoxAndNormals -> UpdateNormal::PerVertexAngleWeighted): true if the
/// mesh's own per-vertex normals differ materially (more than 10 degrees on more than 1%
/// of the used vertices), i.e. they came from a file or a tool rather than from the
/// geometry, so losing them is visible.
inline bool hasOwnVertexNormals(const CMeshO &m) {
  using P = vcg::Point3f;
  std::vector<P> acc(m.vert.size(), P(0, 0, 0));
  std::vector<char> used(m.vert.size(), 0);
  for (const CFaceO &f : m.face) {
    if (f.IsD())
      continue;
    const P p0 = P::Construct(f.cP(0)), p1 = P::Construct(f.cP(1)), p2 = P::Construct(f.cP(2));
    P n = (p1 - p0) ^ (p2 - p0);
    const float len = n.Norm();
    if (!(len > 0) || !std::isfinite(len))
      continue;
    n /= len;
    const P e0 = (p1 - p0).Normalize(), e1 = (p2 - p1).Normalize(), e2 = (p0 - p2).Normalize();
    const float w[3] = {vcg::AngleN(e0, -e2), vcg::AngleN(-e0, e1), vcg::AngleN(-e1, e2)};
    for (int k = 0; k < 3; ++k) {
      const size_t v = pomar::vertex_position(m, f.cV(k));
      if (v >= acc.size() || !std::isfinite(w[k]))
        continue;
      acc[v] += n * w[k];
      used[v] = 1;
    }
  }
  const float cosLimit = std::cos(10.0f * float(M_PI) / 180.0f);
  size_t count = 0, differ = 0;
  for (size_t v = 0; v < m.vert.size(); ++v) {
    if (m.vert[v].IsD() || !used[v] || !(acc[v].Norm() > 0))
      continue;
    ++count;
    const P stored = P::Construct(m.vert[v].cN());
    const float sn = stored.Norm();
    if (!(sn > 0) || (acc[v] / acc[v].Norm()) * (stored / sn) < cosLimit)
      ++differ;
  }
  return count > 0 && differ * 100 > count;
}

namespace io_detail {

/// Names of the layer's custom attributes a .pomar file does not keep: all but pomar's own
/// and the named per-vertex floats.
inline QStringList unkeptCustomAttributes(const CMeshO &m) {
  QStringList custom;
  auto addNames = [&](const auto &attributes) {
    for (const auto &a : attributes)
      if (!a._name.empty() && !isPomarAttribute(a._name))
        custom << QString::fromStdString(a._name);
  };
  for (const auto &a : m.vert_attr) // named float attributes are kept
    if (!a._name.empty() && !isPomarAttribute(a._name) && a._type != typeid(float))
      custom << QString::fromStdString(a._name);
  addNames(m.face_attr);
  addNames(m.edge_attr);
  addNames(m.mesh_attr);
  return custom;
}

} // namespace io_detail

/// What the mesh carries that the saved .pomar file does not keep: everything but positions,
/// triangles, named per-vertex float attributes and the per-vertex and per-wedge data in
/// `saveMask` (texture names with either texture coordinates); each with the tick that
/// would keep it, where there is one.
inline QStringList notKept(MeshModel &mm, int saveMask) {
  using M = vcg::tri::io::Mask;
  const CMeshO &m = mm.cm;
  QStringList out;
  auto anyVertex = [&](auto pred) {
    for (const CVertexO &v : m.vert)
      if (!v.IsD() && pred(v))
        return true;
    return false;
  };
  auto anyFace = [&](auto pred) {
    for (const CFaceO &f : m.face)
      if (!f.IsD() && pred(f))
        return true;
    return false;
  };
  auto has = [&](int dataMask) { return mm.hasDataMask(dataMask); };
  const vcg::Color4b white(vcg::Color4b::White);
  if (has(MeshModel::MM_VERTCOLOR) && !(saveMask & M::IOM_VERTCOLOR) &&
      anyVertex([&](const CVertexO &v) { return v.cC() != white; }))
    out << "per-vertex colors (tick Color in the save dialog / meshlabserver -m vc)";
  if (has(MeshModel::MM_VERTNORMAL) && !(saveMask & M::IOM_VERTNORMAL) && hasOwnVertexNormals(m))
    out << "per-vertex normals (tick Normal / -m vn)";
  if (has(MeshModel::MM_VERTQUALITY) && !(saveMask & M::IOM_VERTQUALITY) &&
      anyVertex([](const CVertexO &v) { return v.cQ() != 0; }))
    out << "per-vertex quality (tick Quality / -m vq)";
  if (has(MeshModel::MM_VERTTEXCOORD) && !(saveMask & M::IOM_VERTTEXCOORD))
    out << "per-vertex texture coordinates (tick TexCoord / -m vt)";
  if (has(MeshModel::MM_VERTRADIUS))
    out << "per-vertex radius";
  if (has(MeshModel::MM_FACECOLOR) && anyFace([&](const CFaceO &f) { return f.cC() != white; }))
    out << "per-face colors";
  if (has(MeshModel::MM_FACEQUALITY) && anyFace([](const CFaceO &f) { return f.cQ() != 0; }))
    out << "per-face quality";
  if (has(MeshModel::MM_WEDGTEXCOORD) && !(saveMask & M::IOM_WEDGTEXCOORD))
    out << "per-wedge texture coordinates (tick TexCoord under Wedge / -m wt)";
  if (has(MeshModel::MM_WEDGNORMAL))
    out << "per-wedge normals";
  if (has(MeshModel::MM_WEDGCOLOR))
    out << "per-wedge colors";
  if (has(MeshModel::MM_POLYGONAL))
    out << "polygons (faux edges; saved as triangles)";
  if (!m.textures.empty() && !(saveMask & (M::IOM_VERTTEXCOORD | M::IOM_WEDGTEXCOORD)))
    out << QString("%1 texture(s)").arg(m.textures.size());
  if (m.en > 0)
    out << QString("%1 edge(s)").arg(m.en);
  if (m.shot.IsValid())
    out << "camera";
  const QStringList custom = io_detail::unkeptCustomAttributes(m);
  if (!custom.isEmpty())
    out << "custom attributes (" + custom.join(", ") + ")";
  return out;
}

/// A layer encoded for saving.
struct EncodedLayer {
  std::vector<uint8_t> bytes;
  QString repaired; ///< what the Repair option changed, "" if off or nothing
  QString stored;   ///< what the file keeps beyond the coded mesh (any mesh saves exactly)
};

/// Encodes the layer's mesh with the attributes of from_vcg's mask `attributes`: deleted
/// elements skipped, unreferenced vertices kept (the file stores them), the layer's own
/// colours when Show Clusters / Show Levels painted it. Throws pomar::Error (an invalid mesh
/// or invalid options) or std::bad_alloc; the layer is left as it was.
inline EncodedLayer encodeLayer(MeshModel &m, int attributes, SaveRequest request,
                                ProgressRelay &progress) {
  request.options.progress = progress.function();
  progress.report(0);
  swapSavedColours(m.cm);
  pomar::Mesh mesh;
  try {
    mesh = pomar::from_vcg(m.cm, nullptr, attributes, true);
  } catch (...) {
    swapSavedColours(m.cm);
    throw;
  }
  swapSavedColours(m.cm);
  EncodedLayer out;
  if (request.repair) {
    const pomar::RepairReport report = pomar::make_manifold(mesh);
    if (report.changed())
      out.repaired = QString::fromStdString(report.summary()).replace('\n', "; ");
  }
  pomar::EncodeReport report;
  out.bytes = pomar::encode(mesh, request.options, &report);
  out.stored = QString::fromStdString(report.lossless.summary());
  return out;
}

/// Writes `bytes` to `path` atomically: a temporary file next to the destination, renamed
/// over it on commit. False with `why` set if that fails (the destination is untouched).
inline bool replaceFile(const QString &path, const std::vector<uint8_t> &bytes, QString &why) {
  QSaveFile file(path);
  if (!file.open(QIODevice::WriteOnly)) {
    why = file.errorString();
    return false;
  }
  if (file.write(reinterpret_cast<const char *>(bytes.data()), qint64(bytes.size())) !=
          qint64(bytes.size()) ||
      !file.commit()) {
    why = file.errorString();
    file.cancelWriting();
    return false;
  }
  return true;
}

/// The messages of a successful save: the repairs made (warning), what the file stores for
/// an exact decode (log), what it does not keep (warning), the size (log).
inline void reportSave(MeshLabInterface &plugin, const QString &path, const EncodedLayer &encoded,
                       const QStringList &dropped) {
  const QString name = QFileInfo(path).fileName();
  if (!encoded.repaired.isEmpty())
    warn(plugin, "", QString("%1: repaired before saving: %2").arg(name, encoded.repaired));
  if (!encoded.stored.isEmpty())
    plugin.Log("pomar: %s: stored for an exact decode: %s", qUtf8Printable(name),
               qUtf8Printable(encoded.stored));
  if (!dropped.isEmpty())
    warn(plugin, "",
         QString("%1: not saved (a .pomar file keeps positions, triangles, per-vertex colour, "
                 "normals, quality, texture coordinates and float attributes, per-wedge texture "
                 "coordinates and texture names): %2")
             .arg(name, dropped.join("; ")));
  plugin.Log("pomar: saved %s: %zu bytes", qUtf8Printable(path), encoded.bytes.size());
}

} // namespace pomar::meshlab
