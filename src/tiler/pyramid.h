// The coverage pyramid (Greene's mask pyramid), in samples.
//
// The screen of width x height samples is padded to a square of 8^n samples, n = levels >= 2.
// Level 0 is one triage mask for the whole square; a mask at level l covers 8^(n-l) samples per
// side, and subcell (col, row) of mask (mx, my) is mask (8 mx + col, 8 my + row) of level l + 1.
// Levels 0 .. n-2 hold triage masks (c, v: covered / vacant, neither = active); level n-1 holds
// one-bit masks of 8x8 samples (1 = covered). Bit order everywhere: bit = row * 8 + col, row 0 at
// the top (as tables/mask_tables.h).
//
// Only masks that overlap the screen are stored: level l keeps ceil(W / 8^(n-l)) x ceil(H / 8^(n-l))
// masks row-major. Subcells and samples outside the screen start covered, so they are never
// subdivided or written and the missing masks are never read. For a screen that is the whole padded
// square this is 1 + (2/63)(1 - 64^-(n-1)) bits per sample; otherwise fewer bytes.
//
// Stale children: when a subcell becomes covered through a coarse write its finer masks are left as
// they were; nothing reads them again (tiling skips covered subcells).
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/arena.h"

namespace ml {

constexpr int kPyramidMaxLevels = 5;  // 8^5 = 32768 = kMaxSampleDim samples per side

struct TriageMask {
  uint64_t c, v;
};

struct PyramidLayout {
  int width = 0, height = 0;            // samples
  int levels = 0;                       // n
  int cols[kPyramidMaxLevels] = {};     // masks stored per level
  int rows[kPyramidMaxLevels] = {};
  uint32_t triage_count = 0;            // masks on levels 0 .. n-2
  uint32_t block_count = 0;             // one-bit masks on level n-1

  // log2 of a level-l mask's side in samples.
  int shift(int level) const { return 3 * (levels - level); }
  int finest() const { return levels - 1; }
  uint32_t bytes() const { return triage_count * 16u + block_count * 8u; }
};

// False when width or height is outside 1..kMaxSampleDim.
bool make_pyramid_layout(int width, int height, PyramidLayout* out);

struct Pyramid {
  PyramidLayout layout;
  TriageMask* triage[kPyramidMaxLevels - 1] = {};  // level l row-major, layout.cols[l] per row
  uint64_t* blocks = nullptr;                      // finest level

  // Arena bytes allocate() can take at most.
  static size_t arena_bytes(const PyramidLayout& layout);
  // Takes the masks from the arena; false when it is too small.
  bool allocate(const PyramidLayout& layout, Arena& arena);
  // Start-of-frame state: everything on screen vacant, everything off screen covered.
  void clear();

  TriageMask& mask(int level, int mx, int my) const {
    return triage[level][size_t(my) * size_t(layout.cols[level]) + size_t(mx)];
  }
  uint64_t& block(int bx, int by) const {
    return blocks[size_t(by) * size_t(layout.cols[layout.levels - 1]) + size_t(bx)];
  }
};

}  // namespace ml
