// In-memory image sink that checks the Sink contract (core/sink.h): begin_frame once; bands flushed
// top to bottom, each the full width and `band_rows` high (the last one the remainder), so every
// pixel arrives exactly once; each buffer released before the next flush of it; end_frame once.
// Pixels are decoded from any PixelFormat back to 0x00RRGGBB (ids stay ids) through
// core/pixel_format.h. Tests use it to check renderers.
//
// Unwritten pixels inside a band: after copying a band the sink overwrites the lent bytes with
// kPoisonByte (it owns them until flush_ready), so a pixel the renderer skips in a later band shows
// as poison: Xrgb8888's unused top byte or an Id32 id no scene can have. Fill the arena with
// kPoisonByte before the render to catch it in the first band too.
#pragma once
#include <stdint.h>

#include <string>
#include <vector>

#include "core/sink.h"

namespace mlhost {

constexpr uint8_t kPoisonByte = 0xA5;

// The band-order part of the contract, shared by every host sink: which band comes next.
class BandContract {
 public:
  // "" when the frame is acceptable.
  std::string begin(const ml::FrameInfo& frame);
  // "" when `band` is the next band of the frame.
  std::string check(const ml::Flush& band);
  // "" when every row arrived.
  std::string end() const;
  const ml::FrameInfo& frame() const { return frame_; }

 private:
  ml::FrameInfo frame_;
  int next_row_ = 0;
  bool begun_ = false, ended_ = false;
};

class ImageSink : public ml::Sink {
 public:
  explicit ImageSink(bool strict = false) : strict_(strict) {}

  bool begin_frame(const ml::FrameInfo& frame) override;
  bool flush(const ml::Flush& band) override;
  bool end_frame() override;

  // True when the frame was begun and ended once and every pixel arrived exactly once and written.
  bool contract_ok() const { return error_.empty() && ended_ && unwritten_ == 0; }
  // First violation, or why contract_ok() is false ("" when it holds).
  std::string contract_error() const;

  int width() const { return frame_.width; }
  int height() const { return frame_.height; }
  ml::PixelFormat format() const { return frame_.format; }
  // Decoded pixels: 0x00RRGGBB (ids in id mode).
  const std::vector<ml::Pixel>& pixels() const { return pixels_; }
  ml::Pixel at(int x, int y) const { return pixels_[size_t(y) * size_t(frame_.width) + size_t(x)]; }
  // The values the format stored (RGB565 word, grey level, ...), before decoding.
  const std::vector<uint32_t>& stored() const { return stored_; }
  // Times pixel (x, y) arrived written (1 when the contract holds; 0 never, or left unwritten).
  uint8_t writes_at(int x, int y) const { return writes_[size_t(y) * size_t(frame_.width) + size_t(x)]; }
  const std::vector<uint8_t>& writes() const { return writes_; }

  uint64_t pixel_writes() const { return pixel_writes_; }
  uint64_t flushes() const { return flushes_; }
  int band_rows() const { return frame_.band_rows; }

 private:
  void fail(const std::string& message);

  bool strict_;
  BandContract contract_;
  ml::FrameInfo frame_;
  std::vector<ml::Pixel> pixels_;
  std::vector<uint32_t> stored_;
  std::vector<uint8_t> writes_;  // saturating count per pixel
  uint64_t pixel_writes_ = 0, flushes_ = 0, unwritten_ = 0;
  int begins_ = 0;
  bool ended_ = false;
  std::string error_;
};

}  // namespace mlhost
