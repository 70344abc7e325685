// Cosine-hump filter tables (Greene, SIGGRAPH '96 §5), shared by tools/maskgen (writes tables/) and
// the filter tests.
//
// Kernel: one pixel in radius, w(r) = (1 + cos(pi r)) / 2 for r < 1 pixel, 0 beyond, r the distance
// from the destination pixel's centre. It reaches the 3 x 3 pixels around it. A source pixel's 8 x 8
// samples sit at ((col + 1/2) / 8, (row + 1/2) / 8) pixels (the tiler's regular grid at aa 8); each
// sample's weight for each of the 9 destinations is w at that point.
//
// Integer weights: the 576 sample weights of one destination are scaled so they sum to exactly
// kOne = 2^16 (a pixel's weights are exactly 1): each takes the floor of its scaled value, and the
// units still missing go to the samples with the largest remainders, four at a time to the four
// mirror images of a sample (left-right and up-down about the destination's centre; no sample lies on
// an axis, and the four have the same value), ties to the lower index (neighbour * 64 + row * 8 +
// col, neighbour d = (dy + 1) * 3 + dx + 1 for the source pixel at (dx, dy) from the destination).
// So the weights keep the kernel's mirror symmetry exactly.
// Entries (Greene's per-byte coefficients): for a byte b of row r of a source pixel's 8 x 8 mask, the
// summed weights of the samples b sets for the three destinations on one row, packed in 16-bit lanes
// of a 64-bit word: lane dx + 1 for the source at (dx, dy) from the destination. Table 0 holds dy = 0
// for rows 0..3 (row 7 - r weighs as row r); table 1 holds dy = 1 for rows 0..3 (a source's rows 4..7
// are more than a pixel from the centre of the destination above it, and dy = -1 is dy = 1 with row
// 7 - r). So a mask's weights for all nine destinations are two look-ups a non-zero byte. A lane sums
// to at most a neighbour's whole weight (< 2^16).
//
// Only IEEE-754 basic operations (+, -, *, /, sqrt: correctly rounded) are used, and cos is a
// Taylor series of them, so the output is the same on every machine.
#pragma once
#include <stdint.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tools/maskgen/table_crc.h"

namespace filtergen {

constexpr int kNeighbours = 9;
constexpr uint32_t kOne = 1u << 16;

// cos(x) for 0 <= x <= pi by its Taylor series (terms below 1e-20 dropped).
inline double taylor_cos(double x) {
  double term = 1, sum = 1;
  for (int n = 1; n < 40; ++n) {
    term *= -x * x / double((2 * n - 1) * (2 * n));
    sum += term;
  }
  return sum;
}

inline double hump(double dx, double dy) {
  const double r = std::sqrt(dx * dx + dy * dy);
  const double pi = 3.14159265358979323846;
  return r < 1 ? (1 + taylor_cos(pi * r)) / 2 : 0;
}

// Index (d * 64 + row * 8 + col) of the sample's mirror image left-right (about the destination).
inline int mirror_x(int i) {
  const int d = i / 64, s = i % 64;
  return (d / 3 * 3 + 2 - d % 3) * 64 + (s & ~7) + 7 - (s & 7);
}
inline int mirror_y(int i) {
  const int d = i / 64, s = i % 64;
  return ((2 - d / 3) * 3 + d % 3) * 64 + (7 - (s >> 3)) * 8 + (s & 7);
}

// weights[d * 64 + row * 8 + col]: integer weight of sample (col, row) of neighbour d, summing to kOne.
inline std::vector<uint32_t> sample_weights() {
  // Coordinates are odd multiples of 1/16, so a mirror image's are exactly the negated ones and its
  // kernel value is the same double.
  std::vector<double> w(kNeighbours * 64);
  double total = 0;
  for (int d = 0; d < kNeighbours; ++d)
    for (int s = 0; s < 64; ++s) {
      const double x = (d % 3 - 1) + ((s & 7) + 0.5) / 8 - 0.5, y = (d / 3 - 1) + ((s >> 3) + 0.5) / 8 - 0.5;
      w[size_t(d * 64 + s)] = hump(x, y);
      total += w[size_t(d * 64 + s)];
    }
  std::vector<uint32_t> out(w.size());
  std::vector<std::pair<double, int>> rest;  // one a group of four mirror images, at its lowest index
  uint32_t sum = 0;
  for (int i = 0; i < int(w.size()); ++i) {
    const double scaled = w[size_t(i)] * kOne / total;
    out[size_t(i)] = uint32_t(std::floor(scaled));
    sum += out[size_t(i)];
    if (i < mirror_x(i) && i < mirror_y(i) && i < mirror_x(mirror_y(i))) rest.push_back({scaled - out[size_t(i)], i});
  }
  std::stable_sort(rest.begin(), rest.end(), [](const std::pair<double, int>& a, const std::pair<double, int>& b) {
    return a.first > b.first;
  });
  for (size_t k = 0; sum < kOne; ++k, sum += 4) {
    const int i = rest[k].second;
    for (int j : {i, mirror_x(i), mirror_y(i), mirror_x(mirror_y(i))}) ++out[size_t(j)];
  }
  return out;
}

// table[((dy * 4) + row) * 256 + byte] for dy 0..1, row 0..3: lane dx + 1 (16 bits) the summed
// weight of the byte's samples on that row of the source at (dx, dy) from the destination.
inline std::vector<uint64_t> byte_table(const std::vector<uint32_t>& weights) {
  std::vector<uint64_t> t(2 * 4 * 256);
  for (int dy = 0; dy < 2; ++dy)
    for (int row = 0; row < 4; ++row)
      for (int b = 0; b < 256; ++b) {
        uint64_t packed = 0;
        for (int dx = -1; dx <= 1; ++dx) {
          uint64_t s = 0;
          for (int col = 0; col < 8; ++col)
            if (b >> col & 1) s += weights[size_t(((dy + 1) * 3 + dx + 1) * 64 + row * 8 + col)];
          packed |= s << (16 * (dx + 1));
        }
        t[size_t((dy * 4 + row) * 256 + b)] = packed;
      }
  return t;
}

// Weight of all 64 samples of each neighbour.
inline std::vector<uint32_t> neighbour_totals(const std::vector<uint32_t>& weights) {
  std::vector<uint32_t> t(kNeighbours, 0);
  for (int d = 0; d < kNeighbours; ++d)
    for (int s = 0; s < 64; ++s) t[size_t(d)] += weights[size_t(d * 64 + s)];
  return t;
}

// CRC-32/IEEE of the entries as little-endian 64-bit values, as the header states.
inline uint32_t table_crc(const std::vector<uint64_t>& t) {
  uint32_t crc = 0;
  for (uint64_t v : t) crc = maskgen::crc32_le64(v, crc);
  return crc;
}

}  // namespace filtergen
