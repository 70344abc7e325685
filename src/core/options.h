// What a caller chooses for one frame: renderer, shading, samples and the output format. Both
// renderers and render() take these; they live in core so no module depends on render/.
#pragma once
#include <stdint.h>

#include "core/sink.h"

namespace ml {

class TextureSource;  // texture/source.h

// RenderOptions::texture_pool_bytes asking for the pool that holds every texture at once.
constexpr uint32_t kTexturePoolAll = 0xFFFFFFFFu;

enum class RendererKind : uint8_t { Tiler, Scanline };

// How an antialiased pixel is made from its samples (the tiler, aa > 1): the mean of its own samples
// (box, the A-buffer's), or a cosine-hump kernel one pixel in radius over the samples of the 3 x 3
// pixels around it (tables/filter_tables.h, docs/tiler.md).
enum class FilterKind : uint8_t { Box, Cosine };

// Where a pixel's samples lie (aa > 1): a regular grid at the sub-cell centres, or jittered inside
// their sub-cells by one of several patterns chosen per pixel (core/jitter.h). The tiler samples
// either; the scanline renderer's supersampling keeps its own corner lattice.
enum class SamplePattern : uint8_t { Regular, Jittered };

enum class ShadingMode : uint8_t {
  Unlit,    // base colour
  Flat,     // face normal, one directional light + ambient
  Gouraud,  // vertex normals lit per vertex, colours interpolated across the triangle
  Ids,      // pixel = triangle id + 1 (core/sink.h)
  Lines,    // hidden-line drawing (scanline renderer)
};

// Optional per-pixel work counter (Greene's work image): the tiler adds, for every pyramid cell it
// visits, 1 / (pixels the cell covers) to each of those pixels, in Q16 units. Host-owned buffer of
// width * height entries; null when not wanted.
struct WorkImage {
  uint32_t* q16 = nullptr;
  int width = 0, height = 0;
};

// How pixels leave the renderer (core/sink.h): the display's format, ordered dithering where the
// format loses precision, and the band buffers lent from the arena.
struct OutputOptions {
  PixelFormat format = PixelFormat::Xrgb8888;  // ids shading always outputs Id32
  bool dither = false;                         // 4x4 ordered dither (RGB565, grey, mono)
  int band_rows = 16;                          // rows a band buffer holds; 0 = the whole frame
  int buffers = 1;                             // 1, or 2 so sending one band overlaps the next
  // Rows the tiler may render at once when the arena has room beyond its least (core/band.h's render
  // bands: each band still leaves on its own, but only once all of them are rendered, so a display
  // sends none of them while they render). 0 = the whole frame with one buffer, one band at a time
  // with two (so that sending one band overlaps the next); band_rows or fewer = one band at a time.
  int render_rows = 0;
};

struct RenderOptions {
  RendererKind renderer = RendererKind::Tiler;
  ShadingMode shading = ShadingMode::Flat;
  int aa = 1;                         // samples per pixel per axis (scanline: 1..8; tiler: 1, 2, 4, 8)
  FilterKind filter = FilterKind::Box;  // tiler, aa > 1
  SamplePattern samples = SamplePattern::Regular;  // tiler, aa > 1
  Pixel background = 0x202830;        // 0x00RRGGBB; ignored (0) in Ids mode
  uint32_t seed = 1;                  // for stochastic choices (adaptive shading, the jitter patterns)
  WorkImage* work = nullptr;
  OutputOptions output;
  // Textures (texture/pager.h): the pool the pager may take from the arena (clamped to what the scene
  // can use; texture_pool_needs() gives the desired and the minimum size) and where texels come from
  // (null: the blob's own Texels section).
  uint32_t texture_pool_bytes = kTexturePoolAll;
  TextureSource* texture_source = nullptr;
};

}  // namespace ml
