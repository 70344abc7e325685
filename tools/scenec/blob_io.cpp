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

namespace {

// Opens `path`, checks it is a regular file of at most max_bytes, asks `storage` for that many bytes
// and reads into them. *got is the byte count read (a file that shrank meanwhile is shorter).
template <typename Storage>
bool read_regular_file(const std::string& path, uint64_t max_bytes, Storage storage, size_t* got, std::string* error) {
  *got = 0;
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
  const size_t size = size_t(st.st_size);
  uint8_t* data = nullptr;
  try {
    data = storage(size);
  } catch (const std::bad_alloc&) {
    ::close(fd);
    if (error) *error = path + ": out of memory";
    return false;
  }
  // Read what fstat promised and no more: a file that grows meanwhile is read only that far.
  while (*got < size) {
    const ssize_t n = ::read(fd, data + *got, size - *got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      ::close(fd);
      if (error) *error = "cannot read " + path + ": " + std::strerror(errno);
      return false;
    }
    if (n == 0) break;
    *got += size_t(n);
  }
  ::close(fd);
  return true;
}

}  // namespace

bool read_input_file(const std::string& path, uint64_t max_bytes, std::vector<uint8_t>* out, std::string* error) {
  out->clear();
  size_t got = 0;
  auto storage = [out](size_t n) {
    out->resize(n);
    return out->data();
  };
  if (!read_regular_file(path, max_bytes, storage, &got, error)) return false;
  out->resize(got);
  return true;
}

bool load_blob_file(const std::string& path, Blob* out, std::string* error) {
  // Straight into the blob's aligned storage: no second copy of a large blob.
  size_t got = 0;
  auto storage = [out](size_t n) {
    out->resize(n);
    return out->bytes();
  };
  if (!read_regular_file(path, kMaxBlobFileBytes, storage, &got, error)) return false;
  out->size = got;
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
