// The tiler's frame: BSP front to back, each piece projected, back-face culled, set up and tiled
// into the coverage pyramid (tile.h); newly covered blocks go straight to the Sink, shaded; the
// background is tiled through the root mask last. See docs/tiler.md.
#include "tiler/tiler.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "core/band.h"
#include "core/build.h"
#include "core/jitter.h"
#include "shade/shade.h"
#include "texture/mapping.h"
#include "texture/pager.h"
#include "texture/sampler.h"
#include "tiler/filter.h"
#include "tiler/tile.h"
#include "view/vertex_cache.h"

namespace ml {

namespace {

constexpr int kRowPixels = 64;  // Gouraud row buffer: rows of wider blocks go out in chunks
// Texture segments kept per piece: one per row of a 16-row stretch (blocks are at most 8 rows high at
// the finest level), so the next block along finds its rows' segments decided (texture/mapping.h).
constexpr int kSegmentRowBits = 4;

size_t segment_rows_bytes(size_t pager_bytes) {
  return pager_bytes ? arena_worst_case(sizeof(TextureSegment) << kSegmentRowBits, 8) : 0;
}

// One traversal frame, 4 bytes: node index (< 2^31, the reader bounds counts far below) and, in the
// top bit, whether the near side is done.
using BspFrame = uint32_t;
constexpr BspFrame kNearDone = 0x80000000u;

size_t bsp_stack_entries(const Scene& scene) {
  return scene.info ? size_t(scene.info->bsp_depth) + 1 : 1;
}

// Antialiasing (aa > 1): a pixel of the band sums the colours of its samples as pieces cover them,
// front to back, so each sample counts once; the band's pixels leave, packed once, a run of a row at
// a time, when the background has covered the last samples (BandWriter::finish_pixels: a one-pixel
// fill as each pixel's last sample came cost about 100 instructions a pixel, docs/tiler.md). Sums
// stay below 64 * 255 < 2^16.
struct PixelSum {
  uint16_t r, g, b, samples;
};

// Textured triangles' texture planes kept from one band to the next when the arena has room
// (tiler_plan_bytes; scenes with texels, frames of several bands or BSPs that split triangles): a
// piece the band edges cut is drawn in every band it reaches, and a split triangle's pieces each
// draw it, and its planes (the cross products and the small-triangle box, about 450 instructions)
// are the same each time (the textured duck at 320x240 in one band: 562 of 2,138 pieces' planes
// kept, 13.85 M -> 13.58 M instructions).
// Direct-mapped by triangle id, 256 sets of the planes as made (without their caches: 128 bytes, 32
// KB), given only to the triangles that may be drawn again (BandWriter::may_draw_again): a
// triangle whose set another took is made again, as without the cache (the same planes, the same
// images). On 64-bit hosts only (as the band plan's extras): a board has neither the RAM to spare
// nor the flash.
class PlaneCache {
 public:
  static constexpr bool kActive = sizeof(void*) >= 8;
  static constexpr uint32_t kSets = 256;
  // A frame of one band draws a triangle again only when the BSP split it.
  static size_t bytes(const Scene& scene, int bands) {
    const bool again = bands >= 2 || scene.bsp_split_count > 0;
    return !kActive || !again || scene.texture_texels_count == 0 ? 0
                                                                : arena_worst_case(sizeof(Set) * kSets, alignof(Set));
  }
  void init(Arena& arena) {
    if (!kActive) return;
    sets_ = arena.allocate_array<Set>(kSets);
    for (uint32_t i = 0; sets_ && i < kSets; ++i) sets_[i].triangle = kNone;
  }
  // Triangle `triangle`'s planes as made (nothing cached in them yet) into *planes; false when not kept.
  bool find(uint32_t triangle, TexturePlanes* planes) const {
    if (!kActive || !sets_) return false;
    const Set& set = sets_[triangle & (kSets - 1)];
    if (set.triangle != triangle) return false;
    memcpy(static_cast<void*>(planes), set.made, sizeof set.made);
    if (planes->boxed) memcpy(&planes->sums, set.made, sizeof planes->sums);
    clear_texture_caches(planes);
    return true;
  }
  void keep(uint32_t triangle, const TexturePlanes& planes) {
    if (!kActive || !sets_) return;
    Set& set = sets_[triangle & (kSets - 1)];
    set.triangle = triangle;
    memcpy(set.made, static_cast<const void*>(&planes), sizeof set.made);
    if (planes.boxed) memcpy(set.made, &planes.sums, sizeof planes.sums);
  }

 private:
  // TexturePlanes' fields make_texture_planes gives (a, b, k .. whole_denom), the caches after them.
  // A boxed small triangle's sums are kept in place of its planes and coordinates (a, b, k, uv),
  // which it does not use again.
  static constexpr size_t kMade = offsetof(TexturePlanes, rows);
  static_assert(sizeof(BoxSums) <= offsetof(TexturePlanes, size_bits), "the sums in place of the planes");
  struct Set {
    alignas(8) unsigned char made[kMade];
    uint32_t triangle;
  };
  static_assert(sizeof(Set) <= 128, "a set in 128 bytes");
  Set* sets_ = nullptr;
};

// The BandWriter's texture fast paths of 64-bit hosts (#if UINTPTR_MAX > 0xFFFFFFFFu: the boards keep
// their flash and stack for other code): a small triangle's 8x8 block sampled straight from its mask
// and written into the band (write_textured_mask; the boards make a list of runs, texture_runs, and
// put them row by row), a piece's texture looked up once a batch (BatchTextures, which on the boards
// looks each piece's up), and the kept planes given only to triangles that may be drawn again
// (may_draw_again).

// Turns newly covered sample blocks (band-local rows) into band-buffer writes of the current piece's
// colours. Colours are computed on the first write, so hidden pieces cost no shading.
class BandWriter : public CoverageWriter {
 public:
  BandWriter(BandOutput& out, Stats* stats, Pixel* row) : out_(out), stats_(stats), row_(row) {}

  // Oversampling: factor x factor samples a pixel (a power of two), sums for a band of `width` pixels.
  void oversample(int factor, PixelSum* sums, int width) {
    factor_ = factor;
    factor_bits_ = factor == 8 ? 6 : factor == 4 ? 4 : factor == 2 ? 2 : 0;
    pixel_mask_ = corner_samples(factor);  // the samples of the top-left pixel of an 8x8-sample block
    sums_ = sums;
    width_ = width;
  }
  // The cosine-hump filter instead of the box (filter.h): masks go to it, per source pixel.
  void use_filter(SampleFilter* filter) { cosine_ = filter; }
  void begin_band(int top, int rows) {
    top_ = top;
    rows_ = rows;
#if UINTPTR_MAX > 0xFFFFFFFFu
    band_end_ = top + rows;
#endif
    if (factor_ > 1 && !cosine_) memset(sums_, 0, sizeof(PixelSum) * size_t(rows) * size_t(width_));
  }
  // whole_view: the triangle's view_triangle when the piece is the whole triangle (valid while it is
  // tiled), else null.
  void begin_piece(const Scene* scene, const Light* light, ShadingMode mode, uint32_t triangle,
                   bool front_facing, const ViewTriangle* whole_view = nullptr) {
    whole_view_ = whole_view;
#if UINTPTR_MAX > 0xFFFFFFFFu
    split_ = whole_view == nullptr;
#endif
    scene_ = scene;
    light_ = light;
    mode_ = mode;
    // The colours are kept when the piece's triangle and side are the last shaded one's (the walk
    // often draws a split triangle's pieces one after the other).
    shaded_ = triangle == shaded_triangle_ && front_facing == shaded_front_;
    triangle_ = triangle;
    front_facing_ = front_facing;
    wrote_piece_ = false;
    texture_ = kTextures && pager_ ? batch_textures_.of_triangle(*scene, triangle) : kNone;
    texture_ready_ = false;
    lut_ = nullptr;
  }
  // Whether the current piece is textured (never without ML_TEXTURES: its paths then compile away).
  bool textured() const { return kTextures && texture_ != kNone; }
  // The whole triangle's view_triangle for a split piece's texture planes (valid while it is tiled).
  void use_whole_view(const ViewTriangle* whole_view) { whole_view_ = whole_view; }
  // Textured pieces (texture/): the pager, and the view their texture planes are built in.
  void use_textures(TexturePager* pager, const View* view, TextureSegment* segment_rows, PlaneCache* cache) {
    pager_ = pager->active() ? pager : nullptr;
    view_ = view;
    segment_rows_ = segment_rows;
    plane_cache_ = cache;
  }
  // world: the piece's triangle's world vertices when read already (for its shading; valid while the
  // part is tiled), or null.
  void begin_part(const ScreenTriangle* part, const Vec3i* world) {
    world_ = world;
    part_ = part;
    planes_ready_ = false;
  }
  void begin_background(Pixel value) {
    texture_ = kNone;
    shaded_ = true;
    shaded_triangle_ = kNone;
    colors_.flat = value;
    colors_.smooth = false;
  }
  bool wrote_piece() const { return wrote_piece_; }
  void clear_piece() { wrote_piece_ = false; }
  // The box filter's pixels of the band that took their samples one by one (add_to_pixel; a pixel a
  // piece or the background covers whole is written at once, write_pixels), once the background has
  // covered the band's last samples: each the mean of its samples, rounded, a run of a row at a time.
  void finish_pixels() {
    if (cosine_) return cosine_->end_band();
    if (factor_ == 1) return;
    const uint32_t half = (1u << factor_bits_) >> 1;
    uint32_t written = 0;
    for (int py = 0; py < rows_; ++py) {
      const PixelSum* sums = sums_ + size_t(py) * size_t(width_);
      written += out_.put_row_runs(
          py + top_, width_, row_, kRowPixels, [sums](int px) { return sums[px].samples != 0; },
          [&](int px) {
            const PixelSum& s = sums[px];
            return rgb((s.r + half) >> factor_bits_, (s.g + half) >> factor_bits_, (s.b + half) >> factor_bits_);
          });
    }
    stats_->pixel_writes += written;
  }

  bool write(int x, int band_y, int w, int h) override {
    first_write();
    if (cosine_) {
      cosine_->add_samples(x, band_y, w, h, colours_);
      return true;
    }
    if (factor_ > 1) {
      add_samples(x, band_y, w, h);
      return true;
    }
    return write_pixels(x, band_y, w, h);
  }

  bool write_block(uint64_t mask, int x, int band_y) override {
    // The common block on 64-bit hosts: one sample a pixel, the piece shaded, one colour, quantized
    // already. Its path calls nothing, so it saves no registers: the rest is out of line
    // (2CylinderEngine at 1024x768: 12,167 of 18,608 blocks a frame). A small textured piece's blocks
    // after its first are the textured frames' common block: write_lean_textured.
    if (kLeanBlocks && factor_ == 1 && shaded_) {
      if (!textured() && !colors_.smooth && !cosine_ && out_.mask_value_ready(colors_.flat) &&
          fill_flat(mask, x, band_y)) {
        wrote_piece_ = true;
        return true;
      }
#if UINTPTR_MAX > 0xFFFFFFFFu
      if (textured() && texture_ready_ && lean_sampling_) return write_lean_textured(mask, x, band_y + top_);
#endif
    }
    return write_any_block(mask, x, band_y);
  }

 private:
  static constexpr bool kLeanBlocks = UINTPTR_MAX > 0xFFFFFFFFu;
  ML_HOST_NOINLINE bool write_any_block(uint64_t mask, int x, int band_y) {
    first_write();
    if (factor_ == 1 && !cosine_) {
      // One colour for the whole block: the mask goes to the band as it is, not run by run.
      if (!textured() && !colors_.smooth && fill_flat(mask, x, band_y)) return true;
      if (textured() && !colors_.smooth && write_textured_block(mask, x, band_y + top_)) return true;
#if UINTPTR_MAX > 0xFFFFFFFFu
      if (!textured() && colors_.smooth) return write_smooth_block(mask, x, band_y + top_);
#endif
      return CoverageWriter::write_block(mask, x, band_y);
    }
    if (cosine_) {
      cosine_->add_block(mask, x, band_y, colours_);
      return true;
    }
    // The block holds (8 / f)^2 pixels of f x f samples each.
    const int f = factor_, per_side = 8 / f;
    if (kLeanBlocks && !colors_.smooth && !textured()) {  // one colour: its channels once a block
      add_block_flat(mask, x / f, band_y / f, per_side);
      return true;
    }
    for (int j = 0; j < per_side; ++j)
      for (int i = 0; i < per_side; ++i) {
        const uint64_t m = mask & (pixel_mask_ << (j * f * 8 + i * f));
        if (m != 0) add_to_pixel(x / f + i, band_y / f + j, uint32_t(bit_count64(m)));
      }
    return true;
  }

  // The mask in the piece's flat colour through the band's one-colour block fill, its pixels counted;
  // false (nothing written) when the format takes the mask run by run.
  ML_HOST_INLINE bool fill_flat(uint64_t mask, int x, int band_y) {
    const int stored = out_.fill_mask(mask, x, band_y + top_, colors_.flat);
    if (stored < 0) return false;
    stats_->pixel_writes += uint64_t(stored);
    return true;
  }
  // A block's samples each written and shaded on their own (textured, Gouraud): counted; their number.
  uint64_t count_shaded(uint64_t mask) {
    const uint64_t n = uint64_t(bit_count64(mask));
    stats_->pixel_writes += n;
    stats_->shading_calls += n;
    return n;
  }
  // Every write of a piece: it counts as drawn, and it is shaded once, on the first.
  void first_write() {
    wrote_piece_ = true;
    if (!shaded_) shade();
  }
  void shade() {
    shade_triangle(*scene_, *light_, mode_, triangle_, front_facing_, &colors_, world_);
    shaded_ = true;
    shaded_triangle_ = triangle_;
    shaded_front_ = front_facing_;
    ++stats_->shading_calls;
  }

