#include "tests/oracle/scene_triangles.h"

#include "tools/maskgen/filter_gen.h"

#include <algorithm>

namespace oracle {

std::vector<Triangle> scene_triangles(const ml::Scene& scene) {
  std::vector<Triangle> out(scene.triangle_count);
  for (uint32_t id = 0; id < scene.triangle_count; ++id) {
    ml::Vec3i w[3];
    ml::triangle_world(scene, id, w);
    for (int k = 0; k < 3; ++k) out[id].v[k] = {double(w[k].x), double(w[k].y), double(w[k].z)};
    const ml::Batch& batch = scene.batches[ml::triangle_at(scene, id).batch];
    out[id].double_sided = scene.materials[batch.material].double_sided != 0;
  }
  return out;
}

std::vector<Surface> scene_surfaces(const ml::Scene& scene) {
  std::vector<Surface> out(scene.triangle_count);
  for (uint32_t id = 0; id < scene.triangle_count; ++id) {
    const ml::Triangle& t = ml::triangle_at(scene, id);
    const ml::Material& m = scene.materials[scene.batches[t.batch].material];
    for (int k = 0; k < 3; ++k) {
      int32_t uv[2];
      ml::vertex_uv(scene, t.v[k], uv);
      out[id].uv[k][0] = uv[0] / 65536.0;
      out[id].uv[k][1] = uv[1] / 65536.0;
    }
    out[id].base = uint32_t(m.base_color[0]) << 16 | uint32_t(m.base_color[1]) << 8 | m.base_color[2];
    if (m.texture != ml::kNone && scene.texture_texels &&
        scene.texture_texels[m.texture].format != uint8_t(ml::TexelFormat::None))
      out[id].texture = int(m.texture);
  }
  return out;
}

std::vector<Texture> scene_textures(const ml::Scene& scene) {
  std::vector<Texture> out(scene.texture_texels_count);
  auto rgb565 = [](uint32_t v) {
    const uint32_t r = (v >> 11) & 31, g = (v >> 5) & 63, b = v & 31;
    // The format's expansion to 8 bits (blob_format.h): bit replication.
    return (r << 3 | r >> 2) << 16 | (g << 2 | g >> 4) << 8 | (b << 3 | b >> 2);
  };
  // Level l of texture t, read from its bytes as the blob format states them: levels one after the
  // other, each halving the sides down to 1, a Palette8 level with its palette.
  const auto decode = [&](const ml::TextureTexels& t, int level, size_t at, Texture* tex) {
    tex->width = std::max(1, t.width >> level);
    tex->height = std::max(1, t.height >> level);
    const Wrap wraps[3] = {Wrap::Repeat, Wrap::Mirrored, Wrap::Clamp};
    tex->wrap_s = wraps[t.wrap_s];
    tex->wrap_t = wraps[t.wrap_t];
    tex->bilinear = t.filter == uint8_t(ml::TextureFilter::Bilinear);
    const uint8_t* b = scene.texels + at;
    size_t bytes = 0;
    for (int y = 0; y < tex->height; ++y)
      for (int x = 0; x < tex->width; ++x) {
        const size_t k = size_t(y) * size_t(tex->width) + size_t(x);
        uint32_t c = 0;
        if (t.format == uint8_t(ml::TexelFormat::Rgb565)) {
          c = rgb565(b[2 * k] | uint32_t(b[2 * k + 1]) << 8);
          bytes = 2 * (k + 1);
        } else if (t.format == uint8_t(ml::TexelFormat::Palette8)) {
          const uint32_t index = b[2 * size_t(t.palette_size) + k];
          c = rgb565(b[2 * index] | uint32_t(b[2 * index + 1]) << 8);
          bytes = 2 * size_t(t.palette_size) + k + 1;
        } else {
          const size_t row = size_t(tex->width + 1) / 2;
          const uint32_t byte = b[size_t(y) * row + size_t(x / 2)];
          const uint32_t g = ((x & 1) ? byte >> 4 : byte & 15) * 17;
          c = g << 16 | g << 8 | g;
          bytes = size_t(y + 1) * row;
        }
        tex->rgb.push_back(c);
      }
    return bytes;
  };
  for (uint32_t i = 0; i < scene.texture_texels_count; ++i) {
    const ml::TextureTexels& t = scene.texture_texels[i];
    if (t.format == uint8_t(ml::TexelFormat::None)) continue;
    size_t at = t.offset + decode(t, 0, t.offset, &out[i]);
    out[i].levels.resize(t.levels);
    for (int l = 1; l <= t.levels; ++l) at += decode(t, l, at, &out[i].levels[size_t(l - 1)]);
  }
  return out;
}

Camera to_oracle_camera(const ml::Camera& c) {
  Camera o;
  o.eye = {double(c.eye.x), double(c.eye.y), double(c.eye.z)};
  o.target = {double(c.target.x), double(c.target.y), double(c.target.z)};
  o.up = {double(c.up.x), double(c.up.y), double(c.up.z)};
  o.vfov_deg = c.fov_deg_q16 / 65536.0;
  o.width = c.width;
  o.height = c.height;
  o.near = c.near;
  o.shift_x = c.sample_shift_x / 256.0;
  o.shift_y = c.sample_shift_y / 256.0;
  return o;
}

ml::Pixel base_colour(const ml::Scene& scene, int64_t id, ml::Pixel background) {
  if (id < 0) return background;
  const ml::Material& m = scene.materials[scene.batches[ml::triangle_at(scene, uint32_t(id)).batch].material];
  return ml::rgb(m.base_color[0], m.base_color[1], m.base_color[2]);
}

namespace {

// The scene's ids cast from rays x rays rays a pixel of `camera`.
Result rasterize_rays(const ml::Scene& scene, const ml::Camera& camera, int rays) {
  Camera c = to_oracle_camera(camera);
  c.width *= rays;
  c.height *= rays;
  return rasterize(scene_triangles(scene), c);
}

}  // namespace

std::vector<double> box_filtered_unlit(const ml::Scene& scene, const ml::Camera& camera, int rays,
                                       ml::Pixel background) {
  const Result ref = rasterize_rays(scene, camera, rays);
  std::vector<double> out(size_t(camera.width) * size_t(camera.height) * 3, 0.0);
  const double weight = 1.0 / (rays * rays);
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) {
      const ml::Pixel p = base_colour(scene, ref.id[ref.index(x, y)], background);
      const size_t i = size_t(y / rays) * size_t(camera.width) + size_t(x / rays);
      for (int k = 0; k < 3; ++k) out[i * 3 + size_t(k)] += double((p >> (16 - 8 * k)) & 0xFF) * weight;
    }
  return out;
}

