#include "texture/source.h"

namespace ml {

bool BlobTextureSource::read(uint32_t texture, uint8_t* dst, uint32_t bytes) {
  if (scene_ == nullptr || texture >= scene_->texture_texels_count) return false;
  const TextureTexels& t = scene_->texture_texels[texture];
  if (bytes != t.bytes) return false;  // read_scene keeps [offset, offset + bytes) inside Texels
  const uint8_t* src = scene_->texels + t.offset;
  for (uint32_t i = 0; i < bytes; ++i) dst[i] = src[i];
  return true;
}

}  // namespace ml
