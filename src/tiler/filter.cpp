#include "tiler/filter.h"

#include "core/fixed.h"
#include "tables/filter_tables.h"

namespace ml {

namespace {

// The weights of a source's samples `mask` for the nine destinations around it, as three words of
// 16-bit lanes: word dy + 1, lane dx + 1 for the destination that sees the source at (dx, dy).
// Two look-ups a non-zero byte (tables/filter_tables.h).
void mask_weights(uint64_t mask, uint64_t lanes[3]) {
  uint64_t above = 0, level = 0, below = 0;
  // Rows 0..3 count for the destination above; rows 4..7 weigh as rows 3..0 (the mirror image) and
  // count for the destination below.
  for (int row = 0; row < 4; ++row) {
    const uint32_t top = uint32_t(mask >> (8 * row)) & 0xFFu, bottom = uint32_t(mask >> (56 - 8 * row)) & 0xFFu;
    level += kCosineByteWeights[0][row][top] + kCosineByteWeights[0][row][bottom];
    above += kCosineByteWeights[1][row][top];
    below += kCosineByteWeights[1][row][bottom];
  }
  lanes[0] = below;
  lanes[1] = level;
  lanes[2] = above;
}

}  // namespace

void CosineFilter::init(FilterSum* sums, int width, int height, int f, int band_rows, BandOutput* out,
                        Stats* stats) {
  sums_ = sums;
  f_ = f;
  width_ = width;
  height_ = height;
  carry_ = band_rows;
  out_ = out;
  stats_ = stats;
}

uint32_t CosineFilter::full_weight(int px, int py) const {
  uint32_t w = 0;
  for (int d = 0; d < 9; ++d) {
    const int x = px + d % 3 - 1, y = py + d / 3 - 1;
    if (x >= 0 && y >= 0 && x < width_ && y < height_) w += kCosineTotals[d];
  }
  return w;
}

// Zero sums for row `row` of sums_ (frame row py); border pixels start at the weight they lack.
void CosineFilter::start_row(int row, int py) {
  for (int x = 0; x < width_; ++x) {
    const uint32_t start = on_border(x, py) ? kFilterWeightOne - full_weight(x, py) : 0;
    sums_[size_t(row) * size_t(width_) + size_t(x)] = FilterSum{0, 0, 0, start};
  }
}

void CosineFilter::begin_band(int top, int rows) {
  // The first row takes the carry of the band above (all it got from that band's samples).
  if (top > 0)
    for (int x = 0; x < width_; ++x) sums_[x] = sums_[size_t(carry_) * size_t(width_) + size_t(x)];
  else
    start_row(0, 0);
  for (int y = 1; y < rows; ++y) start_row(y, top + y);
  if (top + rows < height_) start_row(carry_, top + rows);
  top_ = top;
  rows_ = rows;
}

uint64_t CosineFilter::expand(uint64_t mask, int f) {
  if (f == 8) return mask;
  const int k = 8 / f;
  const uint64_t block = corner_samples(k);
  uint64_t out = 0;
  while (mask != 0) {
    const int bit = __builtin_ctzll(mask);
    mask &= mask - 1;
    out |= block << ((bit >> 3) * k * 8 + (bit & 7) * k);
  }
  return out;
}

// The lanes (as mask_weights) of a whole source pixel.
constexpr uint64_t whole_lanes(int row) {
  return kCosineTotals[row * 3] | uint64_t(kCosineTotals[row * 3 + 1]) << 16 | uint64_t(kCosineTotals[row * 3 + 2]) << 32;
}
constexpr uint64_t kWholeLanes[3] = {whole_lanes(0), whole_lanes(1), whole_lanes(2)};

void CosineFilter::add_samples(int x, int y, int w, int h, SourceColours& colours) {
  const int f = f_;
  const int px0 = (x + f - 1) / f, px1 = (x + w) / f, py0 = (y + f - 1) / f, py1 = (y + h) / f;
  if (px0 < px1 && py0 < py1) {  // whole pixels
    Pixel c;
    if (colours.flat(&c)) {
      add_flat_rect(px0, py0 + top_, px1 - px0, py1 - py0, c);
    } else {
      for (int py = py0 + top_; py < py1 + top_; ++py)
        for (int px = px0; px < px1; ++px) add(px, py, ~uint64_t(0), colours.colour_at(px, py));
    }
  }
  for (int py = y / f; py <= (y + h - 1) / f; ++py) {
    const int r0 = max_of(y, py * f) - py * f, r1 = min_of(y + h, (py + 1) * f) - py * f;
    for (int px = x / f; px <= (x + w - 1) / f; ++px) {
      if (px >= px0 && px < px1 && py >= py0 && py < py1) continue;  // whole: done above
      const int c0 = max_of(x, px * f) - px * f, c1 = min_of(x + w, (px + 1) * f) - px * f;
      const uint64_t row = ((uint64_t(1) << c1) - 1) & ~((uint64_t(1) << c0) - 1);
      uint64_t m = 0;
      for (int r = r0; r < r1; ++r) m |= row << (8 * r);
      add(px, py + top_, expand(m, f), colours.colour_at(px, py + top_));
    }
  }
}

void CosineFilter::add_block(uint64_t mask, int x, int y, SourceColours& colours) {
  if (f_ == 8) {  // one pixel
    const int px = x / 8, py = y / 8 + top_;
    add(px, py, mask, colours.colour_at(px, py));
    return;
  }
  // The block holds (8 / f)^2 pixels of f x f samples each.
  const int f = f_, per_side = 8 / f;
  const uint64_t pixel = corner_samples(f);
  for (int j = 0; j < per_side; ++j)
    for (int i = 0; i < per_side; ++i) {
      const int shift = j * f * 8 + i * f;
      const uint64_t m = mask & (pixel << shift);
      if (m == 0) continue;
      const int px = x / f + i, py = y / f + j + top_;
      add(px, py, expand(m >> shift, f), colours.colour_at(px, py));
    }
}

void CosineFilter::add(int px, int py, uint64_t mask, Pixel c) {
  uint64_t lanes[3];
  if (mask == ~uint64_t(0)) {
    for (int k = 0; k < 3; ++k) lanes[k] = kWholeLanes[k];
  } else {
    mask_weights(mask, lanes);
  }
  const Channels ch = channels(c);
  // Destination (px - dx, py - dy) sees this source at (dx, dy).
  const int end = rows_end(py);
  ML_HOST_UNROLL for (int dy = -1; dy <= 1; ++dy) {
    const int y = py - dy;
    const uint64_t l = lanes[dy + 1];
    if (y < top_ || y >= end || l == 0) continue;
    FilterSum* row = row_at(y);
    ML_HOST_UNROLL for (int dx = -1; dx <= 1; ++dx) {
      const int x = px - dx;
      const uint32_t w = uint32_t(l >> (16 * (dx + 1))) & 0xFFFFu;
      if (w != 0 && x >= 0 && x < width_) add_weight(row[x], w, ch);
    }
  }
}

// Whole-pixel weight of a rectangle's pixels for a destination, from which of its three neighbour
// rows (bit dy + 1 of rows) and columns (bit dx + 1 of cols) lie inside.
uint32_t inside_weight(uint32_t rows, uint32_t cols) {
  uint32_t w = 0;
  for (int d = 0; d < 9; ++d)
    if ((rows >> (d / 3) & 1) && (cols >> (d % 3) & 1)) w += kCosineTotals[d];
  return w;
}

void CosineFilter::add_flat_rect(int x, int y, int w, int h, Pixel c) {
  // Inside: pixels whose every on-screen neighbour is in the rectangle.
  const int ix0 = x > 0 ? x + 1 : x, ix1 = x + w < width_ ? x + w - 1 : x + w;
  const int iy0 = max_of(y > 0 ? y + 1 : y, top_), iy1 = min_of(y + h < height_ ? y + h - 1 : y + h, top_ + rows_);
  const int end = rows_end(y);  // the rectangle lies in the band's own rows
  if (ix0 < ix1 && iy0 < iy1) {
    out_->fill(ix0, iy0, ix1 - ix0, iy1 - iy0, c);
    stats_->pixel_writes += uint64_t(ix1 - ix0) * uint64_t(iy1 - iy0);
  }
  // The ring around them: each takes the whole-pixel weights of its neighbours inside.
  const Channels ch = channels(c);
  auto inside = [](int v, int lo, int hi) {  // bit k: v + k - 1 in [lo, hi)
    return uint32_t(v - 1 >= lo && v - 1 < hi) | uint32_t(v >= lo && v < hi) << 1 | uint32_t(v + 1 >= lo && v + 1 < hi) << 2;
  };
  for (int py = max_of(y - 1, top_); py <= min_of(y + h, end - 1); ++py) {
    const uint32_t rows = inside(py, y, y + h);
    FilterSum* row = row_at(py);
    for (int px = max_of(x - 1, 0); px <= min_of(x + w, width_ - 1); ++px) {
      if (py >= iy0 && py < iy1 && px == ix0 && ix0 < ix1) px = ix1;  // skip the inside
      if (px > min_of(x + w, width_ - 1)) break;
      const uint32_t weight = inside_weight(rows, inside(px, x, x + w));
      if (weight != 0) add_weight(row[px], weight, ch);
    }
  }
}

Pixel CosineFilter::mean(const FilterSum& s, int px, int py) const {
  // Rounded to nearest: a shift inside the frame, a division by the on-screen weight at its edges.
  if (!on_border(px, py)) {
    const uint32_t half = kFilterWeightOne / 2;
    return rgb((s.r + half) >> kFilterWeightBits, (s.g + half) >> kFilterWeightBits, (s.b + half) >> kFilterWeightBits);
  }
  const uint32_t full = full_weight(px, py), half = full / 2;
  return rgb((s.r + half) / full, (s.g + half) / full, (s.b + half) / full);
}

void CosineFilter::end_band() {
  Pixel run[32];  // the colours of a put_row
  uint32_t written = 0;
  for (int y = 0; y < rows_; ++y) {
    const FilterSum* sums = sums_ + size_t(y) * size_t(width_);
    written += out_->put_row_runs(
        top_ + y, width_, run, 32, [sums](int px) { return sums[px].weight == kFilterWeightOne; },
        [&](int px) { return mean(sums[px], px, top_ + y); });
  }
  stats_->pixel_writes += written;
}

}  // namespace ml
