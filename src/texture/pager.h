// The lazy texture pager (Woo & Chall §5): a bounded pool in the arena holds the textures the rows
// in flight need. A texture is read through its TextureSource the first time a visible sample needs
// it and freed after the last row that uses it (the renderer plans each texture's last row before
// drawing and reports rows as they finish). When the pool has no room, resident textures are evicted
// — the one the renderer needs last (TextureNextUse), or first those no active triangle uses, then
// the least recently sampled — and read again if needed later, so a frame never fails for lack of
// texture memory. A texture that cannot be read, or is
// larger than the whole pool, is drawn in its material's colour (a fallback). A source whose bytes
// can be read where they lie (TextureSource::in_place: the blob in memory-mapped flash) bypasses the
// pool: nothing is loaded, evicted or counted. docs/textures.md.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/arena.h"
#include "core/build.h"
#include "core/stats.h"
#include "core/status.h"
#include "core/sink.h"
#include "scene/scene.h"
#include "texture/sampler.h"
#include "texture/source.h"

namespace ml {

// Pool sizes for a scene: `desired` holds every texture at once (never evicts), `minimum` holds the
// largest one (every texture can be drawn, with reloads). Both 0 for a scene without texels.
struct TexturePoolNeeds {
  uint32_t desired = 0, minimum = 0;
};
TexturePoolNeeds texture_pool_needs(const Scene& scene);
// The bytes texture `t` takes in the pool (0: no texels).
uint32_t texture_pool_size(const Scene& scene, uint32_t t);

// What a renderer knows about when each texture is needed next (the tiler: its BSP order), for the
// pager's evictions: larger is later; kNever: not again this frame.
class TextureNextUse {
 public:
  static constexpr uint64_t kNever = ~uint64_t(0);
  virtual uint64_t next_use(uint32_t texture) const = 0;
};

class TexturePager {
 public:
  // Arena bytes begin() takes for a pool of (at most) pool_bytes: 0 for a scene without texels.
  static size_t arena_bytes(const Scene& scene, uint32_t pool_bytes);

  // Sets up the pool (min(pool_bytes, desired)) and the per-texture table. source null: the blob's
  // own Texels. ArenaTooSmall when the arena cannot hold arena_bytes(). Inactive (every call below a
  // no-op, get() null) for a scene without texels.
  Status begin(const Scene& scene, TextureSource* source, uint32_t pool_bytes, Arena& arena, Stats* stats);
  bool active() const { return kTextures && slots_ != nullptr; }

  // Planning, before the first get(): texture t is used up to row `last_row` (any increasing unit the
  // renderer reports with rows_done).
  // (Inline: once a triangle.)
  void plan(uint32_t t, uint32_t last_row) {
    if (!slots_ || t >= count_) return;
    Slot& s = slots_[t];
    s.last_row = s.last_row == kNone ? last_row : max_of(s.last_row, last_row);
  }
  void finish_plan();

  // The texture's bytes, reading them if needed; null for a fallback (the read failed or the texture
  // is larger than the pool; counted once per frame and texture).
  const uint8_t* get(uint32_t t) {
    if (!kTextures) return nullptr;
    if (slots_ && t < count_ && slots_[t].bytes) {  // resident or in place: the common case, inline
      slots_[t].touch = ++clock_;
      return slots_[t].bytes;
    }
    return load(t);
  }

  // Active triangles using t (the scanline renderer's yActiveList): used to choose evictions.
  // Inline: once a triangle in the scanline renderer's activation and compaction.
  void add_user(uint32_t t) {
    if (slots_ && t < count_ && slots_[t].users < 0xFFFF) ++slots_[t].users;
  }
  void drop_user(uint32_t t) {
    if (slots_ && t < count_ && slots_[t].users > 0) --slots_[t].users;
  }
  // Or the renderer's own next uses (set after begin): the texture needed last is evicted first.
  void use_next_use(const TextureNextUse* next) { next_use_ = next; }

  // Every row up to `row` is finished: frees the textures whose last row that was.
  void rows_done(uint32_t row);

  // The texel table (texture/sampler.h make_texel_lut) texture_row takes for `samples` samples of
  // texture t drawn in `colour`, and the colour it was made for (*lut_colour): the table of that
  // colour, else the white one (t's texels alone), the product then made per sample.
  // Tables come from a cache of kLutSlots in the arena, made from `bytes` (t's texels, from get())
  // over the least recently used: one of a colour only for kLutMinSamples samples or more, so small
  // pieces do not pay for a table they would hardly use; the white one whenever needed (one serves
  // every colour). Null: none (a texture index out of range).
  // Tables outlive evictions of their texture.
  static constexpr uint32_t kLutSlots = 4;
  static constexpr uint32_t kLutMinSamples = 32;
  const Pixel* texel_lut(uint32_t t, Pixel colour, const uint8_t* bytes, uint32_t samples, Pixel* lut_colour);
  // Texture t's white table (texel_lut's for white: its texels alone), made if needed; kept at hand
  // from one call to the next while no table is made. A small triangle's samples take it: fewer in all
  // than a table of their colour has entries. Null as texel_lut.
  const Pixel* white_lut(uint32_t t, const uint8_t* bytes) {
    if (white_lut_ready(t)) return white_;
    return find_white_lut(t, bytes);
  }
  // Whether white_lut(t) would answer its last answer again, doing nothing else.
  bool white_lut_ready(uint32_t t) const { return t == white_texture_ && white_generation_ == lut_clock_made_; }
  // The colours of table `lut` of texture t (texel_lut's or white_lut's answer, still valid) in 16-bit
  // lanes of a 64-bit word (spread_texel_lut), made if needed: the bilinear filters blend them
  // without spreading each texel. 64-bit hosts only, one beside each table (null on the boards, whose
  // words are 32 bits); null for a null table. Valid while lut_generation() does not change.
  static constexpr bool kLanes = sizeof(void*) >= 8;
  const uint64_t* lanes_of(uint32_t t, const Pixel* lut) {
    if (!kLanes || !lut) return nullptr;
    const uint32_t slot = uint32_t(lut - luts_) / kTexelLutEntries;
    if (lanes_made_[slot] != lut_keys_[slot].made) make_lanes(t, slot);
    return lanes_ + slot * kTexelLutEntries;
  }
  // lanes_of where texture_rows / texture_runs take them (blends_table_as_is), else null: a table
  // of texture t for lut_colour, drawn in `colour`, for exact planes (a small triangle) or not.
  const uint64_t* lanes_for(uint32_t t, const Pixel* lut, Pixel lut_colour, Pixel colour, bool exact) {
    if (!kLanes || !blends_table_as_is(scene_->texture_texels[t], exact, lut_colour, colour)) return nullptr;
    return lanes_of(t, lut);
  }
  // Counts the tables made: a table pointer from texel_lut stays valid while this does not change.
  uint32_t lut_generation() const { return lut_clock_made_; }

