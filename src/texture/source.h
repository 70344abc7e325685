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
  bool read(uint32_t texture, uint8_t* dst, uint32_t bytes) override;

 private:
  const Scene* scene_ = nullptr;
};

}  // namespace ml
