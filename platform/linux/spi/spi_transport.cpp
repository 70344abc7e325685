#include "platform/linux/spi/spi_transport.h"

#include <errno.h>
#include <fcntl.h>
#include <gpiod.h>
#include <linux/spi/spidev.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include <fstream>

namespace mlpanels {

namespace {

constexpr const char* kConsumer = "maskline";

std::string errno_text() { return strerror(errno); }

}  // namespace

bool parse_spi_panel_spec(const std::string& spec, SpiPanelConfig* out, std::string* error) {
  std::string ignored;
  if (!error) error = &ignored;
  SpiPanelConfig c = *out;
  size_t at = spec.find(',');
  c.panel = spec.substr(0, at);
  if (c.panel.empty()) {
    *error = "spi display: panel name missing";
    return false;
  }
  while (at != std::string::npos) {
    const size_t next = spec.find(',', at + 1);
    const std::string item = spec.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
    at = next;
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0) {
      *error = "spi display: expected key=value, got '" + item + "'";
      return false;
    }
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "device") {
      c.device = value;
      continue;
    }
    if (key == "chip") {
      c.gpio_chip = value;
      continue;
    }
    static const char* const kNumeric[] = {"rotation", "speed", "mode", "bits", "dc", "reset", "max"};
    bool known = false;
    for (const char* k : kNumeric) known = known || key == k;
    if (!known) {
      *error = "spi display: unknown option '" + key + "' (rotation, device, speed, mode, bits, chip, dc, reset, max)";
      return false;
    }
    char* end = nullptr;
    errno = 0;
    const long long n = strtoll(value.c_str(), &end, 0);
    if (value.empty() || *end != '\0' || errno != 0) {
      *error = "spi display: " + key + " needs a number, got '" + value + "'";
      return false;
    }
    auto in = [&](long long lo, long long hi) {
      if (n >= lo && n <= hi) return true;
      *error = "spi display: " + key + " must be " + std::to_string(lo) + ".." + std::to_string(hi);
      return false;
    };
    if (key == "rotation") {
      if (!in(0, 270)) return false;
      c.rotation = int(n);
    } else if (key == "speed") {
      if (!in(1, 200000000)) return false;
      c.speed_hz = uint32_t(n);
    } else if (key == "mode") {
      if (!in(0, 3)) return false;
      c.mode = uint8_t(n);
    } else if (key == "bits") {
      if (!in(1, 32)) return false;
      c.bits_per_word = uint8_t(n);
    } else if (key == "dc") {
      if (!in(0, 65535)) return false;
      c.dc_line = int(n);
    } else if (key == "reset") {
      if (!in(-1, 65535)) return false;
      c.reset_line = int(n);
    } else {  // max
      if (!in(0, 1 << 24)) return false;
      c.max_transfer = size_t(n);
    }
  }
  *out = c;
  return true;
}

size_t spidev_bufsiz(const std::string& path) {
  std::ifstream in(path);
  long long value = 0;
  if (in >> value && value > 0) return size_t(value);
  return 4096;
}

// ---- SpiDevice ----

SpiDevice::~SpiDevice() { close(); }

void SpiDevice::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool SpiDevice::open(const std::string& path, uint8_t mode, uint8_t bits, uint32_t speed_hz, std::string* error) {
  close();
  path_ = path;
  fd_ = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd_ < 0) {
    *error = "cannot open SPI device " + path + ": " + errno_text();
    return false;
  }
  const char* what = nullptr;
  if (ioctl(fd_, SPI_IOC_WR_MODE, &mode) < 0) what = "set mode on";
  else if (ioctl(fd_, SPI_IOC_WR_BITS_PER_WORD, &bits) < 0) what = "set bits per word on";
  else if (ioctl(fd_, SPI_IOC_WR_MAX_SPEED_HZ, &speed_hz) < 0) what = "set speed on";
  if (what) {
    *error = std::string("cannot ") + what + " " + path + " (not an spidev device?): " + errno_text();
    close();
    return false;
  }
  speed_hz_ = speed_hz;
  bits_ = bits;
  return true;
}

bool SpiDevice::transfer(const uint8_t* bytes, size_t n, std::string* error) {
  if (fd_ < 0) {
    *error = "SPI device not open";
    return false;
  }
  spi_ioc_transfer tr;
  memset(&tr, 0, sizeof tr);
  tr.tx_buf = reinterpret_cast<uintptr_t>(bytes);
  tr.len = uint32_t(n);
  tr.speed_hz = speed_hz_;
  tr.bits_per_word = bits_;
  if (ioctl(fd_, SPI_IOC_MESSAGE(1), &tr) < 0) {
    *error = "SPI transfer of " + std::to_string(n) + " bytes on " + path_ + " failed: " + errno_text();
    return false;
  }
  return true;
}

// ---- GpioLines ----

