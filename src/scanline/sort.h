// The two sorts of Woo & Chall §3.3, without recursion and without heap memory.
//  - ySortList: quicksort with an explicit stack (the larger part is pushed, the smaller one is
//    worked on next, so the stack never holds more than log2(n) ranges: at most 34 entries of
//    8 bytes, 272 bytes), and one insertion-sort pass over the runs it leaves shorter than
//    kQuickCutoff.
//  - yActiveList order: heap sort, or insertion sort below kActiveInsertionMax entries (the
//    threshold is measured, docs/scanline.md).
// Both count comparisons + element moves in *work (Stats::sort_instructions).
#pragma once
#include <stdint.h>

namespace ml {
namespace scan {

constexpr uint32_t kQuickCutoff = 12;
constexpr uint32_t kActiveInsertionMax = 40;   // random keys: insertion wins below ~40 (measured)

// Insertion sort that gives up after `budget` comparisons + moves (a[] is then still a permutation,
// partly sorted). Returns whether it finished.
template <typename T, typename KeyFn>
bool insertion_sort_within(T* a, uint32_t n, KeyFn key, uint64_t budget, uint64_t* work) {
  uint64_t w = 0;
  for (uint32_t i = 1; i < n; ++i) {
    const T v = a[i];
    const auto k = key(v);
    uint32_t j = i;
    while (j > 0) {
      ++w;
      if (!(k < key(a[j - 1]))) break;
      a[j] = a[j - 1];
      ++w;
      --j;
    }
    if (j != i) { a[j] = v; w += 2; }
    if (w > budget) { *work += w; return false; }
  }
  *work += w;
  return true;
}

// Insertion sort of a[0..n) by key(a[i]) ascending. Fast on nearly sorted input.
template <typename T, typename KeyFn>
void insertion_sort(T* a, uint32_t n, KeyFn key, uint64_t* work) {
  insertion_sort_within(a, n, key, UINT64_MAX, work);
}

// Non-recursive quicksort (Sedgewick's formulation: median of three, Hoare partition that stops on
// equal keys, so all-equal input stays O(n log n)), then one insertion pass.
template <typename T, typename KeyFn>
void quick_sort(T* a, uint32_t n, KeyFn key, uint64_t* work) {
  if (n < 2) return;
  struct Range { uint32_t lo, hi; };  // inclusive
  Range stack[34];                    // depth <= log2(2^32) + 1 (the smaller part is processed first)
  int top = 0;
  uint64_t w = 0;
  uint32_t lo = 0, hi = n - 1;
  for (;;) {
    while (hi - lo + 1 > kQuickCutoff) {
      const uint32_t mid = lo + (hi - lo) / 2;
      // Median of three into a[mid], then park it at a[hi - 1]; a[lo] <= pivot <= a[hi] are sentinels.
      if (key(a[mid]) < key(a[lo])) { T t = a[mid]; a[mid] = a[lo]; a[lo] = t; w += 3; }
      if (key(a[hi]) < key(a[lo])) { T t = a[hi]; a[hi] = a[lo]; a[lo] = t; w += 3; }
      if (key(a[hi]) < key(a[mid])) { T t = a[hi]; a[hi] = a[mid]; a[mid] = t; w += 3; }
      w += 3;
      { T t = a[mid]; a[mid] = a[hi - 1]; a[hi - 1] = t; w += 3; }
      const auto pivot = key(a[hi - 1]);
      uint32_t i = lo, j = hi - 1;
      for (;;) {
        do { ++i; ++w; } while (key(a[i]) < pivot);
        do { --j; ++w; } while (pivot < key(a[j]));
        if (i >= j) break;
        T t = a[i]; a[i] = a[j]; a[j] = t; w += 3;
      }
      { T t = a[i]; a[i] = a[hi - 1]; a[hi - 1] = t; w += 3; }
      // Left part [lo, i-1], right part [i+1, hi]. Push the larger, continue with the smaller.
      const uint32_t left_n = i - lo, right_n = hi - i;
      if (left_n > right_n) {
        stack[top++] = Range{lo, i - 1};
        lo = i + 1;
      } else {
        if (right_n > 0) stack[top++] = Range{i + 1, hi};
        if (left_n == 0) break;
        hi = i - 1;
      }
    }
    if (top == 0) break;
    --top;
    lo = stack[top].lo;
    hi = stack[top].hi;
  }
  *work += w;
  insertion_sort(a, n, key, work);
}

// Heap sort (max-heap, sift-down), ascending by key.
template <typename T, typename KeyFn>
void heap_sort(T* a, uint32_t n, KeyFn key, uint64_t* work) {
  if (n < 2) return;
  uint64_t w = 0;
  auto sift = [&](uint32_t root, uint32_t end) {  // heap is a[0..end)
    const T v = a[root];
    const auto k = key(v);
    uint32_t r = root;
    for (;;) {
      uint32_t child = 2 * r + 1;
      if (child >= end) break;
      if (child + 1 < end) {
        ++w;
        if (key(a[child]) < key(a[child + 1])) ++child;
      }
      ++w;
      if (!(k < key(a[child]))) break;
      a[r] = a[child];
      ++w;
      r = child;
    }
    if (r != root) { a[r] = v; w += 2; }
  };
  for (uint32_t i = n / 2; i-- > 0;) sift(i, n);
  for (uint32_t end = n - 1; end > 0; --end) {
    T t = a[0]; a[0] = a[end]; a[end] = t; w += 3;
    sift(0, end);
  }
  *work += w;
}

// The yActiveList sort: insertion sort for short lists, heap sort otherwise.
template <typename T, typename KeyFn>
void active_sort(T* a, uint32_t n, KeyFn key, uint64_t* work, uint32_t insertion_max = kActiveInsertionMax) {
  if (n <= insertion_max) insertion_sort(a, n, key, work);
  else heap_sort(a, n, key, work);
}

// Moves per element the kept order may cost by insertion before heap sort takes over (measured on
// 2CylinderEngine and the tessellated model, docs/scanline.md).
constexpr uint32_t kKeptMovesPerEntry = 8;

// Sorts kept[0, nk) (the previous row's order with keys moved a little: insertion sort, heap sort if
// that gets expensive) and fresh[0, nf) (active_sort), then merges fresh into kept from the back:
// kept[0, nk + nf) holds the result (kept needs room for nk + nf entries).
template <typename T, typename KeyFn>
void sort_kept_and_fresh(T* kept, uint32_t nk, T* fresh, uint32_t nf, KeyFn key, uint64_t* work) {
  if (!insertion_sort_within(kept, nk, key, uint64_t(kKeptMovesPerEntry) * nk, work)) heap_sort(kept, nk, key, work);
  if (nf <= kActiveInsertionMax) insertion_sort(fresh, nf, key, work);
  else quick_sort(fresh, nf, key, work);  // random keys: fewer steps than heap sort
  uint32_t i = nk, j = nf, o = nk + nf;
  while (j > 0) {
    if (i > 0 && key(fresh[j - 1]) < key(kept[i - 1])) kept[--o] = kept[--i];
    else kept[--o] = fresh[--j];
  }
  *work += 2 * uint64_t(nf);
}

}  // namespace scan
}  // namespace ml
