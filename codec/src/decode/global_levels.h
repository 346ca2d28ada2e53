// The global part of a file, decoded for every request: base mesh and global levels.
// Used by pomar::decode and by the SelectiveDecoder.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "entropy/models.h"
#include "format/file_format.h"
#include "pomar/pomar.h"
#include "refine/level_mesh.h"

namespace pomar {

/// Decode global levels [from, to) of `mesh` (the file image must hold the global part)
/// and return `to`. A damaged level throws pomar::Error, or, if `damaged` is given, is
/// recorded there and ends the decoding: the mesh stays at the level before it, whose
/// number is returned.
size_t decode_global_levels(const uint8_t *data, const FileLayout &layout, size_t from, size_t to,
                            LevelMesh &mesh, Models &models, const Progress &progress,
                            std::vector<DamagedBlock> *damaged = nullptr);

/// The base mesh of a file as a LevelMesh (lineage initialised).
LevelMesh base_level_mesh(const uint8_t *data, const FileLayout &layout);

/// Dequantized positions and triangles of a LevelMesh.
Mesh to_mesh(const LevelMesh &lm, const Quantizer &grid);
/// The same, taking the triangles over (no copy of the corner table's vertex array) and
/// freeing the rest of the mesh first; `lm` keeps only its attribute codes.
Mesh to_mesh(LevelMesh &&lm, const Quantizer &grid);

} // namespace pomar
