// Names of the pixel formats on the command line and in --stats (core/sink.h: PixelFormat).
#pragma once
#include <string>

#include "core/sink.h"

namespace mlhost {

inline const char* format_name(ml::PixelFormat f) {
  switch (f) {
    case ml::PixelFormat::Rgb565Be: return "rgb565be";
    case ml::PixelFormat::Rgb565Le: return "rgb565le";
    case ml::PixelFormat::Xrgb8888: return "xrgb8888";
    case ml::PixelFormat::Grey8: return "grey8";
    case ml::PixelFormat::Grey4: return "grey4";
    case ml::PixelFormat::Mono1: return "mono1";
    case ml::PixelFormat::Id32: return "id32";
  }
  return "?";
}

// False for an unknown name. "rgb565" means the panels' big-endian order.
inline bool parse_format(const std::string& name, ml::PixelFormat* out) {
  if (name == "rgb565") { *out = ml::PixelFormat::Rgb565Be; return true; }
  for (ml::PixelFormat f : {ml::PixelFormat::Rgb565Be, ml::PixelFormat::Rgb565Le, ml::PixelFormat::Xrgb8888,
                            ml::PixelFormat::Grey8, ml::PixelFormat::Grey4, ml::PixelFormat::Mono1})
    if (name == format_name(f)) { *out = f; return true; }
  return false;
}

}  // namespace mlhost
