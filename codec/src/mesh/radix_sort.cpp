#include "mesh/radix_sort.h"

#include <algorithm>

#include "memory/prefault.h"

namespace pomar {

void sort_by_key(std::vector<Keyed> &a) {
  constexpr int kBits = 11;
  constexpr uint64_t kMask = (uint64_t(1) << kBits) - 1;
  std::vector<Keyed> scratch = filled_vector<Keyed>(a.size());
  std::vector<uint32_t> start(kMask + 2);
  for (int shift = 0; shift < 64; shift += kBits) {
    std::fill(start.begin(), start.end(), 0);
    for (const Keyed &x : a)
      ++start[((x.key >> shift) & kMask) + 1];
    if (std::count(start.begin(), start.end(), uint32_t(a.size())) == 1)
      continue; // one digit for all: the pass would not move anything
    for (size_t d = 1; d < start.size(); ++d)
      start[d] += start[d - 1];
    for (const Keyed &x : a)
      scratch[start[(x.key >> shift) & kMask]++] = x;
    a.swap(scratch);
  }
}

} // namespace pomar
