// Triage mask tables (tables/, tools/maskgen): T1-T4 of the digest's §5, the runtime lookup, and
// byte-identical regeneration.
#include <gtest/gtest.h>

#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "tables/mask_tables.h"
#include "tests/cli/cli_runner.h"
#include "tiler/tile.h"
#include "tools/maskgen/mask_gen.h"

namespace {

using maskgen::Pt;

std::vector<maskgen::Entry> compiled_table() {
  return std::vector<maskgen::Entry>(reinterpret_cast<const maskgen::Entry*>(ml::kMaskTable),
                                     reinterpret_cast<const maskgen::Entry*>(ml::kMaskTable) +
                                         ml::kMaskEntryCount);
}

TEST(MaskTable, HeaderMatchesGenerator) {
  static_assert(sizeof(maskgen::Entry) == sizeof(ml::MaskEntry), "entry layout");
  ASSERT_EQ(ml::kMaskEntryCount, uint32_t(6 * ml::kMaskK * ml::kMaskK));
  EXPECT_EQ(1 << ml::kMaskKBits, ml::kMaskK);
  EXPECT_EQ(ml::kMaskTableBytes, ml::kMaskEntryCount * 16);
  const auto generated = maskgen::make_table(ml::kMaskK);
  const auto compiled = compiled_table();
  for (size_t i = 0; i < compiled.size(); ++i) {
    ASSERT_EQ(compiled[i].c, generated[i].c) << i;
    ASSERT_EQ(compiled[i].v, generated[i].v) << i;
  }
  EXPECT_EQ(maskgen::table_crc(compiled), ml::kMaskTableCrc32);
  // Fits in a 256 KB flash with room for code.
  EXPECT_LE(ml::kMaskTableBytes, 64u * 1024u);
}

// T1
TEST(MaskTable, CoveredAndVacantAreDisjoint) {
  int active_total = 0;
  for (const auto& e : compiled_table()) {
    ASSERT_EQ(e.c & e.v, 0u);
    active_total += __builtin_popcountll(~(e.c | e.v));
  }
  EXPECT_GT(active_total, 0);
}

// T2 on the table itself: random exact edges through each entry's two intervals, on a lattice 64
// times finer than the intervals. Covered subcells must have all four corners strictly inside,
// vacant ones strictly outside.
TEST(MaskTable, CoveredAndVacantExactForRandomEdges) {
  const int k = ml::kMaskK;
  const int64_t fine = 64;
  const int64_t n = 16 * k * fine;  // the generator's square, scaled by `fine`
  const auto table = compiled_table();
  std::mt19937 rng(7);
  for (int g1 = 0; g1 < 4 * k; ++g1)
    for (int g2 = g1 + 1; g2 < 4 * k; ++g2) {
      if (g1 / k == g2 / k) continue;
      const auto& e = table[size_t(maskgen::entry_index(k, g1, g2))];
      Pt a0, a1, b0, b1;
      maskgen::interval_points(k, n, g1 / k, g1 % k, &a0, &a1);
      maskgen::interval_points(k, n, g2 / k, g2 % k, &b0, &b1);
      const Pt arc_corner = maskgen::side_end(n, g1 / k);
      for (int trial = 0; trial < 48; ++trial) {
        // Strictly inside each interval, so the corner ending g1's side is off the line.
        const int64_t t = 1 + int64_t(rng() % uint32_t(16 * fine - 1));
        const int64_t u = 1 + int64_t(rng() % uint32_t(16 * fine - 1));
        const Pt p{a0.x + (a1.x - a0.x) * t / (16 * fine), a0.y + (a1.y - a0.y) * t / (16 * fine)};
        const Pt q{b0.x + (b1.x - b0.x) * u / (16 * fine), b0.y + (b1.y - b0.y) * u / (16 * fine)};
        const int64_t arc = maskgen::edge_at(p, q, arc_corner);
        ASSERT_NE(arc, 0);
        const int sign = arc > 0 ? 1 : -1;  // sign of the arc side g1 -> g2
        const int64_t cell = n / 8;
        for (int bit = 0; bit < 64; ++bit) {
          const int col = bit & 7, row = bit >> 3;
          int64_t lo = INT64_MAX, hi = INT64_MIN;
          for (int c = 0; c < 4; ++c) {
            const Pt corner{(col + (c & 1)) * cell, (row + (c >> 1)) * cell};
            const int64_t v = sign * maskgen::edge_at(p, q, corner);
            lo = std::min(lo, v);
            hi = std::max(hi, v);
          }
          if (e.c >> bit & 1) {
            ASSERT_GT(lo, 0) << "entry " << g1 << "," << g2 << " bit " << bit;
          }
          if (e.v >> bit & 1) {
            ASSERT_LT(hi, 0) << "entry " << g1 << "," << g2 << " bit " << bit;
          }
        }
      }
    }
}

// T2 through the runtime lookup (intercept quantization and orientation included), with edges
// through lattice points so that corner and interval-boundary ties happen often.
TEST(MaskTable, RuntimeLookupExactForRandomEdges) {
  std::mt19937 rng(11);
  const int64_t side = 8 * 64 * 3;  // a square of 8x8 subcells of 192 units
  const int64_t cell = side / 8;
  int checked = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    int64_t a, b, c;
    if (trial & 1) {
      // Through two lattice points (multiples of cell / 4, also outside the square).
      const int64_t x0 = (int64_t(rng() % 49) - 8) * cell / 4, y0 = (int64_t(rng() % 49) - 8) * cell / 4;
      const int64_t x1 = (int64_t(rng() % 49) - 8) * cell / 4, y1 = (int64_t(rng() % 49) - 8) * cell / 4;
      if (x0 == x1 && y0 == y1) continue;
      a = y0 - y1;
      b = x1 - x0;
      c = -(a * x0 + b * y0);
      if (rng() & 1) c -= 1;  // the fill rule's nudge
    } else {
      a = int64_t(rng() % 2001) - 1000;
      b = int64_t(rng() % 2001) - 1000;
      if (a == 0 && b == 0) continue;
      c = -(a * int64_t(rng() % uint32_t(side + 1)) + b * int64_t(rng() % uint32_t(side + 1)));
    }
    const int64_t corner[4] = {c, a * side + c, a * side + b * side + c, b * side + c};
    const int64_t lo = std::min({corner[0], corner[1], corner[2], corner[3]});
    const int64_t hi = std::max({corner[0], corner[1], corner[2], corner[3]});
    if (!(lo < 0 && hi > 0)) continue;
    const ml::TriageMask m = ml::edge_triage_mask(corner);
    ASSERT_EQ(m.c & m.v, 0u);
    for (int bit = 0; bit < 64; ++bit) {
      const int col = bit & 7, row = bit >> 3;
      int64_t clo = INT64_MAX, chi = INT64_MIN;
      for (int q = 0; q < 4; ++q) {
        const int64_t v = a * (col + (q & 1)) * cell + b * (row + (q >> 1)) * cell + c;
        clo = std::min(clo, v);
        chi = std::max(chi, v);
      }
      if (m.c >> bit & 1) {
        ASSERT_GT(clo, 0) << trial;
      }
      if (m.v >> bit & 1) {
        ASSERT_LT(chi, 0) << trial;
      }
    }
    ++checked;
  }
  EXPECT_GT(checked, 50000);
}

