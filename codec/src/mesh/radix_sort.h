// A stable sort of (64-bit key, 32-bit id) pairs by key: the Morton order of the encoder's
// vertices (mesh/reorder.cpp) and the lossless record's vertices grouped by position
// (lossless/lossless_record.cpp).
#pragma once

#include <cstdint>
#include <vector>

namespace pomar {

// (12 bytes, not 16: the sorts hold two arrays of them, of a mesh's vertices or faces.)
#pragma pack(push, 4)
struct Keyed {
  uint64_t key;
  uint32_t id;
};
#pragma pack(pop)
static_assert(sizeof(Keyed) == 12, "Keyed is packed");

/// Sort by (key, id) when the entries arrive by increasing id: a stable least-significant-
/// digit radix sort on the key alone, 11 bits a pass, skipping the digits every key shares
/// (a 12-bit grid gives 27-bit keys: 3 passes instead of 6).
void sort_by_key(std::vector<Keyed> &a);

} // namespace pomar
