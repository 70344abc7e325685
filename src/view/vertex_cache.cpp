#include "view/vertex_cache.h"

namespace ml {

uint32_t VertexCache::entries_for(uint32_t vertices) {
  uint32_t n = kMinEntries;
  while (n < vertices && n < kMaxEntries) n *= 2;
  return n;
}

void VertexCache::init(Arena& arena, const Scene& scene, const View& view, uint32_t entries, size_t keep) {
  scene_ = &scene;
  view_ = &view;
  entries_ = nullptr;
  decoded_ = transformed_ = 0;
  const size_t free = arena.size() - arena.used();
  uint32_t n = entries;
  while (n >= kMinEntries && free < keep + arena_bytes(n)) n /= 2;
  if (n < kMinEntries) return;
  entries_ = arena.allocate_array<Entry>(n);
  if (!entries_) return;
  mask_ = n - 1;
  for (uint32_t i = 0; i < n; ++i) entries_[i].vertex = kNone;  // empty (a key store each: memset took 40 a entry)
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
