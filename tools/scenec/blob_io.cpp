// Blob storage and file I/O.
#include <cerrno>
#include <cstdio>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tools/scenec/limits.h"

#include "tools/scenec/scenec.h"

namespace ml {

void Blob::assign(const void* src, size_t n) {
  resize(n);
  if (n != 0) std::memcpy(words.data(), src, n);
}

bool read_input_file(const std::string& path, uint64_t max_bytes, std::vector<uint8_t>* out, std::string* error) {
  out->clear();
  // O_NONBLOCK: opening a FIFO must not wait for a writer (it is refused below anyway).
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (error) *error = "cannot open " + path + ": " + std::strerror(errno);
    return false;
  }
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    if (error) *error = path + ": not a regular file";
    return false;
  }
  if (uint64_t(st.st_size) > max_bytes) {
    ::close(fd);
    if (error) *error = path + ": file too large (" + std::to_string(uint64_t(st.st_size)) + " bytes, at most " +
                        std::to_string(max_bytes) + ")";
    return false;
  }
  try {
    out->resize(size_t(st.st_size));
  } catch (const std::bad_alloc&) {
    ::close(fd);
    if (error) *error = path + ": out of memory";
    return false;
  }
  // Read what fstat promised and no more: a file that grows meanwhile is read only that far; one that
  // shrinks ends early.
  size_t got = 0;
  while (got < out->size()) {
    const ssize_t n = ::read(fd, out->data() + got, out->size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      ::close(fd);
      if (error) *error = "cannot read " + path + ": " + std::strerror(errno);
      return false;
    }
    if (n == 0) break;
    got += size_t(n);
  }
  ::close(fd);
  out->resize(got);
  return true;
}

bool load_blob_file(const std::string& path, Blob* out, std::string* error) {
  std::vector<uint8_t> bytes;
  if (!read_input_file(path, kMaxBlobFileBytes, &bytes, error)) return false;
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