  bool write_pixels(int x, int band_y, int w, int h) {
    const int y = band_y + top_;
    stats_->pixel_writes += uint64_t(w) * uint64_t(h);
    if (textured()) {
      write_textured(x, y, w, h);
      return true;
    }
    if (!colors_.smooth) {
      out_.fill(x, y, w, h, colors_.flat);
      return true;
    }
    ready_planes();
    stats_->shading_calls += uint64_t(w) * uint64_t(h);
    for (int yy = y; yy < y + h; ++yy)
      for (int x0 = x; x0 < x + w; x0 += kRowPixels) {
        const int n = min_of(kRowPixels, x + w - x0);
        ColorPlanesRow colours(planes_, x0, yy);
        for (int i = 0; i < n; ++i, colours.step()) row_[i] = colours.colour();
        out_.put_row(x0, yy, row_, n);
      }
    return true;
  }

 private:
  // The current part's colour planes (a smooth piece's), made at its first use.
  const ColorPlanes& ready_planes() {
    if (!planes_ready_) {
      make_color_planes(*part_, colors_, &planes_);
      planes_ready_ = true;
    }
    return planes_;
  }
  // The colour before texturing at pixel (px, py) of the frame: flat, or the planes of a smooth piece.
  Pixel base_at(int px, int py) {
    if (!colors_.smooth) return colors_.flat;
    ready_planes();
    uint32_t ch[3];
    for (int c = 0; c < 3; ++c) ch[c] = uint32_t(clamp_to(planes_.channel[c].at(px, py), 0, 255));
    return rgb(ch[0], ch[1], ch[2]);
  }

  // The current piece's colours as the cosine filter asks for them.
  class Colours final : public SourceColours {
   public:
    explicit Colours(BandWriter* w) : w_(w) {}
    bool flat(Pixel* c) override {
      *c = w_->colors_.flat;
      return !w_->colors_.smooth && !w_->textured();
    }
    Pixel colour_at(int px, int py) override { return w_->color_at(px, py); }

   private:
    BandWriter* w_;
  };

  // Colour of the current piece (or the background) at pixel (px, py) of the frame, textured.
  Pixel color_at(int px, int py) {
    if (colors_.smooth || textured()) ++stats_->shading_calls;
    const Pixel c = base_at(px, py);
    return textured() ? texel_at(px, py, c) : c;
  }

  // The texel at pixel (px, py) modulates colour c (c alone when the pager falls back). Texture
  // planes come from the whole triangle, as in the scanline renderer; oversampled frames take the
  // texel at the pixel centre.
  Pixel texel_at(int px, int py, Pixel c) {
    const uint8_t* bytes = pager_->get(texture_);
    if (!bytes) return c;
    int32_t uv[2];
    TexturePlanes& planes = texture_planes();
    const TextureTexels& t = level_texels(&bytes);
    texture_uv(planes, px, py, uv);
    return sample_texture(t, bytes, uv, c, planes.exact);
  }
  TexturePlanes& texture_planes() { return texture_ready_ ? texture_planes_ : make_texture_planes(); }
  [[gnu::noinline]] TexturePlanes& make_texture_planes() {  // once a piece, off the per-block paths
    if (plane_cache_->find(triangle_, &texture_planes_)) {  // made for an earlier piece or band
      ++stats_->texture_planes_reused;
    } else {
      triangle_texture_planes(*scene_, *view_, triangle_, texture_, 1, kSubpixelHalf, kSubpixelHalf,
                              &texture_planes_, whole_view_);
      if (may_draw_again()) plane_cache_->keep(triangle_, texture_planes_);
    }
    // A small triangle's samples are divided one by one: no segments to keep (planes' rows stay null).
    if (!texture_planes_.exact) use_segment_rows(&texture_planes_, segment_rows_, kSegmentRowBits);
    texture_ready_ = true;
#if UINTPTR_MAX > 0xFFFFFFFFu
    lean_sampling_ = nullptr;  // an earlier piece's: this piece's first block sets its own
#endif
    return texture_planes_;
  }

  // The texels the piece samples, its planes' mip level (TextureLevels), with *bytes (the texture's,
  // from the pager) moved to the level's (once its planes are ready).
  const TextureTexels& level_texels(const uint8_t** bytes) {
    *bytes = levels_.bytes(*scene_, texture_, texture_planes_.level, *bytes);
    return levels_.texels(*scene_, texture_, texture_planes_.level);
  }

  // Whether the piece's triangle may be drawn again, so that its planes are worth keeping (PlaneCache,
  // 64-bit hosts): a split piece's triangle has other pieces; a whole one, unless its view is
  // unclipped and its vertices end above the band's last row (the cache keeps its sets for the
  // triangles that reach a later band).
  bool may_draw_again() const {
#if UINTPTR_MAX > 0xFFFFFFFFu
    if (split_ || !whole_view_ || !whole_view_->unclipped) return true;
    const int64_t bottom = max_of(whole_view_->oy[0], max_of(whole_view_->oy[1], whole_view_->oy[2]));
    return view_->center_y + bottom >= int64_t(band_end_ - 1) * kSubpixelOne;
#else
    return true;
#endif
  }

  // The piece's texel table for `samples` samples of its texture's `bytes`, looked up once for its
  // blocks: again only when the pager has made one since, or for a block large enough to have a
  // table of the colour made; a small triangle's is the texture's white one.
  [[gnu::noinline]] void lookup_lut(const uint8_t* bytes, uint32_t samples, bool small) {
    if (small) {  // the texture's white table (TexturePager::white_lut)
      lut_ = pager_->white_lut(texture_, bytes);
      lut_colour_ = 0xFFFFFF;
      lut_generation_ = pager_->lut_generation();
      return;
    }
    if (!lut_ || lut_generation_ != pager_->lut_generation() ||
        (lut_colour_ != colors_.flat && samples >= TexturePager::kLutMinSamples)) {
      lut_ = pager_->texel_lut(texture_, colors_.flat, bytes, samples, &lut_colour_);
      lut_generation_ = pager_->lut_generation();
    }
  }

  // An 8x8 block's newly covered samples (mask) of a small flat textured triangle, its runs of rows in
  // one texture_runs: no rectangles through write() (its block is a few short rows). False for other
  // pieces, or when the pager falls back (the caller's runs then draw them).
  [[gnu::noinline]] bool write_textured_block(uint64_t mask, int x, int y) {
    TexturePlanes& planes = texture_planes();
    if (!planes.exact) return false;  // larger pieces: rectangles of rows (write_textured)
    const uint8_t* bytes = pager_->get(texture_);
    if (!bytes) return false;
#if UINTPTR_MAX > 0xFFFFFFFFu
    count_shaded(mask);
    return write_textured_mask(planes, bytes, mask, x, y);
#else
    lookup_lut(bytes, uint32_t(count_shaded(mask)), true);
    static_assert(kRowPixels >= 64, "a block's colours fit the row buffer");
    SampleRun runs[32];  // at most 4 runs a row of 8
    int32_t count = 0;
    while (mask != 0) runs[count++] = take_mask_run(&mask, x, y);
    // One texture_runs for the block, then its runs out.
    const TextureTexels& t = level_texels(&bytes);
    texture_runs(planes, t, bytes, lut_, lut_colour_, colors_.flat, runs, count, row_,
                 pager_->lanes_for(texture_, lut_, lut_colour_, colors_.flat, true));
    const Pixel* colours = row_;
    for (int32_t k = 0; k < count; ++k) {
      out_.put_row(runs[k].x, runs[k].y, colours, runs[k].n);
      colours += runs[k].n;
    }
    return true;
#endif
  }

#if UINTPTR_MAX > 0xFFFFFFFFu
  // A Gouraud block (one sample a pixel, no texture) on a 64-bit host: each row's pixels from the
  // colour planes stepped across the row (write_pixels' sums, the same values), straight into the band
  // when it stores colours as they are, else into row_ at their bits and out as a mask (or run by run),
  // instead of a write_pixels call a run with its own plane sums (the duck's Gouraud frame 14.49 M ->
  // 12.31 M instructions).
  bool write_smooth_block(uint64_t mask, int x, int y) {
    ready_planes();
    count_shaded(mask);
    uint32_t stride;
    Pixel* const to = block_colours_at(x, y, &stride);
    for (uint64_t m = mask; m != 0;) {
      const int r = __builtin_ctzll(m) >> 3;
      const uint32_t bits = uint32_t(m >> (8 * r)) & 0xFFu;
      m &= ~(uint64_t(0xFF) << (8 * r));
      const int first = __builtin_ctz(bits), last = 31 - __builtin_clz(bits);
      ColorPlanesRow colours(planes_, x + first, y + r);
      Pixel* const row = to + size_t(r) * stride;
      for (int c = first; c <= last; ++c, colours.step())
        if ((bits >> c) & 1u) row[c] = colours.colour();
    }
    return put_block_colours(mask, x, y, to);
  }

  // Where a 64-bit host's block writer puts the colours of the 8x8 block at (x, y): the band itself
  // when it stores colours as they are, else row_ (pixel (x + c, y + r) at 8 r + c); rows *stride apart.
  Pixel* block_colours_at(int x, int y, uint32_t* stride) {
    Pixel* const band = out_.pixels_at(x, y, stride);
    if (band) return band;
    *stride = 8;
    return row_;
  }
  // The block's colours out of row_ when block_colours_at gave it (to): as a mask, or run by run when
  // the format needs them so. Always true.
  bool put_block_colours(uint64_t mask, int x, int y, const Pixel* to) {
    if (to != row_ || out_.put_mask(mask, x, y, row_)) return true;
    for (uint64_t m = mask; m != 0;) {  // row_[8 r + c] holds pixel (x + c, y + r)
      const SampleRun run = take_mask_run(&m, x, y);
      out_.put_row(run.x, run.y, row_ + 8 * (run.y - y) + (run.x - x), run.n);
    }
    return true;
  }

  // write_textured_block on a 64-bit host: the samples straight from the mask (sample_block), into
  // the band itself when it stores colours as they are, else into row_ at their bits and out as a mask
  // (or run by run). The sampling is kept from small piece to small piece (KeptSampling); each piece
  // sets its colour.
  bool write_textured_mask(TexturePlanes& planes, const uint8_t* bytes, uint64_t mask, int x, int y) {
    const TextureTexels& t = level_texels(&bytes);
    lean_sampling_ = &kept_sampling_.for_texture(*pager_, t, texture_, bytes, planes, colors_.flat);
    return sample_lean_block(mask, x, y);
  }
  // The block through the piece's sampling (forced inline: called out of line it cost the duck's frame
  // 46,000 instructions).
  ML_HOST_INLINE bool sample_lean_block(uint64_t mask, int x, int y) {
    static_assert(kRowPixels >= 64, "a block's colours fit the row buffer");
    uint32_t stride;
    Pixel* const to = block_colours_at(x, y, &stride);
    sample_block(*lean_sampling_, mask, x, y, to, stride);
    return put_block_colours(mask, x, y, to);
  }
  // A small piece's blocks after its first, which went through write_textured_mask and left its
  // sampling in lean_sampling_: straight from write_block, without the checks and look-ups that gave
  // the same answers for the first block (the duck's tiler frame: 1,717 of its 3,854 textured blocks,
  // 13,575,634 -> 13,439,728 instructions; untextured frames as before). The sampling is the piece's
  // while it is textured and its planes are ready (texture_ready_, which the background that follows
  // the last piece leaves as it was): make_texture_planes forgets an earlier piece's, and only the
  // piece's first block sets it. The texture is not asked of the pager again: the first block
  // did, and no other texture is used until the piece ends, so the order of the textures' last uses,
  // which the pager's evictions go by, stays the same.
  [[gnu::noinline]] bool write_lean_textured(uint64_t mask, int x, int y) {
    count_shaded(mask);
    return sample_lean_block(mask, x, y);
  }
#endif

  // A block of a textured piece: flat colours a few rows at a time (texture/sampler.h texture_rows),
  // smooth ones pixel by pixel.
  void write_textured(int x, int y, int w, int h) {
    stats_->shading_calls += uint64_t(w) * uint64_t(h);
    const uint8_t* bytes = colors_.smooth ? nullptr : pager_->get(texture_);
    if (!bytes) {
      for (int yy = y; yy < y + h; ++yy)
        for (int x0 = x; x0 < x + w; x0 += kRowPixels) {
          const int n = min_of(kRowPixels, x + w - x0);
          for (int i = 0; i < n; ++i) row_[i] = color_of_textured(x0 + i, yy);
          out_.put_row(x0, yy, row_, n);
        }
      return;
    }
    TexturePlanes& planes = texture_planes();
    const TextureTexels& t = level_texels(&bytes);
    lookup_lut(bytes, uint32_t(w) * uint32_t(h), planes.exact);
    const Pixel* lut = lut_;
    const Pixel lut_colour = lut_colour_;
    const uint64_t* lanes = pager_->lanes_for(texture_, lut, lut_colour, colors_.flat, planes.exact);
    if (w <= kRowPixels) {  // as many whole rows at once as the row buffer holds
      const int per = kRowPixels / w;
      for (int yy = y; yy < y + h; yy += per) {
        const int rows = min_of(per, y + h - yy);
        texture_rows(planes, t, bytes, lut, lut_colour, colors_.flat, x, yy, w, rows, row_, lanes);
        for (int r = 0; r < rows; ++r) out_.put_row(x, yy + r, row_ + r * w, w);
      }
      return;
    }
    for (int yy = y; yy < y + h; ++yy)
      for (int x0 = x; x0 < x + w; x0 += kRowPixels) {
        const int n = min_of(kRowPixels, x + w - x0);
        texture_row(planes, t, bytes, lut, lut_colour, colors_.flat, x0, yy, n, row_, lanes);
        out_.put_row(x0, yy, row_, n);
      }
  }
  Pixel color_of_textured(int px, int py) { return texel_at(px, py, base_at(px, py)); }

