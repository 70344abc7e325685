// The wire a panel driver talks through: bytes with the D/C line low (commands) or high (data), the
// RESET line, and millisecond delays. Implemented by the Linux spidev + GPIO transport
// (platform/linux/spi), a bare-metal SSI driver, and the host panel emulator
// (platform/host/panel_emulator.h).
//
// Shared by Linux and bare-metal firmware: no heap, no exceptions, no floats, only <stdint.h> and
// <stddef.h>.
#pragma once
#include <stddef.h>
#include <stdint.h>

namespace mlpanels {

class Transport {
 public:
  virtual ~Transport() = default;
  // Sends n bytes with D/C low (commands; on SSD1306/SSD0323 also command parameters).
  virtual bool write_command(const uint8_t* bytes, size_t n) = 0;
  // Sends n bytes with D/C high (parameters of ILI9341/ST7789 commands, display RAM data).
  virtual bool write_data(const uint8_t* bytes, size_t n) = 0;
  // Drives the RESET line (active low: false holds the controller in reset). A transport without a
  // RESET line returns true and does nothing.
  virtual bool set_reset(bool high) = 0;
  virtual void delay_ms(uint32_t ms) = 0;
};

}  // namespace mlpanels
