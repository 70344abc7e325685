#include "platform/cortex-m/lm3s6965evb/ssi_transport.h"

namespace fw {
namespace {

inline volatile uint32_t& reg(uint32_t address) { return *reinterpret_cast<volatile uint32_t*>(address); }
// A read for its side effect (popping the RX FIFO) or its delay.
inline void touch(uint32_t address) {
  const uint32_t value = reg(address);
  (void)value;
}

constexpr uint32_t kRcgc1 = 0x400FE104, kRcgc2 = 0x400FE108;
constexpr uint32_t kGpioA = 0x40004000, kGpioC = 0x40006000, kGpioD = 0x40007000;
constexpr uint32_t kGpioDir = 0x400, kGpioAfsel = 0x420, kGpioDen = 0x51C;
constexpr uint32_t kSsi0 = 0x40008000;
constexpr uint32_t kSsiCr0 = 0x00, kSsiCr1 = 0x04, kSsiDr = 0x08, kSsiSr = 0x0C, kSsiCpsr = 0x10;
constexpr uint32_t kSrTnf = 1u << 1, kSrRne = 1u << 2, kSrBsy = 1u << 4;

// GPIO data through the masked address: only the bits in the address mask are written.
inline void gpio_write(uint32_t base, uint32_t pin_mask, bool high) { reg(base + (pin_mask << 2)) = high ? pin_mask : 0; }

inline void drain_rx() {
  while (reg(kSsi0 + kSsiSr) & kSrRne) touch(kSsi0 + kSsiDr);
}

inline void wait_idle() {
  while (reg(kSsi0 + kSsiSr) & kSrBsy) drain_rx();
  drain_rx();
}

}  // namespace

void SsiTransport::init() {
  reg(kRcgc1) |= 1u << 4;                            // SSI0
  reg(kRcgc2) |= (1u << 0) | (1u << 2) | (1u << 3);  // GPIO A, C, D
  touch(kRcgc2);                                 // a few cycles before the peripherals are touched
  touch(kRcgc2);
  const uint32_t ssi_pins = (1u << 2) | (1u << 3) | (1u << 5);  // PA2 clock, PA3 frame, PA5 TX
  reg(kGpioA + kGpioAfsel) |= ssi_pins;
  reg(kGpioA + kGpioDen) |= ssi_pins;
  reg(kGpioC + kGpioDir) |= 1u << 7;                 // PC7: D/C
  reg(kGpioC + kGpioDen) |= 1u << 7;
  reg(kGpioD + kGpioDir) |= 1u << 0;                 // PD0: OLED chip select
  reg(kGpioD + kGpioDen) |= 1u << 0;
  gpio_write(kGpioD, 1u << 0, true);                 // select the OLED (QEMU: active high)
  reg(kSsi0 + kSsiCr1) = 0;                          // disabled while configuring; master
  reg(kSsi0 + kSsiCpsr) = 2;                         // clock prescaler
  reg(kSsi0 + kSsiCr0) = 0xC7;                       // 8-bit frames, Motorola SPI, SPO = 1, SPH = 1
  reg(kSsi0 + kSsiCr1) = 0x02;                       // enable
  drain_rx();
}

bool SsiTransport::write(bool data, const uint8_t* bytes, size_t n) {
  if (dc_ != int(data)) {
    wait_idle();
    gpio_write(kGpioC, 1u << 7, data);
    dc_ = int(data);
  }
  for (size_t i = 0; i < n; ++i) {
    while (!(reg(kSsi0 + kSsiSr) & kSrTnf)) drain_rx();
    reg(kSsi0 + kSsiDr) = bytes[i];
    drain_rx();
  }
  return true;
}

void SsiTransport::delay_ms(uint32_t ms) {
  // About 12,500 cycles a millisecond at the 12.5 MHz reset clock; a loop iteration is ~3 cycles.
  for (uint32_t i = 0; i < ms * 4000u; ++i) asm volatile("nop");
}

}  // namespace fw