  // Samples [x, x + w) x [band_y, band_y + h) newly covered with the current colour. A pixel covered
  // whole by one write had none of its samples covered before (each is handed over once): it leaves
  // at once, without sums (coarse cells and the background are such writes).
  void add_samples(int x, int band_y, int w, int h) {
    const int f = factor_;
    if (((x | band_y | w | h) & (f - 1)) == 0) {
      write_pixels(x / f, band_y / f, w / f, h / f);
      return;
    }
    for (int py = band_y / f; py <= (band_y + h - 1) / f; ++py) {
      const uint32_t ny = uint32_t(min_of(band_y + h, (py + 1) * f) - max_of(band_y, py * f));
      for (int px = x / f; px <= (x + w - 1) / f; ++px)
        add_to_pixel(px, py, ny * uint32_t(min_of(x + w, (px + 1) * f) - max_of(x, px * f)));
    }
  }

  // add_to_pixel of each pixel of an oversampled block (mask as write_block's, its first pixel (px, py),
  // per_side pixels a side) in the piece's one colour, shaded already (64-bit hosts: the colour taken
  // once for the block, not looked up again for each pixel).
  void add_block_flat(uint64_t mask, int px, int py, int per_side) {
    const Pixel c = colors_.flat;
    const int f = factor_;
    for (int j = 0; j < per_side; ++j) {
      PixelSum* row = sums_ + size_t(py + j) * size_t(width_) + size_t(px);
      for (int i = 0; i < per_side; ++i) {
        const uint64_t m = mask & (pixel_mask_ << (j * f * 8 + i * f));
        if (m == 0) continue;
        add_samples_to(row[i], c, uint32_t(bit_count64(m)));
      }
    }
  }
  // n more samples of colour c in a pixel's sums.
  static void add_samples_to(PixelSum& s, Pixel c, uint32_t n) {
    s.r = uint16_t(s.r + ((c >> 16) & 0xFF) * n);
    s.g = uint16_t(s.g + ((c >> 8) & 0xFF) * n);
    s.b = uint16_t(s.b + (c & 0xFF) * n);
    s.samples = uint16_t(s.samples + n);
  }

  // n more samples of pixel (px, band row py) in the current colour. One copy everywhere (inlined in
  // write and write_block it takes the boards' images 600 to 900 bytes more).
  [[gnu::noinline]] void add_to_pixel(int px, int py, uint32_t n) {
    add_samples_to(sums_[size_t(py) * size_t(width_) + size_t(px)], color_at(px, py + top_), n);
  }

  BandOutput& out_;
  Stats* stats_;
  Pixel* row_;
  int factor_ = 1, factor_bits_ = 0, width_ = 0, rows_ = 0;
  uint64_t pixel_mask_ = 0;
  PixelSum* sums_ = nullptr;
  Colours colours_{this};
  SampleFilter* cosine_ = nullptr;
  int top_ = 0;
  const Scene* scene_ = nullptr;
  const Vec3i* world_ = nullptr;
  const Light* light_ = nullptr;
  ShadingMode mode_ = ShadingMode::Flat;
  uint32_t triangle_ = 0;
  bool front_facing_ = true;
  bool shaded_ = false;
  uint32_t shaded_triangle_ = kNone;  // the triangle and side colors_ were shaded for (kNone: none)
  bool shaded_front_ = true;
  bool wrote_piece_ = false;
  const ScreenTriangle* part_ = nullptr;
  bool planes_ready_ = false;
  TriangleColors colors_{};
  ColorPlanes planes_{};
  TexturePager* pager_ = nullptr;
  const View* view_ = nullptr;
  uint32_t texture_ = kNone;
  TextureLevels levels_;  // the mip levels sampled
  bool texture_ready_ = false;
  TexturePlanes texture_planes_{};
  TextureSegment* segment_rows_ = nullptr;
  PlaneCache* plane_cache_ = nullptr;  // set whenever textured (inactive: finds nothing)
  const ViewTriangle* whole_view_ = nullptr;
  const Pixel* lut_ = nullptr;  // the piece's texel table (null: not looked up yet), its colour and generation
  Pixel lut_colour_ = 0;
  uint32_t lut_generation_ = 0;
  [[no_unique_address]] BatchTextures batch_textures_;  // the pieces' textures (boards: empty)
#if UINTPTR_MAX > 0xFFFFFFFFu  // the fast paths' state
  int band_end_ = 0;    // the band's end (pixel rows, may_draw_again)
  bool split_ = false;  // the piece is a BSP split part (begin_piece without the whole view)
  KeptSampling kept_sampling_;  // small pieces' blocks' sampling (write_textured_mask)
  const TextureSampling* lean_sampling_ = nullptr;  // write_lean_textured's (null: none)
#endif
};

// A BSP piece cut from a triangle has split vertices quantized like any vertex, so its outer edges
// can stray from the triangle's own edges by a fraction of a subpixel: a sliver of overlap or crack
// against the neighbour across that edge. For a piece that may be visible, the piece is tiled as
// its (unclipped) triangle intersected with the piece's inner edges (those not along a triangle
// edge, shared with its sibling pieces): the outer boundary is then the triangle's exactly
// (watertight with the neighbour, the same samples the scanline renderer gives the triangle). The
// box grows by one pixel for the sliver.
bool is_split_piece(const BspPiece& piece, const Triangle& tri) {
  if (piece.v[0] == tri.v[0] && piece.v[1] == tri.v[1] && piece.v[2] == tri.v[2]) return false;  // most pieces
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i)
    if (piece.v[i] != tri.v[0] && piece.v[i] != tri.v[1] && piece.v[i] != tri.v[2]) return true;
  return false;
}

// How far a split vertex may sit from its triangle's edge on screen: three world units (a batch's
// int16 grid and the rounding of vertex_world move a vertex by up to about 1.5) projected at the
// nearer endpoint's depth, at least two subpixels, at most half a pixel.
int64_t split_tolerance(const View& view, const ScreenVertex& p, const ScreenVertex& q) {
  const int64_t z = max_of<int64_t>(1, min_of(p.z, q.z));  // 1/16 world unit (kViewFractionBits)
  return clamp_to<int64_t>((3 * view.focal_q8 << kViewFractionBits) / z, 2, kSubpixelHalf);
}

// Whether two edges have their insides on the same side: the angle between their normals (a, b) is
// below 90 degrees. |a|, |b| < 2^23 (view.h): the sum is below 2^47.
bool faces_alike(const EdgeFunction& p, const EdgeFunction& q) { return p.a * q.a + p.b * q.b > 0; }

// Pairs piece edges with the triangle edges they run along (far[i][k]: piece edge i's farther end's
// |E_k|, or -1 beyond the tolerance) when some edge has several partners: each piece edge along one
// triangle edge at most, each triangle edge taken once, the nearest pair first (distances end / norm
// compared as end_1 norm_2 < end_2 norm_1; end <= 2^7 norm and norm < 2^24 (view.h): below 2^55). A
// sliver piece, cut by a plane that runs almost along a triangle edge, has two edges near that edge:
// the nearer is it, the other is the cut, shared with the piece beside and kept
// (OracleRenderersAgree.SliverPiecesOfRealModels: a sample on the edge went to neither piece). A piece
// edge facing away from a triangle edge (its inside on the other side: a sliver's cut) is never that
// edge, however near: taken for it, the piece would grow over the far side of the cut
// (OracleRenderersAgree.CrossingTriangles). Returns the triangle edges taken (bit k).
int pair_nearest_first(const int64_t (&far)[3][3], const int64_t (&norm)[3], const ConvexPoly& piece,
                       const ConvexPoly& whole, int (&along)[3]) {
  along[0] = along[1] = along[2] = -1;
  int used = 0;
  for (int taken = 0; taken < 3; ++taken) {
    int bi = -1, bk = 0;
    for (int i = 0; i < 3; ++i) {
      if (along[i] >= 0) continue;
      for (int k = 0; k < 3; ++k) {
        if (far[i][k] < 0 || (used >> k & 1) || !faces_alike(piece.edge[i], whole.edge[k])) continue;
        if (bi < 0 || far[i][k] * norm[bk] < far[bi][bk] * norm[k]) {
          bi = i;
          bk = k;
        }
      }
    }
    if (bi < 0) break;
    along[bi] = bk;
    used |= 1 << bk;
  }
  return used;
}

// whole: the triangle's polygon and box in samples; grow: samples a pixel; width, height: samples.
void clip_to_triangle(const View& view, const ScreenTriangle& part, const ConvexPoly& whole, int grow,
                      int width, int height, ConvexPoly* poly) {
  // A piece edge runs along triangle edge k when both its ends lie near the edge's line:
  // |E_k| <= tol (|a| + |b|), a distance of at most tol sqrt(2) subpixels (|a| + |b| is at most
  // sqrt(2) times the normal's length). Each |E_k| at each corner of the part, and each |a| + |b|, once.
  int64_t off[3][3], norm[3];
  ML_HOST_UNROLL for (int k = 0; k < 3; ++k) {
    const EdgeFunction& e = whole.edge[k];
    norm[k] = abs64(e.a) + abs64(e.b);
    ML_HOST_UNROLL for (int i = 0; i < 3; ++i) off[k][i] = abs64(e.at(part.v[i].x, part.v[i].y));
  }
  int64_t far[3][3];  // piece edge i, triangle edge k: its farther end's |E_k|, or -1 beyond tol
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    const int i1 = i == 2 ? 0 : i + 1;
    const int64_t tol = split_tolerance(view, part.v[i], part.v[i1]);
    ML_HOST_UNROLL for (int k = 0; k < 3; ++k) {
      const int64_t end = max_of(off[k][i], off[k][i1]);
      far[i][k] = end <= tol * norm[k] ? end : -1;
    }
  }
  // Usually each piece edge runs along one triangle edge at most, and no two along the same one.
  int along[3] = {-1, -1, -1};
  int used = 0;  // bit k: some piece edge runs along triangle edge k
  bool ambiguous = false;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    ML_HOST_UNROLL for (int k = 0; k < 3; ++k) {
      if (far[i][k] < 0) continue;
      ambiguous |= along[i] >= 0 || (used >> k & 1);
      along[i] = k;
      used |= 1 << k;
    }
  }
  // (A piece edge facing away from the one triangle edge it runs along puts the piece's inside beyond
  // that edge: the piece's other edges run along it too, and the pairing below sorts them out.)
  if (ambiguous) used = pair_nearest_first(far, norm, *poly, whole, along);
  // Nothing on the boundary: the piece as it is. All three edges: the piece is the whole triangle but
  // for a sliver beside it, and takes the triangle's edges, so that it meets the neighbours' exactly
  // (its own, through quantized split points, may leave a sample on the boundary to neither).
  if (used == 0) return;
  // In place: the piece edges kept move down (to a slot no later than their own), the triangle's follow.
  int n = 0;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i)
    if (along[i] < 0) poly->edge[n++] = poly->edge[i];
  ML_HOST_UNROLL for (int k = 0; k < 3; ++k) poly->edge[n++] = whole.edge[k];
  poly->n = n;
  poly->min_x = max_of(poly->min_x - grow, max_of(whole.min_x, 0));
  poly->min_y = max_of(poly->min_y - grow, max_of(whole.min_y, 0));
  poly->max_x = min_of(poly->max_x + grow, min_of(whole.max_x, width - 1));
  poly->max_y = min_of(poly->max_y + grow, min_of(whole.max_y, height - 1));
}

// Subtree culling (Greene's hierarchical visibility applied to the BSP itself): a subtree of at
// least kCullMinPieces pieces whose world box projects to a screen rectangle without an uncovered
// sample is skipped whole. Smaller subtrees are cheaper to walk than to test. The test's four 64-bit
// divisions are single instructions on a 64-bit host and library calls on the boards, where testing
// pays only on larger subtrees (measured, 16-row bands with the plan: 2CylinderEngine on the host
// 166.3 M at 4, 165.9 M at 8, 168.5 M at 16, 185.6 M at 64; the bundled scene on the Cortex-M3
// 11.28 M at 8, 11.10 M at 16, 10.96 M at 64; without the plan, one band: 2CylinderEngine 137.0 M at
// 4, 136.6 M at 8, 138.6 M at 16). The host projects the box's corners instead (corner_rect, 16
// divisions): 8 still pays best (one band, 320x240: 62.72 M at 4, 62.47 M at 6, 62.45 M at 8,
// 62.70 M at 12).
constexpr bool kDivideIsCheap = sizeof(void*) >= 8;
constexpr uint32_t kCullMinPieces = kDivideIsCheap ? 8 : 16;
constexpr uint32_t kCullMinPiecesPlanned = kDivideIsCheap ? 8 : 64;

// A node's box seen from the eye: the view-space bounds of its eight corners, each transformed exactly
// (row · (corner − eye) in units of 2^-26 view unit, before the renderer's rounding), rounded down to
// view units and widened by one view unit for that rounding (floor - 1 .. floor + 2 covers every
// rounding of a point near an exact value). Every point of the box, as the renderer transforms it,
// lies inside: the bounds of a linear function over a box are taken at its corners.
struct ViewBox {
  int64_t lo[3], hi[3];  // x, y, z, view units
};

// From the box's centre and extent: a row's smallest corner value picks, per axis, the lower bound
// where the row's component is positive and the upper one elsewhere, so it is
// (row · (min + max − 2 eye) − |row| · (max − min)) / 2, exactly (the numerator is even), and the
// largest likewise: 18 multiplications for the 24 coordinates of the corners. False when the box
// reaches the near plane (then nothing is known and the caller assumes visible).
bool view_box(const View& view, const BspNode& node, ViewBox* out) {
  constexpr int shift = kUnitBits - kViewFractionBits + 1;  // and the halving
  const Vec3i* rows[3] = {&view.right, &view.down, &view.forward};
  const int64_t eye[3] = {view.eye.x, view.eye.y, view.eye.z};
  int64_t mid2[3], ext[3];  // |values| < 2^26: corners and eye below 2^24
  ML_HOST_UNROLL for (int a = 0; a < 3; ++a) {
    mid2[a] = int64_t(node.bounds_min[a]) + node.bounds_max[a] - 2 * eye[a];
    ext[a] = int64_t(node.bounds_max[a]) - node.bounds_min[a];
  }
  ML_HOST_UNROLL for (int r = 0; r < 3; ++r) {
    const int64_t m[3] = {rows[r]->x, rows[r]->y, rows[r]->z};  // Q1.30: products below 2^56, sums 2^58
    const int64_t mid = m[0] * mid2[0] + m[1] * mid2[1] + m[2] * mid2[2];
    const int64_t half = abs64(m[0]) * ext[0] + abs64(m[1]) * ext[1] + abs64(m[2]) * ext[2];
    out->lo[r] = ((mid - half) >> shift) - 1;
    out->hi[r] = ((mid + half) >> shift) + 2;
  }
  return out->lo[2] > view.near;
}

