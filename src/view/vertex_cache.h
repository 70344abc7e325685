// A frame's vertices in world and view space, kept by vertex index so that a vertex is decoded
// (vertex_world) and transformed (view_vertex) about once a frame, not once for each triangle that
// shares it (about six in a mesh), again in every band a piece is drawn in (the tiler) and again when
// a triangle activates (the scanline renderer). Direct-mapped: entry
// `vertex & (entries - 1)`, so the neighbouring indices of a mesh's neighbouring triangles take
// different entries. The values are the ones vertices_world and view_triangle give, exactly: a cache of
// any size changes no image and no count.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/arena.h"
#include "core/build.h"
#include "scene/scene.h"
#include "view/view.h"

namespace ml {

// Whether the renderers keep a vertex cache in this build (core/build.h ML_VERTEX_CACHE): in the arena
// they are given beyond the least, when it holds kMinEntries or more.
constexpr bool kVertexCacheBuilt = ML_VERTEX_CACHE != 0;

class VertexCache {
 public:
  // One vertex: the key (its index and the batch it is read with: the same index read with another
  // batch is another point), its world position and, once asked for, its view_vertex. 40 bytes.
  struct Entry {
    uint32_t vertex, batch;  // vertex == kNone: empty
    ViewVertex view;         // view.ox == kNotViewed: not transformed yet
    Vec3i world;
  };
  // The largest cache a frame takes, and the smallest worth its lookups (entries, powers of two).
  static constexpr uint32_t kMaxEntries = 1024;
  static constexpr uint32_t kMinEntries = 64;

  // Entries a scene of `vertices` vertices can use: the smallest power of two holding them all, at
  // least kMinEntries and at most kMaxEntries.
  static uint32_t entries_for(uint32_t vertices);
  // Bytes of `entries` entries with their worst-case alignment: from an arena (init) or at the end of a
  // block (init_at_end).
  static size_t arena_bytes(uint32_t entries) { return arena_worst_case(sizeof(Entry) * entries, alignof(Entry)); }

  // Takes the largest power of two of entries, at most `entries`, whose bytes leave `keep` bytes of the
  // arena free; none when fewer than kMinEntries fit (then entries() is 0 and the lookups below must
  // not be called). The scene and view must outlive the cache.
  void init(Arena& arena, const Scene& scene, const View& view, uint32_t entries, size_t keep);
  // The same in a block of memory the caller owns: the largest power of two of entries, at most
  // `entries`, placed at the end of the `bytes` at `memory` (another structure may grow from the start
  // until it needs them: then drop()). Returns the bytes taken from the end (0: none, fewer than
  // kMinEntries fit).
  size_t init_at_end(void* memory, size_t bytes, const Scene& scene, const View& view, uint32_t entries);
  // No entries from now on: their memory is the caller's again.
  void drop() { entries_ = nullptr; }
  // Entries held (0: no cache).
  uint32_t entries() const { return entries_ ? mask_ + 1 : 0; }

  // The world positions of vertices v[0..2] read with `batch`: vertices_world's. (One copy on the
  // boards, whose flash it spares: inlined at each call site it took 730 bytes more, and ran slower.)
  ML_BOARD_NOINLINE void world(uint32_t batch, const uint32_t v[3], Vec3i out[3]) {
    ML_HOST_UNROLL for (int i = 0; i < 3; ++i) out[i] = lookup(batch, v[i], false).world;
  }
  // Their view_triangle.
  ML_BOARD_NOINLINE void view(uint32_t batch, const uint32_t v[3], ViewTriangle* out) {
    bool unclipped = true;
    ML_HOST_UNROLL for (int i = 0; i < 3; ++i)
      if (!put_view_vertex(lookup(batch, v[i], true).view, i, out)) unclipped = false;
    out->unclipped = unclipped;
  }

  // Vertices decoded so far, and vertices transformed (lookups that missed).
  uint32_t decoded() const { return decoded_; }
  uint32_t transformed() const { return transformed_; }

 private:
  static constexpr int32_t kNotViewed = INT32_MAX;  // never a ViewVertex::ox (|ox| <= 2^21 or clipped)
  // The vertex's entry, filled (and transformed when `viewed`). Valid until the next lookup.
  const Entry& lookup(uint32_t batch, uint32_t vertex, bool viewed) {
    Entry& e = entries_[vertex & mask_];
    if (e.vertex == vertex && e.batch == batch && !(viewed && e.view.ox == kNotViewed)) return e;
    return fill(&e, batch, vertex, viewed);
  }
  const Entry& fill(Entry* e, uint32_t batch, uint32_t vertex, bool viewed);
  void start(const Scene& scene, const View& view, Entry* entries, uint32_t n);

  const Scene* scene_ = nullptr;
  const View* view_ = nullptr;
  Entry* entries_ = nullptr;
  uint32_t mask_ = 0;
  uint32_t decoded_ = 0, transformed_ = 0;
};

}  // namespace ml