// T3: the entry for the reversed pair is (V, C) of the stored one; the active set is unchanged.
TEST(MaskTable, ReversalSwapsCoveredAndVacant) {
  const int k = ml::kMaskK;
  const auto table = compiled_table();
  for (int g1 = 0; g1 < 4 * k; ++g1)
    for (int g2 = g1 + 1; g2 < 4 * k; ++g2) {
      if (g1 / k == g2 / k) continue;
      const auto& e = table[size_t(maskgen::entry_index(k, g1, g2))];
      const maskgen::Entry r = maskgen::make_entry(k, g2, g1);
      ASSERT_EQ(r.c, e.v);
      ASSERT_EQ(r.v, e.c);
    }
  // And the runtime lookup: negating an edge (no corner exactly on it) swaps the words.
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20000; ++trial) {
    int64_t corner[4], neg[4];
    bool pos = false, negv = false, zero = false;
    for (int i = 0; i < 3; ++i) corner[i] = int64_t(rng() % 20001) - 10000;
    corner[3] = corner[0] + corner[2] - corner[1];  // a plane: TL + BR = TR + BL
    for (int i = 0; i < 4; ++i) {
      pos |= corner[i] > 0;
      negv |= corner[i] < 0;
      zero |= corner[i] == 0;
      neg[i] = -corner[i];
    }
    if (!pos || !negv || zero) continue;
    const ml::TriageMask m = ml::edge_triage_mask(corner), r = ml::edge_triage_mask(neg);
    ASSERT_EQ(m.c, r.v);
    ASSERT_EQ(m.v, r.c);
  }
}