// Projected offsets from the screen centre (subpixels) of the widened box: x/z over it takes its
// extremes at its corners; for a coordinate >= 0 the smallest depth gives the largest value. The
// projection of a convex set in front of the eye lies inside the hull of its corners' projections.
int64_t offset_low(int64_t focal, int64_t lo, int64_t z_lo, int64_t z_hi) {
  return div_floor(focal * lo, lo >= 0 ? z_hi : z_lo);
}
int64_t offset_high(int64_t focal, int64_t hi, int64_t z_lo, int64_t z_hi) {
  return div_floor(focal * hi, hi >= 0 ? z_lo : z_hi) + 1;
}

// A sample row (pixel) centre py * 256 + 128 inside [s0, s1] (subpixels from the screen top) has
// floor(s0 / 256) <= py <= floor(s1 / 256); the rectangle grows by two samples more: one for the
// rounding of projection and sample centres, one for the pixel a split piece's box may grow by.
constexpr int kBoxMarginSamples = 2;

// Whether every sample any piece inside the box can write lies in rows above `top` or at and below
// `bottom` (exclusive end): the row bounds of box_screen_rect, compared by multiplication (no
// division): floor(f y / z) + 1 < K - ... rewritten as f y < (K - 1) z for z > 0 (|f y| < 2^59,
// |K z| < 2^55).
bool box_outside_rows(const View& view, const ViewBox& box, int32_t top, int32_t bottom) {
  const int64_t f = view.focal_q8;
  // Above: offset_high of the box < (top - margin) * 256 - center_y.
  const int64_t above = (int64_t(top) - kBoxMarginSamples) * kSubpixelOne - view.center_y - 1;
  // Below: offset_low of the box >= (bottom + margin) * 256 - center_y.
  const int64_t below = (int64_t(bottom) + kBoxMarginSamples) * kSubpixelOne - view.center_y;
  const int64_t y_lo = box.lo[1], y_hi = box.hi[1], z_lo = box.lo[2], z_hi = box.hi[2];
  return f * y_hi < above * (y_hi >= 0 ? z_lo : z_hi) || f * y_lo >= below * (y_lo >= 0 ? z_hi : z_lo);
}

// The sample rectangle (inclusive, unclipped) that every sample any piece inside the box can write
// lies in. Conservative by construction (see ViewBox, offset_low, kBoxMarginSamples); four divisions.
void box_screen_rect(const View& view, const ViewBox& box, int32_t* x0, int32_t* y0, int32_t* x1,
                     int32_t* y1) {
  const int64_t f = view.focal_q8, z_lo = box.lo[2], z_hi = box.hi[2];
  // Clamped far outside the screen so the int32 results stay meaningful.
  const int64_t lim = int64_t(kMaxScreenDim) * 4;
  auto sample = [&](int64_t center, int64_t s, int64_t margin) {
    return int32_t(clamp_to<int64_t>(floor_shift(center + s, kSubpixelBits) + margin, -lim, lim));
  };
  *x0 = sample(view.center_x, offset_low(f, box.lo[0], z_lo, z_hi), -kBoxMarginSamples);
  *x1 = sample(view.center_x, offset_high(f, box.hi[0], z_lo, z_hi), kBoxMarginSamples);
  *y0 = sample(view.center_y, offset_low(f, box.lo[1], z_lo, z_hi), -kBoxMarginSamples);
  *y1 = sample(view.center_y, offset_high(f, box.hi[1], z_lo, z_hi), kBoxMarginSamples);
}

// box_screen_rect's rectangle, tighter, on a 64-bit host (kDivideIsCheap; 16 divisions): the box's
// eight corners projected one by one, where the view-space box pairs each coordinate's extreme with
// either depth extreme, and a margin of one pixel instead of two (2CylinderEngine at 320x240, one
// band: 78.9 M -> 62.5 M a frame with the witness and LastCornerRect). Conservative:
// - the box is widened by kCornerMarginWorld world units. The renderer's view coordinates of a point
//   p of the box (each rounded to nearest) are the exact ones of a point within 0.06 world unit of p.
//   The corners' view coordinates here are rounded down, the lowest corner's and the steps along the
//   axes apart (within 4 view units a coordinate: 0.44 world unit), and the hull of points so moved
//   holds every point 0.44 world unit inside the widened box: every point the renderer makes of the
//   box, and of its pieces' edges (or within a view unit of them, where clipping rounds), lies inside.
// - x / z over a convex set in front of the eye takes its extremes at its corners; the truncated
//   quotients here are within a subpixel of the corners' exact ones, and the renderer rounds its own
//   to the nearest subpixel: its vertices lie within the subpixel bounds, one wider than the quotients.
// - a pixel whose centre (or, jittered, any of whose samples) lies within subpixels [s0, s1] is between
//   floor(s0 / 256) and floor(s1 / 256); a split piece's box may grow by one pixel (clip_to_triangle):
//   kCornerMarginPixels.
// False when the box reaches the near plane (nothing known).
constexpr int32_t kCornerMarginWorld = 1;
constexpr int kCornerMarginPixels = 1;
bool corner_rect(const View& view, const BspNode& node, int32_t* x0, int32_t* y0, int32_t* x1, int32_t* y1) {
  constexpr int shift = kUnitBits - kViewFractionBits;
  const int64_t eye[3] = {view.eye.x, view.eye.y, view.eye.z};
  int64_t low[3], ext[3];  // |values| < 2^26: corners and eye below 2^24
  ML_HOST_UNROLL for (int a = 0; a < 3; ++a) {
    low[a] = int64_t(node.bounds_min[a]) - kCornerMarginWorld - eye[a];
    ext[a] = int64_t(node.bounds_max[a]) - node.bounds_min[a] + 2 * kCornerMarginWorld;
  }
  // View coordinates (view units, below 2^31): the lowest corner's and the steps along the world axes.
  struct Point {
    int64_t x, y, z;
    Point operator+(const Point& o) const { return Point{x + o.x, y + o.y, z + o.z}; }
  };
  auto row = [&](const Vec3i& m) { return (m.x * low[0] + m.y * low[1] + m.z * low[2]) >> shift; };
  const Point c0{row(view.right), row(view.down), row(view.forward)};
  const Point sx{(view.right.x * ext[0]) >> shift, (view.down.x * ext[0]) >> shift, (view.forward.x * ext[0]) >> shift};
  const Point sy{(view.right.y * ext[1]) >> shift, (view.down.y * ext[1]) >> shift, (view.forward.y * ext[1]) >> shift};
  const Point sz{(view.right.z * ext[2]) >> shift, (view.down.z * ext[2]) >> shift, (view.forward.z * ext[2]) >> shift};
  if (c0.z + min_of<int64_t>(sx.z, 0) + min_of<int64_t>(sy.z, 0) + min_of<int64_t>(sz.z, 0) <= view.near) return false;
  const int64_t f = view.focal_q8;  // f x < 2^57
  int64_t lx = INT64_MAX, hx = INT64_MIN, ly = INT64_MAX, hy = INT64_MIN;
  // One corner at a time, written out: a loop over an array of corners costs 2CylinderEngine 0.4 M.
  auto project = [&](const Point& c) {
    const int64_t qx = f * c.x / c.z, qy = f * c.y / c.z;  // truncated: within a subpixel
    lx = min_of(lx, qx);
    hx = max_of(hx, qx);
    ly = min_of(ly, qy);
    hy = max_of(hy, qy);
  };
  const Point c1 = c0 + sx, c2 = c0 + sy, c3 = c1 + sy;
  project(c0);
  project(c1);
  project(c2);
  project(c3);
  project(c0 + sz);
  project(c1 + sz);
  project(c2 + sz);
  project(c3 + sz);
  // Clamped far outside the screen so the int32 results stay meaningful.
  const int64_t lim = int64_t(kMaxScreenDim) * 4;
  auto pixel = [&](int64_t center, int64_t s, int64_t margin) {
    return int32_t(clamp_to<int64_t>(floor_shift(center + s, kSubpixelBits) + margin, -lim, lim));
  };
  *x0 = pixel(view.center_x, lx - 1, -kCornerMarginPixels);
  *x1 = pixel(view.center_x, hx + 1, kCornerMarginPixels);
  *y0 = pixel(view.center_y, ly - 1, -kCornerMarginPixels);
  *y1 = pixel(view.center_y, hy + 1, kCornerMarginPixels);
  return true;
}

// corner_rect of the last box asked for, kept for the next: a BSP node's near child often has its
// parent's box (2CylinderEngine, one band: 320x240 63.34 M -> 62.45 M a frame, 1024x768 89.19 M ->
// 88.41 M). A 64-bit host's, as corner_rect; on the boards an empty stand-in.
template <bool kKept>
class LastCornerRectIf {
 public:
  bool get(const View&, const BspNode&, int32_t*, int32_t*, int32_t*, int32_t*) { return false; }
};
template <>
class LastCornerRectIf<true> {
 public:
  bool get(const View& view, const BspNode& node, int32_t* x0, int32_t* y0, int32_t* x1, int32_t* y1) {
    if (memcmp(node.bounds_min, bounds_, 12) != 0 || memcmp(node.bounds_max, bounds_ + 3, 12) != 0) {
      memcpy(bounds_, node.bounds_min, 12);
      memcpy(bounds_ + 3, node.bounds_max, 12);
      known_ = corner_rect(view, node, &rect_[0], &rect_[1], &rect_[2], &rect_[3]);
    }
    *x0 = rect_[0], *y0 = rect_[1], *x1 = rect_[2], *y1 = rect_[3];
    return known_;
  }

 private:
  int32_t bounds_[6] = {0, 0, 0, -1, -1, -1};  // min, max: no box yet
  int32_t rect_[4] = {};
  bool known_ = false;
};
using LastCornerRect = LastCornerRectIf<kDivideIsCheap>;

// The rows of the screen one band covers: the pyramid holds only these, and polygons are moved into
// band-local rows (E(x, y + top) folds top into c, so coverage is the screen's exactly).
struct BandRows {
  int top = 0, rows = 0;  // pixels: the band's own rows, and a partial row below for the cosine filter
  int factor = 1;         // samples a pixel per axis
  int samples = 0;        // sample rows tiled: rows * factor, or the band's own and a halo (tiled_samples)

  // The band's part of a screen-space polygon's box (samples) in band rows, in box's box (its edges
  // untouched); false when the polygon has no sample there.
  bool clip_box(const ConvexPoly& poly, ConvexPoly* box) const {
    const int first = top * factor, count = samples;
    if (poly.max_y < first || poly.min_y >= first + count || poly.min_x > poly.max_x || poly.min_y > poly.max_y)
      return false;
    box->min_x = poly.min_x;
    box->max_x = poly.max_x;
    box->min_y = max_of(poly.min_y - first, 0);
    box->max_y = min_of(poly.max_y - first, count - 1);
    return true;
  }
  // Moves a screen-space edge into the band's rows.
  void to_band(EdgeFunction* e) const { e->c += e->b * (int64_t(top) * kSubpixelOne); }
  // Moves a screen-space polygon (box in samples) into the band; false when it has no row there.
  bool clip(ConvexPoly* poly) const {
    ConvexPoly box;
    if (!clip_box(*poly, &box)) return false;
    for (int i = 0; i < poly->n; ++i) to_band(&poly->edge[i]);
    copy_box(box, poly);
    return true;
  }
};

// Samples a pixel per axis: options.aa, except for ids, which are point-sampled at pixel centres.
int sample_factor(const RenderOptions& options) {
  return options.shading == ShadingMode::Ids ? 1 : options.aa;
}

bool jittered(const RenderOptions& options) {
  return sample_factor(options) > 1 && options.samples == SamplePattern::Jittered;
}

bool uses_cosine(const RenderOptions& options) {
  return sample_factor(options) > 1 && options.filter == FilterKind::Cosine;
}

// Sample rows tiled below a band's own (the halo): a cosine-filtered pixel needs the samples of its
// neighbours within one pixel of its centre, so the band's last row needs the top half of the next
// band's first row; what the band's last row gives the next band's first is carried (filter.h).
int halo_samples(const RenderOptions& options) { return uses_cosine(options) ? sample_factor(options) / 2 : 0; }

// Sample rows of a band of `rows` own pixel rows from `top`: its own, and the halo inside the frame.
int tiled_samples(const RenderOptions& options, int top, int rows, int height) {
  const int f = sample_factor(options);
  return min_of(rows * f + halo_samples(options), (height - top) * f);
}

// Arena bytes of the antialiasing sums of one band.
size_t sums_arena_bytes(const RenderOptions& options, int width, int rows) {
  if (uses_cosine(options)) return arena_worst_case(sizeof(FilterSum) * CosineFilter::sums_count(width, rows), alignof(FilterSum));
  return sample_factor(options) > 1
             ? arena_worst_case(sizeof(PixelSum) * size_t(width) * size_t(rows), alignof(PixelSum))
             : 0;
}


// Pyramid layout of one band (the last band may be lower than the others): width pixels, sample rows.
bool band_layout(int width, int samples, int factor, PyramidLayout* out) {
  return make_pyramid_layout(clamp_to(width, 1, kMaxScreenDim) * factor, clamp_to(samples, 1, kMaxSampleDim), out);
}

