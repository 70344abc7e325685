// CRC-32 (IEEE 802.3, reflected, as zlib's crc32): the scene blob's checksum (scene/reader.cpp checks
// it, the compiler writes it), the mask and filter tables' (tools/maskgen states it in their headers),
// and a firmware frame's.
#pragma once
#include <stddef.h>
#include <stdint.h>

namespace ml {

// Pass the previous value to continue a running CRC.
uint32_t crc32(const void* data, size_t size, uint32_t previous = 0);

}  // namespace ml
