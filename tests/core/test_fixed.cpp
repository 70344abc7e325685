// Property tests of the fixed-point core (src/core/fixed.h) against double math.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "core/arena.h"
#include "core/fixed.h"

namespace {

using ml::Vec3i;

// The reference: floor(sqrt(v)) bit by bit in 128-bit arithmetic (no shortcut either root takes).
uint64_t reference_isqrt(uint64_t v) {
  uint64_t r = 0;
  for (int b = 31; b >= 0; --b) {
    const unsigned __int128 t = r | (uint64_t(1) << b);
    if (t * t <= v) r = uint64_t(t);
  }
  return r;
}

// Both roots (the hosts' Newton steps and the boards' 32-bit root, fixed.h) give the reference's root
// on edge cases, every power of two and square with their neighbours, and a large random sample of
// every bit length; isqrt64 is one of them.
TEST(FixedIsqrt, BothRootsMatchFloorSqrtOnRandomAndExtremeInputs) {
  std::mt19937_64 rng(7);
  std::vector<uint64_t> inputs = {0, 1, 2, 3, 4, 15, 16, 17, UINT64_MAX, UINT64_MAX - 1,
                                  uint64_t(1) << 62, (uint64_t(1) << 62) - 1, uint64_t(4294967295u) * 4294967295u,
                                  0xFFFFFFFFu, uint64_t(0xFFFFFFFFu) + 1, uint64_t(0xFFFFFFFFu) + 2};
  for (int i = 0; i < 1000000; ++i) inputs.push_back(rng() >> (rng() % 64));
  for (uint64_t r = 1; r < 100000; r += 97) { inputs.push_back(r * r); inputs.push_back(r * r - 1); }
  // Every power of two and its neighbours; squares and their neighbours at every root bit length
  // (where a Newton start or a stopping test would be off by one), up to the largest root 2^32 - 1.
  for (int b = 0; b < 64; ++b)
    for (int d = -3; d <= 3; ++d) inputs.push_back((uint64_t(1) << b) + uint64_t(int64_t(d)));
  for (int b = 1; b <= 32; ++b)
    for (uint64_t r : {(uint64_t(1) << b) - 1, uint64_t(1) << (b - 1), (uint64_t(3) << b) / 4}) {
      inputs.push_back(r * r - 1);
      inputs.push_back(r * r);
      inputs.push_back(r * r + 1);
      inputs.push_back(r * r + 2 * r);  // (r + 1)^2 - 1
    }
  for (uint64_t i = 0; i < 5000; ++i) inputs.push_back(UINT64_MAX - i);
  for (uint64_t v : inputs) {
    const uint64_t want = reference_isqrt(v);
    ASSERT_EQ(ml::isqrt64_newton(v), want) << v;
    ASSERT_EQ(ml::isqrt64_root32(v), want) << v;
    ASSERT_EQ(ml::isqrt64(v), want) << v;
  }
}

TEST(FixedIsqrt, ReferenceIsFloorSqrt) {
  // The reference itself: r^2 <= v < (r + 1)^2 at the ends and across the range.
  for (uint64_t v : {uint64_t(0), uint64_t(1), uint64_t(2), uint64_t(24), uint64_t(25), UINT64_MAX,
                     uint64_t(1) << 63, uint64_t(0xFFFFFFFEu) * 0xFFFFFFFEu}) {
    const unsigned __int128 r = reference_isqrt(v);
    EXPECT_LE(r * r, v);
    EXPECT_GT((r + 1) * (r + 1), v);
  }
}

TEST(FixedBits, BitCountEqualsCountingEachBit) {
  std::mt19937_64 rng(5);
  std::vector<uint64_t> inputs = {0, 1, UINT64_MAX, uint64_t(1) << 63, 0x8000000000000001u, 0xFF00FF00FF00FF00u};
  for (int b = 0; b < 64; ++b) inputs.push_back((uint64_t(2) << b) - 1);
  for (int i = 0; i < 20000; ++i) inputs.push_back(rng() & rng() & (rng() | rng()));
  for (uint64_t v : inputs) {
    int n = 0;
    for (int b = 0; b < 64; ++b) n += int(v >> b & 1);
    ASSERT_EQ(ml::bit_count64(v), n) << std::hex << v;
  }
}

TEST(FixedArithmetic, ShiftsAndDivisionsRoundLikeDouble) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 50000; ++i) {
    const int64_t a = int64_t(rng() >> 34) - (int64_t(1) << 29);   // |a| < 2^30
    const int64_t b = int64_t(rng() >> 31) - (int64_t(1) << 32);   // |b| < 2^33
    const int s = 1 + int(rng() % 40);
    const long double exact = (long double)a * b / std::ldexp(1.0L, s);
    EXPECT_LE(std::fabs((long double)ml::mul_shift(a, b, s) - exact), 0.5L) << a << " " << b << " " << s;
    const int64_t d = (b == 0) ? 1 : b;
    const long double q = (long double)(a * 1048576) / d;
    EXPECT_LE(std::fabs((long double)ml::div_round(a * 1048576, d) - q), 0.5L);
    if (d > 0) { EXPECT_EQ(ml::div_floor(a, d), (int64_t)std::floor((long double)a / d)); }
  }
  EXPECT_EQ(ml::div_round(5, 2), 3);
  EXPECT_EQ(ml::div_round(-5, 2), -3);
  EXPECT_EQ(ml::div_round(5, -2), -3);
  EXPECT_EQ(ml::div_floor(-1, 256), -1);
  EXPECT_EQ(ml::div_floor(-256, 256), -1);
  EXPECT_EQ(ml::reciprocal(3, 30), 357913941);
  EXPECT_EQ(ml::shift_round(INT64_MAX / 2, 62), 1);
}