// The arena bytes that depend on the rows rendered at once (render_rows_for; 0: one band): the band
// buffers, one band's pyramid and its antialiasing sums. 0 for a frame no pyramid can hold.
size_t band_bytes(int width, int height, const RenderOptions& options, int render_rows) {
  const int rows = kRenderBands ? render_rows_for(options.output, height, render_rows) : band_rows_for(options.output, height);
  const int factor = clamp_to(sample_factor(options), 1, kMaxTilerAa);
  PyramidLayout layout;
  if (!band_layout(width, tiled_samples(options, 0, rows, height), factor, &layout)) return 0;
  return Pyramid::arena_bytes(layout) + sums_arena_bytes(options, width, rows) +
         BandOutput::arena_bytes(options.output, width, height, rows);
}

Status check_options(const Camera& camera, const RenderOptions& options) {
  if (options.aa != 1 && options.aa != 2 && options.aa != 4 && options.aa != 8)
    return error(StatusCode::Unsupported, "the tiler takes 1, 2, 4 or 8 samples a pixel per axis (aa)");
  if (options.filter == FilterKind::Cosine && options.aa == 1 && options.shading != ShadingMode::Ids)
    return error(StatusCode::Unsupported, "the cosine filter needs samples: aa 2, 4 or 8");
  if (options.samples == SamplePattern::Jittered && options.aa == 1 && options.shading != ShadingMode::Ids)
    return error(StatusCode::Unsupported, "jittered samples need aa 2, 4 or 8");
  if (options.shading == ShadingMode::Lines)
    return error(StatusCode::Unsupported, "the tiler has no hidden-line mode (use the scanline renderer)");
  if (camera.width < 1 || camera.height < 1 || camera.width > kMaxScreenDim ||
      camera.height > kMaxScreenDim)
    return error(StatusCode::InvalidArgument, "screen size out of range");
  if (options.work && (!options.work->q16 || options.work->width != camera.width ||
                       options.work->height != camera.height))
    return error(StatusCode::InvalidArgument, "work image must match the screen size");
  return BandOutput::check(options.output);
}

// When each texture is needed next in the tiler's order of work: bands top to bottom, each walking
// the BSP front to back — the same walk in every band, so pieces are numbered once. Planned before
// drawing (the textured triangles' rows, one walk of the whole BSP for each texture's first and last
// piece), it lets the pager evict the texture needed last, as the scanline renderer's evictions
// follow its active triangles.
class TexturePlan : public TextureNextUse {
 public:
  static size_t arena_bytes(const Scene& scene) {
    return 4 * arena_worst_case(sizeof(uint32_t) * scene.texture_texels_count, 4);
  }
  bool allocate(const Scene& scene, Arena& arena) {
    count_ = scene.texture_texels_count;
    first_piece_ = arena.allocate_array<uint32_t>(count_);
    last_piece_ = arena.allocate_array<uint32_t>(count_);
    first_row_ = arena.allocate_array<uint32_t>(count_);
    last_row_ = arena.allocate_array<uint32_t>(count_);
    if (!first_piece_ || !last_piece_ || !first_row_ || !last_row_) return false;
    for (uint32_t t = 0; t < count_; ++t) {
      first_piece_[t] = first_row_[t] = kNone;
      last_piece_[t] = last_row_[t] = 0;
    }
    return true;
  }
  void rows(uint32_t t, uint32_t first, uint32_t last) {
    first_row_[t] = min_of(first_row_[t], first);
    last_row_[t] = max_of(last_row_[t], last);
  }
  // Piece k of the walk is texture t's: true when it is the first one t was given.
  bool piece(uint32_t t, uint32_t k) {
    const bool first = first_piece_[t] == kNone;
    first_piece_[t] = min_of(first_piece_[t], k);
    last_piece_[t] = max_of(last_piece_[t], k);
    return first;
  }
  // For a walk from the back once every texture has a piece: the last pieces forgotten, then piece k
  // of that walk is texture t's, true when it is t's last (the first so given).
  void forget_last_pieces() {
    for (uint32_t t = 0; t < count_; ++t) last_piece_[t] = kNone;
  }
  bool last_piece(uint32_t t, uint32_t k) {
    if (last_piece_[t] != kNone) return false;
    last_piece_[t] = k;
    return true;
  }
  // Where the work is: band `band` of `band_rows` rows (pixels [top, top + rows)), piece k of the walk.
  void at_band(int band, int band_rows, int top, int rows) {
    band_ = uint32_t(band);
    band_rows_ = uint32_t(band_rows);
    top_ = uint32_t(top);
    end_ = uint32_t(top + rows);
    k_ = 0;
  }
  void at_piece(uint32_t k) { k_ = k; }
  // The most pool bytes of the textures whose planned rows meet one band of `rows` rows (bands from
  // row 0 to `height`): what the pager holds at most when each texture is read in the first band that
  // shows it and freed after the last band that uses it.
  uint64_t band_peak(const Scene& scene, int rows, int height) const {
    uint64_t peak = 0;
    for (uint32_t top = 0; top < uint32_t(height); top += uint32_t(rows)) {
      uint64_t bytes = 0;
      for (uint32_t t = 0; t < count_; ++t)
        if (first_row_[t] < top + uint32_t(rows) && last_row_[t] >= top) bytes += texture_pool_size(scene, t);
      peak = max_of(peak, bytes);
    }
    return peak;
  }

  uint64_t next_use(uint32_t t) const override {
    if (t >= count_ || first_piece_[t] == kNone || first_row_[t] == kNone || last_row_[t] < top_) return kNever;
    if (first_row_[t] >= end_) return when(first_row_[t] / band_rows_, first_piece_[t]);  // a later band
    if (k_ <= last_piece_[t]) return when(band_, max_of(k_, first_piece_[t]));            // later in this band
    return last_row_[t] >= end_ ? when(band_ + 1, first_piece_[t]) : kNever;             // the next band
  }

 private:
  static uint64_t when(uint32_t band, uint32_t k) { return (uint64_t(band) << 32) | k; }
  uint32_t count_ = 0;
  uint32_t* first_piece_ = nullptr;
  uint32_t* last_piece_ = nullptr;
  uint32_t* first_row_ = nullptr;
  uint32_t* last_row_ = nullptr;
  uint32_t band_ = 0, band_rows_ = 1, top_ = 0, end_ = 0, k_ = 0;
};

// The band plan, made when the arena has room for one entry a BSP piece and two bits a triangle
// (tiler_plan_bytes): the bands each piece can reach, worked out on its first visit in any band
// together with its facing (its sample box when projection does not clip it, else triangle_row_span,
// exactly the per-band row test). Later bands then skip the
// piece from its entry, without reading its vertices, and never repeat its facing test; pieces the walk
// never reaches cost nothing. An entry holds the first and last band group: a byte of two 4-bit groups
// for at most 16 bands, else two bytes of 8-bit groups (bytes grouping 1024x768's 48 bands by three left
// 6.5 M of 2CylinderEngine's 218 M frame in the per-band row test of grouped bands). A group is one
// band up to 256 bands, else ceil(bands / 256) bands, and the per-band test still runs; first > last:
// no band. A triangle's facing is kept too, from the first of its pieces the walk
// reaches: the other pieces of a triangle the BSP split take it from two bits, without the test or
// the triangle's vertices (2CylinderEngine at the bench camera: 74,352 of 128,119 first visits).
class BandPlan {
 public:
  static constexpr int kFacingUnknown = -2;  // facing(): no piece of the triangle tested yet
  // Two-byte entries and the facing bits are a 64-bit host's: on the boards they cost code (the
  // m0plus image would pass its 96 KB budget) and RAM that their frames (at most 16 bands, few split
  // triangles in scenes that fit their flash) do not repay: the bundled scene on the Cortex-M3 took
  // 10.96 M instructions without them, 11.12 M with them.
  static constexpr bool kExtras = sizeof(void*) >= 8;

  // Bytes of the entries (aligned for two-byte ones; none for a frame of one band) and of the facing bits.
  static size_t entry_bytes(uint32_t pieces, int bands) {
    return bands < 2 ? 0 : kExtras && bands > 16 ? 2 * size_t(pieces) + 1 : size_t(pieces);
  }
  static size_t facing_bytes(uint32_t triangles) { return kExtras ? (size_t(triangles) + 3) / 4 : 0; }
  // Entries from the arena, and two bits a triangle with keep_facing (else the facing is not kept).
  void init(Arena& arena, uint32_t pieces, bool keep_facing, uint32_t triangles, int bands) {
    bits_ = kExtras && bands > 16 ? 8 : 4;
    const uint32_t max = (1u << bits_) - 1;
    no_band_ = uint16_t(max << bits_);
    unknown_ = uint16_t(no_band_ | 1);
    every_band_ = uint16_t(max);
    group_ = (bands + int(max)) >> bits_;
    if (kExtras && bits_ == 8) {
      wide_ = arena.allocate_array<uint16_t>(pieces);
      // Set by doubling copies: a store at a time took 6 instructions a piece.
      if (wide_ && pieces > 0) {
        wide_[0] = unknown_;
        for (size_t done = 1; done < pieces; done *= 2)
          memcpy(wide_ + done, wide_, min_of(done, size_t(pieces) - done) * sizeof(uint16_t));
      }
    } else {
      narrow_ = arena.allocate_array<uint8_t>(pieces);
      if (narrow_) memset(narrow_, unknown(), pieces);  // a byte at a time took 5 instructions a piece
    }
    if (keep_facing) keep_facings(arena, triangles);
    active_ = narrow_ || wide_;
  }
  // The facing bits alone: a frame of one band visits each piece once, but the pieces of a split
  // triangle still share its facing test.
  void keep_facings(Arena& arena, uint32_t triangles) {
    facing_ = kExtras ? arena.allocate_array<uint8_t>(facing_bytes(triangles)) : nullptr;  // facing + 2, 0 = unknown
    if (facing_) memset(facing_, 0, facing_bytes(triangles));
  }
  bool active() const { return active_; }
  bool keeps_facing() const { return kExtras && facing_ != nullptr; }
  // Whether an entry's bands are exactly the per-band test's (no test needed after it).
  bool exact() const { return group_ == 1; }
  // Constants on the boards (one-byte entries only).
  int bits() const { return kExtras ? bits_ : 4; }
  uint16_t unknown() const { return kExtras ? unknown_ : 0xF1; }
  uint16_t no_band() const { return kExtras ? no_band_ : 0xF0; }
  uint16_t every_band() const { return kExtras ? every_band_ : 0x0F; }
  uint16_t get(uint32_t piece) const { return kExtras && wide_ ? wide_[piece] : narrow_[piece]; }
  void set(uint32_t piece, uint16_t entry) {
    if (kExtras && wide_) wide_[piece] = entry; else narrow_[piece] = uint8_t(entry);
  }
  uint16_t make(int first_band, int last_band) const {
    return uint16_t((first_band / group_) << bits() | (last_band / group_));
  }
  // The band the walk is in (its group, computed once a band rather than once a piece).
  void at_band(int band) { band_group_ = band / group_; }
  // Whether the entry's bands hold the current band.
  bool has(uint16_t entry) const {
    return (entry >> bits()) <= band_group_ && band_group_ <= (entry & every_band());
  }
  // triangle_facing of triangle t (-1, 0 or 1), or kFacingUnknown.
  int facing(uint32_t t) const { return int((facing_[t >> 2] >> ((t & 3) * 2)) & 3) - 2; }
  void set_facing(uint32_t t, int facing) { facing_[t >> 2] = uint8_t(facing_[t >> 2] | (facing + 2) << ((t & 3) * 2)); }

 private:
  uint8_t* narrow_ = nullptr;
  uint16_t* wide_ = nullptr;
  uint8_t* facing_ = nullptr;
  bool active_ = false;
  int bits_ = 4, group_ = 1, band_group_ = 0;
  uint16_t no_band_ = 0, unknown_ = 0, every_band_ = 0;
};

// Screen rectangles of BSP subtree boxes, kept from a node's first subtree test in any band for the
// later bands when the arena has room (tiler_plan_bytes; frames of several bands): a box projects to
// the same rectangle in every band, and working it out (view_box, four divisions) took most of the
// per-band cost of small scenes' walks (the duck at 320x240 in 16-row bands: 28.6 M -> 25.5 M).
class NodeRects {
 public:
  // A 64-bit host's, as the plan's extras: on the boards their bytes would pass the RAM budgets
  // docs/firmware.md states (the Cortex-M3 tiler frames gained 2.4 % with them).
  static size_t bytes(uint32_t nodes, int bands) {
    return !BandPlan::kExtras || bands < 2 ? 0 : arena_worst_case(sizeof(Rect) * nodes, 4);
  }
  void init(Arena& arena, uint32_t nodes) {
    rects_ = arena.allocate_array<Rect>(nodes);
    for (uint32_t i = 0; rects_ && i < nodes; ++i) rects_[i] = Rect{kUnknown, 0, 0, 0};
  }
  bool active() const { return BandPlan::kExtras && rects_ != nullptr; }
  // Whether node i's subtree faces away from the eye (`test`, the normal cone's answer, made on the
  // first call: it holds for every band).
  template <typename Test>
  bool faces_away(uint32_t i, Test test) {
    Rect& r = rects_[i];
    if (r.x0 == kBack) return true;
    if (r.x0 != kUnknown || r.y0 == kFacing) return false;  // a rectangle is made only for a node facing
    const bool back = test();
    if (back) r.x0 = kBack;
    else r.y0 = kFacing;
    return back;
  }
  // Node i's rectangle (pixels, inclusive, unclipped: box_screen_rect's), or false when its box
  // reaches the near plane (nothing known); made by `make` on the first call.
  template <typename Make>
  bool get(uint32_t i, int32_t* x0, int32_t* y0, int32_t* x1, int32_t* y1, Make make) {
    Rect& r = rects_[i];
    if (r.x0 == kUnknown) {
      if (!make(x0, y0, x1, y1)) {
        r.x0 = kNear;
        return false;
      }
      r = Rect{int16_t(*x0), int16_t(*y0), int16_t(*x1), int16_t(*y1)};
      return true;
    }
    if (r.x0 == kNear) return false;
    *x0 = r.x0, *y0 = r.y0, *x1 = r.x1, *y1 = r.y1;
    return true;
  }

