// A Sink that streams bands straight into a PNG file: no frame buffer anywhere, only one PNG row.
// Colour formats are decoded to 8-bit RGB (as the display would show them, core/pixel_format.h); Id32
// frames are written as little-endian RGBA8 so ids decode back exactly (png_io.h). The band order is
// checked (BandContract); any violation or write error fails the flush with a one-line message.
#pragma once
#include <stdint.h>
#include <stdio.h>

#include <string>
#include <vector>

#include "core/sink.h"
#include "platform/host/image_sink.h"

namespace mlhost {

class PngStreamSink : public ml::Sink {
 public:
  explicit PngStreamSink(std::string path) : path_(std::move(path)) {}
  ~PngStreamSink() override;

  bool begin_frame(const ml::FrameInfo& frame) override;
  bool flush(const ml::Flush& band) override;
  bool end_frame() override;

  // "" when the file was written completely.
  const std::string& error() const { return error_; }

 private:
  bool fail(const std::string& message);
  void close();

  std::string path_;
  BandContract contract_;
  FILE* file_ = nullptr;
  void* png_ = nullptr;   // png_structp
  void* info_ = nullptr;  // png_infop
  std::vector<uint8_t> row_;
  std::string error_;
};

}  // namespace mlhost