TEST(FixedNormalize, UnitLengthAndDirectionForAnyMagnitude) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 20000; ++i) {
    const int mag = int(rng() % 31);
    auto comp = [&] { return int32_t(int64_t(rng() % (uint64_t(2) << mag)) - (int64_t(1) << mag)); };
    Vec3i v{comp(), comp(), comp()};
    if (i % 97 == 0) v = Vec3i{INT32_MAX, INT32_MIN + 1, INT32_MAX};
    Vec3i n;
    const bool ok = ml::normalize_q30(v, &n);
    if (v.x == 0 && v.y == 0 && v.z == 0) { EXPECT_FALSE(ok); continue; }
    ASSERT_TRUE(ok);
    const double len = std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z);
    const double one = double(ml::kUnitOne);
    EXPECT_NEAR(n.x / one, v.x / len, 4e-6);
    EXPECT_NEAR(n.y / one, v.y / len, 4e-6);
    EXPECT_NEAR(n.z / one, v.z / len, 4e-6);
  }
  Vec3i n;
  EXPECT_FALSE(ml::normalize_q30(Vec3i{0, 0, 0}, &n));
}

TEST(FixedNewton, TwoStepsRenormalizeInterpolatedNormals) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> angle(0, 6.283185307179586), len_dist(0.85, 1.15), z(-1, 1);
  for (int i = 0; i < 20000; ++i) {
    const double zz = z(rng), a = angle(rng), r = std::sqrt(1 - zz * zz), len = len_dist(rng);
    Vec3i v{int32_t(std::lround(r * std::cos(a) * len * ml::kNormalOne)),
            int32_t(std::lround(r * std::sin(a) * len * ml::kNormalOne)), int32_t(std::lround(zz * len * ml::kNormalOne))};
    Vec3i once = ml::newton_renormalize_q14(v);
    Vec3i twice = ml::newton_renormalize_q14(once);
    const double l1 = std::sqrt(double(ml::dot64(once, once))) / ml::kNormalOne;
    const double l2 = std::sqrt(double(ml::dot64(twice, twice))) / ml::kNormalOne;
    EXPECT_LT(std::fabs(l2 - 1), std::fabs(len - 1) + 1e-4);
    EXPECT_LT(std::fabs(l2 - 1), 2.5e-3) << len;
    if (std::fabs(len - 1) < 0.05) { EXPECT_LT(std::fabs(l2 - 1), 4.0 / ml::kNormalOne) << len; }
    // Direction is kept.
    const double dl = std::sqrt(double(ml::dot64(v, v)));
    EXPECT_NEAR(twice.x / (l2 * ml::kNormalOne), v.x / dl, 4e-4);
    (void)l1;
  }
}

TEST(FixedTan, TableInterpolationMatchesTan) {
  for (int32_t deg_q16 = 0; deg_q16 < (89 << 16); deg_q16 += 977) {
    const double deg = deg_q16 / 65536.0;
    const double expect = std::tan(deg * 3.14159265358979323846 / 180) * 65536;
    EXPECT_NEAR(ml::tan_deg_q16(deg_q16), expect, std::max(1.0, expect * 1e-5)) << deg;
  }
  EXPECT_EQ(ml::tan_deg_q16(-5), 0);
  EXPECT_GT(ml::tan_deg_q16(89 << 16), ml::tan_deg_q16(88 << 16));
}

TEST(ArenaAllocation, AlignsTracksPeakAndReportsNeed) {
  alignas(16) uint8_t buffer[256];
  ml::Arena arena(buffer + 1, 200);  // deliberately misaligned base
  void* a = arena.allocate(10, 8);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(a) % 8, 0u);
  const size_t mark = arena.mark();
  void* b = arena.allocate(100, 16);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(b) % 16, 0u);
  const size_t peak = arena.peak();
  arena.release_to(mark);
  EXPECT_EQ(arena.peak(), peak);
  EXPECT_EQ(arena.allocate(500, 8), nullptr);
  EXPECT_GE(arena.failed_need(), 500u + mark);
  EXPECT_LE(arena.failed_need(), 500u + mark + 7);
  EXPECT_EQ(arena.used(), mark);
}

