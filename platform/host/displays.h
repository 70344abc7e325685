// The displays `maskline show --display SPEC` draws on, behind one interface for the CLI:
//   fb:/dev/fbN                      a Linux framebuffer (platform/linux/fbdev)
//   spi:PANEL[,key=value...]         a panel on spidev + libgpiod (platform/linux/spi; keys in docs/panels.md)
//   emu:PANEL[,rotation=DEG]         a panel emulator that decodes the bytes a panel would receive
//                                    (platform/host/panel_emulator)
// PANEL is ili9341, st7789, st7789-240, ssd1306 or ssd0323. A panel without an explicit rotation is
// mounted in the rotation whose size is the requested frame size (a 320x240 frame on an ILI9341:
// rotation 90); without a requested size, at rotation 0 with the panel's own size.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/sink.h"

namespace mlhost {

class Display {
 public:
  virtual ~Display() = default;
  virtual ml::Sink& sink() = 0;
  // The pixel format the display takes, and the frame size it shows (a framebuffer: its visible
  // screen, which takes any smaller frame centred).
  virtual ml::PixelFormat format() const = 0;
  virtual int width() const = 0;
  virtual int height() const = 0;
  // Whether a frame of w x h fits.
  virtual bool accepts(int w, int h) const { return w == width() && h == height(); }
  // One line for people: what the display is.
  virtual std::string describe() const = 0;
  // Why the last frame failed, from the display's side ("" when it did not).
  virtual std::string error() const = 0;
  // The picture the display shows now, as 0x00RRGGBB (emulators only; false elsewhere).
  virtual bool picture(std::vector<ml::Pixel>* pixels, int* w, int* h) const {
    (void)pixels; (void)w; (void)h;
    return false;
  }
};

// Opens SPEC for a frame of want_w x want_h (0 x 0: the display's own size). Null with a one-line
// message when the spec is malformed, the device is missing or refuses, or the size cannot fit.
std::unique_ptr<Display> open_display(const std::string& spec, int want_w, int want_h, std::string* error);

}  // namespace mlhost
