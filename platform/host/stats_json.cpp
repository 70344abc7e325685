#include "platform/host/stats_json.h"

#include <stdio.h>

#include <sstream>

namespace mlhost {
namespace {

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string number(double v) {
  char buf[32];
  snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

std::string stats_json(const ml::Stats& s, const RunInfo& run) {
  std::ostringstream o;
  const double pixels = double(run.width) * double(run.height);
  o << "{\"scene\":" << quoted(run.scene) << ",\"size\":" << quoted(std::to_string(run.width) + "x" + std::to_string(run.height))
    << ",\"renderer\":" << quoted(run.renderer) << ",\"aa\":" << run.aa << ",\"shading\":" << quoted(run.shading)
    << ",\"width\":" << s.width << ",\"height\":" << s.height << ",\"samples_per_pixel\":" << s.samples_per_pixel
    << ",\"triangles_in\":" << s.triangles_in << ",\"triangles_culled\":" << s.triangles_culled
    << ",\"triangles_drawn\":" << s.triangles_drawn << ",\"pixel_writes\":" << s.pixel_writes
    << ",\"sink_calls\":" << s.sink_calls << ",\"bands\":" << s.bands << ",\"render_bands\":" << s.render_bands
    << ",\"band_rows\":" << run.band_rows
    << ",\"format\":" << quoted(run.format) << ",\"display\":" << quoted(run.display)
    << ",\"display_bytes\":" << s.display_bytes << ",\"display_windows\":" << s.display_windows
    << ",\"display_bytes_per_pixel\":" << number(pixels > 0 ? double(s.display_bytes) / pixels : 0.0)
    << ",\"shading_calls\":" << s.shading_calls
    << ",\"peak_arena_bytes\":" << s.peak_arena_bytes << ",\"cells_visited\":" << s.cells_visited
    << ",\"cells_visited_per_pixel\":" << number(pixels > 0 ? double(s.cells_visited) / pixels : 0.0)
    << ",\"triangles_tiled\":" << s.triangles_tiled << ",\"bsp_nodes\":" << s.bsp_nodes
    << ",\"bsp_pieces\":" << s.bsp_pieces << ",\"bsp_split_ratio\":" << number(run.bsp_split_ratio)
    << ",\"pyramid_bytes\":" << s.pyramid_bytes << ",\"bsp_subtrees_culled\":" << s.bsp_subtrees_culled
    << ",\"bsp_subtrees_back_facing\":" << s.bsp_subtrees_back_facing
    << ",\"texture_planes_reused\":" << s.texture_planes_reused << ",\"n\":" << s.n << ",\"m_max\":" << s.m_max
    << ",\"geometry_samples\":" << s.geometry_samples << ",\"sort_instructions\":" << s.sort_instructions
    << ",\"texture_loads\":" << s.texture_loads << ",\"texture_reloads\":" << s.texture_reloads
    << ",\"texture_evictions\":" << s.texture_evictions << ",\"texture_fallbacks\":" << s.texture_fallbacks
    << ",\"texture_bytes_loaded\":" << s.texture_bytes_loaded << ",\"texture_bytes_peak\":" << s.texture_bytes_peak
    << ",\"textures_resident_peak\":" << s.textures_resident_peak
    << "}";
  return o.str();
}

}  // namespace mlhost
