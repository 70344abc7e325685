// Instruction counts of the yActiveList sorts (run under callgrind; docs/scanline.md).
//   sort_bench ALG N REPS ORDER   ALG: none | insertion | heap; ORDER: random | near (a few swaps)
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "scanline/sort.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: sort_bench none|insertion|heap N REPS random|near\n");
    return 2;
  }
  const char* alg = argv[1];
  const uint32_t n = uint32_t(std::atoi(argv[2])), reps = uint32_t(std::atoi(argv[3]));
  const bool near = std::strcmp(argv[4], "near") == 0;
  std::vector<uint16_t> keys(n);
  std::vector<uint32_t> idx(n);
  uint32_t s = 12345;
  uint64_t work = 0;
  for (uint32_t r = 0; r < reps; ++r) {
    for (uint32_t i = 0; i < n; ++i) {
      s ^= s << 13; s ^= s >> 17; s ^= s << 5;
      keys[i] = near ? uint16_t(i * 4 + (s % 9)) : uint16_t(s);
      idx[i] = i;
    }
    auto key = [&](uint32_t i) { return keys[i]; };
    if (std::strcmp(alg, "insertion") == 0) ml::scan::insertion_sort(idx.data(), n, key, &work);
    else if (std::strcmp(alg, "heap") == 0) ml::scan::heap_sort(idx.data(), n, key, &work);
  }
  std::printf("%llu\n", (unsigned long long)work);
  return 0;
}
