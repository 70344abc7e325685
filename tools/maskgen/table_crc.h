// The tables' CRC-32 (the core's crc32), fed 64-bit values as little-endian bytes, as the headers
// maskgen writes state it.
#pragma once
#include <stdint.h>

#include "core/crc32.h"

namespace maskgen {

// crc continued over v's 8 bytes, least significant first.
inline uint32_t crc32_le64(uint64_t v, uint32_t crc) {
  uint8_t bytes[8];
  for (int k = 0; k < 8; ++k) bytes[k] = uint8_t(v >> (8 * k));
  return ml::crc32(bytes, sizeof bytes, crc);
}

}  // namespace maskgen
