// PNG files for the host: colour images (0x00RRGGBB pixels), id images (id + 1 as little-endian RGBA8,
// core/sink.h) and Greene's work image as a log-scale heatmap. Errors come back as a one-line message.
#pragma once
#include <stdint.h>

#include <string>
#include <vector>

#include "core/sink.h"

namespace mlhost {

// Writes 8-bit RGB. Returns "" on success or a one-line error.
std::string write_png_rgb(const std::string& path, int width, int height, const std::vector<ml::Pixel>& pixels);

// Writes 8-bit RGBA where R, G, B, A are bytes 0..3 of each 32-bit value (little-endian), so an id
// image decodes back to id + 1 exactly.
std::string write_png_rgba_le(const std::string& path, int width, int height,
                              const std::vector<uint32_t>& values);

// Reads an 8-bit RGB or RGBA PNG back (for tests): pixels as 0x00RRGGBB, or raw little-endian RGBA
// values when `raw_rgba` is set. Returns "" on success.
std::string read_png(const std::string& path, int* width, int* height, std::vector<uint32_t>* values,
                     bool raw_rgba);

// Greene's work image: per-pixel cell visits (Q16) mapped through log2(1 + visits) onto a
// black-blue-red-yellow-white ramp, scaled so the busiest pixel is white.
std::vector<ml::Pixel> work_heatmap(const std::vector<uint32_t>& work_q16);

}  // namespace mlhost
