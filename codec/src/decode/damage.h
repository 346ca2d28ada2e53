// Damage reports shared by the decoders (pomar::DamagedBlock is public, in pomar.h): one
// way to name each kind of block, and the wording of damage no block can be blamed for.
#pragma once

#include <cstdint>
#include <string>

#include "pomar/pomar.h"

namespace pomar {

/// The message for damage in the cluster data that no block's own check found.
extern const char *const kUnlocatedDamage;
/// The caution added when a block that passes its 8-bit check fails to decode.
extern const char *const kUnplacedDamage;

/// Global level `level` (1-based) is damaged: the mesh stays at level - 1.
DamagedBlock damaged_level(size_t level, const std::string &problem);
/// Cluster `cluster`'s block is damaged (or suspect): the cluster stays at `level_kept`.
DamagedBlock damaged_cluster(uint32_t cluster, const std::string &problem, int level_kept);
/// Damage in the cluster data that cannot be located ("cluster data", level_kept -1).
DamagedBlock unlocated_damage(const char *problem);

} // namespace pomar