// T4: with nested interval grids (2k inside k), the finer table's active set is a subset.
TEST(MaskTable, FinerTableNeverHasMoreActiveCells) {
  for (int k : {4, 8, ml::kMaskK}) {
    const auto coarse = maskgen::make_table(k);
    const auto finer = maskgen::make_table(2 * k);
    const int kf = 2 * k;
    uint64_t coarse_active = 0, finer_active = 0;
    for (int g1 = 0; g1 < 4 * kf; ++g1)
      for (int g2 = g1 + 1; g2 < 4 * kf; ++g2) {
        if (g1 / kf == g2 / kf) continue;
        const auto& f = finer[size_t(maskgen::entry_index(kf, g1, g2))];
        // Interval i of side s at 2k lies in interval i / 2 of side s at k.
        const int c1 = (g1 / kf) * k + (g1 % kf) / 2, c2 = (g2 / kf) * k + (g2 % kf) / 2;
        const auto& c = coarse[size_t(maskgen::entry_index(k, c1, c2))];
        const uint64_t fa = ~(f.c | f.v), ca = ~(c.c | c.v);
        ASSERT_EQ(fa & ~ca, 0u) << "k=" << k << " " << g1 << "," << g2;
        // Same orientation: what is surely covered stays covered.
        ASSERT_EQ(c.c & ~f.c, 0u);
        ASSERT_EQ(c.v & ~f.v, 0u);
        coarse_active += uint64_t(__builtin_popcountll(ca));
        finer_active += uint64_t(__builtin_popcountll(fa));
      }
    EXPECT_LT(finer_active, 4 * coarse_active);  // finer intervals do reduce subdivision
  }
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The table generator: $MASKLINE_MASKGEN (tests/run_all.sh sets it), else where the build puts it
// beside this binary (BUILD/san/tests: BUILD/maskgen), so the test binary run directly gives the
// answer `make test` gives. "" when neither exists.
std::string maskgen_path() {
  if (const char* env = std::getenv("MASKLINE_MASKGEN")) return env;
  for (const char* name : {"../maskgen", "maskgen"}) {
    const std::string path = clitest::beside_test_binary(name);
    if (!path.empty() && access(path.c_str(), X_OK) == 0) return path;
  }
  return "";
}

TEST(MaskTable, RegenerationIsByteIdentical) {
  const std::string gen = maskgen_path();
  if (gen.empty())
    GTEST_SKIP() << "no maskgen binary beside the test binary (BUILD/maskgen; `make BUILD/maskgen` builds it) "
                    "and MASKLINE_MASKGEN is not set: the regeneration cannot be checked";
  char dir[] = "/tmp/maskline-maskgen-XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string cmd = gen + " --k " + std::to_string(ml::kMaskK) + " --out " + dir +
                          " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  for (const char* name : {"mask_tables.h", "mask_tables_data.cpp", "filter_tables.h", "filter_tables_data.cpp"}) {
    const std::string fresh = slurp(std::string(dir) + "/" + name);
    const std::string committed_path = clitest::in_source_tree(std::string("tables/") + name);
    EXPECT_FALSE(committed_path.empty()) << "tables/" << name << " found neither from the working directory nor "
                                         << "above the test binary";
    const std::string committed = slurp(committed_path);
    EXPECT_FALSE(fresh.empty()) << name;
    EXPECT_TRUE(fresh == committed) << "tables/" << name << " differs from a fresh `maskgen --k "
                                    << ml::kMaskK << "`: run `make tables`";
    std::remove((std::string(dir) + "/" + name).c_str());
  }
  rmdir(dir);
}

}  // namespace
