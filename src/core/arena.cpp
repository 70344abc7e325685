#include "core/arena.h"

namespace ml {

void* Arena::allocate(size_t bytes, size_t align) {
  const uintptr_t start = reinterpret_cast<uintptr_t>(base_) + used_;
  const uintptr_t aligned = (start + (align - 1)) & ~uintptr_t(align - 1);
  const size_t padding = size_t(aligned - start);
  if (padding > size_ - used_ || bytes > size_ - used_ - padding) {
    const size_t need = used_ + padding + bytes;
    if (need > failed_need_) failed_need_ = need;
    return nullptr;
  }
  used_ += padding + bytes;
  if (used_ > peak_) peak_ = used_;
  return reinterpret_cast<void*>(aligned);
}

}  // namespace ml
