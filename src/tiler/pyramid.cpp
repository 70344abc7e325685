#include "tiler/pyramid.h"

#include "core/fixed.h"

namespace ml {

bool make_pyramid_layout(int width, int height, PyramidLayout* out) {
  *out = PyramidLayout{};
  if (width < 1 || height < 1 || width > kMaxSampleDim || height > kMaxSampleDim) return false;
  const int side = max_of(width, height);
  int n = 2;  // a root triage mask over one-bit blocks at least
  while ((1 << (3 * n)) < side) ++n;
  out->width = width;
  out->height = height;
  out->levels = n;
  for (int l = 0; l < n; ++l) {
    const int s = out->shift(l);
    out->cols[l] = (width + (1 << s) - 1) >> s;
    out->rows[l] = (height + (1 << s) - 1) >> s;
    const uint32_t count = uint32_t(out->cols[l]) * uint32_t(out->rows[l]);
    if (l < n - 1) out->triage_count += count; else out->block_count = count;
  }
  return true;
}

size_t Pyramid::arena_bytes(const PyramidLayout& layout) {
  size_t bytes = 0;
  for (int l = 0; l + 1 < layout.levels; ++l)
    bytes += arena_worst_case(size_t(layout.cols[l]) * size_t(layout.rows[l]) * sizeof(TriageMask));
  const int f = layout.levels - 1;
  bytes += arena_worst_case(size_t(layout.cols[f]) * size_t(layout.rows[f]) * sizeof(uint64_t));
  return bytes;
}

bool Pyramid::allocate(const PyramidLayout& l, Arena& arena) {
  layout = l;
  for (int i = 0; i < kPyramidMaxLevels - 1; ++i) triage[i] = nullptr;
  for (int i = 0; i + 1 < l.levels; ++i) {
    triage[i] = arena.allocate_array<TriageMask>(size_t(l.cols[i]) * size_t(l.rows[i]));
    if (!triage[i]) return false;
  }
  const int f = l.levels - 1;
  blocks = arena.allocate_array<uint64_t>(size_t(l.cols[f]) * size_t(l.rows[f]));
  return blocks != nullptr;
}

// Pyramid::clear's masks wholly on screen stored without a test each, on 64-bit hosts.
constexpr bool kFastClear = UINTPTR_MAX > 0xFFFFFFFFu;

// Bits of an 8x8 mask whose subcells (side 2^sub samples, mask origin x0, y0) lie wholly or partly
// off screen: a subcell is wholly off when its column or its row is, partly when neither is but its
// column or row crosses the screen edge. Columns and rows are classified once each (16 tests, not 64).
static void offscreen_bits(int x0, int y0, int sub, int width, int height, uint64_t* wholly,
                           uint64_t* partly) {
  const int q = 1 << sub;
  uint32_t col_off = 0, col_cut = 0;
  uint64_t row_off = 0, row_cut = 0;
  for (int i = 0; i < 8; ++i) {
    const int x = x0 + i * q, y = y0 + i * q;
    if (x >= width) col_off |= 1u << i;
    else if (x + q > width) col_cut |= 1u << i;
    if (y >= height) row_off |= uint64_t(0xFF) << (8 * i);
    else if (y + q > height) row_cut |= uint64_t(0xFF) << (8 * i);
  }
  constexpr uint64_t kEveryRow = 0x0101010101010101u;
  *wholly = col_off * kEveryRow | row_off;
  *partly = (col_cut * kEveryRow | row_cut) & ~*wholly;
}

void Pyramid::clear() {
  const int n = layout.levels;
  for (int l = 0; l < n; ++l) {
    const int s = layout.shift(l);
    // On 64-bit hosts the masks that end on screen start all vacant, stored without a test each: only a
    // row's last mask and the last row's masks may reach past the screen (2CylinderEngine at 1024x768:
    // 0.25 M -> 0.04 M instructions a frame). The boards test every mask (the Cortex-M0+ image's flash).
    const int inside_cols = kFastClear ? min_of(layout.cols[l], layout.width >> s) : 0;
    for (int my = 0; my < layout.rows[l]; ++my) {
      const int y0 = my << s;
      const int inside = y0 + (1 << s) > layout.height ? 0 : inside_cols;
      if (l == n - 1) {
        uint64_t* row = &block(0, my);
        for (int mx = 0; mx < inside; ++mx) row[mx] = 0;
      } else {
        TriageMask* row = &mask(l, 0, my);
        for (int mx = 0; mx < inside; ++mx) row[mx] = TriageMask{0, ~uint64_t(0)};
      }
      for (int mx = inside; mx < layout.cols[l]; ++mx) {
        const int x0 = mx << s;
        uint64_t wholly = 0, partly = 0;
        // Masks wholly on screen need no per-subcell work.
        if (x0 + (1 << s) > layout.width || y0 + (1 << s) > layout.height)
          offscreen_bits(x0, y0, s - 3, layout.width, layout.height, &wholly, &partly);
        if (l == n - 1) block(mx, my) = wholly;
        else mask(l, mx, my) = TriageMask{wholly, ~(wholly | partly)};
      }
    }
  }
}

}  // namespace ml
