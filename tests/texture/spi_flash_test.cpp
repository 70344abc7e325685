// The SPI-flash TextureSource (texture/spi_flash_source.h) against an emulated SPI NOR flash that
// decodes the bytes on the bus as a real one does: a command byte after chip select, READ (0x03)
// with three address bytes, then one memory byte out per byte clocked, the address wrapping at the
// end of the chip; any other command reads as 0xFF (an idle MISO line).
#include <gtest/gtest.h>

#include <vector>

#include "tests/scene/scene_test_util.h"
#include "tests/texture/texture_test_util.h"
#include "texture/spi_flash_source.h"

namespace {

using textest::Frame;

class EmulatedSpiFlash : public ml::SpiBus {
 public:
  struct Command {
    std::vector<uint8_t> mosi;  // every byte the host sent while selected
    uint32_t clocked = 0;       // bytes clocked in all
  };

  explicit EmulatedSpiFlash(size_t size) : memory(size, 0xFF) {}

  bool select(bool active) override {
    if (fail_select_at && ++selects == fail_select_at) return false;
    if (active == selected_) return false;  // a glitch on CS: the host's protocol is wrong
    selected_ = active;
    if (active) {
      log.push_back(Command{});
      phase_ = 0;
    }
    return true;
  }

  bool transfer(const uint8_t* tx, uint8_t* rx, uint32_t n) override {
    if (!selected_) return false;  // clocks without chip select reach no flash
    if (fail_transfer_at && ++transfers == fail_transfer_at) return false;
    Command& c = log.back();
    for (uint32_t i = 0; i < n; ++i) {
      const uint8_t in = tx ? tx[i] : 0;
      c.mosi.push_back(in);
      ++c.clocked;
      uint8_t out = 0xFF;
      if (phase_ == 0) {
        command_ = in;
        address_ = 0;
      } else if (command_ == ml::SpiFlashTextureSource::kRead && phase_ <= 3) {
        address_ = (address_ << 8) | in;
      } else if (command_ == ml::SpiFlashTextureSource::kRead) {
        out = memory[address_ % memory.size()];
        address_ = uint32_t((address_ + 1) % memory.size());
      }
      ++phase_;
      if (rx) rx[i] = out;
    }
    return true;
  }

  std::vector<uint8_t> memory;
  std::vector<Command> log;
  int fail_select_at = 0, fail_transfer_at = 0;  // 1-based; 0: never
  int selects = 0, transfers = 0;

 private:
  bool selected_ = false;
  uint32_t phase_ = 0, command_ = 0, address_ = 0;
};

// The banded scene's blob written into a 16 MB flash at `address`.
EmulatedSpiFlash flash_with(const mlhost::LoadedScene& s, uint32_t address) {
  EmulatedSpiFlash flash(size_t(1) << 24);
  const uint8_t* bytes = static_cast<const uint8_t*>(s.blob.data());
  std::copy(bytes, bytes + s.blob.size, flash.memory.begin() + address);
  return flash;
}

TEST(SpiFlashTextures, FramesMatchTheBlobAndTheBusCarriesReadCommands) {
  const mlhost::LoadedScene& s = textest::load("builtin:banded");
  ASSERT_NE(s.scene.texels, nullptr);
  const ml::Camera cam = textest::camera_for(s, 160, 120);
  const uint32_t address = 0x012345;  // no alignment needed
  for (ml::RendererKind r : {ml::RendererKind::Scanline, ml::RendererKind::Tiler}) {
    const Frame blob = textest::render(s.scene, cam, textest::options(r));
    EmulatedSpiFlash flash = flash_with(s, address);
    ml::SpiFlashTextureSource source(s.scene, flash, address);
    ml::RenderOptions o = textest::options(r);
    o.texture_source = &source;
    const Frame f = textest::render(s.scene, cam, o);
    ASSERT_TRUE(f.status.ok()) << f.status.message;
    EXPECT_EQ(f.stats.texture_fallbacks, 0u);
    EXPECT_EQ(f.pixels, blob.pixels);
    // One command a texture read: 03, the address big-endian, then exactly the texture's bytes.
    ASSERT_EQ(flash.log.size(), size_t(f.stats.texture_loads));
    std::vector<bool> seen(s.scene.texture_texels_count, false);
    for (const EmulatedSpiFlash::Command& c : flash.log) {
      ASSERT_GE(c.mosi.size(), 4u);
      EXPECT_EQ(c.mosi[0], 0x03);
      const uint32_t at = uint32_t(c.mosi[1]) << 16 | uint32_t(c.mosi[2]) << 8 | c.mosi[3];
      bool matched = false;
      for (uint32_t t = 0; t < s.scene.texture_texels_count; ++t) {
        const ml::TextureTexels& tt = s.scene.texture_texels[t];
        if (at != address + uint32_t(s.scene.texels - s.scene.base) + tt.offset) continue;
        EXPECT_EQ(c.clocked, 4 + tt.bytes);
        seen[t] = matched = true;
      }
      EXPECT_TRUE(matched) << "address " << at;
    }
    for (uint32_t t = 0; t < s.scene.texture_texels_count; ++t) EXPECT_TRUE(seen[t]) << t;
  }
}

TEST(SpiFlashTextures, BusFailuresAndUnreachableAddressesFallBack) {
  const mlhost::LoadedScene& s = textest::load("builtin:banded");
  const ml::Camera cam = textest::camera_for(s, 160, 120);
  const ml::RenderOptions plain = textest::options(ml::RendererKind::Scanline);
  const Frame blob = textest::render(s.scene, cam, plain);
  for (int mode = 0; mode < 3; ++mode) {
    EmulatedSpiFlash flash = flash_with(s, 0);
    if (mode == 0) flash.fail_select_at = 3;    // the second read's chip select
    if (mode == 1) flash.fail_transfer_at = 4;  // the second read's data
    // mode 2: the blob placed so that the texels lie past 16 MB
    const uint32_t address = mode == 2 ? (1u << 24) - 64 : 0;
    ml::SpiFlashTextureSource source(s.scene, flash, address);
    ml::RenderOptions o = plain;
    o.texture_source = &source;
    const Frame f = textest::render(s.scene, cam, o);
    ASSERT_TRUE(f.status.ok()) << f.status.message;  // the frame completes
    EXPECT_TRUE(f.contract) << f.contract_error;
    if (mode == 2) {
      EXPECT_EQ(f.stats.texture_fallbacks, s.scene.texture_texels_count);
      EXPECT_TRUE(flash.log.empty());  // nothing sent for an address READ cannot reach
    } else {
      EXPECT_EQ(f.stats.texture_fallbacks, 1u) << mode;
      size_t differ = 0;
      for (size_t i = 0; i < f.pixels.size(); ++i) differ += f.pixels[i] != blob.pixels[i];
      EXPECT_GT(differ, 0u);  // one texture drawn in its material colour
    }
  }
}

}  // namespace
