// Per-frame counts every render returns. The host CLI prints them as JSON (platform/host), tests and
// benchmarks read them. Fields a renderer does not use stay 0.
#pragma once
#include <stdint.h>

namespace ml {

struct Stats {
  // common
  uint32_t width = 0, height = 0;
  uint32_t samples_per_pixel = 1;      // aa * aa
  // The tiler draws BSP pieces (a split triangle is several) band by band, so for it culled and drawn
  // count (piece, render band) pairs and add up to bsp_pieces * render_bands (with one band: pieces);
  // the scanline renderer counts triangles.
  uint32_t triangles_in = 0;           // triangles in the scene
  uint32_t triangles_culled = 0;       // back-facing, behind the eye, off screen, degenerate, or hidden
  uint32_t triangles_drawn = 0;        // triangles (pieces) that wrote at least one pixel
  uint64_t pixel_writes = 0;           // pixels packed into band buffers (a block of n pixels counts n)
  uint64_t sink_calls = 0;             // flush() calls: one per band
  uint32_t bands = 0;                  // bands rendered (each flushed once)
  uint32_t render_bands = 0;           // the tiler's walks: bands rendered at once (BandOutput's
                                       // render bands; fewer than `bands` when the arena had room)
  uint64_t display_bytes = 0;          // bytes on the bus or into the framebuffer, commands included
  uint32_t display_windows = 0;        // address-window commands sent to the display
  uint64_t shading_calls = 0;          // colour evaluations
  uint32_t peak_arena_bytes = 0;

  // tiler
  uint64_t cells_visited = 0;          // pyramid cells (masks) visited by tile_poly
  // tile_poly calls: a clipped part of a piece once per render band it reaches; with Gouraud colours
  // a split piece's part whose whole triangle projects in several parts (the near plane or the guard
  // band cut it) once per whole part plus once more (its samples outside them).
  uint32_t triangles_tiled = 0;
  uint32_t bsp_nodes = 0;
  uint32_t bsp_pieces = 0;             // pieces stored in the BSP (>= triangles when some were split)
  uint32_t pyramid_bytes = 0;
  uint32_t bsp_subtrees_culled = 0;    // BSP subtrees skipped whole (box proved hidden or off screen)
  uint32_t bsp_subtrees_back_facing = 0;  // BSP subtrees skipped whole (normal cone: all back faces)
  uint32_t texture_planes_reused = 0;  // textured pieces whose texture planes an earlier band made (kept)

  // scanline
  uint32_t n = 0;                      // triangles in ySortList
  uint32_t m_max = 0;                  // most triangles active on one row
  uint64_t geometry_samples = 0;       // samples whose visible surface was resolved
  uint64_t sort_instructions = 0;      // work units spent sorting (comparisons + moves)

  // texture pager (texture/pager.h)
  uint32_t texture_loads = 0;          // textures read from the TextureSource (reloads included)
  uint32_t texture_reloads = 0;        // reads of a texture already read earlier in the frame
  uint32_t texture_evictions = 0;      // textures dropped before their last use to make room
  uint32_t texture_fallbacks = 0;      // textures drawn in their material colour: read failed or too large
  uint32_t texture_bytes_loaded = 0;   // bytes read from the TextureSource
  uint32_t texture_bytes_peak = 0;     // most pool bytes resident at once
  uint32_t textures_resident_peak = 0; // most textures resident at once
};

}  // namespace ml