 private:
  // box_screen_rect clamps to +-4 kMaxScreenDim: int16 holds every rectangle and three markers in x0
  // (no rectangle yet; the box reaches the near plane; the subtree faces away), and with kUnknown, y0
  // says whether the subtree was found facing the eye.
  static_assert(4 * kMaxScreenDim < INT16_MAX - 1, "a box's rectangle fits int16");
  static constexpr int16_t kUnknown = INT16_MAX, kNear = INT16_MIN, kBack = INT16_MAX - 1, kFacing = 1;
  struct Rect {
    int16_t x0, y0, x1, y1;
  };
  Rect* rects_ = nullptr;
};

// The vertex cache (view/vertex_cache.h), where the build has it (not the Cortex-M0+ image's).
constexpr bool kVertexCache = kVertexCacheBuilt;

uint32_t vertex_cache_entries(const Scene& scene) {
  return kVertexCache ? VertexCache::entries_for(scene.vertex_count) : 0;
}

// One frame: the BSP walked front to back once per band, each band's pyramid rebuilt in the same
// arena space.
class TilerFrame {
 public:
  TilerFrame(const Scene& scene, const Camera& camera, const RenderOptions& options, const View& view,
             Stats* st, SampleFilter* cosine)
      : scene_(scene), camera_(camera), options_(options), view_(view), st_(st), cosine_(cosine),
        hides_(has_hidden_material(scene)) {}

  Status run(Arena& arena, Sink& sink);

 private:
  Status render_band(int band, Arena& arena);
  // The BSP front to back into the band's pyramid, until the band is covered. Inline on 64-bit hosts:
  // GCC's own choice turns with small changes to draw_piece (out of line, 2CylinderEngine at 320x240
  // took 53.04 M instead of 52.33 M).
  ML_HOST_INLINE Status walk_bsp();
  // bsp_subtree_faces_away for node `index`, its answer kept with the plan's rectangles (tested once a
  // frame, not once a band). Out of line on 64-bit hosts: the walk's loop keeps its registers (inline,
  // 2CylinderEngine's one-band frame took 0.8 M more).
  ML_HOST_NOINLINE bool subtree_faces_away(uint32_t index);
  // True when no sample of the band that a piece of the node's subtree could write is still
  // uncovered (or the subtree has no pieces).
  bool subtree_hidden(uint32_t index, uint32_t subtree_pieces);
  // Projects, culls and tiles one piece into the band's pyramid; false when the sink refused a write.
  // entry: the piece's plan entry (unknown without the plan), in this band or unknown.
  // Inline in the walk, its one caller, on 64-bit hosts (out of line, its calls cost 2.8 M of
  // 2CylinderEngine's 102 M at 320x240); on the boards the compiler's own choice is smaller and faster
  // (forced inline: m0plus 19.69 M -> 19.78 M a frame, 124 bytes more code).
  ML_HOST_INLINE bool draw_piece(uint32_t index, uint16_t entry);
  // A split piece's whole triangle, transformed and projected (its view is the one the piece's texture
  // planes take), kept for the next piece: the BSP walk often reaches pieces of one triangle one after
  // the other (2CylinderEngine at 320x240: 1,952 of 4,539 projections; the duck: 491 of 1,380).
  struct WholeTriangle {
    uint32_t triangle = kNone;  // the scene's triangle index (none yet)
    int facing = 0;
    ViewTriangle view;
    ScreenTriangle parts[kMaxClipTriangles];
    int n = 0;        // parts
    ConvexPoly poly;  // parts[0]'s sample box and edges, when n == 1
  };
  // Makes whole_ the whole triangle of a split piece of triangle `id` (kept when it is already): its
  // vertices from the vertex cache, or whole_world() without one.
  template <class WholeWorld>
  void project_whole(const Triangle& tri, uint32_t id, int facing, WholeWorld whole_world);
  // A split piece's part (of n) clipped to its whole triangle; the triangle its colour planes take, or
  // null when it is to be tiled in the whole triangle's parts (tile_in_whole_parts). Out of line on
  // 64-bit hosts: the walk's loop keeps its registers (2CylinderEngine 320x240 flat 91.65 M inline,
  // 91.35 M so); the boards' compiler chooses.
  ML_HOST_NOINLINE const ScreenTriangle* clip_to_whole(int n, const ScreenTriangle& part, ConvexPoly* poly);
  // A split piece's part whose whole triangle projects in several parts, tiled in each with its colour
  // planes; false when the sink refused a write.
  // Out of line and optimized for size: rare (triangles the near plane or the guard band cuts), off
  // the walk's loop (m0plus: 278 bytes, 312 at -O2).
  [[gnu::noinline]] ML_OPTIMIZE_SIZE bool tile_in_whole_parts(ConvexPoly* poly, const ScreenTriangle* whole_parts, int count,
                                             const Vec3i* world);
  // The rows rendered at once: the most whole bands whose extra arena bytes (tiler_render_rows_bytes)
  // `spare` holds and, with paged textures, whose planned texture residency (TexturePlan::band_peak)
  // is no more than a band at a time's; the pieces' per-band work (the walk, subtree tests, plan
  // entries) is then done once for them all (the duck at 320x240: 16-row bands 23.9 M, one 240-row
  // band 15.1 M). Before the plan and caches, which a frame of fewer bands needs less.
  int rows_at_once(size_t spare) const;
  // The plan entry of a piece facing the eye, from its view-space vertices.
  uint16_t plan_bands(const ViewTriangle& view) const;
  // The sample box (part_box's) of a piece that projects unclipped, from its view-space vertices; false
  // when it holds no sample of the screen, so that the piece can be dropped before it is projected.
  bool unclipped_sample_box(const ViewTriangle& view, ConvexPoly* box) const;
  // The box of the samples a projected part can cover (no edges yet).
  void part_box(const ScreenTriangle& part, ConvexPoly* poly) const;
  // Plans each texture's rows from the textured triangles' projected extent, and its first and last
  // piece in the BSP walk (TexturePlan).
  ML_HOST_NOINLINE void plan_textures();
  // An invisible material's piece left out: with the plan, in every band (returns true, as draw_piece).
  // Cold and out of line: inline, draw_piece's code grows and GCC lays the walk out worse (2CylinderEngine
  // at 320x240: 52.33 M -> 52.95 M).
  [[gnu::cold, gnu::noinline]] bool leave_out(uint32_t index) {
    if (plan_.active()) plan_.set(index, plan_.no_band());
    return true;
  }
  // The texture a triangle is drawn with: kNone for an invisible material's (never drawn).
  uint32_t drawn_texture(BatchTextures& textures, uint32_t triangle) const {
    if (hides_ && material_hidden(triangle_material(scene_, triangle))) return kNone;
    return textures.of_triangle(scene_, triangle);
  }
  bool projected_rows(const Vec3i world[3], int facing, int32_t* first, int32_t* last) const;
  // visit(piece, k) for the pieces in the drawing walk's order (k: 0, 1, ...), or backwards (k from the
  // last down), until it returns false.
  template <bool kBackwards, typename Visit>
  void walk_pieces(Visit visit);
  // The node's children ordered for a front-to-back walk: the one on the eye's side of its plane
  // first (kNone where there is none). One side test a visit, shared by the drawing walk and the plan's.
  void children(const BspNode& node, uint32_t* near, uint32_t* far) const;
  // BSP node `index` without its box: the decoder inline on 64-bit hosts (where the walk decodes each
  // node twice a band, and inline it reads only the fields used), out of line on the boards (flash).
  BspNode node_at(uint32_t index) const {
    if (!BandPlan::kExtras) return bsp_node_unboxed(scene_, index);
    return scene_.wide ? scene_detail::node<uint32_t>(scene_, index) : scene_detail::node<uint16_t>(scene_, index);
  }
  // Its box: the decoder inline on 64-bit hosts, as node_at.
  void node_box(uint32_t index, BspNode* node) const {
    if (!BandPlan::kExtras) return bsp_node_box(scene_, index, node);
    if (scene_.wide) scene_detail::node_box<uint32_t>(scene_, index, node);
    else scene_detail::node_box<uint16_t>(scene_, index, node);
  }
  Status finish(Status s, const Arena& arena) {
    st_->peak_arena_bytes = uint32_t(arena.peak());
    return s;
  }

  const Scene& scene_;
  const Camera& camera_;
  const RenderOptions& options_;
  const View& view_;
  Stats* st_;
  Light light_{};
  BandOutput out_;
  Pyramid pyramid_;
  HierTiler tiler_;
  BandRows band_;
  SampleGrid grid_;  // the pieces' sample boxes' lattice (part_box, unclipped_sample_box)
  BandPlan plan_;
  NodeRects node_rects_;
  LastCornerRect last_rect_;
  PlaneCache plane_cache_;
  VertexCache vertices_;
  bool cached_ = false;  // vertices_ holds entries
  WholeTriangle whole_;   // the last split piece's whole triangle
  BandWriter* writer_ = nullptr;
  SampleFilter* cosine_;
  const bool hides_;  // some material is invisible (material_hidden)
  uint8_t* jitter_table_ = nullptr;  // every pattern's offsets (core/jitter.h), when jittered
  BspFrame* stack_ = nullptr;
  size_t stack_cap_ = 0;
  TexturePager pager_;
  TexturePlan texture_plan_;
};

Status TilerFrame::run(Arena& arena, Sink& sink) {
  const size_t need = tiler_arena_bytes(scene_, camera_, options_);
  const size_t spare = arena.size() - arena.used() - need;
  stack_cap_ = bsp_stack_entries(scene_);
  stack_ = arena.allocate_array<BspFrame>(stack_cap_);
  Pixel* row = arena.allocate_array<Pixel>(kRowPixels);
  if (!stack_ || !row) return error(StatusCode::ArenaTooSmall, "arena too small", need);
  if (options_.shading != ShadingMode::Ids) {
    const Status t = pager_.begin(scene_, options_.texture_source, options_.texture_pool_bytes, arena, st_);
    if (!t.ok()) return finish(error(t.code, t.message, need), arena);
    if (pager_.active() && !texture_plan_.allocate(scene_, arena))
      return finish(error(StatusCode::ArenaTooSmall, "arena too small", need), arena);
    plan_textures();
  }
  TextureSegment* segment_rows = nullptr;
  if (pager_.active()) {
    segment_rows = arena.allocate_array<TextureSegment>(size_t(1) << kSegmentRowBits);
    if (!segment_rows) return finish(error(StatusCode::ArenaTooSmall, "arena too small", need), arena);
  }
  Status s = out_.begin(options_.output, camera_.width, camera_.height, arena, sink, rows_at_once(spare));
  if (!s.ok()) return finish(s.code == StatusCode::ArenaTooSmall ? error(s.code, s.message, need) : s, arena);
  light_ = make_light(view_);
  BandWriter writer(out_, st_, row);
  writer.use_textures(&pager_, &view_, segment_rows, &plane_cache_);
  writer_ = &writer;
  band_.factor = sample_factor(options_);
  grid_ = sample_grid(band_.factor, camera_.width, camera_.height, jittered(options_));
  if (jittered(options_)) {
    jitter_table_ = arena.allocate_array<uint8_t>(jitter_table_bytes(band_.factor));
    if (!jitter_table_) return finish(error(StatusCode::ArenaTooSmall, "arena too small", need), arena);
    fill_jitter_table(band_.factor, jitter_table_);
  }
  if (uses_cosine(options_)) {
    FilterSum* sums = arena.allocate_array<FilterSum>(CosineFilter::sums_count(camera_.width, out_.band_rows()));
    if (!sums) return finish(error(StatusCode::ArenaTooSmall, "arena too small", need), arena);
    cosine_->init(sums, camera_.width, camera_.height, band_.factor, out_.band_rows(), &out_, st_);
    writer.oversample(band_.factor, nullptr, camera_.width);
    writer.use_filter(cosine_);
  } else if (band_.factor > 1) {
    PixelSum* sums = arena.allocate_array<PixelSum>(size_t(camera_.width) * size_t(out_.band_rows()));
    if (!sums) return finish(error(StatusCode::ArenaTooSmall, "arena too small", need), arena);
    writer.oversample(band_.factor, sums, camera_.width);
  }
  st_->bsp_nodes = scene_.bsp_node_count;
  st_->bsp_pieces = scene_.bsp_piece_count;
  {  // the plan, when the bands' pyramid still fits beside it
    PyramidLayout layout;
    band_layout(camera_.width, tiled_samples(options_, 0, out_.band_rows(), camera_.height), band_.factor, &layout);
    // The triangles' facing bits only when there is room for them as well (the microbit has room for
    // the pieces' entries alone); with one band, the facing bits alone.
    const size_t free = arena.size() - arena.used(), pyramid = Pyramid::arena_bytes(layout);
    const size_t entries = BandPlan::entry_bytes(scene_.bsp_piece_count, out_.band_count());
    const size_t facing = BandPlan::facing_bytes(scene_.triangle_count);
    if (out_.band_count() > 1 && free >= pyramid + entries)
      plan_.init(arena, scene_.bsp_piece_count, free >= pyramid + entries + facing, scene_.triangle_count,
                 out_.band_count());
    else if (out_.band_count() == 1 && facing > 0 && free >= pyramid + facing)
      plan_.keep_facings(arena, scene_.triangle_count);
    const size_t rects = NodeRects::bytes(scene_.bsp_node_count, out_.band_count());
    if (rects > 0 && arena.size() - arena.used() >= pyramid + rects) node_rects_.init(arena, scene_.bsp_node_count);
    const size_t planes = pager_.active() ? PlaneCache::bytes(scene_, out_.band_count()) : 0;
    if (planes > 0 && arena.size() - arena.used() >= pyramid + planes) plane_cache_.init(arena);
    // The vertex cache in what the bands' pyramid leaves beside the plan.
    if (kVertexCache) vertices_.init(arena, scene_, view_, vertex_cache_entries(scene_), pyramid);
    cached_ = kVertexCache && vertices_.entries() > 0;
  }
  for (int band = 0; band < out_.band_count(); ++band) {
    s = render_band(band, arena);
    if (!s.ok()) return finish(s, arena);
  }
  return finish(out_.end(), arena);
}