// The 32-bit boards' division (udiv_64_32, three 32-bit divides) equals the native 64-bit one for
// every kind of operand: small and huge numerators, divisors of every width, the normalization
// shifts' extremes and the quotient-digit corrections of the long division.
TEST(FixedDivision, SixtyFourByThirtyTwoEqualsNativeDivision) {
  std::mt19937_64 rng(99);
  auto check = [](uint64_t n, uint32_t d) {
    uint32_t r = 0;
    const uint64_t q = ml::udiv_64_32(n, d, &r);
    ASSERT_EQ(q, n / d) << n << " / " << d;
    ASSERT_EQ(r, n % d) << n << " % " << d;
  };
  const uint64_t edges[] = {0, 1, 2, 0xFFFFu, 0x10000u, 0xFFFFFFFFu, 0x100000000ull, 0x7FFFFFFFFFFFFFFFull,
                            0x8000000000000000ull, 0xFFFFFFFFFFFFFFFFull, 0xFFFFFFFF00000000ull, 0x00000001FFFFFFFFull};
  const uint32_t divisors[] = {1, 2, 3, 7, 0xFFFFu, 0x10000u, 0x10001u, 0x7FFFFFFFu, 0x80000000u, 0xFFFFFFFFu, 0x80000001u};
  for (uint64_t n : edges)
    for (uint32_t d : divisors) check(n, d);
  for (int i = 0; i < 2000000; ++i) {
    const uint64_t n = rng() >> (rng() % 64);
    uint32_t d = uint32_t(rng() >> (32 + rng() % 32));
    if (d == 0) d = 1;
    check(n, d);
    // Numerators just below a multiple of the divisor, where the digit estimates overshoot.
    const uint64_t m = n / d * d;
    if (m > 0) check(m - 1, d);
    check(m, d);
  }
}

TEST(FixedDivision, RoundingAndFloorDivisionMatchTheirDefinitions) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 200000; ++i) {
    const int64_t n = int64_t(rng() >> (1 + rng() % 63)) * ((rng() & 1) ? -1 : 1);
    int64_t d = int64_t(rng() >> (33 + rng() % 31)) * ((rng() & 1) ? -1 : 1);
    if (d == 0) d = 3;
    const long double exact = (long double)n / (long double)d;
    const int64_t q = ml::div_round(n, d);
    ASSERT_LE(std::fabs((long double)q - exact), 0.5L + 1e-9L) << n << " / " << d;
    if (d > 0) {
      const int64_t f = ml::div_floor(n, d);
      ASSERT_TRUE((__int128)f * d <= n && (__int128)(f + 1) * d > n) << n << " / " << d;
    }
  }
  EXPECT_EQ(ml::div_round(-5, 2), -3);  // ties away from zero
  EXPECT_EQ(ml::div_round(5, -2), -3);
  EXPECT_EQ(ml::div_floor(-5, 2), -3);
  EXPECT_EQ(ml::div_floor(INT64_MIN, 1), INT64_MIN);
}

}  // namespace

// The reciprocal division (one reciprocal a divisor, none a quotient) is exact over its stated range:
// divisors 1..2^46, numerators below 2^17 d, with the extremes of the normalizing shift and numerators
// next to multiples of the divisor, where the estimate falls short.
TEST(FixedDivision, ReciprocalDivisionEqualsNativeDivision) {
  std::mt19937_64 rng(2027);
  auto check = [](uint64_t n, uint64_t d) {
    const uint32_t r = ml::make_reciprocal(d);
    ASSERT_EQ(ml::divide_by_reciprocal(n, d, r), n / d) << n << " / " << d;
  };
  const uint64_t max_d = uint64_t(1) << ml::kReciprocalDivisorBits;
  const uint64_t divisors[] = {1, 2, 3, 7, (1u << 19) - 1, 1u << 19, (1u << 20) - 1, 1u << 20, (1u << 20) + 1,
                               0xFFFFFFFFull, max_d - 1, max_d};
  for (uint64_t d : divisors) {
    const uint64_t top = (d << 17) - 1;
    for (uint64_t n : {uint64_t(0), uint64_t(1), d - 1, d, d + 1, top - d, top - 1, top}) check(n, d);
  }
  for (int i = 0; i < 1000000; ++i) {
    const uint64_t d = std::max<uint64_t>(1, (rng() >> 18) >> (rng() % 46));
    const uint64_t n = rng() % (d << 17);
    check(n, d);
    const uint64_t m = n / d * d;
    if (m > 0) check(m - 1, d);
    check(m, d);
  }
}

TEST(FixedArithmetic, FloorShiftRoundsDown) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 100000; ++i) {
    const int64_t v = int64_t(rng() >> (1 + rng() % 62)) * ((rng() & 1) ? -1 : 1);
    const int s = int(rng() % 20);
    ASSERT_EQ(ml::floor_shift(v, s), ml::div_floor(v, int64_t(1) << s)) << v << " >> " << s;
  }
}
