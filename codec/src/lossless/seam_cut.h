// Texture seams: per-corner texture coordinates and face materials as per-vertex values.
//
// The levels code per-vertex values. A mesh with a value per corner (Mesh::corner_texcoords,
// Mesh::face_materials) is coded as its seam cut: around each vertex, the corners that meet
// across an edge with the same texture coordinate and material form a wedge, and every
// wedge but the first becomes a copy of the vertex (same position). The wedge values are two
// per-vertex attributes of the cut (kWedgeTexcoord, kWedgeMaterial), coded with the splits
// like any other attribute. The copies are vertex copies of the lossless record, so a full
// decode welds them back; the cut faces are the input's, in its order, so the corners keep
// their places.
//
// Seams never open. A vertex inside a seam's run (two wedges, two seam edges) has two copies,
// twins, which decimation collapses together, each along its side of the seam onto the
// copies of one neighbour, in one level; every other vertex on a seam edge (an edge whose
// two faces disagree at either end: chart corners, seam ends, seams on the mesh's boundary)
// is locked and never removed. So both sides of a seam have the same vertices and edges at
// every level; a selective decode keeps the clusters of copies at one level (the decoder's
// cluster links), so both sides also refine together there. A coarse face comes from a
// finer face of the same wedges, so its corners are valid lookups in the chart of the face
// it replaces. docs/architecture.md, "Texture seams".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pomar/pomar.h"
#include "pomar/repair.h"

namespace pomar {

/// The cut's per-vertex attributes that carry the wedge values (internal names: an input
/// attribute may not use the prefix "pomar:").
extern const char *const kWedgeTexcoord; ///< TexCoord: the wedge's (u, v)
extern const char *const kWedgeMaterial; ///< Scalar: the wedge's material index (an integer)

/// Whether `name` is one of the codec's internal attribute names.
bool internal_attribute_name(const std::string &name);

/// Whether an attribute named `name` of kind `kind` is kept under `mask`: the wedge material
/// goes with the texture coordinates, everything else with its kind.
bool keeps_attribute(const std::string &name, AttributeKind kind, const AttributeMask &mask);

/// Whether `mesh` has values per corner or per face that the seam cut carries.
bool has_corner_values(const Mesh &mesh);

/// Throws pomar::Error (InvalidMesh) naming the face if the per-corner values do not fit the
/// mesh: sizes, material indices out of range, NaN or infinite coordinates (unless `exact`).
void validate_corner_values(const Mesh &mesh, bool exact);

/// Give `cut` (the lossless stage's cut of `input`, related by `map`) the per-corner values
/// of `input`: cut face f has those of input face map.face_origin[f], corners 1 and 2
/// swapped if it is flipped.
void corner_values_of_cut(const Mesh &input, const RepairMap &map, Mesh &cut);

struct SeamCut {
  size_t seam_edges = 0;   ///< edges whose faces disagree at an end
  size_t wedge_copies = 0; ///< vertices added (one per wedge but the first)
  /// Per vertex of the cut: 1 if it is on a seam (decimation keeps it).
  std::vector<uint8_t> locked;
  /// Per vertex of the cut: for the two copies of a vertex on a simple seam (two wedges,
  /// two seam edges, not on the mesh's boundary), the other one; else kNone. Twins are not
  /// locked: they collapse together (DecimationOptions::twin).
  std::vector<uint32_t> twin;
  /// Per vertex of the cut: the vertex it is a copy of (itself for the first wedge).
  std::vector<uint32_t> origin;
  size_t twins = 0; ///< vertices with a twin
};

/// Cut `mesh` (manifold and oriented: the lossless stage's cut) along its texture seams:
/// copies appended after its vertices (their positions and attributes those of the vertex
/// they copy), faces renumbered in place, the wedge attributes added, the per-corner values
/// cleared (materials and texture files stay). `map.copy_of` is extended so that it names,
/// for each copy, the vertex of the lossless stage's input (`input_vertices` vertices) it
/// stands for.
SeamCut cut_at_seams(Mesh &mesh, RepairMap &map, uint32_t input_vertices);

/// A decoded mesh: the wedge attributes, if it has them, become per-corner texture
/// coordinates and face materials (and are removed). A material index that is not an
/// integer of the file's materials is a damaged file.
void corners_from_wedges(Mesh &mesh);

} // namespace pomar