Status TilerFrame::render_band(int band, Arena& arena) {
  Status s = out_.start_band(band);
  if (!s.ok()) return s;
  if (plan_.active()) plan_.at_band(band);
  band_.top = out_.band_top(band);
  band_.samples = tiled_samples(options_, band_.top, out_.band_height(band), camera_.height);
  band_.rows = (band_.samples + band_.factor - 1) / band_.factor;  // with the halo's partial row
  PyramidLayout layout;
  band_layout(camera_.width, band_.samples, band_.factor, &layout);
  const size_t mark = arena.mark();
  if (!pyramid_.allocate(layout, arena)) return error(StatusCode::ArenaTooSmall, "arena too small");
  pyramid_.clear();
  st_->pyramid_bytes = max_of(st_->pyramid_bytes, layout.bytes());
  tiler_.init(&pyramid_, kSubpixelOne / band_.factor, options_.work, band_.top);
  tiler_.jitter(jitter_table_ ? band_.factor : 0, options_.seed, jitter_table_);
  writer_->begin_band(band_.top, band_.rows);
  if (uses_cosine(options_)) cosine_->begin_band(band_.top, out_.band_height(band));
  texture_plan_.at_band(band, out_.band_rows(), band_.top, band_.rows);
  s = walk_bsp();
  if (!s.ok()) return s;
  writer_->begin_background(options_.shading == ShadingMode::Ids ? 0 : options_.background);
  const uint64_t before = tiler_.cells_visited;
  if (!tiler_.background(*writer_)) return error(StatusCode::SinkFailed, "sink refused a write");
  writer_->finish_pixels();
  tiler_.cells_visited = before;
  st_->cells_visited = tiler_.cells_visited;
  arena.release_to(mark);
  ++st_->render_bands;
  st_->bands += uint32_t(out_.sink_bands_in(band));
  pager_.rows_done(uint32_t(band_.top + out_.band_height(band) - 1));  // frees textures no later band uses
  return out_.finish_band();
}

int TilerFrame::rows_at_once(size_t spare) const {
  const int rows = band_rows_for(options_.output, camera_.height);
  if (!kRenderBands) return rows;
  // With paged textures, no more rows at once than keep the planned residency of a band at a time.
  const uint64_t resident = pager_.active() ? texture_plan_.band_peak(scene_, rows, camera_.height) : 0;
  for (int bands = render_rows_allowed(options_.output, camera_.height) / rows; bands > 1; --bands)
    if (tiler_render_rows_bytes(camera_, options_, bands * rows) <= spare &&
        (!pager_.active() || texture_plan_.band_peak(scene_, bands * rows, camera_.height) <= resident))
      return bands * rows;
  return rows;
}

void TilerFrame::plan_textures() {
  // The plan picks when to free a texture and which to evict; a scene of one texture has neither
  // choice (it is read at its first use and kept, the same loads and peak), so it is not planned (the
  // duck at 320x240: 1.54 M of a 23.35 M frame, a band at a time).
  if (!pager_.active() || scene_.texture_texels_count < 2) return;
  BatchTextures textures;
  for (uint32_t id = 0; id < scene_.triangle_count; ++id) {
    const Triangle tri = triangle_at(scene_, id);
    const uint32_t texture = drawn_texture(textures, id);
    if (texture == kNone) continue;
    Vec3i world[3];
    vertices_world(scene_, tri.batch, tri.v, world);
    const int facing = triangle_facing(view_, world);
    if (facing == 0 || (facing < 0 && !batch_material(scene_, tri.batch).double_sided)) continue;
    int32_t first, last;
    if (!projected_rows(world, facing, &first, &last) || last < 0) continue;
    // BSP pieces are quantized split points of the triangle: a pixel of margin covers them.
    const uint32_t last_row = uint32_t(min_of(last / kSubpixelOne + 1, camera_.height - 1));
    pager_.plan(texture, last_row);
    texture_plan_.rows(texture, uint32_t(max_of(first / kSubpixelOne - 1, 0)), last_row);
  }
  pager_.finish_plan();
  // Each texture's first and last piece in the walk's order, once for the frame. On 64-bit hosts the
  // walk ends once every texture has a piece, and a walk from the back finds the last pieces (the
  // duck: one piece each way instead of its 8,544); the boards walk it all (flash).
  const uint32_t count = scene_.texture_texels_count;
  uint32_t found = 0;
  // (Captures named: with [&] the M0+ image's code is 4 bytes larger.)
  walk_pieces<false>([this, &textures, &found, count](uint32_t p, uint32_t k) {
    const uint32_t texture = drawn_texture(textures, bsp_piece(scene_, p).triangle);
    if (texture != kNone && texture_plan_.piece(texture, k)) ++found;
    return !kVertexCache || found < count;
  });
  if (kVertexCache && found == count) {
    found = 0;
    texture_plan_.forget_last_pieces();
    walk_pieces<true>([&](uint32_t p, uint32_t k) {
      const uint32_t texture = drawn_texture(textures, bsp_piece(scene_, p).triangle);
      if (texture != kNone && texture_plan_.last_piece(texture, k)) ++found;
      return found < count;
    });
  }
  pager_.use_next_use(&texture_plan_);
}

// The rows (subpixels) a facing triangle's projection spans; false when it projects to nothing. On
// 64-bit hosts an unclipped triangle's rows come from its vertices' view (project_triangle's, with
// its test of the snapped area) without building its screen triangle.
bool TilerFrame::projected_rows(const Vec3i world[3], int facing, int32_t* first, int32_t* last) const {
  ViewTriangle view;
  view_triangle(view_, world, &view);
  if (kVertexCache && view.unclipped) {
    const int64_t area2 = (view.ox[1] - view.ox[0]) * (view.oy[2] - view.oy[0]) -
                          (view.ox[2] - view.ox[0]) * (view.oy[1] - view.oy[0]);
    *first = int32_t(view_.center_y + min_of(view.oy[0], min_of(view.oy[1], view.oy[2])));
    *last = int32_t(view_.center_y + max_of(view.oy[0], max_of(view.oy[1], view.oy[2])));
    return area2 != 0;
  }
  ScreenTriangle parts[kMaxClipTriangles];
  const int n = project_triangle(view_, view, facing, parts, false);
  *first = INT32_MAX, *last = -1;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) {
      *first = min_of(*first, parts[i].v[j].y);
      *last = max_of(*last, parts[i].v[j].y);
    }
  return n > 0;
}

template <bool kBackwards, typename Visit>
void TilerFrame::walk_pieces(Visit visit) {
  const uint32_t total = kBackwards && scene_.bsp_node_count ? node_at(0).subtree_pieces : 0;
  size_t sp = 0;
  uint32_t k = 0, visits = 0;
  stack_[sp++] = 0;
  while (sp > 0 && ++visits <= 2 * scene_.bsp_node_count) {  // a malformed BSP: walk_bsp reports it
    BspFrame& f = stack_[sp - 1];
    const uint32_t index = f & ~kNearDone;
    if (index >= scene_.bsp_node_count) break;
    const BspNode node = node_at(index);
    uint32_t near, far;
    children(node, kBackwards ? &far : &near, kBackwards ? &near : &far);
    if (!(f & kNearDone)) {
      f |= kNearDone;
      if (near != kNone && sp < stack_cap_) stack_[sp++] = near;
      continue;
    }
    for (uint32_t i = 0; i < node.piece_count; ++i, ++k) {
      const uint32_t p = kBackwards ? node.first_piece + node.piece_count - 1 - i : node.first_piece + i;
      if (!visit(p, kBackwards ? total - 1 - k : k)) return;
    }
    if (far != kNone) f = far; else --sp;
  }
}
void TilerFrame::children(const BspNode& node, uint32_t* near, uint32_t* far) const {
  const int64_t side = int64_t(node.normal[0]) * view_.eye.x + int64_t(node.normal[1]) * view_.eye.y +
                       int64_t(node.normal[2]) * view_.eye.z - node.d;
  *near = side >= 0 ? node.front : node.back;
  *far = side >= 0 ? node.back : node.front;
}

inline Status TilerFrame::walk_bsp() {
  // Front to back without recursion: one frame per node on the current root-to-node path; the far
  // child replaces its parent's frame, so the stack never holds more than the path.
  const TriageMask& root = pyramid_.mask(0, 0, 0);
  uint32_t pieces_done = 0, visits = 0;
  const bool planned = plan_.active();
  const BandPlan plan = plan_;
  const uint16_t unknown = plan.unknown();
  const uint32_t cull_min = planned ? kCullMinPiecesPlanned : kCullMinPieces;
  size_t sp = 0;
  stack_[sp++] = 0;
  while (sp > 0 && root.c != ~uint64_t(0)) {
    if (++visits > 2 * scene_.bsp_node_count) return error(StatusCode::BadScene, "BSP is not a tree");
    BspFrame& f = stack_[sp - 1];
    const uint32_t index = f & ~kNearDone;
    if (index >= scene_.bsp_node_count) return error(StatusCode::BadScene, "BSP child out of range");
    const BspNode node = node_at(index);
    uint32_t near, far;
    children(node, &near, &far);
    if (!(f & kNearDone)) {
      // Every piece below is a back face (the node's normal cone), or hidden (or outside the band).
      const bool back = scene_.bsp_cones && subtree_faces_away(index);
      if (back || (node.subtree_pieces >= cull_min && subtree_hidden(index, node.subtree_pieces))) {
        pieces_done += node.subtree_pieces;
        st_->triangles_culled += node.subtree_pieces;
        ++(back ? st_->bsp_subtrees_back_facing : st_->bsp_subtrees_culled);
        --sp;
        continue;
      }
      f |= kNearDone;
      if (near != kNone) {
        if (sp == stack_cap_) return error(StatusCode::BadScene, "BSP deeper than bsp_depth");
        stack_[sp++] = near;
      }
      continue;
    }
    // Most visits, with the plan, end at the piece's entry: culled, or not in this band. The entries
    // are read through a copy of the plan, which the compiler keeps in registers (stores to the
    // stats could alias the plan's members).
    uint32_t skipped = 0;
    for (uint32_t p = node.first_piece, end = p + node.piece_count; p < end; ++p) {
      const uint16_t entry = planned ? plan.get(p) : unknown;
      if (entry != unknown && !plan.has(entry)) {
        ++skipped;
        continue;
      }
      texture_plan_.at_piece(pieces_done + (p - node.first_piece));
      if (!draw_piece(p, entry)) return error(StatusCode::SinkFailed, "sink refused a write");
      if (writer_->wrote_piece()) ++st_->triangles_drawn; else ++st_->triangles_culled;
    }
    pieces_done += node.piece_count;
    st_->triangles_culled += skipped;
    if (far != kNone) f = far; else --sp;
  }
  // Once the root is covered every remaining piece is hidden.
  if (scene_.bsp_piece_count > pieces_done) st_->triangles_culled += scene_.bsp_piece_count - pieces_done;
  return ok_status();
}

bool TilerFrame::subtree_faces_away(uint32_t index) {
  auto test = [&] { return bsp_subtree_faces_away(scene_, index, view_.eye); };
  return node_rects_.active() ? node_rects_.faces_away(index, test) : test();
}

bool TilerFrame::subtree_hidden(uint32_t index, uint32_t subtree_pieces) {
  if (subtree_pieces == 0) return true;
  const BandRows& band = band_;
  int32_t x0, y0, x1, y1;  // pixels
  // The box's rectangle; false when the box reaches the near plane (nothing is known). On the boards,
  // with test_rows a box outside the band's rows sets `outside` instead, without a division (the
  // rectangle's row test, exactly): most subtrees lie outside most bands. A 64-bit host divides
  // (corner_rect, the last one kept).
  bool outside = false;
  auto rect = [&](int32_t* rx0, int32_t* ry0, int32_t* rx1, int32_t* ry1, bool test_rows) {
    BspNode node;  // its box alone (the walk's copy of the rest is not copied a test)
    node_box(index, &node);
    if (kDivideIsCheap) return last_rect_.get(view_, node, rx0, ry0, rx1, ry1);
    ViewBox vbox;
    if (!view_box(view_, node, &vbox)) return false;
    outside = test_rows && box_outside_rows(view_, vbox, band.top, band.top + band.rows);
    if (!outside) box_screen_rect(view_, vbox, rx0, ry0, rx1, ry1);
    return true;
  };
  if (node_rects_.active()) {
    auto make = [&](int32_t* rx0, int32_t* ry0, int32_t* rx1, int32_t* ry1) { return rect(rx0, ry0, rx1, ry1, false); };
    if (!node_rects_.get(index, &x0, &y0, &x1, &y1, make)) return false;
  } else {
    if (!rect(&x0, &y0, &x1, &y1, true)) return false;
    if (outside) return true;
  }
  x0 = max_of(x0, 0);
  x1 = min_of(x1, view_.width - 1);
  if (y1 < band.top || y0 >= band.top + band.rows) return true;
  y0 = max_of(y0 - band.top, 0);
  y1 = min_of(y1 - band.top, band.rows - 1);
  const int f = band.factor;  // to band samples
  ConvexPoly box;
  box.min_x = x0 * f;
  box.max_x = x1 * f + f - 1;
  box.min_y = y0 * f;
  box.max_y = min_of(y1 * f + f - 1, band.samples - 1);
  return !tiler_.box_visible(box);  // false for an empty (off-screen) box too
}

inline bool TilerFrame::unclipped_sample_box(const ViewTriangle& view, ConvexPoly* box) const {
  // Unclipped offsets lie inside the guard band (ViewVertex): 32-bit values.
  int32_t min_x = int32_t(view.ox[0]), max_x = min_x, min_y = int32_t(view.oy[0]), max_y = min_y;
  for (int i = 1; i < 3; ++i) {
    min_x = min_of(min_x, int32_t(view.ox[i]));
    max_x = max_of(max_x, int32_t(view.ox[i]));
    min_y = min_of(min_y, int32_t(view.oy[i]));
    max_y = max_of(max_y, int32_t(view.oy[i]));
  }
  const int32_t cx = int32_t(view_.center_x), cy = int32_t(view_.center_y);
  grid_box(grid_, cx + min_x, cy + min_y, cx + max_x, cy + max_y, box);
  return box->min_x <= box->max_x && box->min_y <= box->max_y;
}

