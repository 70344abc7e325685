// A TextureSource for a board that keeps the scene blob's texels in an external SPI NOR flash: the
// pager's reads become READ commands (0x03, a 24-bit address, then the data clocked out) on a small
// SPI bus interface the board implements (chip select and full-duplex byte transfers). The rest of
// the blob (geometry, BSP, materials) is read from memory as usual; only the texels stay outside.
// docs/textures.md, "Where texels come from".
#pragma once
#include <stdint.h>

#include "scene/scene.h"
#include "texture/source.h"

namespace ml {

// The bus to the flash. Inline, with no out-of-line key function (see texture/source.h).
class SpiBus {
 public:
  virtual ~SpiBus() = default;
  // Drives chip select: true asserts it (low) and starts a command, false ends it.
  virtual bool select(bool active) = 0;
  // Clocks n bytes: tx[i] goes out (null: zeros), what comes back goes to rx[i] (null: dropped).
  virtual bool transfer(const uint8_t* tx, uint8_t* rx, uint32_t n) = 0;
};

// Reads texture t's bytes at flash address blob_address + (its offset in the blob): a copy of the
// whole .mls image stored at blob_address. Fails (the pager falls back to the material colour) when
// the bus fails or the bytes lie beyond the 24-bit addresses READ reaches.
class SpiFlashTextureSource : public TextureSource {
 public:
  static constexpr uint8_t kRead = 0x03;
  static constexpr uint32_t kAddressLimit = 1u << 24;

  SpiFlashTextureSource(const Scene& scene, SpiBus& bus, uint32_t blob_address)
      : scene_(scene), bus_(bus), blob_address_(blob_address) {}

  bool read(uint32_t texture, uint8_t* dst, uint32_t bytes) override {
    if (texture >= scene_.texture_texels_count || scene_.texels == nullptr) return false;
    const TextureTexels& t = scene_.texture_texels[texture];
    if (bytes != t.bytes) return false;
    const uint64_t at = uint64_t(blob_address_) + uint64_t(scene_.texels - scene_.base) + t.offset;
    if (at + bytes > kAddressLimit) return false;
    const uint8_t command[4] = {kRead, uint8_t(at >> 16), uint8_t(at >> 8), uint8_t(at)};
    if (!bus_.select(true)) return false;
    const bool ok = bus_.transfer(command, nullptr, 4) && bus_.transfer(nullptr, dst, bytes);
    return bus_.select(false) && ok;
  }

 private:
  const Scene& scene_;
  SpiBus& bus_;
  uint32_t blob_address_;
};

}  // namespace ml
