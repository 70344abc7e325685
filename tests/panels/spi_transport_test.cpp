// The Linux spidev + libgpiod transport's error paths (this machine has no SPI controller or GPIO
// chip): one clear message, nothing left open.
#include <gtest/gtest.h>
#include <stdio.h>
#include <unistd.h>

#include <string>

#include "platform/linux/spi/spi_transport.h"

namespace {

using mlpanels::SpiPanelConfig;

TEST(SpiTransport, MissingSpiDeviceIsOneClearError) {
  mlpanels::SpiDevice spi;
  std::string error;
  EXPECT_FALSE(spi.open("/dev/spidev9.9", 0, 8, 1000000, &error));
  EXPECT_FALSE(spi.is_open());
  EXPECT_NE(error.find("/dev/spidev9.9"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);

  SpiPanelConfig config;
  config.device = "/dev/spidev9.9";
  error.clear();
  EXPECT_FALSE(mlpanels::open_spi_panel(config, &error));
  EXPECT_NE(error.find("cannot open SPI device /dev/spidev9.9"), std::string::npos) << error;
}

TEST(SpiTransport, NonSpiFileIsRefused) {
  mlpanels::SpiDevice spi;
  std::string error;
  EXPECT_FALSE(spi.open("/dev/null", 0, 8, 1000000, &error));
  EXPECT_FALSE(spi.is_open());
  EXPECT_NE(error.find("not an spidev device"), std::string::npos) << error;
  EXPECT_FALSE(spi.transfer(reinterpret_cast<const uint8_t*>("x"), 1, &error));
}

TEST(SpiTransport, MissingGpioChipIsOneClearError) {
  mlpanels::GpioLines gpio;
  std::string error;
  EXPECT_FALSE(gpio.open("gpiochip97", 25, 24, &error));
  EXPECT_FALSE(gpio.is_open());
  EXPECT_NE(error.find("GPIO chip gpiochip97"), std::string::npos) << error;
  EXPECT_FALSE(gpio.set_dc(true));
  EXPECT_FALSE(gpio.set_reset(true));
  error.clear();
  EXPECT_FALSE(gpio.open("/dev/no-such-gpiochip", 25, -1, &error));
  EXPECT_NE(error.find("/dev/no-such-gpiochip"), std::string::npos) << error;
  error.clear();
  EXPECT_FALSE(gpio.open("gpiochip0", -1, -1, &error));
  EXPECT_NE(error.find("D/C"), std::string::npos) << error;
}

TEST(SpiTransport, PanelNameAndRotationCheckedFirst) {
  SpiPanelConfig config;
  config.device = "/dev/spidev9.9";
  config.panel = "nope";
  std::string error;
  EXPECT_FALSE(mlpanels::open_spi_panel(config, &error));
  EXPECT_NE(error.find("unknown panel 'nope'"), std::string::npos) << error;
  config.panel = "ssd1306";
  config.rotation = 90;
  EXPECT_FALSE(mlpanels::open_spi_panel(config, &error));
  EXPECT_NE(error.find("rotation 90"), std::string::npos) << error;
  config.rotation = 0;
  config.mode = 7;
  EXPECT_FALSE(mlpanels::open_spi_panel(config, &error));
  EXPECT_NE(error.find("mode"), std::string::npos) << error;
  EXPECT_FALSE(mlpanels::open_spi_panel(config, nullptr));
}

TEST(SpiTransport, BufsizFromSysfsOrDefault) {
  EXPECT_EQ(mlpanels::spidev_bufsiz("/nonexistent/bufsiz"), 4096u);
  char path[] = "/tmp/maskline-bufsizXXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  const char text[] = "65536\n";
  ASSERT_EQ(write(fd, text, sizeof text - 1), ssize_t(sizeof text - 1));
  close(fd);
  EXPECT_EQ(mlpanels::spidev_bufsiz(path), 65536u);
  FILE* f = fopen(path, "w");
  ASSERT_TRUE(f);
  fputs("garbage\n", f);
  fclose(f);
  EXPECT_EQ(mlpanels::spidev_bufsiz(path), 4096u);
  unlink(path);
}

}  // namespace

namespace {

TEST(SpiTransport, ParsesDisplaySpecs) {
  mlpanels::SpiPanelConfig c;
  std::string error;
  ASSERT_TRUE(mlpanels::parse_spi_panel_spec("st7789-240,rotation=90,device=/dev/spidev1.0,speed=40000000,mode=3,"
                                             "chip=gpiochip2,dc=17,reset=-1,max=1024",
                                             &c, &error))
      << error;
  EXPECT_EQ(c.panel, "st7789-240");
  EXPECT_EQ(c.rotation, 90);
  EXPECT_EQ(c.device, "/dev/spidev1.0");
  EXPECT_EQ(c.speed_hz, 40000000u);
  EXPECT_EQ(c.mode, 3);
  EXPECT_EQ(c.gpio_chip, "gpiochip2");
  EXPECT_EQ(c.dc_line, 17);
  EXPECT_EQ(c.reset_line, -1);
  EXPECT_EQ(c.max_transfer, 1024u);
  mlpanels::SpiPanelConfig d;
  ASSERT_TRUE(mlpanels::parse_spi_panel_spec("ssd1306", &d, &error));
  EXPECT_EQ(d.panel, "ssd1306");
  EXPECT_EQ(d.device, "/dev/spidev0.0");
  EXPECT_FALSE(mlpanels::parse_spi_panel_spec("", &d, &error));
  EXPECT_FALSE(mlpanels::parse_spi_panel_spec("ili9341,dc", &d, &error));
  EXPECT_FALSE(mlpanels::parse_spi_panel_spec("ili9341,dc=x", &d, &error));
  EXPECT_NE(error.find("dc needs a number"), std::string::npos) << error;
  EXPECT_FALSE(mlpanels::parse_spi_panel_spec("ili9341,mode=4", &d, &error));
  EXPECT_FALSE(mlpanels::parse_spi_panel_spec("ili9341,colour=red", &d, &error));
  EXPECT_NE(error.find("unknown option 'colour'"), std::string::npos) << error;
  EXPECT_EQ(d.panel, "ssd1306");  // unchanged on failure
}

}  // namespace