 private:
  struct Slot {
    const uint8_t* bytes;  // the texels while resident (in the pool) or in place; null otherwise
    uint32_t offset;     // in the pool, while resident
    uint32_t touch;      // get() count at the last use
    uint32_t last_row;   // planned last use; kNone: never freed early
    uint16_t users;
    uint8_t state;       // kAbsent, kResident, kFailed
    uint8_t loaded;      // read at least once this frame
  };
  static constexpr uint8_t kAbsent = 0, kResident = 1, kFailed = 2;

  const uint8_t* load(uint32_t t);
  bool find_room(uint32_t bytes, uint32_t* offset) const;
  bool evict_one(uint32_t keep);
  void release(uint32_t t);
  void fallback(uint32_t t);
  const Pixel* cached_lut(uint32_t t, Pixel colour, const uint8_t* bytes, bool make);
  const Pixel* find_white_lut(uint32_t t, const uint8_t* bytes);
  void make_lanes(uint32_t t, uint32_t slot);

  const Scene* scene_ = nullptr;
  TextureSource* source_ = nullptr;
  BlobTextureSource blob_source_;
  Stats* stats_ = nullptr;
  uint8_t* pool_ = nullptr;
  uint32_t pool_bytes_ = 0;
  Slot* slots_ = nullptr;
  uint32_t count_ = 0;
  uint32_t* resident_ = nullptr;  // resident textures by pool offset
  uint32_t resident_count_ = 0;
  uint32_t resident_bytes_ = 0;
  uint32_t* free_order_ = nullptr;  // textures by last row
  uint32_t next_free_ = 0;
  uint32_t clock_ = 0;
  const TextureNextUse* next_use_ = nullptr;
  struct LutKey {
    uint32_t texture;  // kNone: empty
    Pixel colour;
    uint32_t touch;
    uint32_t made;     // lut_clock_made_ once this table was made
  };
  Pixel* luts_ = nullptr;  // kLutSlots tables of kTexelLutEntries
  LutKey lut_keys_[kLutSlots] = {};
  uint32_t lut_clock_ = 0;
  uint32_t lut_clock_made_ = 0;
  uint32_t white_texture_ = kNone, white_generation_ = 0;  // white_lut's last answer
  const Pixel* white_ = nullptr;
  uint64_t* lanes_ = nullptr;             // lanes_of's tables, one a slot (64-bit hosts)
  uint32_t lanes_made_[kLanes ? kLutSlots : 1] = {};  // each one's table's LutKey::made when it was made
};

#if UINTPTR_MAX > 0xFFFFFFFFu
// Small triangles' sampling (TexturePlanes::exact, texture_sampling) kept from one small triangle to
// the next (both renderers, 64-bit hosts). A small triangle takes its texture's white table whatever
// its colour, so the table, its lanes and the sampler's loop are looked up again only for another
// texture or other bytes, or when the pager would do more than answer the same (a table made since,
// another texture's white table asked for).
class KeptSampling {
 public:
  // The sampling of the scene's texture `texture` for a small triangle's planes, drawn in `colour`:
  // texels t and bytes of the planes' mip level (texture_level_texels; bytes from TexturePager::get).
  const TextureSampling& for_texture(TexturePager& pager, const TextureTexels& t, uint32_t texture,
                                     const uint8_t* bytes, TexturePlanes& planes, Pixel colour) {
    // (The same bytes may hold another mip level of the texture after the pager moved it: the sides
    // tell the levels apart.)
    if (texture != texture_ || bytes != sampling_.bytes || t.width != texels_.width || t.height != texels_.height ||
        pager.lut_generation() != generation_ || !pager.white_lut_ready(texture))
      look_up(pager, t, texture, bytes, planes, colour);
    sampling_.planes = &planes;
    sampling_.colour = colour;
    return sampling_;
  }

 private:
  // Out of line: seldom taken, and the renderers' loops keep their registers.
  void look_up(TexturePager& pager, const TextureTexels& t, uint32_t texture, const uint8_t* bytes,
               TexturePlanes& planes, Pixel colour);

  TextureSampling sampling_{};
  TextureTexels texels_{};  // sampling_'s texels, copied (a mip level's are a caller's temporary)
  uint32_t texture_ = kNone, generation_ = 0;  // sampling_'s texture and the pager's lut_generation then
};
#endif

}  // namespace ml
