#include "tests/oracle/texturer.h"
#include "tests/oracle/vec3_math.h"

#include <algorithm>
#include <cmath>

namespace oracle {
namespace {

int wrap(long i, int n, Wrap mode) {
  if (mode == Wrap::Clamp) return int(i < 0 ? 0 : (i >= n ? n - 1 : i));
  long m = ((i % (2L * n)) + 2L * n) % (2L * n);
  if (mode == Wrap::Repeat) return int(m % n);
  return int(m < n ? m : 2L * n - 1 - m);
}

double channel(uint32_t c, int k) { return double((c >> (16 - 8 * k)) & 0xFF); }

// Level margin: a level choice this close to the next is not compared (the renderers round the
// projected vertices).
constexpr double kLevelMargin = 0.02;

// The mip level of triangle t with surface s of texture tex, or -1 when too close to call: its area in
// texels over its area in pixels, projected exactly.
int mip_level(const Triangle& t, const Surface& s, const Texture& tex, const Camera& cam, const Vec3& forward,
              const Vec3& right, const Vec3& down, double focal) {
  if (tex.levels.empty()) return 0;
  double px[3], py[3];
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = sub(t.v[i], cam.eye);
    const double z = dot(d, forward);
    if (z <= cam.near) return -1;
    px[i] = focal * dot(d, right) / z;
    py[i] = focal * dot(d, down) / z;
  }
  const double pixels = std::fabs((px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]));
  const double texels = std::fabs((s.uv[1][0] - s.uv[0][0]) * (s.uv[2][1] - s.uv[0][1]) -
                                  (s.uv[2][0] - s.uv[0][0]) * (s.uv[1][1] - s.uv[0][1])) *
                        tex.width * tex.height;
  if (texels == 0) return 0;
  if (pixels == 0) return int(tex.levels.size());
  const double lambda = std::log2(texels / pixels) / 2 + 0.5;
  if (std::fabs(lambda - std::round(lambda)) < kLevelMargin && lambda > 1 - kLevelMargin &&
      lambda < double(tex.levels.size()) + kLevelMargin)
    return -1;
  return std::clamp(int(std::floor(lambda)), 0, int(tex.levels.size()));
}

}  // namespace

