// MeshLab 2020.09 filter plugin for layers opened from .pomar files (libfilter_pomar.so).
//
// A thin wrapper over pomar::SelectiveDecoder (pomar/random_access.h); what the filters do is
// in pomar/meshlab_filters.h, the decoders kept between calls in pomar/meshlab_session.h. It
// works on a layer that libio_pomar.so opened: that plugin stores, per vertex, the float
// attributes "pomar_cluster" and "pomar_level" and, per mesh, the std::string attribute
// "pomar_source" (the absolute path of the file). Filters (the names are stable; scripts
// use them):
//
//   "POMAR: Refine Selected Clusters"   TargetLevel (int): the clusters of the selected
//        faces go up to that level; the level map completes the rest. Afterwards the
//        selection is the faces whose three vertices are in the requested clusters.
//   "POMAR: Coarsen Selected Clusters"  TargetLevel (int): those clusters go down to it.
//   "POMAR: Set Level of Detail"        Level (int, -1 = full resolution): every cluster.
//   "POMAR: Show Clusters"              per-vertex colour per cluster (hash palette).
//   "POMAR: Show Levels"                per-vertex colour of the level map, blue (coarse)
//                                       to red (fine).
//   "POMAR: Show Original Colours"      the colours the layer had before the Show filters.
//
// The plugin keeps one decoder per source file. When the layer is still what that decoder
// produced last (same vertex and face counts and the same positions and triangles), a
// refinement decodes only what is missing on top of it; otherwise a fresh decoder is
// brought to the levels recorded in the layer's attributes first.
#pragma once

#include <QObject>

#include <common/interfaces.h>

#include <pomar/meshlab_session.h>

class PomarFilterPlugin : public QObject, public MeshFilterInterface {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(MESH_FILTER_INTERFACE_IID)
  Q_INTERFACES(MeshFilterInterface)

public:
  enum {
    FP_REFINE_SELECTED,
    FP_COARSEN_SELECTED,
    FP_SET_LEVEL,
    FP_SHOW_CLUSTERS,
    FP_SHOW_LEVELS,
    FP_SHOW_ORIGINAL_COLOURS,
  };

  PomarFilterPlugin();
  ~PomarFilterPlugin() override;

  QString pluginName() const override;
  using MeshFilterInterface::filterInfo;
  using MeshFilterInterface::filterName;
  QString filterName(FilterIDType filter) const override;
  QString filterInfo(FilterIDType filter) const override;
  FilterClass getClass(QAction *a) override;
  FILTER_ARITY filterArity(QAction *a) const override;
  int getRequirements(QAction *a) override;
  int getPreConditions(QAction *a) const override;
  int postCondition(QAction *a) const override;

  using MeshFilterInterface::initParameterSet;
  void initParameterSet(QAction *a, MeshModel &m, RichParameterList &par) override;
  bool applyFilter(QAction *a, MeshDocument &md, const RichParameterList &par,
                   vcg::CallBackPos *cb) override;

private:
  /// A filter that decodes (refine, coarsen, set level, show levels) on the layer `mm` from
  /// `path`.
  bool applyWithDecoder(int id, MeshModel &mm, const std::string &path,
                        const RichParameterList &par, vcg::CallBackPos *cb);
  /// errorMessage = text, also logged (meshlabserver prints the log, not errorMessage).
  bool fail(const QString &text);
  /// true if `refusal` is empty (the filter was done), else fail(refusal).
  bool finish(const QString &refusal);

  pomar::meshlab::Sessions sessions_; ///< one decoder per .pomar file
};
