// A Sink (core/sink.h) that drives a panel through a Transport: each flushed band becomes exactly one
// address window followed by the band's packed bytes, sent synchronously, after which the band
// buffer is given back (flush_ready). counters.bytes counts every byte on the bus, commands and
// parameters included; counters.windows the address-window commands (one per flush).
//
// No heap, no exceptions, no floats: shared with bare-metal firmware.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/sink.h"
#include "platform/panels/panel.h"
#include "platform/panels/transport.h"

namespace mlpanels {

class PanelSink : public ml::Sink {
 public:
  // max_transfer: the largest write the transport takes at once (spidev's bufsiz); 0 = unlimited.
  PanelSink(const Panel& panel, Transport& transport, size_t max_transfer)
      : panel_(panel), transport_(&transport), max_transfer_(max_transfer) {}

  // Resets and initializes the controller. Its bytes are not part of any frame's counters.
  bool init();

  // False when the frame's size or format is not the panel's.
  bool begin_frame(const ml::FrameInfo& frame) override;
  bool flush(const ml::Flush& band) override;
  bool end_frame() override;

  const Panel& panel() const { return panel_; }
  // Bytes init() put on the bus.
  uint64_t init_bytes() const { return init_bytes_; }
  // Why the last call returned false ("" when none did).
  const char* error() const { return error_; }

 private:
  bool fail(const char* message) {
    error_ = message;
    return false;
  }

  Panel panel_;
  Transport* transport_;
  size_t max_transfer_;
  uint64_t init_bytes_ = 0;
  bool in_frame_ = false;
  const char* error_ = "";
};

}  // namespace mlpanels
