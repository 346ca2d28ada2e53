// One sort for every platform, where the order of equal elements is part of the bitstream.
//
// Two sorts with equal elements leave them in an order that depends on the algorithm: the
// edge ranking of a split vertex with more than 16 edges (refine/patch.h: a view ring can
// name one neighbour twice, and the two entries tie) and the encoder's face order
// (mesh/reorder.cpp: faces tie on their smallest vertex). The bitstream follows the order
// of GCC's std::sort, an introsort; the browser decoder is built by Emscripten, whose
// library (libc++) sorts small ranges otherwise. On 96,230 random rings of 17-40 entries
// with one tie, GCC's std::sort leaves about half of the ties in another order than a
// stable sort, and the Emscripten build's std::sort does not give GCC's orders (a hash of
// all of them differs): a browser decode of such a file would take another edge.
// `introsort` is that algorithm, written out so that every build sorts alike and every
// file keeps its meaning (the Emscripten build of it gives GCC's orders on those rings):
//
// - while more than 16 elements remain: the median of the second, middle and last
//   elements is swapped to the front and the rest partitioned around it (Hoare's scheme,
//   unguarded: both scans stop at an element equal to the pivot); the right part is
//   sorted recursively, the left one by the loop; past 2 floor(log2 n) levels the range
//   is heap-sorted instead;
// - then one insertion sort over everything (the first 16 guarded, the rest unguarded: the
//   partitions put a smaller-or-equal element before each of them).
//
// tests/test_introsort.cpp compares it with the standard library's std::sort and
// std::partial_sort (the heap path) on tie-heavy inputs when that library is GCC's.
#pragma once

#include <cstddef>
#include <utility>

namespace pomar {
namespace introsort_detail {

constexpr ptrdiff_t kThreshold = 16;

template <class T, class Less>
void move_median_to_first(T *result, T *a, T *b, T *c, const Less &less) {
  if (less(*a, *b)) {
    if (less(*b, *c))
      std::swap(*result, *b);
    else if (less(*a, *c))
      std::swap(*result, *c);
    else
      std::swap(*result, *a);
  } else if (less(*a, *c)) {
    std::swap(*result, *a);
  } else if (less(*b, *c)) {
    std::swap(*result, *c);
  } else {
    std::swap(*result, *b);
  }
}

/// Partition [first, last) around *pivot (outside the range, before it): returns the
/// first element of the right part.
template <class T, class Less> T *partition(T *first, T *last, const T *pivot, const Less &less) {
  for (;;) {
    while (less(*first, *pivot))
      ++first;
    --last;
    while (less(*pivot, *last))
      --last;
    if (!(first < last))
      return first;
    std::swap(*first, *last);
    ++first;
  }
}

/// Move the value at `hole` down towards `top` while its parent is smaller.
template <class T, class Less>
void push_heap(T *first, ptrdiff_t hole, ptrdiff_t top, T value, const Less &less) {
  ptrdiff_t parent = (hole - 1) / 2;
  while (hole > top && less(first[parent], value)) {
    first[hole] = std::move(first[parent]);
    hole = parent;
    parent = (hole - 1) / 2;
  }
  first[hole] = std::move(value);
}

/// Fill the hole at `hole` of a heap of `len` by moving the larger child up to the
/// bottom, then push `value` back up from there.
template <class T, class Less>
void adjust_heap(T *first, ptrdiff_t hole, ptrdiff_t len, T value, const Less &less) {
  const ptrdiff_t top = hole;
  ptrdiff_t child = hole;
  while (child < (len - 1) / 2) {
    child = 2 * (child + 1);
    if (less(first[child], first[child - 1]))
      --child;
    first[hole] = std::move(first[child]);
    hole = child;
  }
  if ((len & 1) == 0 && child == (len - 2) / 2) {
    child = 2 * (child + 1);
    first[hole] = std::move(first[child - 1]);
    hole = child - 1;
  }
  introsort_detail::push_heap(first, hole, top, std::move(value), less);
}

/// Heap sort (the depth limit's fallback): a max-heap built from the last parent back to
/// the root, then the root swapped to the end one element at a time.
template <class T, class Less> void heap_sort(T *first, T *last, const Less &less) {
  const ptrdiff_t len = last - first;
  if (len >= 2) {
    for (ptrdiff_t parent = (len - 2) / 2;; --parent) {
      T value = std::move(first[parent]);
      introsort_detail::adjust_heap(first, parent, len, std::move(value), less);
      if (parent == 0)
        break;
    }
  }
  while (last - first > 1) {
    --last;
    T value = std::move(*last);
    *last = std::move(*first);
    introsort_detail::adjust_heap(first, ptrdiff_t(0), last - first, std::move(value), less);
  }
}

template <class T, class Less> void loop(T *first, T *last, int depth, const Less &less) {
  while (last - first > kThreshold) {
    if (depth == 0) {
      introsort_detail::heap_sort(first, last, less);
      return;
    }
    --depth;
    introsort_detail::move_median_to_first(first, first + 1, first + (last - first) / 2, last - 1,
                                           less);
    T *cut = introsort_detail::partition(first + 1, last, first, less);
    introsort_detail::loop(cut, last, depth, less);
    last = cut;
  }
}

/// Insert *at into the sorted elements before it; one of them is not larger (no bound).
template <class T, class Less> void insert_unguarded(T *at, const Less &less) {
  T value = std::move(*at);
  T *next = at - 1;
  while (less(value, *next)) {
    *at = std::move(*next);
    at = next;
    --next;
  }
  *at = std::move(value);
}

template <class T, class Less> void insertion_sort(T *first, T *last, const Less &less) {
  if (first == last)
    return;
  for (T *i = first + 1; i != last; ++i) {
    if (less(*i, *first)) {
      T value = std::move(*i);
      for (T *j = i; j != first; --j)
        *j = std::move(*(j - 1));
      *first = std::move(value);
    } else {
      introsort_detail::insert_unguarded(i, less);
    }
  }
}

inline int floor_log2(size_t n) {
  int k = 0;
  while (n >>= 1)
    ++k;
  return k;
}

} // namespace introsort_detail

/// Sort [first, last) by `less` (a strict weak order), equal elements ending where GCC's
/// std::sort leaves them, on every platform (see above).
template <class T, class Less> void introsort(T *first, T *last, const Less &less) {
  namespace d = introsort_detail;
  if (last - first < 2)
    return;
  d::loop(first, last, 2 * d::floor_log2(size_t(last - first)), less);
  if (last - first > d::kThreshold) {
    d::insertion_sort(first, first + d::kThreshold, less);
    for (T *i = first + d::kThreshold; i != last; ++i)
      d::insert_unguarded(i, less);
  } else {
    d::insertion_sort(first, last, less);
  }
}

} // namespace pomar
