// MeshLab 2020.09 IO plugin for .pomar files: see io_pomar.h.
#include "io_pomar.h"
#include "pomar_layer.h"

#include <pomar/pomar.h>
#include <pomar/random_access.h>
#include <pomar/repair.h>
#include <pomar/vcg_adapter.h>

#include <QFile>
#include <QFileInfo>
#include <QSaveFile>
#include <QStringList>
#include <QtGlobal>

#include <vcg/complex/allocate.h>

#include <cmath>
#include <exception>
#include <memory>
#include <string>
#include <vector>

namespace {

const char *const kFormatName = "POMAR progressive mesh";
const char *const kExtension = "pomar";

bool isPomar(const QString &format) {
  return format.compare(QLatin1String(kExtension), Qt::CaseInsensitive) == 0;
}

using pomar::meshlab::ProgressRelay;

/// Angle-weighted vertex normals as MeshLab computes them after opening a file
/// (MeshModel::UpdateBoxAndNormals -> UpdateNormal::PerVertexAngleWeighted): true if the
/// mesh's own per-vertex normals differ materially (more than 10 degrees on more than 1%
/// of the used vertices), i.e. they came from a file or a tool rather than from the
/// geometry, so losing them is visible.
bool hasOwnVertexNormals(const CMeshO &m) {
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

/// The per-vertex data a .pomar file keeps (vcg::tri::io::Mask bits).
constexpr int kKeptMask = vcg::tri::io::Mask::IOM_VERTCOLOR | vcg::tri::io::Mask::IOM_VERTNORMAL |
                          vcg::tri::io::Mask::IOM_VERTQUALITY |
                          vcg::tri::io::Mask::IOM_VERTTEXCOORD;

/// What the layer has of the kept per-vertex data (MeshModel's data mask), as from_vcg's mask.
int layerAttributes(MeshModel &mm) {
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
  return mask;
}

/// What the mesh carries that the saved .pomar file does not keep: everything but positions,
/// triangles, named per-vertex float attributes and the per-vertex data in `saveMask`.
QStringList notKept(MeshModel &mm, int saveMask) {
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
  if (mm.hasDataMask(MeshModel::MM_VERTCOLOR) && !(saveMask & M::IOM_VERTCOLOR) &&
      anyVertex([](const CVertexO &v) { return v.cC() != vcg::Color4b(vcg::Color4b::White); }))
    out << "per-vertex colors (tick Color in the save dialog / meshlabserver -m vc)";
  if (mm.hasDataMask(MeshModel::MM_VERTNORMAL) && !(saveMask & M::IOM_VERTNORMAL) &&
      hasOwnVertexNormals(m))
    out << "per-vertex normals (tick Normal / -m vn)";
  if (mm.hasDataMask(MeshModel::MM_VERTQUALITY) && !(saveMask & M::IOM_VERTQUALITY) &&
      anyVertex([](const CVertexO &v) { return v.cQ() != 0; }))
    out << "per-vertex quality (tick Quality / -m vq)";
  if (mm.hasDataMask(MeshModel::MM_VERTTEXCOORD) && !(saveMask & M::IOM_VERTTEXCOORD))
    out << "per-vertex texture coordinates (tick TexCoord / -m vt)";
  if (mm.hasDataMask(MeshModel::MM_VERTRADIUS))
    out << "per-vertex radius";
  if (mm.hasDataMask(MeshModel::MM_FACECOLOR) &&
      anyFace([](const CFaceO &f) { return f.cC() != vcg::Color4b(vcg::Color4b::White); }))
    out << "per-face colors";
  if (mm.hasDataMask(MeshModel::MM_FACEQUALITY) &&
      anyFace([](const CFaceO &f) { return f.cQ() != 0; }))
    out << "per-face quality";
  if (mm.hasDataMask(MeshModel::MM_WEDGTEXCOORD))
    out << "per-wedge texture coordinates";
  if (mm.hasDataMask(MeshModel::MM_WEDGNORMAL))
    out << "per-wedge normals";
  if (mm.hasDataMask(MeshModel::MM_WEDGCOLOR))
    out << "per-wedge colors";
  if (mm.hasDataMask(MeshModel::MM_POLYGONAL))
    out << "polygons (faux edges; saved as triangles)";
  if (!m.textures.empty() &&
      !(mm.hasDataMask(MeshModel::MM_VERTTEXCOORD) && (saveMask & M::IOM_VERTTEXCOORD)))
    out << QString("%1 texture(s)").arg(m.textures.size());
  if (m.en > 0)
    out << QString("%1 edge(s)").arg(m.en);
  if (m.shot.IsValid())
    out << "camera";
  QStringList custom;
  auto addNames = [&](const auto &attributes) {
    for (const auto &a : attributes)
      if (!a._name.empty() && !pomar::meshlab::isPomarAttribute(a._name))
        custom << QString::fromStdString(a._name);
  };
  for (const auto &a : m.vert_attr) // named float attributes are kept
    if (!a._name.empty() && !pomar::meshlab::isPomarAttribute(a._name) && a._type != typeid(float))
      custom << QString::fromStdString(a._name);
  addNames(m.face_attr);
  addNames(m.edge_attr);
  addNames(m.mesh_attr);
  if (!custom.isEmpty())
    out << "custom attributes (" + custom.join(", ") + ")";
  return out;
}

} // namespace

QString PomarIOPlugin::pluginName() const { return "IOPomar"; }

QList<MeshIOInterface::Format> PomarIOPlugin::importFormats() const {
  return {Format(kFormatName, kExtension)};
}

QList<MeshIOInterface::Format> PomarIOPlugin::exportFormats() const {
  return {Format(kFormatName, kExtension)};
}

void PomarIOPlugin::GetExportMaskCapability(QString & /*format*/, int &capability,
                                            int &defaultBits) const {
  // Per-vertex colour, normals, quality and texture coordinates (named per-vertex float
  // attributes are always kept). Normals are off by default: MeshLab recomputes them from
  // the geometry; a layer with its own normals gets a warning if they are not ticked.
  capability = kKeptMask;
  defaultBits = kKeptMask & ~vcg::tri::io::Mask::IOM_VERTNORMAL;
}

bool PomarIOPlugin::fail(const QString &text) {
  errorMessage = text;
  qWarning("pomar: %s", qUtf8Printable(text));
  return false;
}

// ---------------------------------------------------------------- open

void PomarIOPlugin::initPreOpenParameter(const QString &format, const QString & /*fileName*/,
                                         RichParameterList &par) {
  if (!isPomar(format))
    return;
  par.addParam(RichEnum("OpenAt", OPEN_FULL,
                        QStringList() << "Full resolution"
                                      << "Base clustered mesh"
                                      << "Global level N",
                        "Open at",
                        "Full resolution: every level (lossless). Base clustered mesh: the "
                        "coarse mesh whose vertices are the random-access clusters. Global "
                        "level N: the whole mesh after N refinement levels (0 = base mesh)."));
  par.addParam(RichInt("Level", 0, "Level N", "Used by \"Global level N\"."));
  par.addParam(RichBool("SkipDamaged", false, "Skip damaged blocks",
                        "Open a damaged or truncated file anyway: regions whose blocks fail "
                        "their checks stay coarse (listed as warnings). Off: such a file is "
                        "refused with a message naming the damaged block."));
}

bool PomarIOPlugin::open(const QString &format, const QString &fileName, MeshModel &m, int &mask,
                         const RichParameterList &par, vcg::CallBackPos *cb, QWidget *) {
  mask = 0; // positions and faces
  if (!isPomar(format))
    return fail(QString("unknown format \"%1\"").arg(format));
  // meshlabserver passes an absolute path, the GUI a bare name with the CWD at its directory.
  const QString path = QFileInfo(fileName).absoluteFilePath();
  const std::string native = QFile::encodeName(path).toStdString();
  const int openAt = par.hasParameter("OpenAt") ? par.getEnum("OpenAt") : OPEN_FULL;
  const int wantedLevel = par.hasParameter("Level") ? par.getInt("Level") : 0;
  const bool skipDamaged = par.hasParameter("SkipDamaged") && par.getBool("SkipDamaged");

  ProgressRelay progress(cb, "Decoding pomar");
  try {
    progress.report(0);
    pomar::SelectiveOptions options;
    options.skip_damaged = skipDamaged;
    pomar::SelectiveDecoder decoder(std::make_unique<pomar::FileSource>(native), options);
    const pomar::FileInfo &info = decoder.info();
    int level = decoder.finest_level();
    if (openAt == OPEN_BASE_CLUSTERED)
      level = decoder.base_clustered_level();
    else if (openAt == OPEN_GLOBAL_LEVEL)
      level = wantedLevel;
    pomar::check_level_exists(level, decoder.finest_level());

    pomar::Mesh mesh;
    std::vector<uint32_t> cluster, vertexLevel;
    std::vector<pomar::DamagedBlock> damaged;
    if (info.clustered() && level < decoder.base_clustered_level()) {
      // Below the base clustered mesh only the plain decoder goes; it knows no vertex levels.
      QFile file(path);
      QByteArray bytes;
      if (file.open(QIODevice::ReadOnly))
        bytes = file.readAll();
      if (!file.isOpen() || file.error() != QFileDevice::NoError)
        throw pomar::Error(pomar::Error::Kind::Io,
                           "cannot read " + native + ": " + file.errorString().toStdString())
            .with_path(native);
      pomar::DecodeOptions options;
      options.level = level;
      options.skip_damaged = skipDamaged;
      options.progress = progress.function();
      pomar::DecodeReport report;
      mesh = pomar::decode(reinterpret_cast<const uint8_t *>(bytes.constData()),
                           size_t(bytes.size()), options, &report);
      damaged = report.damaged;
    } else {
      decoder.want_all(level);
      decoder.update(progress.function());
      // At the finest level, intact: exactly what was saved (a lossless record undone);
      // coarser levels show the coded, cut mesh.
      std::vector<uint32_t> source;
      mesh = decoder.exact_mesh(&source);
      const std::vector<uint32_t> clusters = decoder.vertex_cluster(), levels = decoder.vertex_level();
      for (uint32_t s : source) {
        cluster.push_back(s < clusters.size() ? clusters[s] : UINT32_MAX);
        vertexLevel.push_back(s < levels.size() ? levels[s] : UINT32_MAX);
      }
      damaged = decoder.damaged();
    }
    if (!damaged.empty()) {
      const QString warning = QString("%1: %2 damaged block(s) skipped, the mesh is coarser "
                                      "there:\n%3")
                                  .arg(path)
                                  .arg(damaged.size())
                                  .arg(QString::fromStdString(pomar::describe_damage(damaged)));
      pomar::meshlab::warn(*this, "", warning);
    }

    if (mesh.find(pomar::AttributeKind::TexCoord))
      m.updateDataMask(MeshModel::MM_VERTTEXCOORD); // optional in CMeshO: enable first
    if (!mesh.corner_texcoords.empty())
      m.updateDataMask(MeshModel::MM_WEDGTEXCOORD); // per-corner UVs: the wedges'
    // Also clears m's attributes. What was read goes into the layer's data mask too: the GUI
    // picks the rendering (vertex colour, ...) from that mask, not from the returned one.
    mask = pomar::to_vcg(mesh, m.cm) & (kKeptMask | vcg::tri::io::Mask::IOM_WEDGTEXCOORD);
    m.Enable(mask);
    if (!info.clustered())
      cluster.clear(); // a progressive file's vertices have no cluster
    pomar::meshlab::setLayerAttributes(m.cm, cluster, vertexLevel, native, skipDamaged);

    progress.done();
    Log("pomar: opened %s at level %d of %d (%s): %zu vertices, %zu faces", qUtf8Printable(path),
        level, decoder.finest_level(), info.clustered() ? "clustered file" : "progressive file",
        mesh.vertex_count(), mesh.triangle_count());
    return true;
  } catch (const std::exception &e) { // pomar::Error, or std::bad_alloc
    m.cm.Clear();
    return fail(pomar::meshlab::errorText(e, "cannot open " + path));
  }
}

// ---------------------------------------------------------------- save

void PomarIOPlugin::initSaveParameter(const QString &format, MeshModel & /*m*/,
                                      RichParameterList &par) {
  if (!isPomar(format))
    return;
  const pomar::EncodeOptions defaults;
  par.addParam(RichInt("Bits", defaults.bits, "Quantization bits",
                       "Bits per coordinate (4..24): positions are snapped to a cubic grid of "
                       "2^bits - 1 steps over the bounding box."));
  par.addParam(RichFloat("ClusterRatio", float(defaults.cluster_ratio), "Cluster ratio",
                         "Random access: about ratio x vertices clusters (ignored by a pure "
                         "progressive file)."));
  par.addParam(RichBool("Progressive", defaults.progressive, "Pure progressive",
                        "Global levels only, no clusters: no random access."));
  par.addParam(RichInt("NormalBits", defaults.attributes.normal_bits, "Normal bits",
                       "Bits per octahedral coordinate of per-vertex normals (4..16): at most "
                       "0.332 degrees of error at 9, half as much per extra bit."));
  par.addParam(RichBool("ExactAttributes", false, "Exact attributes",
                        "Store normals, quality and other per-vertex floats bit for bit (colour "
                        "is always exact). Off: quality and custom floats on 16 bits over their "
                        "range, texture coordinates on 12 bits."));
  par.addParam(RichBool("Repair", false, "Repair (cut into a manifold mesh)",
                        "Opt-in: save the mesh cut into a manifold one instead of the mesh as it "
                        "is (faces repeating a vertex and exact duplicates removed, faces "
                        "flipped, non-manifold vertices split into copies at the same position). "
                        "Without it any mesh is saved exactly: the cut is stored in the file and "
                        "undone on open. Every change is reported as a warning; the layer itself "
                        "is not modified."));
}

bool PomarIOPlugin::save(const QString &format, const QString &fileName, MeshModel &m,
                         const int mask, const RichParameterList &par, vcg::CallBackPos *cb,
                         QWidget *) {
  if (!isPomar(format))
    return fail(QString("unknown format \"%1\"").arg(format));
  const QString path = QFileInfo(fileName).absoluteFilePath();

  pomar::EncodeOptions options;
  if (par.hasParameter("Bits"))
    options.bits = par.getInt("Bits");
  if (par.hasParameter("ClusterRatio"))
    options.cluster_ratio = par.getFloat("ClusterRatio");
  if (par.hasParameter("Progressive"))
    options.progressive = par.getBool("Progressive");
  if (par.hasParameter("NormalBits"))
    options.attributes.normal_bits = par.getInt("NormalBits");
  options.attributes.exact = par.hasParameter("ExactAttributes") && par.getBool("ExactAttributes");
  const bool repair = par.hasParameter("Repair") && par.getBool("Repair");
  // The save mask (dialog ticks, meshlabserver -m) limited to what the layer has.
  const int attributes = layerAttributes(m) & (mask | pomar::kVcgCustomScalars);

  ProgressRelay progress(cb, "Encoding pomar");
  options.progress = progress.function();
  QStringList dropped = notKept(m, attributes);
  std::vector<uint8_t> bytes;
  QString repaired; // what the Repair option changed, "" if off or nothing
  QString stored;   // what the file keeps beyond the coded mesh (any mesh saves exactly)
  try {
    progress.report(0);
    // Skips deleted elements, keeps unreferenced vertices (the file stores them), takes the
    // attributes the save mask asks for; the layer's own colours when Show Clusters / Show
    // Levels painted it.
    pomar::meshlab::swapSavedColours(m.cm);
    pomar::Mesh mesh;
    try {
      mesh = pomar::from_vcg(m.cm, nullptr, attributes, true);
    } catch (...) {
      pomar::meshlab::swapSavedColours(m.cm);
      throw;
    }
    pomar::meshlab::swapSavedColours(m.cm);
    if (repair) {
      const pomar::RepairReport report = pomar::make_manifold(mesh);
      if (report.changed())
        repaired = QString::fromStdString(report.summary()).replace('\n', "; ");
    }
    pomar::EncodeReport report;
    bytes = pomar::encode(mesh, options, &report);
    stored = QString::fromStdString(report.lossless.summary());
  } catch (const std::exception &e) { // pomar::Error (invalid mesh or options), std::bad_alloc
    return fail(pomar::meshlab::errorText(e, "cannot save " + path));
  }

  // Atomic replacement: a temporary file next to the destination, renamed over it on commit.
  QSaveFile file(path);
  if (!file.open(QIODevice::WriteOnly))
    return fail(QString("cannot save %1: %2").arg(path, file.errorString()));
  if (file.write(reinterpret_cast<const char *>(bytes.data()), qint64(bytes.size())) !=
          qint64(bytes.size()) ||
      !file.commit()) {
    const QString why = file.errorString();
    file.cancelWriting();
    return fail(QString("cannot save %1: %2").arg(path, why));
  }
  progress.done();

  if (!repaired.isEmpty())
    pomar::meshlab::warn(
        *this, "",
        QString("%1: repaired before saving: %2").arg(QFileInfo(path).fileName(), repaired));
  if (!stored.isEmpty())
    Log("pomar: %s: stored for an exact decode: %s", qUtf8Printable(QFileInfo(path).fileName()),
        qUtf8Printable(stored));
  if (!dropped.isEmpty())
    pomar::meshlab::warn(
        *this, "",
        QString("%1: not saved (a .pomar file keeps positions, triangles and per-vertex "
                "colour, normals, quality, texture coordinates and float attributes): %2")
            .arg(QFileInfo(path).fileName(), dropped.join("; ")));
  Log("pomar: saved %s: %zu bytes", qUtf8Printable(path), bytes.size());
  return true;
}

// One heavy translation unit instead of two (AUTOMOC compiles this in place of mocs_compilation).
#include "moc_io_pomar.cpp"
