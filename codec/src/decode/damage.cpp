// The wording of damage that cannot be pinned on one block (see damage.h).
#include "decode/damage.h"

namespace pomar {

const char *const kUnplacedDamage =
    "damaged .pomar file: a block that passes its 8-bit check failed to decode; it and its "
    "neighbours were skipped, but the damage may lie in another block whose wrong data "
    "decoded: the mesh may be wrong in places";

const char *const kUnlocatedDamage =
    "damaged .pomar file: the cluster data fails its checksum although every block passes "
    "its 8-bit check: a damaged block cannot be located, the mesh may be wrong in places";

} // namespace pomar
