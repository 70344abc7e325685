#include "texture/pager.h"

#include "texture/sampler.h"

namespace ml {
namespace {

inline uint32_t round4(uint32_t v) { return (v + 3u) & ~3u; }

// The bytes a texture takes in the pool (0: no texels).
inline uint32_t pool_size(const TextureTexels& t) {
  return t.format == uint8_t(TexelFormat::None) ? 0 : round4(t.bytes);
}

// Heap sort of texture indices by key (no recursion, no extra memory; counts can be large).
template <typename Key>
void sort_by(uint32_t* a, uint32_t n, Key key) {
  auto sift = [&](uint32_t root, uint32_t end) {
    while (2 * root + 1 < end) {
      uint32_t child = 2 * root + 1;
      if (child + 1 < end && key(a[child]) < key(a[child + 1])) ++child;
      if (!(key(a[root]) < key(a[child]))) return;
      const uint32_t t = a[root]; a[root] = a[child]; a[child] = t;
      root = child;
    }
  };
  for (uint32_t i = n / 2; i-- > 0;) sift(i, n);
  for (uint32_t end = n; end > 1; --end) {
    const uint32_t t = a[0]; a[0] = a[end - 1]; a[end - 1] = t;
    sift(0, end - 1);
  }
}

}  // namespace

uint32_t texture_pool_size(const Scene& scene, uint32_t t) { return pool_size(scene.texture_texels[t]); }

TexturePoolNeeds texture_pool_needs(const Scene& scene) {
  TexturePoolNeeds needs;
  uint64_t total = 0;
  for (uint32_t i = 0; i < scene.texture_texels_count; ++i) {
    const uint32_t b = pool_size(scene.texture_texels[i]);
    total += b;
    needs.minimum = max_of(needs.minimum, b);
  }
  // read_scene bounds every texture inside the blob, so the sum fits in 32 bits unless textures share
  // bytes; saturate rather than wrap.
  needs.desired = total > 0xFFFFFFFCu ? 0xFFFFFFFCu : uint32_t(total);
  return needs;
}

size_t TexturePager::arena_bytes(const Scene& scene, uint32_t pool_bytes) {
  const TexturePoolNeeds needs = texture_pool_needs(scene);
  if (!kTextures || needs.desired == 0) return 0;
  const size_t n = scene.texture_texels_count;
  return arena_worst_case(min_of(pool_bytes, needs.desired) & ~3u, 4) + arena_worst_case(n * sizeof(Slot), 4) +
         2 * arena_worst_case(n * sizeof(uint32_t), 4) + arena_worst_case(kLutSlots * kTexelLutEntries * sizeof(Pixel), 4) +
         (kLanes ? arena_worst_case(kLutSlots * kTexelLutEntries * sizeof(uint64_t), 8) : 0);
}

Status TexturePager::begin(const Scene& scene, TextureSource* source, uint32_t pool_bytes, Arena& arena,
                           Stats* stats) {
  *this = TexturePager();
  if (!kTextures) {  // built without textures (core/build.h): each texture with texels a fallback
    for (uint32_t t = 0; stats && t < scene.texture_texels_count; ++t)
      if (pool_size(scene.texture_texels[t]) > 0) ++stats->texture_fallbacks;
    return ok_status();
  }
  const TexturePoolNeeds needs = texture_pool_needs(scene);
  if (needs.desired == 0) return ok_status();
  scene_ = &scene;
  blob_source_ = BlobTextureSource(scene);
  source_ = source ? source : &blob_source_;
  stats_ = stats;
  count_ = scene.texture_texels_count;
  pool_bytes_ = min_of(pool_bytes, needs.desired) & ~3u;
  pool_ = static_cast<uint8_t*>(arena.allocate(pool_bytes_, 4));
  Slot* slots = arena.allocate_array<Slot>(count_);
  resident_ = arena.allocate_array<uint32_t>(count_);
  free_order_ = arena.allocate_array<uint32_t>(count_);
  luts_ = arena.allocate_array<Pixel>(kLutSlots * kTexelLutEntries);
  if (kLanes) lanes_ = arena.allocate_array<uint64_t>(kLutSlots * kTexelLutEntries);
  for (LutKey& k : lut_keys_) k = LutKey{kNone, 0, 0, 0};
  if ((pool_bytes_ && !pool_) || !slots || !resident_ || !free_order_ || !luts_ || (kLanes && !lanes_))
    return error(StatusCode::ArenaTooSmall, "arena too small for the texture pool");
  for (uint32_t i = 0; i < count_; ++i) {
    slots[i] = Slot{nullptr, 0, 0, kNone, 0, kAbsent, 0};
    free_order_[i] = i;
  }
  slots_ = slots;
  return ok_status();
}

void TexturePager::finish_plan() {
  if (!slots_) return;
  sort_by(free_order_, count_, [this](uint32_t t) { return slots_[t].last_row; });
  next_free_ = 0;
}

void TexturePager::rows_done(uint32_t row) {
  if (!slots_) return;
  while (next_free_ < count_ && slots_[free_order_[next_free_]].last_row <= row) {
    const uint32_t t = free_order_[next_free_++];
    if (slots_[t].state == kResident) release(t);
  }
}

// First gap of `bytes` between resident textures (kept sorted by offset).
bool TexturePager::find_room(uint32_t bytes, uint32_t* offset) const {
  uint32_t at = 0;
  for (uint32_t i = 0; i < resident_count_; ++i) {
    const Slot& s = slots_[resident_[i]];
    if (s.offset - at >= bytes) break;
    at = s.offset + pool_size(scene_->texture_texels[resident_[i]]);
  }
  if (pool_bytes_ - at < bytes) return false;  // `at` is a gap's start or the end of the last texture
  *offset = at;
  return true;
}

void TexturePager::release(uint32_t t) {
  uint32_t w = 0;
  for (uint32_t i = 0; i < resident_count_; ++i)
    if (resident_[i] != t) resident_[w++] = resident_[i];
  resident_count_ = w;
  resident_bytes_ -= pool_size(scene_->texture_texels[t]);
  slots_[t].state = kAbsent;
  slots_[t].bytes = nullptr;
}

// Evicts the resident texture (other than `keep`) needed least soon: the one the renderer's next
// uses put last, or one no active triangle uses before one in use; the least recently sampled among
// equals. False when there is none.
bool TexturePager::evict_one(uint32_t keep) {
  uint32_t victim = kNone;
  uint64_t victim_next = 0;
  for (uint32_t i = 0; i < resident_count_; ++i) {
    const uint32_t t = resident_[i];
    if (t == keep) continue;
    const uint64_t next = next_use_ ? next_use_->next_use(t) : 0;
    if (victim == kNone) { victim = t; victim_next = next; continue; }
    const Slot& a = slots_[t];
    const Slot& b = slots_[victim];
    const bool a_idle = a.users == 0, b_idle = b.users == 0;
    if (next != victim_next ? next > victim_next : (a_idle != b_idle ? a_idle : a.touch < b.touch)) {
      victim = t;
      victim_next = next;
    }
  }
  if (victim == kNone) return false;
  release(victim);
  ++stats_->texture_evictions;
  return true;
}

void TexturePager::fallback(uint32_t t) {
  slots_[t].state = kFailed;
  ++stats_->texture_fallbacks;
}

const uint8_t* TexturePager::load(uint32_t t) {
  if (!slots_ || t >= count_) return nullptr;
  Slot& s = slots_[t];
  s.touch = ++clock_;
  if (s.bytes) return s.bytes;
  if (s.state == kFailed) return nullptr;
  if ((s.bytes = source_->in_place(t)) != nullptr) return s.bytes;  // no read, no pool bytes
  const TextureTexels& info = scene_->texture_texels[t];
  const uint32_t bytes = pool_size(info);
  if (bytes == 0 || bytes > pool_bytes_) { fallback(t); return nullptr; }
  uint32_t offset = 0;
  while (!find_room(bytes, &offset))
    if (!evict_one(t)) { fallback(t); return nullptr; }  // unreachable: an empty pool has room
  if (!source_->read(t, pool_ + offset, info.bytes)) { fallback(t); return nullptr; }
  // Insert into the offset-sorted resident list.
  uint32_t i = resident_count_++;
  while (i > 0 && slots_[resident_[i - 1]].offset > offset) { resident_[i] = resident_[i - 1]; --i; }
  resident_[i] = t;
  s.offset = offset;
  s.bytes = pool_ + offset;
  s.state = kResident;
  if (s.loaded) ++stats_->texture_reloads;
  s.loaded = 1;
  ++stats_->texture_loads;
  stats_->texture_bytes_loaded += info.bytes;
  resident_bytes_ += bytes;
  stats_->texture_bytes_peak = max_of(stats_->texture_bytes_peak, resident_bytes_);
  stats_->textures_resident_peak = max_of(stats_->textures_resident_peak, resident_count_);
  return pool_ + offset;
}

const Pixel* TexturePager::texel_lut(uint32_t t, Pixel colour, const uint8_t* bytes, uint32_t samples,
                                     Pixel* lut_colour) {
  if (!slots_ || t >= count_) return nullptr;
  const bool make = samples >= kLutMinSamples;
  *lut_colour = colour;
  if (const Pixel* lut = cached_lut(t, colour, bytes, make)) return lut;
  // The texels alone, the colour applied per sample: one table a texture whatever the colour, so
  // it is made for any number of samples (a model's small triangles each have their own colour).
  *lut_colour = 0xFFFFFF;
  return cached_lut(t, 0xFFFFFF, bytes, true);
}

const Pixel* TexturePager::find_white_lut(uint32_t t, const uint8_t* bytes) {
  Pixel colour;
  white_ = texel_lut(t, 0xFFFFFF, bytes, 0, &colour);  // (white: the table is the white one)
  white_texture_ = t;
  white_generation_ = lut_clock_made_;
  return white_;
}

const Pixel* TexturePager::cached_lut(uint32_t t, Pixel colour, const uint8_t* bytes, bool make) {
  uint32_t oldest = 0;
  for (uint32_t i = 0; i < kLutSlots; ++i) {
    LutKey& k = lut_keys_[i];
    if (k.texture == t && k.colour == colour) {
      k.touch = ++lut_clock_;
      return luts_ + i * kTexelLutEntries;
    }
    if (k.touch < lut_keys_[oldest].touch) oldest = i;
  }
  if (!make || !bytes) return nullptr;
  Pixel* lut = luts_ + oldest * kTexelLutEntries;
  make_texel_lut(scene_->texture_texels[t], bytes, colour, lut);
  ++lut_clock_made_;
  lut_keys_[oldest] = LutKey{t, colour, ++lut_clock_, lut_clock_made_};
  return lut;
}

void TexturePager::make_lanes(uint32_t t, uint32_t slot) {
  spread_texel_lut(scene_->texture_texels[t], luts_ + slot * kTexelLutEntries, lanes_ + slot * kTexelLutEntries);
  lanes_made_[slot] = lut_keys_[slot].made;
}

#if UINTPTR_MAX > 0xFFFFFFFFu
void KeptSampling::look_up(TexturePager& pager, const TextureTexels& t, uint32_t texture, const uint8_t* bytes,
                           TexturePlanes& planes, Pixel colour) {
  const Pixel* white = pager.white_lut(texture, bytes);
  texels_ = t;
  sampling_ = texture_sampling(planes, texels_, bytes, white, 0xFFFFFF, colour,
                               pager.lanes_for(texture, white, 0xFFFFFF, colour, true));
  texture_ = texture;
  generation_ = pager.lut_generation();
}
#endif

}  // namespace ml
