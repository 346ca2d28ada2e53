// Damage reports (see damage.h).
#include "decode/damage.h"

namespace pomar {

const char *const kUnplacedDamage =
    "damaged .pomar file: a block that passes its 8-bit check failed to decode; it and its "
    "neighbours were skipped, but the damage may lie in another block whose wrong data "
    "decoded: the mesh may be wrong in places";

const char *const kUnlocatedDamage =
    "damaged .pomar file: the cluster data fails its checksum although every block passes "
    "its 8-bit check: a damaged block cannot be located, the mesh may be wrong in places";

DamagedBlock damaged_level(size_t level, const std::string &problem) {
  DamagedBlock b{"level " + std::to_string(level), problem, static_cast<int>(level) - 1};
  b.level = static_cast<int>(level);
  return b;
}

DamagedBlock damaged_cluster(uint32_t cluster, const std::string &problem, int level_kept) {
  DamagedBlock b{"cluster " + std::to_string(cluster), problem, level_kept};
  b.cluster = cluster;
  return b;
}

DamagedBlock unlocated_damage(const char *problem) { return {"cluster data", problem, -1}; }

} // namespace pomar
