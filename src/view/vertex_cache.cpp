#include "view/vertex_cache.h"

namespace ml {

uint32_t VertexCache::entries_for(uint32_t vertices) {
  uint32_t n = kMinEntries;
  while (n < vertices && n < kMaxEntries) n *= 2;
  return n;
}

void VertexCache::start(const Scene& scene, const View& view, Entry* entries, uint32_t n) {
  scene_ = &scene;
  view_ = &view;
  entries_ = entries;
  decoded_ = transformed_ = 0;
  if (!entries_) return;
  mask_ = n - 1;
  for (uint32_t i = 0; i < n; ++i) entries_[i].vertex = kNone;  // empty (a key store each: memset took 40 a entry)
}

void VertexCache::init(Arena& arena, const Scene& scene, const View& view, uint32_t entries, size_t keep) {
  const size_t free = arena.size() - arena.used();
  uint32_t n = entries;
  while (n >= kMinEntries && free < keep + arena_bytes(n)) n /= 2;
  start(scene, view, n < kMinEntries ? nullptr : arena.allocate_array<Entry>(n), n);
}

size_t VertexCache::init_at_end(void* memory, size_t bytes, const Scene& scene, const View& view, uint32_t entries) {
  uint32_t n = entries;
  while (n >= kMinEntries && bytes < arena_bytes(n)) n /= 2;
  if (n < kMinEntries) {
    start(scene, view, nullptr, 0);
    return 0;
  }
  const uintptr_t end = reinterpret_cast<uintptr_t>(memory) + bytes;
  const uintptr_t at = (end - sizeof(Entry) * n) & ~uintptr_t(alignof(Entry) - 1);
  start(scene, view, reinterpret_cast<Entry*>(at), n);
  return size_t(end - at);
}

const VertexCache::Entry& VertexCache::fill(Entry* e, uint32_t batch, uint32_t vertex, bool viewed) {
  if (e->vertex != vertex || e->batch != batch) {
    ++decoded_;
    e->vertex = vertex;
    e->batch = batch;
    e->world = vertex_world(*scene_, batch, vertex);
    e->view.ox = kNotViewed;
  }
  if (viewed) {
    ++transformed_;
    view_vertex(*view_, e->world, &e->view);
  }
  return *e;
}

}  // namespace ml
