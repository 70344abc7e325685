// mlpanels::Transport over the LM3S6965's SSI0 (an ARM PL022) to the evaluation board's SSD0323 OLED:
// SSI0 clock, frame and TX on PA2, PA3, PA5; the OLED's D/C line on PC7 (1 = data); its chip select
// on PD0. Polled: each byte waits for room in the TX FIFO, and the RX FIFO is drained as bytes come
// back (the PL022 stops shifting when its 8-entry RX FIFO is full). Before D/C changes, the bus is
// idled (BSY clear) so no byte of the previous kind is still being shifted out.
// The board has no RESET line for the OLED under the firmware's control: set_reset does nothing.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "platform/panels/transport.h"

namespace fw {

class SsiTransport : public mlpanels::Transport {
 public:
  // Enables the clocks, muxes the pins and configures SSI0 (8-bit Motorola SPI, SPO = SPH = 1).
  void init();
  bool write_command(const uint8_t* bytes, size_t n) override { return write(false, bytes, n); }
  bool write_data(const uint8_t* bytes, size_t n) override { return write(true, bytes, n); }
  bool set_reset(bool) override { return true; }
  void delay_ms(uint32_t ms) override;

 private:
  bool write(bool data, const uint8_t* bytes, size_t n);
  int dc_ = -1;  // the D/C level last driven (-1: not yet)
};

}  // namespace fw
