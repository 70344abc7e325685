// The arena: all working memory of a render comes from a caller-owned byte buffer.
// Allocation is a bump pointer; nothing is freed individually. A render first computes the bytes it
// needs and fails with ArenaTooSmall (naming them) before touching the sink, so a too-small arena
// never causes a partial write. peak() is the high-water mark, reported in Stats.
#pragma once
#include <stddef.h>
#include <stdint.h>

namespace ml {

class Arena {
 public:
  Arena(void* buffer, size_t size) : base_(static_cast<uint8_t*>(buffer)), size_(size) {}

  // Returns aligned memory or nullptr when the buffer is exhausted (then failed_need() tells the
  // total bytes that would have been needed). align must be a power of two.
  void* allocate(size_t bytes, size_t align = 8);

  template <typename T> T* allocate_array(size_t count) {
    return static_cast<T*>(allocate(sizeof(T) * count, alignof(T) < 4 ? 4 : alignof(T)));
  }

  size_t mark() const { return used_; }
  void release_to(size_t mark) { used_ = mark; }
  void reset() { used_ = 0; peak_ = 0; failed_need_ = 0; }

  size_t size() const { return size_; }
  size_t used() const { return used_; }
  size_t peak() const { return peak_; }
  size_t failed_need() const { return failed_need_; }

 private:
  uint8_t* base_;
  size_t size_;
  size_t used_ = 0;
  size_t peak_ = 0;
  size_t failed_need_ = 0;
};

// Bytes an allocate(bytes, align) call can consume at most, for up-front arena sizing.
constexpr size_t arena_worst_case(size_t bytes, size_t align = 8) { return bytes + align - 1; }

}  // namespace ml
