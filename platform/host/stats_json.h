// The --stats JSON object: every field of ml::Stats plus what the run was (size, renderer, aa,
// shading) and two derived ratios. One object, one line.
#pragma once
#include <string>

#include "core/stats.h"

namespace mlhost {

struct RunInfo {
  int width = 0, height = 0;
  std::string renderer;   // "tiler" | "scanline"
  int aa = 1;
  std::string shading;    // "unlit" | "flat" | "gouraud" | "lines" | "ids"
  std::string scene;      // file name, or "default"
  double bsp_split_ratio = 0;  // BSP pieces per scene triangle (1.0 = no splits)
  int band_rows = 0;           // rows per band the frame left in
  std::string format;          // the pixel format the renderer packed ("xrgb8888", "rgb565be", ...)
  std::string display;         // where the frame went ("png", "emu:ili9341", "fb:/dev/fb0", ...)
};

std::string stats_json(const ml::Stats& stats, const RunInfo& run);

}  // namespace mlhost
