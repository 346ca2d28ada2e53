#include "memory/prefault.h"

#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace pomar {

void prefault(void *p, size_t bytes) {
#if defined(__linux__)
  constexpr uintptr_t kPage = 4096;
  constexpr int kPopulateWrite = 23; // MADV_POPULATE_WRITE (glibc headers before 2.35 lack it)
  if (!p || bytes < 16 * kPage)
    return;
  // The pages holding the first and the last byte are mapped (they hold the range's own
  // bytes), and so is every page between: rounding outwards stays inside the mapping.
  const uintptr_t first = uintptr_t(p) & ~(kPage - 1);
  const uintptr_t end = (uintptr_t(p) + bytes + kPage - 1) & ~(kPage - 1);
  (void)::madvise(reinterpret_cast<void *>(first), end - first, kPopulateWrite);
#else
  (void)p;
  (void)bytes;
#endif
}

} // namespace pomar
