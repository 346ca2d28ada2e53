// MeshLab 2020.09 IO plugin for .pomar files: see io_pomar.h. MeshLab's glue only; what open
// and save do is in pomar/meshlab_io.h.
#include "io_pomar.h"

#include <pomar/meshlab_io.h>
#include <pomar/meshlab_layer.h>
#include <pomar/pomar.h>

#include <QFileInfo>
#include <QStringList>
#include <QtGlobal>

#include <exception>

namespace pm = pomar::meshlab;

namespace {

const char *const kFormatName = "POMAR progressive mesh";
const char *const kExtension = "pomar";

bool isPomar(const QString &format) {
  return format.compare(QLatin1String(kExtension), Qt::CaseInsensitive) == 0;
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
  // Per-vertex colour, normals, quality and texture coordinates, per-wedge texture coordinates
  // with each face's texture (named per-vertex float attributes are always kept). Normals are
  // off by default: MeshLab recomputes them from the geometry; a layer with its own normals
  // gets a warning if they are not ticked.
  capability = pm::kKeptMask;
  defaultBits = pm::kKeptMask & ~vcg::tri::io::Mask::IOM_VERTNORMAL;
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
  par.addParam(RichEnum("OpenAt", pm::OPEN_FULL,
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
  const pm::OpenRequest request = pm::openRequest(par);
  pm::ProgressRelay progress(cb, "Decoding pomar");
  try {
    progress.report(0);
    const pm::DecodedFile file = pm::decodeFile(path, request, progress);
    if (!file.damaged.empty())
      pm::warn(*this, "", pm::damageWarning(path, file.damaged));
    // Enables what it reads on the layer: the GUI draws from the layer's data mask.
    mask = pm::fillLayer(m, file, path, request);
    progress.done();
    pm::logOpened(*this, path, file);
    return true;
  } catch (const std::exception &e) { // pomar::Error, or std::bad_alloc
    m.cm.Clear();
    return fail(pm::errorText(e, "cannot open " + path));
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
  const pm::SaveRequest request = pm::saveRequest(par);
  const int attributes = pm::savedAttributes(m, mask);
  pm::ProgressRelay progress(cb, "Encoding pomar");
  const QStringList dropped = pm::notKept(m, attributes);
  pm::EncodedLayer encoded;
  try {
    encoded = pm::encodeLayer(m, attributes, request, progress);
  } catch (const std::exception &e) { // pomar::Error (invalid mesh or options), std::bad_alloc
    return fail(pm::errorText(e, "cannot save " + path));
  }
  QString why;
  if (!pm::replaceFile(path, encoded.bytes, why)) // atomically: nothing written on failure
    return fail(QString("cannot save %1: %2").arg(path, why));
  progress.done();
  pm::reportSave(*this, path, encoded, dropped);
  return true;
}

// One heavy translation unit instead of two (AUTOMOC compiles this in place of mocs_compilation).
#include "moc_io_pomar.cpp"
