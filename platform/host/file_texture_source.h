// A TextureSource that reads texels from the .mls file itself (pread at the texture's offset), the way
// a board reads them from an external SPI flash: only the pager's pool holds texels in memory.
#pragma once
#include <string>

#include "scene/scene.h"
#include "texture/source.h"

namespace mlhost {

class FileTextureSource : public ml::TextureSource {
 public:
  // `scene` must be the validated blob of the file at `path` (its Texels offsets are the file's).
  FileTextureSource(const std::string& path, const ml::Scene& scene);
  ~FileTextureSource() override;
  FileTextureSource(const FileTextureSource&) = delete;
  FileTextureSource& operator=(const FileTextureSource&) = delete;

  bool ok() const { return fd_ >= 0; }
  bool read(uint32_t texture, uint8_t* dst, uint32_t bytes) override;

 private:
  int fd_ = -1;
  const ml::Scene& scene_;
};

}  // namespace mlhost