std::vector<TexturedPixel> texture_image(const std::vector<Triangle>& triangles, const std::vector<Surface>& surfaces,
                                         const std::vector<Texture>& textures, const Camera& cam,
                                         const Result& visible, double texel_margin, double edge_margin,
                                         const CoordinateError& error) {
  std::vector<TexturedPixel> out(size_t(cam.width) * size_t(cam.height));
  const Vec3 forward = normalized(sub(cam.target, cam.eye));
  const Vec3 right = normalized(cross(forward, cam.up));
  const Vec3 down = cross(forward, right);
  const double focal = (cam.height / 2.0) / std::tan(cam.vfov_deg * M_PI / 360.0);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const size_t i = visible.index(x, y);
      const int64_t id = visible.id[i];
      if (id < 0 || !visible.decisive(x, y, edge_margin)) continue;
      const Surface& s = surfaces[size_t(id)];
      if (s.texture < 0) continue;
      const Triangle& t = triangles[size_t(id)];
      // Texture coordinates where the ray through pixel centre (px + 0.5, y + 0.5) meets the triangle's
      // plane: Moller-Trumbore without the inside test (the rasterizer decided coverage).
      auto uv_at = [&](double px, double uv[2]) {
        const Vec3 dir = add(forward, add(scale(right, (px + 0.5 - cam.width / 2.0) / focal),
                                          scale(down, (y + 0.5 - cam.height / 2.0) / focal)));
        const Vec3 e1 = sub(t.v[1], t.v[0]), e2 = sub(t.v[2], t.v[0]);
        const Vec3 p = cross(dir, e2);
        const double det = dot(e1, p);
        if (std::fabs(det) < 1e-30) return false;
        const Vec3 o = sub(cam.eye, t.v[0]);
        const double b1 = dot(o, p) / det;
        const double b2 = dot(dir, cross(o, e1)) / det;
        const double b0 = 1 - b1 - b2;
        for (int k = 0; k < 2; ++k) uv[k] = b0 * s.uv[0][k] + b1 * s.uv[1][k] + b2 * s.uv[2][k];
        return true;
      };
      double uv[2];
      if (!uv_at(x, uv)) continue;
      const double u = uv[0], v = uv[1];
      const Texture& whole = textures[size_t(s.texture)];
      const int level = mip_level(t, s, whole, cam, forward, right, down, focal);
      if (level < 0) continue;
      const Texture& tex = level == 0 ? whole : whole.levels[size_t(level - 1)];
      // The coordinate error allowed here, in texels.
      double delta = tex.bilinear ? error.texel_bilinear : error.texel_nearest;
      if (error.shift > 0) {
        const int x0 = x - x % error.segment;
        double a[2], b[2];
        if (!uv_at(x0, a) || !uv_at(x0 + error.segment, b)) continue;
        const double step = std::max(std::fabs(b[0] - a[0]) * tex.width, std::fabs(b[1] - a[1]) * tex.height) /
                            error.segment;
        delta = std::max(delta, error.shift * step);
      }
      double texel[3];
      TexturedPixel& px = out[i];
      if (!tex.bilinear) {
        const double su = u * tex.width, sv = v * tex.height;
        const double fu = su - std::floor(su), fv = sv - std::floor(sv), m = texel_margin + delta;
        if (fu < m || fu > 1 - m || fv < m || fv > 1 - m) continue;
        const uint32_t c = tex.rgb[size_t(wrap(long(std::floor(sv)), tex.height, tex.wrap_t)) * size_t(tex.width) +
                                   size_t(wrap(long(std::floor(su)), tex.width, tex.wrap_s))];
        for (int k = 0; k < 3; ++k) texel[k] = channel(c, k);
      } else {
        const double su = u * tex.width - 0.5, sv = v * tex.height - 0.5;
        const long x0 = long(std::floor(su)), y0 = long(std::floor(sv));
        const double fu = su - double(x0), fv = sv - double(y0);
        for (int k = 0; k < 3; ++k) {
          auto at = [&](long xx, long yy) {
            return channel(tex.rgb[size_t(wrap(yy, tex.height, tex.wrap_t)) * size_t(tex.width) +
                                   size_t(wrap(xx, tex.width, tex.wrap_s))], k);
          };
          texel[k] = (at(x0, y0) * (1 - fu) + at(x0 + 1, y0) * fu) * (1 - fv) +
                     (at(x0, y0 + 1) * (1 - fu) + at(x0 + 1, y0 + 1) * fu) * fv;
          // Moving the sample point by delta along an axis changes the blend by at most delta times
          // the largest step between neighbours in the texels it can reach; and, both blends being
          // means of those texels, by at most their range (the tighter of the two when delta spans
          // texels: minified textures).
          double steepest = 0, lo = 255, hi = 0;
          const long reach = long(std::ceil(delta)) + 1;
          for (long yy = y0 - reach; yy <= y0 + reach; ++yy)
            for (long xx = x0 - reach; xx <= x0 + reach; ++xx) {
              steepest = std::max(steepest, std::fabs(at(xx + 1, yy) - at(xx, yy)));
              steepest = std::max(steepest, std::fabs(at(xx, yy + 1) - at(xx, yy)));
              lo = std::min(lo, at(xx, yy));
              hi = std::max(hi, at(xx, yy));
            }
          px.slack[k] = std::min(2 * delta * steepest, hi - lo) * channel(s.base, k) / 255.0;
        }
      }
      px.known = true;
      for (int k = 0; k < 3; ++k) px.rgb[k] = texel[k] * channel(s.base, k) / 255.0;
    }
  return out;
}

}  // namespace oracle
