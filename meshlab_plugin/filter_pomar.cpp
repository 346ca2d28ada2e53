// MeshLab 2020.09 filter plugin for layers opened from .pomar files: see filter_pomar.h.
// MeshLab's glue only; what the filters do is in pomar/meshlab_filters.h.
#include "filter_pomar.h"

#include <pomar/meshlab_filters.h>
#include <pomar/meshlab_layer.h>
#include <pomar/meshlab_session.h>

#include <QFile>
#include <QString>

#include <exception>
#include <string>

namespace pm = pomar::meshlab;

namespace {

/// TargetLevel default when the file is unknown: "the finest level" after clamping.
const int kFinestPlaceholder = 99;

bool decodes(int id) {
  return id == PomarFilterPlugin::FP_REFINE_SELECTED ||
         id == PomarFilterPlugin::FP_COARSEN_SELECTED || id == PomarFilterPlugin::FP_SET_LEVEL;
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
  const int id = ID(a);
  const pm::Session *s = nullptr;
  std::string path;
  QString ignored;
  if (decodes(id) && pm::sourceOf(m.cm, path))
    s = sessions_.get(path, pm::skipsDamage(m.cm), ignored); // cheap: header and global part
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
  pm::warn(*this, "POMAR: ", text);
  return false;
}

bool PomarFilterPlugin::finish(const QString &refusal) {
  return refusal.isEmpty() || fail(refusal);
}

// ---------------------------------------------------------------- apply

bool PomarFilterPlugin::applyFilter(QAction *a, MeshDocument &md, const RichParameterList &par,
                                    vcg::CallBackPos *cb) {
  MeshModel *mm = md.mm();
  if (mm == nullptr)
    return fail("no current layer");
  std::string path;
  if (!pm::sourceOf(mm->cm, path))
    return fail(pm::notAPomarLayer(filterName(a), mm->label()));
  switch (ID(a)) {
  case FP_SHOW_CLUSTERS:
    return finish(pm::showClusters(*this, *mm));
  case FP_SHOW_ORIGINAL_COLOURS:
    return finish(pm::showOriginalColours(*this, *mm));
  default:
    return applyWithDecoder(ID(a), *mm, path, par, cb);
  }
}

bool PomarFilterPlugin::applyWithDecoder(int id, MeshModel &mm, const std::string &path,
                                         const RichParameterList &par, vcg::CallBackPos *cb) {
  QString error;
  pm::Session *s = sessions_.get(path, pm::skipsDamage(mm.cm), error);
  if (s == nullptr)
    return fail(error);
  try {
    QString refusal;
    switch (id) {
    case FP_REFINE_SELECTED:
      refusal = pm::refineOrCoarsen(*this, true, mm, *s, par.getInt("TargetLevel"), cb);
      break;
    case FP_COARSEN_SELECTED:
      refusal = pm::refineOrCoarsen(*this, false, mm, *s, par.getInt("TargetLevel"), cb);
      break;
    case FP_SET_LEVEL:
      refusal = pm::setLevel(*this, mm, *s, par.getInt("Level"), cb);
      break;
    case FP_SHOW_LEVELS:
      return finish(pm::showLevels(*this, mm, *s));
    default:
      return fail("unknown filter");
    }
    const bool done = finish(refusal);
    pm::warnAboutNewDamage(*this, *s);
    return done;
  } catch (const std::exception &e) { // pomar::Error (damaged file), std::bad_alloc
    // The decoder may be half way through an update: forget it. The layer is unchanged
    // (it is replaced only after a successful update).
    sessions_.forget(path);
    return fail(pm::errorText(e, QFile::decodeName(path.c_str())));
  }
}

// One heavy translation unit instead of two (AUTOMOC compiles this in place of mocs_compilation).
#include "moc_filter_pomar.cpp"
