// Host side of the QEMU framebuffer test: compares QEMU's screendump (binary PPM) with the expected
// picture, quantized to the framebuffer's format (RGB565 at 16 bpp: the screendump's channels are
// compared by their top 5/6/5 bits; 24 and 32 bpp: exactly).
//   fb_check SCREEN.ppm BPP pattern          the frames of pattern.h (the whole screen)
//   fb_check SCREEN.ppm BPP png FRAME.png    a frame centred on the screen (the rest not compared)
// Prints one line ("match: ..." or what differs); exit 0 on a match, 1 on a difference, 2 on bad input.
#include <stdio.h>
#include <stdlib.h>

#include <string>
#include <vector>

#include "core/pixel_format.h"
#include "platform/host/png_io.h"
#include "tests/qemu-fbdev/pattern.h"

namespace {

bool read_ppm(const std::string& path, int* w, int* h, std::vector<ml::Pixel>* pixels, std::string* error) {
  FILE* f = fopen(path.c_str(), "rb");
  if (!f) {
    *error = path + ": cannot open";
    return false;
  }
  int maxval = 0;
  char magic[3] = {0, 0, 0};
  const bool header = fscanf(f, "%2s %d %d %d", magic, w, h, &maxval) == 4 && std::string(magic) == "P6" &&
                      maxval == 255 && *w > 0 && *h > 0 && fgetc(f) != EOF;
  if (!header) {
    fclose(f);
    *error = path + ": not an 8-bit binary PPM";
    return false;
  }
  std::vector<uint8_t> bytes(size_t(*w) * size_t(*h) * 3);
  const size_t got = fread(bytes.data(), 1, bytes.size(), f);
  fclose(f);
  if (got != bytes.size()) {
    *error = path + ": truncated";
    return false;
  }
  pixels->resize(size_t(*w) * size_t(*h));
  for (size_t i = 0; i < pixels->size(); ++i) (*pixels)[i] = ml::rgb(bytes[3 * i], bytes[3 * i + 1], bytes[3 * i + 2]);
  return true;
}

// The colour as the framebuffer holds it, compared field by field.
uint32_t key_of_expected(int bpp, ml::Pixel p) {
  return bpp == 16 ? ml::quantize_pixel(ml::PixelFormat::Rgb565Le, p, false, 0, 0) : p;
}
uint32_t key_of_screen(int bpp, ml::Pixel p) {
  return bpp == 16 ? (ml::red_of(p) >> 3) << 11 | (ml::green_of(p) >> 2) << 5 | ml::blue_of(p) >> 3 : p;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4 || (std::string(argv[3]) == "png" && argc < 5)) {
    fprintf(stderr, "usage: fb_check SCREEN.ppm BPP pattern | fb_check SCREEN.ppm BPP png FRAME.png\n");
    return 2;
  }
  const int bpp = atoi(argv[2]);
  const std::string mode = argv[3];
  int w = 0, h = 0;
  std::vector<ml::Pixel> screen;
  std::string error;
  if (!read_ppm(argv[1], &w, &h, &screen, &error)) {
    printf("%s\n", error.c_str());
    return 2;
  }
  int fx = 0, fy = 0, fw = w, fh = h;
  std::vector<uint32_t> frame;
  if (mode == "png") {
    error = mlhost::read_png(argv[4], &fw, &fh, &frame, false);
    if (!error.empty()) {
      printf("%s\n", error.c_str());
      return 2;
    }
    if (fw > w || fh > h) {
      printf("the frame %dx%d is larger than the screen %dx%d\n", fw, fh, w, h);
      return 1;
    }
    fx = (w - fw) / 2;
    fy = (h - fh) / 2;
  } else if (mode != "pattern") {
    fprintf(stderr, "fb_check: unknown mode %s\n", mode.c_str());
    return 2;
  }
  long differ = 0;
  std::string first;
  for (int y = 0; y < fh; ++y)
    for (int x = 0; x < fw; ++x) {
      const ml::Pixel want = mode == "png" ? frame[size_t(y) * size_t(fw) + size_t(x)] : fbtest::expected(x, y, w, h);
      const ml::Pixel got = screen[size_t(y + fy) * size_t(w) + size_t(x + fx)];
      if (key_of_expected(bpp, want) != key_of_screen(bpp, got)) {
        if (differ++ == 0) {
          char buf[160];
          snprintf(buf, sizeof buf, "first at (%d,%d): screen #%06X, expected #%06X", x + fx, y + fy, got, want);
          first = buf;
        }
      }
    }
  if (differ) {
    printf("%ld of %d pixels differ (%d bpp, %dx%d frame at %d,%d); %s\n", differ, fw * fh, bpp, fw, fh, fx, fy,
           first.c_str());
    return 1;
  }
  printf("match: %dx%d frame at %d,%d on a %dx%d screen, %d bpp\n", fw, fh, fx, fy, w, h, bpp);
  return 0;
}
