// side_by_side: joins PNG images left to right on one canvas, optionally cropped and enlarged with
// square pixels, so renders can be compared by eye (make demo: point-sampled against antialiased).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <string>
#include <vector>

#include "platform/host/png_io.h"

namespace {

constexpr int kGap = 4;                    // pixels between images
constexpr ml::Pixel kGapColour = 0xFFFFFF;

struct Picture {
  int width = 0, height = 0;
  std::vector<uint32_t> pixels;
};

int usage(const char* why) {
  if (why) fprintf(stderr, "side_by_side: %s\n", why);
  fprintf(why ? stderr : stdout,
          "usage: side_by_side OUT.png [--crop X,Y,W,H] [--zoom N] IN.png IN.png...\n"
          "\n"
          "Joins the images left to right (4 white pixels apart). --crop takes the same rectangle of\n"
          "each image; --zoom (1..16) enlarges it with square pixels.\n");
  return why ? 2 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) return usage(nullptr);
  if (argc < 3) return usage("an output file and at least one image are needed");
  const std::string out = argv[1];
  int crop[4] = {0, 0, 0, 0}, zoom = 1;
  std::vector<Picture> pictures;
  for (int i = 2; i < argc; ++i) {
    if (strcmp(argv[i], "--crop") == 0 && i + 1 < argc) {
      if (sscanf(argv[++i], "%d,%d,%d,%d", &crop[0], &crop[1], &crop[2], &crop[3]) != 4 || crop[0] < 0 ||
          crop[1] < 0 || crop[2] < 1 || crop[3] < 1)
        return usage("--crop: expected X,Y,W,H with W, H >= 1");
    } else if (strcmp(argv[i], "--zoom") == 0 && i + 1 < argc) {
      zoom = atoi(argv[++i]);
      if (zoom < 1 || zoom > 16) return usage("--zoom: expected 1..16");
    } else {
      Picture p;
      const std::string error = mlhost::read_png(argv[i], &p.width, &p.height, &p.pixels, false);
      if (!error.empty()) {
        fprintf(stderr, "side_by_side: %s: %s\n", argv[i], error.c_str());
        return 1;
      }
      pictures.push_back(std::move(p));
    }
  }
  if (pictures.empty()) return usage("no input image");
  const Picture& first = pictures[0];
  const int cw = crop[2] ? crop[2] : first.width, ch = crop[3] ? crop[3] : first.height;
  for (const Picture& p : pictures)
    if (crop[0] + cw > p.width || crop[1] + ch > p.height) return usage("the crop does not fit every image");
  const int n = int(pictures.size());
  const int width = n * cw * zoom + (n - 1) * kGap, height = ch * zoom;
  std::vector<ml::Pixel> canvas(size_t(width) * size_t(height), kGapColour);
  for (int k = 0; k < n; ++k)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < cw * zoom; ++x) {
        const Picture& p = pictures[size_t(k)];
        const uint32_t v = p.pixels[size_t(crop[1] + y / zoom) * size_t(p.width) + size_t(crop[0] + x / zoom)];
        canvas[size_t(y) * size_t(width) + size_t(k * (cw * zoom + kGap) + x)] = v & 0xFFFFFF;
      }
  const std::string error = mlhost::write_png_rgb(out, width, height, canvas);
  if (!error.empty()) {
    fprintf(stderr, "side_by_side: %s\n", error.c_str());
    return 1;
  }
  return 0;
}
