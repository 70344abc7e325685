#include "platform/host/file_texture_source.h"

#include <fcntl.h>
#include <unistd.h>

namespace mlhost {

FileTextureSource::FileTextureSource(const std::string& path, const ml::Scene& scene) : scene_(scene) {
  fd_ = open(path.c_str(), O_RDONLY | O_CLOEXEC);
}

FileTextureSource::~FileTextureSource() {
  if (fd_ >= 0) close(fd_);
}

bool FileTextureSource::read(uint32_t texture, uint8_t* dst, uint32_t bytes) {
  if (fd_ < 0 || texture >= scene_.texture_texels_count || scene_.texels == nullptr) return false;
  const ml::TextureTexels& t = scene_.texture_texels[texture];
  if (bytes != t.bytes) return false;
  off_t at = off_t(scene_.texels - scene_.base) + off_t(t.offset);
  uint32_t done = 0;
  while (done < bytes) {
    const ssize_t n = pread(fd_, dst + done, bytes - done, at);
    if (n <= 0) return false;
    done += uint32_t(n);
    at += n;
  }
  return true;
}

}  // namespace mlhost
