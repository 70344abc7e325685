// TextureSource: where a texture's bytes come from when the pager (texture/pager.h) first needs them
// — the blob itself (in flash or mmap'd), a file, an external SPI flash. The pager owns the buffer;
// a source only copies into it. A read may fail: the frame then draws that texture's triangles in
// their material colour and counts the fallback (Stats::texture_fallbacks).
#pragma once
#include <stdint.h>

#include "scene/scene.h"

namespace ml {

class TextureSource {
 public:
  virtual ~TextureSource() = default;
  // Copies the `bytes` bytes of texture `texture` (TextureTexels::bytes of a texture with texels)
  // into dst. Returns false when they cannot be read.
  virtual bool read(uint32_t texture, uint8_t* dst, uint32_t bytes) = 0;
};

// The blob's own Texels section, wherever the blob lives (flash, mmap, a buffer).
class BlobTextureSource : public TextureSource {
 public:
  BlobTextureSource() = default;
  explicit BlobTextureSource(const Scene& scene) : scene_(&scene) {}
  // Inline, with no out-of-line key function: src/ is built without RTTI and host code deriving from
  // or holding these classes must be able to emit their type information itself.
  bool read(uint32_t texture, uint8_t* dst, uint32_t bytes) override {
    if (scene_ == nullptr || texture >= scene_->texture_texels_count) return false;
    const TextureTexels& t = scene_->texture_texels[texture];
    if (bytes != t.bytes) return false;  // read_scene keeps [offset, offset + bytes) inside Texels
    const uint8_t* src = scene_->texels + t.offset;
    for (uint32_t i = 0; i < bytes; ++i) dst[i] = src[i];
    return true;
  }

 private:
  const Scene* scene_ = nullptr;
};

}  // namespace ml
