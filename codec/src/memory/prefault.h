// Memory about to be written for the first time, mapped in one system call instead of
// one page fault per 4 KiB page as the writes reach it.
//
// A decode writes its mesh arrays (reserved from the level table's counts), the
// dequantized positions and the output buffer once each, front to back; an encode the
// arrays of its input preparation (quantized positions, Morton keys, renumbered faces,
// corner tables) and the PLY reader's. Each first write to a page is a page fault. Where
// faults are dear (virtual machines: about 7 us each on the 2-core VM of bench/README.md,
// "Page faults", against under 1 us a page in one madvise call) they are a seventh of
// the CPU time of a 134k-vertex decode that does not prefault. Prefaulting changes no byte and no result: the
// pages would be mapped a moment later anyway.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace pomar {

/// Map the pages holding [p, p + bytes) writable now (Linux 5.14 and later:
/// madvise(MADV_POPULATE_WRITE)). Elsewhere, or when the kernel refuses, nothing happens
/// and the pages fault in as they are written. Small ranges (under 64 KiB) are left alone.
void prefault(void *p, size_t bytes);

/// Prefault a vector's room past its size (what reserve() made), when all of it is about
/// to be written (a buffer, an array sized then filled).
template <class T> void prefault_room(std::vector<T> &v) {
  prefault(v.data() + v.size(), (v.capacity() - v.size()) * sizeof(T));
}

/// Room for `n` elements with the room past the size mapped (for an assign or resize that
/// writes it all next).
template <class T> void reserve_prefaulted(std::vector<T> &v, size_t n) {
  v.reserve(n);
  prefault_room(v);
}

/// resize(n) with the new room mapped first (an array about to be written whole).
template <class T> void resize_prefaulted(std::vector<T> &v, size_t n) {
  reserve_prefaulted(v, n);
  v.resize(n);
}

/// `n` value-initialised elements (zeros: a memset), the memory mapped in one call before
/// the fill (a large array about to be written whole).
template <class T> std::vector<T> filled_vector(size_t n) {
  std::vector<T> v;
  resize_prefaulted(v, n);
  return v;
}

/// `n` copies of `value`, the same way.
template <class T> std::vector<T> filled_vector(size_t n, const T &value) {
  std::vector<T> v;
  reserve_prefaulted(v, n);
  v.resize(n, value);
  return v;
}

/// A vector filled front to back within a room reserved from counts a file claims (a
/// hostile header may claim more than its data makes): its room is mapped a stretch ahead
/// of its end, never all at once. The mapped part ends at the stretch after the end's
/// stretch (within the capacity): prefault_ahead_start after reserve(), prefault_ahead
/// after each growth (from `old_size` elements).
constexpr size_t kPrefaultStretch = size_t(256) << 10;
template <class T> size_t mapped_ahead_end(const std::vector<T> &v, size_t size) {
  const size_t end = (size * sizeof(T) / kPrefaultStretch + 2) * kPrefaultStretch;
  return std::min(end, v.capacity() * sizeof(T));
}
template <class T> void prefault_ahead_start(std::vector<T> &v) {
  const size_t from = v.size() * sizeof(T), to = mapped_ahead_end(v, v.size());
  if (to > from)
    prefault(reinterpret_cast<char *>(v.data()) + from, to - from);
}
template <class T> void prefault_ahead(std::vector<T> &v, size_t old_size, size_t new_size) {
  const size_t from = mapped_ahead_end(v, old_size), to = mapped_ahead_end(v, new_size);
  if (to > from)
    prefault(reinterpret_cast<char *>(v.data()) + from, to - from);
}
template <class T> void prefault_ahead(std::vector<T> &v, size_t old_size) {
  prefault_ahead(v, old_size, v.size());
}

} // namespace pomar
