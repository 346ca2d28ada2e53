// memory/prefault.h: mapping memory ahead of its first writes changes no byte, maps what
// it says (Linux: the pages become resident, read back with mincore), and a room reserved
// from a file's claimed counts is mapped a stretch ahead of the end, never all at once.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

#include "memory/prefault.h"
#include "refine/level_mesh.h"
#include "refine/traversal_marks.h"

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace pomar {
namespace {

TEST(Prefault, ChangesNoByte) {
  std::vector<uint32_t> v(100000);
  std::iota(v.begin(), v.end(), 7u);
  v.reserve(1 << 20);
  prefault_room(v);
  prefault(v.data(), v.size() * sizeof(uint32_t)); // (over bytes already written)
  prefault_ahead_start(v);
  const size_t before = v.size();
  v.resize(v.size() + 70000, 5u);
  prefault_ahead(v, before);
  ASSERT_EQ(v.size(), 170000u);
  for (uint32_t i = 0; i < 100000; ++i)
    ASSERT_EQ(v[i], i + 7) << i;
  for (uint32_t i = 100000; i < 170000; ++i)
    ASSERT_EQ(v[i], 5u) << i;
  prefault(nullptr, 1 << 20); // nothing to map: no effect
  prefault(v.data(), 0);
}

// A cluster traversed on one thread begins with the mesh's face count, a few faces more
// each time: the claim stamps must grow by doubling (reserving each exact count, as a first
// version of the prefault did, copied them at every cluster: 14 times slower).
TEST(Prefault, ClaimStampsGrowByDoubling) {
  TraversalScratch s;
  int moves = 0;
  const uint32_t *at = nullptr;
  for (uint32_t faces = 1000; faces < 1000000; faces += 37) {
    s.begin(0, faces);
    ASSERT_GE(s.claimed.size(), faces);
    moves += s.claimed.data() != at;
    at = s.claimed.data();
  }
  EXPECT_LE(moves, 12); // 1000 -> 1000000: 10 doublings
  for (uint32_t c : s.claimed)
    ASSERT_NE(c, s.stamp); // (new stamps are zero: no face claimed by this traversal)
}

#if defined(__linux__)
/// Resident pages of [p, p + bytes) (whole pages inside it), or -1 if mincore fails.
long resident_pages(const void *p, size_t bytes) {
  const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
  const uintptr_t first = (uintptr_t(p) + page - 1) & ~(page - 1);
  const uintptr_t end = (uintptr_t(p) + bytes) & ~(page - 1);
  if (end <= first)
    return 0;
  std::vector<unsigned char> in((end - first) / page);
  if (mincore(reinterpret_cast<void *>(first), end - first, in.data()) != 0)
    return -1;
  long n = 0;
  for (unsigned char c : in)
    n += c & 1;
  return n;
}

/// Whether this kernel maps pages on request (MADV_POPULATE_WRITE, Linux 5.14+).
bool kernel_populates() {
  const long page = sysconf(_SC_PAGESIZE);
  void *p = mmap(nullptr, size_t(page), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED)
    return false;
  const bool ok = madvise(p, size_t(page), 23 /* MADV_POPULATE_WRITE */) == 0;
  munmap(p, size_t(page));
  return ok;
}

TEST(Prefault, MapsTheRoomOfAVector) {
  if (!kernel_populates())
    GTEST_SKIP() << "this kernel has no MADV_POPULATE_WRITE";
  std::vector<uint8_t> v;
  v.reserve(size_t(16) << 20); // (a fresh mapping of its own: nothing resident yet)
  const size_t pages = (size_t(16) << 20) / size_t(sysconf(_SC_PAGESIZE));
  ASSERT_LT(resident_pages(v.data(), v.capacity()), long(pages / 2));
  prefault_room(v);
  EXPECT_GE(resident_pages(v.data(), v.capacity()), long(pages) - 2);
}

TEST(Prefault, ReservedRoomIsMappedAStretchAhead) {
  if (!kernel_populates())
    GTEST_SKIP() << "this kernel has no MADV_POPULATE_WRITE";
  const long page = sysconf(_SC_PAGESIZE);
  const long stretch_pages = long(kPrefaultStretch) / page;
  std::vector<uint8_t> v;
  v.reserve(size_t(64) << 20); // as if a header claimed 64 MB: none of it written yet
  prefault_ahead_start(v);
  const long start = resident_pages(v.data(), v.capacity());
  EXPECT_GE(start, 2 * stretch_pages - 2); // the end's stretch and the next
  EXPECT_LE(start, 3 * stretch_pages);     // not the 64 MB
  // Growing through five stretches maps five more, and keeps the end's next one mapped.
  v.resize(5 * kPrefaultStretch + 100);
  prefault_ahead(v, 0);
  const long grown = resident_pages(v.data(), v.capacity());
  EXPECT_GE(grown, 7 * stretch_pages - 2);
  EXPECT_LE(grown, 8 * stretch_pages);
  EXPECT_GE(resident_pages(v.data() + 6 * kPrefaultStretch, kPrefaultStretch), stretch_pages - 1);
}

TEST(Prefault, LevelMeshGrowsWithinItsMappedRoom) {
  if (!kernel_populates())
    GTEST_SKIP() << "this kernel has no MADV_POPULATE_WRITE";
  LevelMesh m;
  m.reserve_counts(1000000, 2000000); // claimed counts: 24 MB of corner table each
  const long page = sysconf(_SC_PAGESIZE);
  const size_t room = m.ct.V.capacity() * sizeof(uint32_t);
  EXPECT_LE(resident_pages(m.ct.V.data(), room), 3 * long(kPrefaultStretch) / page);
  m.grow(1000, 2000); // a first level's worth
  EXPECT_EQ(m.ct.V.size(), 6000u);
  EXPECT_EQ(m.vertex_count(), 1000u);
  EXPECT_EQ(m.face_claim.size(), 2000u);
  for (uint16_t c : m.face_claim)
    ASSERT_EQ(c, 0); // new faces: held by no patch
  const long mapped = resident_pages(m.ct.V.data(), room);
  EXPECT_GE(mapped, 2 * long(kPrefaultStretch) / page - 2); // ahead of the end, and
  EXPECT_LE(mapped, 3 * long(kPrefaultStretch) / page);     // not the claimed 24 MB
}
#endif

} // namespace
} // namespace pomar
