// Linux Transport: bytes over spidev (SPI_IOC_MESSAGE), D/C and RESET through GPIO lines (libgpiod
// 1.6). Transfers are never longer than the spidev driver's bufsiz.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include <memory>
#include <string>

#include "platform/panels/panel.h"
#include "platform/panels/panel_sink.h"
#include "platform/panels/transport.h"

struct gpiod_chip;
struct gpiod_line;

namespace mlpanels {

struct SpiPanelConfig {
  std::string panel = "ili9341";       // make_panel name
  int rotation = 0;                    // 0, 90, 180, 270
  std::string device = "/dev/spidev0.0";
  uint32_t speed_hz = 32000000;
  uint8_t mode = 0;                    // SPI mode 0..3
  uint8_t bits_per_word = 8;
  std::string gpio_chip = "gpiochip0";  // gpiod_chip_open_lookup: name, path, label or number
  int dc_line = 25;                    // line offset of D/C on gpio_chip
  int reset_line = 24;                 // line offset of RESET, -1 when not wired
  size_t max_transfer = 0;             // 0: spidev's bufsiz
  std::string bufsiz_path = "/sys/module/spidev/parameters/bufsiz";
};

// Parses "PANEL[,key=value...]" (the part after "spi:" in a --display option) into `out`, starting
// from its current values. Keys: rotation, device, speed (Hz), mode, bits, chip, dc, reset (-1: none),
// max (bytes a transfer). False with a one-line message on an unknown key or a bad number.
bool parse_spi_panel_spec(const std::string& spec, SpiPanelConfig* out, std::string* error);

// The spidev driver's largest transfer, read from `path`; 4096 when it cannot be read.
size_t spidev_bufsiz(const std::string& path = "/sys/module/spidev/parameters/bufsiz");

// An open spidev device set to a mode, word size and speed.
class SpiDevice {
 public:
  SpiDevice() = default;
  ~SpiDevice();
  SpiDevice(const SpiDevice&) = delete;
  SpiDevice& operator=(const SpiDevice&) = delete;
  // False with a one-line message (the device is closed again).
  bool open(const std::string& path, uint8_t mode, uint8_t bits, uint32_t speed_hz, std::string* error);
  // One SPI_IOC_MESSAGE(1) transfer of n bytes (n at most the driver's bufsiz).
  bool transfer(const uint8_t* bytes, size_t n, std::string* error);
  void close();
  bool is_open() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
  std::string path_;
  uint32_t speed_hz_ = 0;
  uint8_t bits_ = 8;
};

// D/C and optional RESET output lines on one GPIO chip, released on close.
class GpioLines {
 public:
  GpioLines() = default;
  ~GpioLines();
  GpioLines(const GpioLines&) = delete;
  GpioLines& operator=(const GpioLines&) = delete;
  // reset_line -1: none. False with a one-line message, every line released.
  bool open(const std::string& chip, int dc_line, int reset_line, std::string* error);
  bool set_dc(bool high);
  bool set_reset(bool high);  // true without a RESET line
  void close();
  bool is_open() const { return chip_ != nullptr; }

 private:
  gpiod_chip* chip_ = nullptr;
  gpiod_line* dc_ = nullptr;
  gpiod_line* reset_ = nullptr;
  int dc_value_ = -1;
};

class SpiTransport : public Transport {
 public:
  // Opens the GPIO lines and the spidev device. nullptr with a one-line message.
  static std::unique_ptr<SpiTransport> open(const SpiPanelConfig& config, std::string* error);

  bool write_command(const uint8_t* bytes, size_t n) override { return send(false, bytes, n); }
  bool write_data(const uint8_t* bytes, size_t n) override { return send(true, bytes, n); }
  bool set_reset(bool high) override;
  void delay_ms(uint32_t ms) override;

  size_t max_transfer() const { return max_transfer_; }
  // Why the last call failed.
  const std::string& error() const { return error_; }

 private:
  bool send(bool data, const uint8_t* bytes, size_t n);

  SpiDevice spi_;
  GpioLines gpio_;
  size_t max_transfer_ = 4096;
  std::string error_;
};

// A panel on a real SPI bus, initialized and ready to render into `sink`.
struct SpiPanel {
  Panel panel;
  std::unique_ptr<SpiTransport> transport;
  std::unique_ptr<PanelSink> sink;
};

// Checks the panel name and rotation, opens the bus and runs the panel's init sequence. nullptr with
// a one-line message (the caller prints it and exits 1); nothing stays open on failure.
std::unique_ptr<SpiPanel> open_spi_panel(const SpiPanelConfig& config, std::string* error);

}  // namespace mlpanels
