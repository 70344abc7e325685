// Texture encoding for the scene blob: resampling to power-of-two sides and the device formats of
// scene/blob_format.h (RGB565, 8-bit palette by median cut, 4-bit grey). docs/textures.md.
#include <algorithm>
#include <array>
#include <map>

#include "core/fixed.h"
#include "scenec.h"

namespace ml {
namespace {

struct Rgb {
  int r, g, b;
};

// The power of two nearest to n (in ratio), within [1, limit].
int pow2_side(int n, int limit) {
  int p = 1;
  while (p * 2 <= n && p * 2 <= limit) p *= 2;
  if (p * 2 <= limit && n - p > 2 * p - n) p *= 2;
  return p;
}

// Box-filtered resample of an RGBA8 image to w x h: each target texel averages up to 8 x 8 source taps.
std::vector<Rgb> resample(const MeshImage& image, int w, int h) {
  std::vector<Rgb> out(size_t(w) * size_t(h));
  const int kx = std::min(8, std::max(1, (image.width + w - 1) / w));
  const int ky = std::min(8, std::max(1, (image.height + h - 1) / h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      long sum[3] = {0, 0, 0};
      for (int j = 0; j < ky; ++j)
        for (int i = 0; i < kx; ++i) {
          const int sx = std::min(image.width - 1, int((double(x) + (i + 0.5) / kx) * image.width / w));
          const int sy = std::min(image.height - 1, int((double(y) + (j + 0.5) / ky) * image.height / h));
          const uint8_t* p = &image.rgba[(size_t(sy) * size_t(image.width) + size_t(sx)) * 4];
          for (int c = 0; c < 3; ++c) sum[c] += p[c];
        }
      const long n = long(kx) * ky;
      out[size_t(y) * size_t(w) + size_t(x)] = Rgb{int((sum[0] + n / 2) / n), int((sum[1] + n / 2) / n),
                                                   int((sum[2] + n / 2) / n)};
    }
  return out;
}

uint16_t to_565(const Rgb& c) {
  return uint16_t(((c.r * 31 + 127) / 255) << 11 | ((c.g * 63 + 127) / 255) << 5 | ((c.b * 31 + 127) / 255));
}
Rgb from_565(uint16_t v) {
  const int r = (v >> 11) & 31, g = (v >> 5) & 63, b = v & 31;
  return Rgb{(r << 3) | (r >> 2), (g << 2) | (g >> 4), (b << 3) | (b >> 2)};
}
void put16(std::vector<uint8_t>* out, uint16_t v) {
  out->push_back(uint8_t(v & 0xFF));
  out->push_back(uint8_t(v >> 8));
}

// Median cut (Heckbert): split the box of colours with the widest channel range at its weighted
// median until there are `limit` boxes; each palette entry is its box's weighted mean.
std::vector<uint16_t> median_cut(const std::map<uint16_t, long>& histogram, size_t limit) {
  struct Entry { Rgb c; long n; };
  std::vector<std::vector<Entry>> boxes(1);
  for (const auto& h : histogram) boxes[0].push_back(Entry{from_565(h.first), h.second});
  auto range = [](const std::vector<Entry>& box, int* channel) {
    int best = -1;
    for (int ch = 0; ch < 3; ++ch) {
      int lo = 255, hi = 0;
      for (const Entry& e : box) {
        const int v = ch == 0 ? e.c.r : ch == 1 ? e.c.g : e.c.b;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      if (hi - lo > best) { best = hi - lo; *channel = ch; }
    }
    return best;
  };
  while (boxes.size() < limit) {
    size_t pick = boxes.size();
    int pick_range = 0, channel = 0;
    for (size_t i = 0; i < boxes.size(); ++i) {
      int ch = 0;
      const int r = boxes[i].size() > 1 ? range(boxes[i], &ch) : 0;
      if (r > pick_range) { pick_range = r; pick = i; channel = ch; }
    }
    if (pick == boxes.size()) break;  // every box is a single colour
    std::vector<Entry>& box = boxes[pick];
    std::sort(box.begin(), box.end(), [channel](const Entry& a, const Entry& b) {
      const int va = channel == 0 ? a.c.r : channel == 1 ? a.c.g : a.c.b;
      const int vb = channel == 0 ? b.c.r : channel == 1 ? b.c.g : b.c.b;
      return va < vb;
    });
    long total = 0, run = 0;
    for (const Entry& e : box) total += e.n;
    size_t cut = 1;
    for (size_t i = 0; i + 1 < box.size(); ++i) {
      run += box[i].n;
      cut = i + 1;
      if (2 * run >= total) break;
    }
    boxes.emplace_back(box.begin() + long(cut), box.end());
    boxes[pick].resize(cut);
  }
  std::vector<uint16_t> palette;
  for (const auto& box : boxes) {
    double sum[3] = {0, 0, 0}, n = 0;
    for (const Entry& e : box) {
      sum[0] += double(e.c.r) * e.n; sum[1] += double(e.c.g) * e.n; sum[2] += double(e.c.b) * e.n;
      n += e.n;
    }
    palette.push_back(to_565(Rgb{int(sum[0] / n + 0.5), int(sum[1] / n + 0.5), int(sum[2] / n + 0.5)}));
  }
  return palette;
}

int nearest_index(const std::vector<uint16_t>& palette, const Rgb& c) {
  int best = 0;
  long best_d = -1;
  for (size_t i = 0; i < palette.size(); ++i) {
    const Rgb p = from_565(palette[i]);
    const long d = long(p.r - c.r) * (p.r - c.r) + long(p.g - c.g) * (p.g - c.g) + long(p.b - c.b) * (p.b - c.b);
    if (best_d < 0 || d < best_d) { best_d = d; best = int(i); }
  }
  return best;
}

int luma(const Rgb& c) { return (77 * c.r + 150 * c.g + 29 * c.b + 128) >> 8; }

// The next mip level of w x h texels: each texel the rounded mean of the (up to) 2 x 2 it covers.
std::vector<Rgb> half_level(const std::vector<Rgb>& texels, int w, int h) {
  const int hw = std::max(1, w / 2), hh = std::max(1, h / 2), kx = w > 1 ? 2 : 1, ky = h > 1 ? 2 : 1;
  std::vector<Rgb> out(size_t(hw) * size_t(hh));
  for (int y = 0; y < hh; ++y)
    for (int x = 0; x < hw; ++x) {
      int sum[3] = {0, 0, 0};
      for (int j = 0; j < ky; ++j)
        for (int i = 0; i < kx; ++i) {
          const Rgb& c = texels[size_t(y * ky + j) * size_t(w) + size_t(x * kx + i)];
          sum[0] += c.r, sum[1] += c.g, sum[2] += c.b;
        }
      const int n = kx * ky;
      out[size_t(y) * size_t(hw) + size_t(x)] = Rgb{(sum[0] + n / 2) / n, (sum[1] + n / 2) / n, (sum[2] + n / 2) / n};
    }
  return out;
}

// A palette8 texture's palette: the median cut of its colours (exact for at most 256); with mip
// levels, whose means are colours of their own, the texture's colours and then as many more entries
// as are left cut from the levels' colours (or, past 256 colours, one cut of them all, the levels'
// weighted by their texel counts as the texture's are).
std::vector<uint16_t> level_palette(const std::map<uint16_t, long>& histogram, const std::vector<std::vector<Rgb>>& levels) {
  if (levels.empty() || histogram.size() > 256) {
    std::map<uint16_t, long> all = histogram;
    for (const auto& level : levels)
      for (const Rgb& c : level) ++all[to_565(c)];
    return median_cut(all, 256);
  }
  std::vector<uint16_t> palette = median_cut(histogram, 256);  // the texture's own colours, exactly
  std::map<uint16_t, long> extra;
  for (const auto& level : levels)
    for (const Rgb& c : level)
      if (!histogram.count(to_565(c))) ++extra[to_565(c)];
  if (!extra.empty() && palette.size() < 256)
    for (uint16_t p : median_cut(extra, 256 - palette.size())) palette.push_back(p);
  return palette;
}

// One level's bytes in the texture's format (scene/blob_format.h): palette8 with the texture's
// palette (each colour's nearest entry, kept in `index`).
void encode_level(const std::vector<Rgb>& texels, int w, int h, TexelFormat format, const std::vector<uint16_t>& palette,
                  std::map<uint16_t, int>* index, std::vector<uint8_t>* out) {
  if (format == TexelFormat::Rgb565) {
    for (const Rgb& c : texels) put16(out, to_565(c));
  } else if (format == TexelFormat::Palette8) {
    for (uint16_t p : palette) put16(out, p);
    for (const Rgb& c : texels) {
      const uint16_t key = to_565(c);
      auto it = index->find(key);
      if (it == index->end()) it = index->emplace(key, nearest_index(palette, from_565(key))).first;
      out->push_back(uint8_t(it->second));
    }
  } else {
    const int row = (w + 1) / 2;
    const size_t start = out->size();
    out->resize(start + size_t(row) * size_t(h), 0);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int g = (luma(texels[size_t(y) * size_t(w) + size_t(x)]) * 15 + 127) / 255;
        (*out)[start + size_t(y) * size_t(row) + size_t(x / 2)] |= uint8_t((x & 1) ? g << 4 : g);
      }
  }
}

}  // namespace

EncodedTexture encode_texture(const MeshImage& image, const MeshSampler& sampler, const CompileOptions& options) {
  EncodedTexture out;
  if (image.width <= 0 || image.height <= 0 || image.rgba.size() != size_t(image.width) * size_t(image.height) * 4)
    return out;  // format None
  const int limit = std::max(1, std::min(int(kMaxTextureDim), options.texture_max_size));
  const int w = pow2_side(image.width, limit), h = pow2_side(image.height, limit);
  const std::vector<Rgb> texels = resample(image, w, h);

  std::map<uint16_t, long> histogram;
  std::map<int, long> greys;
  bool grey = true;
  for (const Rgb& c : texels) {
    ++histogram[to_565(c)];
    grey = grey && c.r == c.g && c.g == c.b;
    if (grey) ++greys[c.r];
  }
  TexelFormat format = TexelFormat::Rgb565;
  switch (options.texture_format) {
    case TextureFormatChoice::Rgb565: format = TexelFormat::Rgb565; break;
    case TextureFormatChoice::Palette8: format = TexelFormat::Palette8; break;
    case TextureFormatChoice::Grey4: format = TexelFormat::Grey4; break;
    case TextureFormatChoice::None:  // (compile_mesh passes no image then)
    case TextureFormatChoice::Auto:
      format = grey && greys.size() <= 16 ? TexelFormat::Grey4
               : histogram.size() <= 256  ? TexelFormat::Palette8
                                          : TexelFormat::Rgb565;
      break;
  }
  out.info.width = uint16_t(w);
  out.info.height = uint16_t(h);
  out.info.format = uint8_t(format);
  out.info.wrap_s = uint8_t(sampler.wrap_s);
  out.info.wrap_t = uint8_t(sampler.wrap_t);
  out.info.filter = uint8_t(options.texture_filter == TextureFilterChoice::Nearest    ? TextureFilter::Nearest
                            : options.texture_filter == TextureFilterChoice::Bilinear ? TextureFilter::Bilinear
                                                                                      : sampler.filter);
  // The mip levels' texels, when stored: from the resampled texels, before they take the format.
  const bool mips = options.texture_mips == TextureMipChoice::On ||
                    (options.texture_mips == TextureMipChoice::Auto && sampler.mipmaps);
  std::vector<std::vector<Rgb>> levels;
  for (uint32_t l = 1; mips && l <= texture_max_levels(uint32_t(w), uint32_t(h)); ++l)
    levels.push_back(half_level(l == 1 ? texels : levels.back(), int(level_side(uint32_t(w), l - 1)),
                                int(level_side(uint32_t(h), l - 1))));
  std::vector<uint16_t> palette;
  if (format == TexelFormat::Palette8) {
    palette = level_palette(histogram, levels);
    out.info.palette_size = uint16_t(palette.size());
  }
  std::map<uint16_t, int> index;  // each distinct colour's nearest palette entry
  encode_level(texels, w, h, format, palette, &index, &out.bytes);
  for (uint32_t l = 1; l <= levels.size(); ++l)
    encode_level(levels[l - 1], int(level_side(uint32_t(w), l)), int(level_side(uint32_t(h), l)), format, palette,
                 &index, &out.bytes);
  out.info.levels = uint8_t(levels.size());
  out.info.bytes = uint32_t(out.bytes.size());
  return out;
}

}  // namespace ml