uint16_t TilerFrame::plan_bands(const ViewTriangle& view) const {
  int64_t first, last;
  if (view.unclipped) {
    // Unclipped, the piece's one part has these vertex positions: the bands its sample box reaches are
    // the only ones where it can be tiled (none when it holds no sample, on screen or at all).
    ConvexPoly box;
    if (!unclipped_sample_box(view, &box)) return plan_.no_band();
    first = box.min_y / band_.factor;
    last = box.max_y / band_.factor;
  } else if (!view_row_span(view_, view.p, &first, &last)) {
    return plan_.every_band();
  }
  const int rows = out_.band_rows(), height = camera_.height;
  if (first > last || last < 0 || first >= height) return plan_.no_band();
  // A row at the top of a band is also in the halo of the band above (cosine filter).
  const int64_t halo_first = halo_samples(options_) > 0 ? first - 1 : first;
  return plan_.make(halo_first <= 0 ? 0 : int(halo_first) / rows, int(min_of<int64_t>(last, height - 1)) / rows);
}

void TilerFrame::part_box(const ScreenTriangle& part, ConvexPoly* poly) const {
  triangle_grid_box(grid_, part, poly);
}

template <class WholeWorld>
void TilerFrame::project_whole(const Triangle& tri, uint32_t id, int facing, WholeWorld whole_world) {
  if (whole_.triangle != id || whole_.facing != facing) {
    if (!kVertexCache || !cached_) view_triangle(view_, whole_world(), &whole_.view);
    else vertices_.view(tri.batch, tri.v, &whole_.view);
    whole_.n = project_triangle(view_, whole_.view, facing, whole_.parts, false);
    if (whole_.n == 1) {
      part_box(whole_.parts[0], &whole_.poly);
      poly_edges(whole_.parts[0], &whole_.poly);
    }
    whole_.triangle = id;
    whole_.facing = facing;
  }
  writer_->use_whole_view(&whole_.view);
}

// A split piece's part clipped to its whole triangle's edges (Frame step 4, docs/tiler.md), when the
// piece is one part and the triangle projects unclipped (whole_, made by project_whole). Returns the
// triangle the part's colour planes are made on (the piece's own corners are split points, not the
// vertices whose colours shade_triangle gives): the whole triangle's screen triangle when it projects
// unclipped; null for Gouraud colours when it projects in several parts; the part itself when it
// projects in none.
const ScreenTriangle* TilerFrame::clip_to_whole(int n, const ScreenTriangle& part, ConvexPoly* poly) {
  if (whole_.n > 1) return options_.shading == ShadingMode::Gouraud ? nullptr : &part;
  if (whole_.n == 0) return &part;
  if (n == 1) {
    const int f = band_.factor;
    clip_to_triangle(view_, part, whole_.poly, f, camera_.width * f, camera_.height * f, poly);
  }
  return &whole_.parts[0];
}

// A split piece whose whole triangle the near plane (or the guard band) cut: the triangle's parts each
// have colour planes of their own (their corners' colours blend the vertex colours by the corners'
// weights), as the scanline renderer draws them. The piece's part is tiled in each whole part (its
// edges and the whole part's), with that part's planes, then as it is, with the first part's planes:
// the samples of the piece outside its whole triangle's parts (split points are quantized, so the
// piece may stray from the triangle by a fraction of a subpixel) are covered as before, only their
// colour extrapolated (the pyramid takes every sample once).
// poly: the piece's part in the band (BandRows::clip); each whole part's edges are added after the
// piece's own and taken off again. Each tile call counts in Stats::triangles_tiled (count + 1 a part).
bool TilerFrame::tile_in_whole_parts(ConvexPoly* poly, const ScreenTriangle* whole_parts, int count,
                                     const Vec3i* world) {
  // The part has its own three edges only: clip_to_whole adds the whole triangle's edges only when
  // that triangle projects in one part, and it comes here only when it projects in several
  // (BandRows::clip moves edges, adds none). So a whole part's three always fit after them.
  static_assert(3 + 3 <= kMaxPolyEdges, "a part's edges and a whole part's fit one polygon");
  const int own = poly->n;
  for (int j = 0; j <= count; ++j) {
    poly->n = own;
    if (j < count) {
      ConvexPoly edges;
      poly_edges(whole_parts[j], &edges);
      for (int k = 0; k < 3; ++k) {
        EdgeFunction& e = poly->edge[poly->n++];
        e = edges.edge[k];
        band_.to_band(&e);  // as the piece's edges (BandRows::clip)
      }
    }
    ++st_->triangles_tiled;
    writer_->begin_part(&whole_parts[j < count ? j : 0], world);
    if (tiler_.tile(*poly, *writer_) == TileResult::Failed) return false;
  }
  poly->n = own;
  return true;
}

inline bool TilerFrame::draw_piece(uint32_t index, uint16_t entry) {
  writer_->clear_piece();
  const bool planned = plan_.active();
  const bool known = entry != plan_.unknown();
  const bool cached = kVertexCache && cached_;
  const BspPiece piece = bsp_piece(scene_, index);
  const Triangle tri = triangle_at(scene_, piece.triangle);
  const Material& mat = batch_material(scene_, tri.batch);
  // Facing is decided on the whole triangle, exactly as the scanline renderer decides it, and
  // before projecting, so back faces cost almost nothing; with the plan once a triangle. The
  // triangle's vertices are read only when needed: for the test, for a whole piece, and for a split
  // piece whose box passes the visibility test and whose whole triangle is not the one kept
  // (project_whole; with the vertex cache, from it).
  Vec3i whole_world[3];
  bool have_whole = false;
  auto whole = [&]() -> const Vec3i* {
    if (!have_whole && cached) vertices_.world(tri.batch, tri.v, whole_world);
    else if (!have_whole) triangle_world(scene_, piece.triangle, whole_world);
    have_whole = true;
    return whole_world;
  };
  // A planned piece faces the eye unless its material is double-sided (then the side picks its
  // shading); only a triangle the BSP split has other pieces to share its facing with.
  const bool split = is_split_piece(piece, tri);
  const bool shared = split && plan_.keeps_facing();
  int facing = known && !mat.double_sided ? 1 : shared ? plan_.facing(piece.triangle) : BandPlan::kFacingUnknown;
  if (facing == BandPlan::kFacingUnknown) {
    facing = triangle_facing(view_, whole());
    if (shared) plan_.set_facing(piece.triangle, facing);
  }
  if (facing == 0 || (facing < 0 && !mat.double_sided)) {
    if (planned) plan_.set(index, plan_.no_band());
    return true;
  }
  // The piece is transformed once: for its plan entry (first visit), its row test and its projection;
  // with the cache its vertices about once a frame. Without it the row test reads world vertices.
  Vec3i split_world[3];
  const Vec3i* world = split_world;
  if (!cached && split) vertices_world(scene_, tri.batch, piece.v, split_world);
  else if (!cached) world = whole();
  ViewTriangle view;
  bool viewed = false;
  auto transform = [&]() -> const ViewTriangle& {
    if (!viewed && cached) vertices_.view(tri.batch, split ? piece.v : tri.v, &view);
    else if (!viewed) view_triangle(view_, world, &view);
    viewed = true;
    return view;
  };
  if (planned && !known) {
    const uint16_t bands = plan_bands(transform());
    plan_.set(index, bands);
    if (!plan_.has(bands)) return true;
  }
  // Without a plan, an unclipped piece's sample box comes from its cached screen positions: a piece too
  // small to hold a sample (most of a detailed model's, on a small screen) is dropped before it is
  // projected (the plan's test), and the others' one part needs no part_box. With a plan, a split
  // piece's too, for its box test before projection (2CylinderEngine a band at a time: 320x240
  // 69.13 M -> 67.59 M, 1024x768 111.29 M -> 109.67 M; the bundled scene and the duck within 0.1 %).
  ConvexPoly unclipped_box;
  const bool have_box = (!planned || split) && cached && transform().unclipped;
  if (have_box && !unclipped_sample_box(view, &unclipped_box)) return true;
  // Outside this band: skipped before projecting (most pieces, with many bands); an exact plan has
  // answered that already.
  if (band_.rows < camera_.height && !(planned && plan_.exact())) {
    const int32_t row0 = band_.top, row1 = band_.top + band_.rows - 1;
    if (cached ? view_outside_rows(view_, transform().p, row0, row1) : triangle_outside_rows(view_, world, row0, row1))
      return true;
  }
  // A split piece's box is tested before its edges are made: most such boxes the walk reaches are
  // hidden (pieces behind what is drawn, near where the BSP cut them), and need neither the whole
  // triangle's edges nor tiling. With its box known before projection, before projecting too.
  const bool box_tested = split && have_box;
  if (box_tested) {
    ConvexPoly box;
    if (!band_.clip_box(unclipped_box, &box) || !tiler_.box_visible(box)) return true;
  }
  // An invisible material's pieces are left out here, where few pieces still are, and only in a
  // scene that has such a material (tested with the facing, for every piece the walk reaches:
  // 2CylinderEngine 320x240 +1.2 %).
  if (hides_ && material_hidden(mat)) return leave_out(index);
  ScreenTriangle parts[kMaxClipTriangles];
  const int n = project_triangle(view_, transform(), facing, parts, false);  // the tiler reads no depths
  writer_->begin_piece(&scene_, &light_, options_.shading, piece.triangle, facing > 0, split ? nullptr : &view);
  for (int i = 0; i < n; ++i) {
    ConvexPoly poly;
    if (have_box) copy_box(unclipped_box, &poly);  // the one part's box (orient only reorders its vertices)
    else part_box(parts[i], &poly);
    ConvexPoly box;  // the band's part of the box alone
    if (!band_.clip_box(poly, &box)) continue;  // a third of the parts: their edges are never needed
    if (split && n == 1 && !box_tested && !tiler_.box_visible(box)) continue;
    poly_edges(parts[i], &poly);
    const ScreenTriangle* colour_part = &parts[i];
    if (split) {
      project_whole(tri, piece.triangle, facing, whole);
      colour_part = clip_to_whole(n, parts[i], &poly);
    }
    if (!band_.clip(&poly)) continue;
    if (!colour_part) {
      if (!tile_in_whole_parts(&poly, whole_.parts, whole_.n, have_whole ? whole_world : nullptr)) return false;
      continue;
    }
    ++st_->triangles_tiled;
    writer_->begin_part(colour_part, have_whole ? whole_world : nullptr);
    if (tiler_.tile(poly, *writer_) == TileResult::Failed)
      return false;
  }
  return true;
}

}  // namespace

size_t tiler_plan_bytes(const Scene& scene, int bands) {
  return BandPlan::entry_bytes(scene.bsp_piece_count, bands) + BandPlan::facing_bytes(scene.triangle_count) +
         NodeRects::bytes(scene.bsp_node_count, bands) + PlaneCache::bytes(scene, bands);
}

size_t tiler_cache_bytes(const Scene& scene) {
  return kVertexCache ? VertexCache::arena_bytes(vertex_cache_entries(scene)) : 0;
}

size_t tiler_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  const int width = clamp_to(camera.width, 1, kMaxScreenDim), height = clamp_to(camera.height, 1, kMaxScreenDim);
  const size_t bands = band_bytes(width, height, options, 0);
  if (bands == 0) return 0;
  const int factor = clamp_to(sample_factor(options), 1, kMaxTilerAa);
  const size_t pager = options.shading == ShadingMode::Ids ? 0 : TexturePager::arena_bytes(scene, options.texture_pool_bytes);
  return pager + segment_rows_bytes(pager) + (pager ? TexturePlan::arena_bytes(scene) : 0) + bands +
         (jittered(options) ? arena_worst_case(jitter_table_bytes(factor), 1) : 0) +
         arena_worst_case(sizeof(BspFrame) * bsp_stack_entries(scene), 4) +
         arena_worst_case(sizeof(Pixel) * kRowPixels, 4);
}

size_t tiler_render_rows_bytes(const Camera& camera, const RenderOptions& options, int render_rows) {
  const int width = clamp_to(camera.width, 1, kMaxScreenDim), height = clamp_to(camera.height, 1, kMaxScreenDim);
  // One buffer of two bands can take less than two buffers of one (their alignment).
  const size_t at_once = band_bytes(width, height, options, render_rows), least = band_bytes(width, height, options, 0);
  return at_once > least ? at_once - least : 0;
}

Status tiler_render(const Scene& scene, const Camera& camera, const RenderOptions& options,
                    Arena& arena, Sink& sink, Stats* stats, SampleFilter* cosine) {
  Stats local;
  Stats* st = stats ? stats : &local;
  st->width = uint32_t(camera.width);
  st->height = uint32_t(camera.height);
  st->samples_per_pixel = uint32_t(sample_factor(options) * sample_factor(options));
  st->triangles_in = scene.triangle_count;
  Status status = check_options(camera, options);
  if (!status.ok()) return status;
  if (uses_cosine(options) && !cosine)
    return error(StatusCode::Unsupported, "this tiler entry has no cosine filter (render_tiler_box); use render_tiler");
  View view;
  status = make_view(camera, &view);
  if (!status.ok()) return status;
  if (scene.bsp_node_count == 0 || scene.info == nullptr)
    return error(StatusCode::Unsupported, "scene has no BSP; recompile it with the scene compiler");
  if (scene.info->bsp_depth > kMaxBspDepth) return error(StatusCode::BadScene, "BSP too deep");

  const size_t need = tiler_arena_bytes(scene, camera, options);
  if (arena.size() - arena.used() < need)
    return error(StatusCode::ArenaTooSmall, "arena too small for the tiler", need);
  TilerFrame frame(scene, camera, options, view, st, cosine);
  return frame.run(arena, sink);
}

}  // namespace ml