std::vector<double> cosine_filtered_unlit(const ml::Scene& scene, const ml::Camera& camera, int rays,
                                          ml::Pixel background) {
  const Result ref = rasterize_rays(scene, camera, rays);
  const size_t pixels = size_t(camera.width) * size_t(camera.height);
  std::vector<double> out(pixels * 3, 0.0), weight(pixels, 0.0);
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) {
      const ml::Pixel p = base_colour(scene, ref.id[ref.index(x, y)], background);
      const double rx = (x + 0.5) / rays, ry = (y + 0.5) / rays;  // in pixels
      for (int py = y / rays - 1; py <= y / rays + 1; ++py)
        for (int px = x / rays - 1; px <= x / rays + 1; ++px) {
          if (px < 0 || py < 0 || px >= camera.width || py >= camera.height) continue;
          const double w = filtergen::hump(rx - (px + 0.5), ry - (py + 0.5));
          const size_t i = size_t(py) * size_t(camera.width) + size_t(px);
          weight[i] += w;
          for (int k = 0; k < 3; ++k) out[i * 3 + size_t(k)] += double((p >> (16 - 8 * k)) & 0xFF) * w;
        }
    }
  for (size_t i = 0; i < pixels; ++i)
    for (int k = 0; k < 3; ++k) out[i * 3 + size_t(k)] /= weight[i];
  return out;
}

}  // namespace oracle
