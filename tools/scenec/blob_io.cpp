// Blob storage and file I/O.
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "tools/scenec/scenec.h"

namespace ml {

void Blob::assign(const void* src, size_t n) {
  resize(n);
  if (n != 0) std::memcpy(words.data(), src, n);
}

bool load_blob_file(const std::string& path, Blob* out, std::string* error) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    if (error) *error = "cannot open " + path + ": " + std::strerror(errno);
    return false;
  }
  std::vector<uint8_t> bytes;
  uint8_t buffer[1 << 16];
  size_t got;
  while ((got = std::fread(buffer, 1, sizeof(buffer), f)) > 0) {
    bytes.insert(bytes.end(), buffer, buffer + got);
    if (bytes.size() > (size_t(1) << 32)) {
      std::fclose(f);
      if (error) *error = path + ": file too large for a scene blob";
      return false;
    }
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) {
    if (error) *error = "cannot read " + path;
    return false;
  }
  out->assign(bytes.data(), bytes.size());
  return true;
}

bool save_blob_file(const std::string& path, const Blob& blob, std::string* error) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    if (error) *error = "cannot create " + path + ": " + std::strerror(errno);
    return false;
  }
  const bool wrote = blob.size == 0 || std::fwrite(blob.data(), 1, blob.size, f) == blob.size;
  const bool closed = std::fclose(f) == 0;
  if (!wrote || !closed) {
    if (error) *error = "cannot write " + path;
    return false;
  }
  return true;
}

}  // namespace ml
