#include "platform/host/displays.h"

#include "platform/host/panel_emulator.h"
#include "platform/linux/fbdev/fbdev_sink.h"
#include "platform/linux/spi/spi_transport.h"
#include "platform/panels/panel.h"

namespace mlhost {

namespace {

class FbDisplay : public Display {
 public:
  explicit FbDisplay(std::unique_ptr<mlfb::FbdevSink> fb) : fb_(std::move(fb)) {}
  ml::Sink& sink() override { return *fb_; }
  ml::PixelFormat format() const override { return fb_->format(); }
  int width() const override { return fb_->width(); }
  int height() const override { return fb_->height(); }
  bool accepts(int w, int h) const override { return w <= width() && h <= height(); }
  std::string describe() const override { return fb_->describe(); }
  std::string error() const override { return fb_->last_error(); }

 private:
  std::unique_ptr<mlfb::FbdevSink> fb_;
};

class PanelDisplay : public Display {
 public:
  PanelDisplay(const mlpanels::Panel& panel, std::string name) : panel_(panel), name_(std::move(name)) {}
  ml::PixelFormat format() const override { return panel_.format(); }
  int width() const override { return panel_.width(); }
  int height() const override { return panel_.height(); }
  std::string describe() const override {
    return name_ + ": " + panel_.name() + " " + std::to_string(width()) + "x" + std::to_string(height()) +
           " at rotation " + std::to_string(panel_.rotation());
  }

 protected:
  mlpanels::Panel panel_;
  std::string name_;
};

class EmuDisplay : public PanelDisplay {
 public:
  EmuDisplay(std::unique_ptr<mlpanels::EmulatedPanel> emu, std::string name)
      : PanelDisplay(emu->panel, std::move(name)), emu_(std::move(emu)) {}
  ml::Sink& sink() override { return emu_->sink; }
  std::string error() const override {
    if (!emu_->emulator.ok()) return "the emulated " + std::string(panel_.name()) + " saw " + emu_->emulator.error();
    return emu_->sink.error();
  }
  bool picture(std::vector<ml::Pixel>* pixels, int* w, int* h) const override {
    *pixels = emu_->emulator.picture();
    *w = emu_->emulator.width();
    *h = emu_->emulator.height();
    return true;
  }

 private:
  std::unique_ptr<mlpanels::EmulatedPanel> emu_;
};

class SpiDisplay : public PanelDisplay {
 public:
  SpiDisplay(std::unique_ptr<mlpanels::SpiPanel> spi, std::string name)
      : PanelDisplay(spi->panel, std::move(name)), spi_(std::move(spi)) {}
  ml::Sink& sink() override { return *spi_->sink; }
  std::string error() const override {
    return !spi_->transport->error().empty() ? spi_->transport->error() : std::string(spi_->sink->error());
  }

 private:
  std::unique_ptr<mlpanels::SpiPanel> spi_;
};

// "PANEL[,key=value...]": the panel name and whether `rotation=` was given.
std::string panel_of(const std::string& spec, bool* has_rotation) {
  *has_rotation = spec.find("rotation=") != std::string::npos;
  return spec.substr(0, spec.find(','));
}

// The rotation that mounts `panel` so it shows want_w x want_h (0 x 0: rotation 0); -1 when none does.
int fitting_rotation(const std::string& panel, int want_w, int want_h) {
  if (want_w == 0 && want_h == 0) return 0;
  for (int rotation : {0, 90, 180, 270}) {
    mlpanels::Panel p;
    if (mlpanels::make_panel(panel.c_str(), rotation, &p) && p.width() == want_w && p.height() == want_h)
      return rotation;
  }
  return -1;
}

// Fills in the rotation for a panel spec that has none; false with a message when no rotation fits.
bool choose_rotation(const std::string& panel, bool has_rotation, int want_w, int want_h, int* rotation,
                     std::string* error) {
  if (has_rotation) return true;
  mlpanels::Panel probe;
  if (!mlpanels::make_panel(panel.c_str(), 0, &probe)) {
    *error = "unknown panel '" + panel + "' (panels: " + mlpanels::panel_names() + ")";
    return false;
  }
  *rotation = fitting_rotation(panel, want_w, want_h);
  if (*rotation < 0) {
    *error = panel + " shows " + std::to_string(probe.width()) + "x" + std::to_string(probe.height()) + " or " +
             std::to_string(probe.height()) + "x" + std::to_string(probe.width()) + ", not " +
             std::to_string(want_w) + "x" + std::to_string(want_h) + " (leave --size out to use its size)";
    return false;
  }
  return true;
}

std::unique_ptr<Display> open_emu(const std::string& rest, int want_w, int want_h, std::string* error) {
  mlpanels::SpiPanelConfig config;  // the same "PANEL,key=value" grammar; only rotation matters here
  bool has_rotation = false;
  config.panel = panel_of(rest, &has_rotation);
  if (!mlpanels::parse_spi_panel_spec(rest, &config, error)) return nullptr;
  if (!choose_rotation(config.panel, has_rotation, want_w, want_h, &config.rotation, error)) return nullptr;
  auto emu = mlpanels::open_emulated_panel(config.panel, config.rotation, error);
  if (!emu) return nullptr;
  return std::unique_ptr<Display>(new EmuDisplay(std::move(emu), "emu"));
}

std::unique_ptr<Display> open_spi(const std::string& rest, int want_w, int want_h, std::string* error) {
  mlpanels::SpiPanelConfig config;
  bool has_rotation = false;
  config.panel = panel_of(rest, &has_rotation);
  if (!mlpanels::parse_spi_panel_spec(rest, &config, error)) return nullptr;
  if (!choose_rotation(config.panel, has_rotation, want_w, want_h, &config.rotation, error)) return nullptr;
  auto spi = mlpanels::open_spi_panel(config, error);
  if (!spi) return nullptr;
  return std::unique_ptr<Display>(new SpiDisplay(std::move(spi), config.device));
}

}  // namespace

std::unique_ptr<Display> open_display(const std::string& spec, int want_w, int want_h, std::string* error) {
  const size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string rest = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (colon == std::string::npos || rest.empty()) {
    *error = "--display: expected fb:/dev/fbN, spi:PANEL[,key=value...] or emu:PANEL[,rotation=DEG], got '" +
             spec + "'";
    return nullptr;
  }
  std::unique_ptr<Display> display;
  if (kind == "fb") {
    auto fb = mlfb::open_fbdev(rest, error);
    if (fb) display.reset(new FbDisplay(std::move(fb)));
  } else if (kind == "emu") {
    display = open_emu(rest, want_w, want_h, error);
  } else if (kind == "spi") {
    display = open_spi(rest, want_w, want_h, error);
  } else {
    *error = "--display: unknown display kind '" + kind + "' (fb, spi or emu)";
    return nullptr;
  }
  if (display && want_w > 0 && !display->accepts(want_w, want_h)) {
    *error = display->describe() + ": cannot show a " + std::to_string(want_w) + "x" + std::to_string(want_h) +
             " frame";
    return nullptr;
  }
  return display;
}

}  // namespace mlhost
