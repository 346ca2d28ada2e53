// MeshLab 2020.09 IO plugin for .pomar files (libio_pomar.so).
//
// A thin wrapper over the pomar library (pomar_core + pomar/meshlab_io.h, which holds what
// open and save do):
//   open():  full resolution by default (what meshlabserver always uses), or, from the
//            "Pre-Open Options" dialog, the base clustered mesh or a global level N.
//            Adds the per-vertex float attributes "pomar_cluster" (-1 in a pure progressive
//            file) and "pomar_level" (-1 when unknown), and the per-mesh std::string
//            attribute "pomar_source": the absolute path of the file, for filter plugins
//            that refine the mesh later from the same file.
//   save():  positions, triangles, named per-vertex floats and what the save mask ticks of
//            per-vertex colour, normals, quality and texture coordinates and per-wedge
//            texture coordinates (with each face's texture and the texture names); anything
//            else is named in a warning. The file is encoded in memory and then replaces the
//            destination atomically.
#pragma once

#include <QObject>

#include <common/interfaces.h>

class PomarIOPlugin : public QObject, public MeshIOInterface {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(MESH_IO_INTERFACE_IID)
  Q_INTERFACES(MeshIOInterface)

public:
  QString pluginName() const override;

  QList<Format> importFormats() const override;
  QList<Format> exportFormats() const override;
  void GetExportMaskCapability(QString &format, int &capability, int &defaultBits) const override;

  void initPreOpenParameter(const QString &format, const QString &fileName,
                            RichParameterList &par) override;
  void initSaveParameter(const QString &format, MeshModel &m, RichParameterList &par) override;

  bool open(const QString &format, const QString &fileName, MeshModel &m, int &mask,
            const RichParameterList &par, vcg::CallBackPos *cb = nullptr,
            QWidget *parent = nullptr) override;
  bool save(const QString &format, const QString &fileName, MeshModel &m, const int mask,
            const RichParameterList &par, vcg::CallBackPos *cb = nullptr,
            QWidget *parent = nullptr) override;

private:
  /// errorMessage = text, also printed on stderr (meshlabserver does not show errorMessage).
  bool fail(const QString &text);
};