GpioLines::~GpioLines() { close(); }

void GpioLines::close() {
  if (dc_) gpiod_line_release(dc_);
  if (reset_) gpiod_line_release(reset_);
  dc_ = reset_ = nullptr;
  if (chip_) gpiod_chip_close(chip_);
  chip_ = nullptr;
  dc_value_ = -1;
}

bool GpioLines::open(const std::string& chip, int dc_line, int reset_line, std::string* error) {
  close();
  if (dc_line < 0) {
    *error = "a D/C line is required";
    return false;
  }
  chip_ = gpiod_chip_open_lookup(chip.c_str());
  if (!chip_) {
    *error = "cannot open GPIO chip " + chip + ": " + errno_text();
    return false;
  }
  auto request = [&](int offset, int initial, const char* role, gpiod_line** out) {
    gpiod_line* line = gpiod_chip_get_line(chip_, unsigned(offset));
    if (!line) {
      *error = std::string("no ") + role + " line " + std::to_string(offset) + " on GPIO chip " + chip + ": " +
               errno_text();
      return false;
    }
    if (gpiod_line_request_output(line, kConsumer, initial) < 0) {
      *error = std::string("cannot claim ") + role + " line " + std::to_string(offset) + " on GPIO chip " + chip +
               ": " + errno_text();
      return false;
    }
    *out = line;
    return true;
  };
  if (!request(dc_line, 0, "D/C", &dc_) || (reset_line >= 0 && !request(reset_line, 1, "RESET", &reset_))) {
    close();
    return false;
  }
  dc_value_ = 0;
  return true;
}

bool GpioLines::set_dc(bool high) {
  if (!dc_) return false;
  if (dc_value_ == int(high)) return true;
  if (gpiod_line_set_value(dc_, high ? 1 : 0) < 0) return false;
  dc_value_ = int(high);
  return true;
}

bool GpioLines::set_reset(bool high) {
  if (!reset_) return chip_ != nullptr;
  return gpiod_line_set_value(reset_, high ? 1 : 0) == 0;
}

// ---- SpiTransport ----

std::unique_ptr<SpiTransport> SpiTransport::open(const SpiPanelConfig& config, std::string* error) {
  std::string ignored;
  if (!error) error = &ignored;
  std::unique_ptr<SpiTransport> t(new SpiTransport());
  if (config.mode > 3) {
    *error = "SPI mode must be 0..3";
    return nullptr;
  }
  if (!t->spi_.open(config.device, config.mode, config.bits_per_word, config.speed_hz, error)) return nullptr;
  if (!t->gpio_.open(config.gpio_chip, config.dc_line, config.reset_line, error)) return nullptr;
  const size_t bufsiz = spidev_bufsiz(config.bufsiz_path);
  t->max_transfer_ = config.max_transfer != 0 && config.max_transfer < bufsiz ? config.max_transfer : bufsiz;
  return t;
}

bool SpiTransport::send(bool data, const uint8_t* bytes, size_t n) {
  if (!gpio_.set_dc(data)) {
    error_ = "cannot set the D/C line: " + errno_text();
    return false;
  }
  while (n > 0) {
    const size_t m = n > max_transfer_ ? max_transfer_ : n;
    if (!spi_.transfer(bytes, m, &error_)) return false;
    bytes += m;
    n -= m;
  }
  return true;
}

bool SpiTransport::set_reset(bool high) {
  if (gpio_.set_reset(high)) return true;
  error_ = "cannot set the RESET line: " + errno_text();
  return false;
}

void SpiTransport::delay_ms(uint32_t ms) {
  timespec ts;
  ts.tv_sec = time_t(ms / 1000);
  ts.tv_nsec = long(ms % 1000) * 1000000L;
  while (nanosleep(&ts, &ts) < 0 && errno == EINTR) {
  }
}

// ---- open_spi_panel ----

std::unique_ptr<SpiPanel> open_spi_panel(const SpiPanelConfig& config, std::string* error) {
  std::string ignored;
  if (!error) error = &ignored;
  std::unique_ptr<SpiPanel> out(new SpiPanel());
  if (!make_panel(config.panel.c_str(), config.rotation, &out->panel)) {
    Panel probe;
    *error = make_panel(config.panel.c_str(), 0, &probe)
                 ? "panel " + config.panel + " does not support rotation " + std::to_string(config.rotation)
                 : "unknown panel '" + config.panel + "' (known: " + panel_names() + ")";
    return nullptr;
  }
  out->transport = SpiTransport::open(config, error);
  if (!out->transport) return nullptr;
  out->sink.reset(new PanelSink(out->panel, *out->transport, out->transport->max_transfer()));
  if (!out->sink->init()) {
    *error = "panel " + config.panel + " init failed: " + out->transport->error();
    return nullptr;
  }
  return out;
}

}  // namespace mlpanels
