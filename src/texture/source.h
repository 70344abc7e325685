// TextureSource: where a texture's bytes come from when the pager (texture/pager.h) first needs them
// — the blob itself (in flash or mmap'd), a file, an external SPI flash. The pager owns the buffer;
// a source only copies into it, unless the bytes can be read where they lie (in_place: the blob in
// memory-mapped flash), which takes no pool at all. A read may fail: the frame then draws that
// texture's triangles in their material colour and counts the fallback (Stats::texture_fallbacks).
#pragma once
#include <stdint.h>
#include <string.h>

#include "scene/scene.h"

namespace ml {

class TextureSource {
 public:
  virtual ~TextureSource() = default;
  // Copies the `bytes` bytes of texture `texture` (TextureTexels::bytes of a texture with texels)
  // into dst. Returns false when they cannot be read.
  virtual bool read(uint32_t texture, uint8_t* dst, uint32_t bytes) = 0;
  // The texture's bytes readable in place for the whole frame, or null (the default): the pager
  // then reads them into its pool.
  virtual const uint8_t* in_place(uint32_t texture) const {
    (void)texture;
    return nullptr;
  }
};

// The blob's own Texels section, wherever the blob lives (flash, mmap, a buffer). Copied into the pool
// by default (the pager's residency is then what a file or an external flash would cost); with
// Access::InPlace the texels are sampled where they lie, so a texture needs no RAM (a board whose
// blob is in memory-mapped flash).
class BlobTextureSource : public TextureSource {
 public:
  enum class Access : uint8_t { Copy, InPlace };
  BlobTextureSource() = default;
  explicit BlobTextureSource(const Scene& scene, Access access = Access::Copy) : scene_(&scene), access_(access) {}
  // Inline, with no out-of-line key function: src/ is built without RTTI and host code deriving from
  // or holding these classes must be able to emit their type information itself.
  bool read(uint32_t texture, uint8_t* dst, uint32_t bytes) override {
    if (scene_ == nullptr || texture >= scene_->texture_texels_count) return false;
    const TextureTexels& t = scene_->texture_texels[texture];
    if (bytes != t.bytes) return false;  // read_scene keeps [offset, offset + bytes) inside Texels
    const uint8_t* src = scene_->texels + t.offset;
    memcpy(dst, src, bytes);
    return true;
  }
  const uint8_t* in_place(uint32_t texture) const override {
    if (access_ != Access::InPlace || scene_ == nullptr || texture >= scene_->texture_texels_count) return nullptr;
    return scene_->texels + scene_->texture_texels[texture].offset;
  }

 private:
  const Scene* scene_ = nullptr;
  Access access_ = Access::Copy;
};

}  // namespace ml
