#include "core/crc32.h"

#include "core/build.h"

namespace ml {
namespace {

// The table built at compile time: a byte a step on 64-bit hosts (1 KB of table); half a byte a step
// on the 32-bit boards, whose 64-byte table spares 960 bytes of flash for about 4 more instructions a
// byte at boot (once).
#if UINTPTR_MAX > 0xFFFFFFFFu
constexpr int kCrcStepBits = 8;
#else
constexpr int kCrcStepBits = 4;
#endif
struct CrcTable {
  uint32_t entry[1u << kCrcStepBits];
  constexpr CrcTable() : entry{} {
    for (uint32_t i = 0; i < (1u << kCrcStepBits); ++i) {
      uint32_t c = i;
      for (int k = 0; k < kCrcStepBits; ++k) c = (c & 1u) ? (0xEDB88320u ^ (c >> 1)) : (c >> 1);
      entry[i] = c;
    }
  }
};
constexpr CrcTable kCrcTable;

}  // namespace

// Optimized for size: a blob's CRC runs once, at load (boot, on a board), and a frame's CRC on the
// microbit image, 4 KB, is its only other use on a board.
ML_OPTIMIZE_SIZE uint32_t crc32(const void* data, size_t size, uint32_t previous) {
  const uint8_t* p = static_cast<const uint8_t*>(data);
  uint32_t c = previous ^ 0xFFFFFFFFu;
  constexpr uint32_t mask = (1u << kCrcStepBits) - 1u;
  for (size_t i = 0; i < size; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; k += kCrcStepBits) c = kCrcTable.entry[c & mask] ^ (c >> kCrcStepBits);
  }
  return c ^ 0xFFFFFFFFu;
}

}  // namespace ml
