// Triage mask-table generator, shared by tools/maskgen (writes tables/) and the table tests (which
// build tables for other k to check nesting). Host code: plain integers, no floating point, so the
// output is the same on every machine.
//
// Canonical square (y down, as src/view/view.h): side N = 16k units, corners TL(0,0) TR(N,0)
// BR(N,N) BL(0,N). The perimeter is walked clockwise on screen: side 0 TL->TR, side 1 TR->BR,
// side 2 BR->BL, side 3 BL->TL; each side is split into k equal intervals numbered along the walk,
// interval id g = side * k + i. Subcell (col, row) is the closed square
// [col N/8, (col+1) N/8] x [row N/8, (row+1) N/8]; its mask bit is row * 8 + col.
//
// Entry (g1 < g2, different sides): the quadrilateral spanned by the two intervals (the convex hull
// of their endpoints = the union of all edges between them) marks every subcell it touches (closed
// sets) as active. Every other subcell lies strictly on one side of every such edge; it is covered
// (C) if it lies on the side of the perimeter arc that runs from g1 forward along the walk to g2,
// vacant (V) otherwise. An edge crossing the square with its positive side (E > 0) on the arc from
// its entry interval to its exit interval uses (C, V) when entry < exit and (V, C) otherwise.
#pragma once
#include <stdint.h>

#include <vector>

#include "tools/maskgen/table_crc.h"

namespace maskgen {

struct Entry {
  uint64_t c, v;
};

struct Pt {
  int64_t x, y;
};

// Endpoints of interval i (0..k-1) on side s, in walk order, for a square of side n.
inline void interval_points(int k, int64_t n, int s, int i, Pt* a, Pt* b) {
  const int64_t t0 = n * i / k, t1 = n * (i + 1) / k;
  switch (s) {
    case 0: *a = {t0, 0}; *b = {t1, 0}; break;
    case 1: *a = {n, t0}; *b = {n, t1}; break;
    case 2: *a = {n - t0, n}; *b = {n - t1, n}; break;
    default: *a = {0, n - t0}; *b = {0, n - t1}; break;
  }
}

// Corner at the end of side s along the walk.
inline Pt side_end(int64_t n, int s) {
  static const int kx[4] = {1, 1, 0, 0}, ky[4] = {0, 1, 1, 0};
  return Pt{kx[s] * n, ky[s] * n};
}

// view.h's edge function of P->Q at p.
inline int64_t edge_at(Pt p, Pt q, Pt s) { return (q.x - p.x) * (s.y - p.y) - (q.y - p.y) * (s.x - p.x); }

inline int side_pair_index(int s1, int s2) {
  static const int idx[4][4] = {{-1, 0, 1, 2}, {0, -1, 3, 4}, {1, 3, -1, 5}, {2, 4, 5, -1}};
  return idx[s1][s2];
}

inline int entry_count(int k) { return 6 * k * k; }

// Table index of the unordered interval pair (g1 < g2 on different sides).
inline int entry_index(int k, int g1, int g2) {
  return side_pair_index(g1 / k, g2 / k) * k * k + (g1 % k) * k + (g2 % k);
}

// Whether the closed convex hull of pts[0..3] and the closed box [x0,x1]x[y0,y1] intersect
// (separating-axis test over the box axes and every pairwise direction of the points).
inline bool hull_touches_box(const Pt pts[4], int64_t x0, int64_t y0, int64_t x1, int64_t y1) {
  const Pt box[4] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  std::vector<Pt> axes = {{1, 0}, {0, 1}};
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      const int64_t dx = pts[j].x - pts[i].x, dy = pts[j].y - pts[i].y;
      if (dx != 0 || dy != 0) axes.push_back(Pt{-dy, dx});
    }
  for (const Pt& ax : axes) {
    int64_t hmin = INT64_MAX, hmax = INT64_MIN, bmin = INT64_MAX, bmax = INT64_MIN;
    for (int i = 0; i < 4; ++i) {
      const int64_t h = ax.x * pts[i].x + ax.y * pts[i].y;
      const int64_t b = ax.x * box[i].x + ax.y * box[i].y;
      if (h < hmin) hmin = h;
      if (h > hmax) hmax = h;
      if (b < bmin) bmin = b;
      if (b > bmax) bmax = b;
    }
    if (hmax < bmin || bmax < hmin) return false;
  }
  return true;
}

inline Entry make_entry(int k, int g1, int g2) {
  const int64_t n = 16 * int64_t(k);  // multiples of N/8 and N/k, midpoints and centres are integers
  Pt p[4];
  interval_points(k, n, g1 / k, g1 % k, &p[0], &p[1]);
  interval_points(k, n, g2 / k, g2 % k, &p[2], &p[3]);
  const Pt m1{(p[0].x + p[1].x) / 2, (p[0].y + p[1].y) / 2};
  const Pt m2{(p[2].x + p[3].x) / 2, (p[2].y + p[3].y) / 2};
  // The corner ending g1's side lies on the arc from g1 to g2 and strictly off the line m1->m2.
  const bool arc_positive = edge_at(m1, m2, side_end(n, g1 / k)) > 0;
  Entry e{0, 0};
  const int64_t q = n / 8;
  for (int row = 0; row < 8; ++row)
    for (int col = 0; col < 8; ++col) {
      if (hull_touches_box(p, col * q, row * q, (col + 1) * q, (row + 1) * q)) continue;
      const Pt centre{col * q + q / 2, row * q + q / 2};
      const bool positive = edge_at(m1, m2, centre) > 0;
      const uint64_t bit = uint64_t(1) << (row * 8 + col);
      if (positive == arc_positive) e.c |= bit; else e.v |= bit;
    }
  return e;
}

// The whole table for k intervals per side, in index order.
inline std::vector<Entry> make_table(int k) {
  std::vector<Entry> t(size_t(entry_count(k)));
  for (int g1 = 0; g1 < 4 * k; ++g1)
    for (int g2 = g1 + 1; g2 < 4 * k; ++g2)
      if (g1 / k != g2 / k) t[size_t(entry_index(k, g1, g2))] = make_entry(k, g1, g2);
  return t;
}

// CRC-32/IEEE over the entries as little-endian bytes (c then v), as the header states.
inline uint32_t table_crc(const std::vector<Entry>& t) {
  uint32_t crc = 0;
  for (const Entry& e : t) crc = crc32_le64(e.v, crc32_le64(e.c, crc));
  return crc;
}

inline bool valid_k(int k) { return k >= 2 && k <= 256 && (k & (k - 1)) == 0; }

}  // namespace maskgen
