// Damage reports shared by the decoders (pomar::DamagedBlock is public, in pomar.h).
#pragma once

namespace pomar {

/// The message for damage in the cluster data that no block's own check found.
extern const char *const kUnlocatedDamage;
/// The caution added when a block that passes its 8-bit check fails to decode.
extern const char *const kUnplacedDamage;

} // namespace pomar
