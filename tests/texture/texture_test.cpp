// Textures end to end: encoding in the compiler, the blob's texture fields and their validation, the
// sampler, both renderers choosing the same texel at every pixel, and the pager's residency, pool
// sweep, fault injection and bytes read (docs/textures.md).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include "core/band.h"
#include "platform/host/file_texture_source.h"
#include "platform/host/png_io.h"
#include "scanline/internal.h"
#include "tests/scene/scene_test_util.h"
#include "tests/texture/texture_test_util.h"
#include "texture/pager.h"
#include "texture/sampler.h"
#include "tiler/tiler.h"
#include "tools/scenec/scenec.h"

namespace {

using textest::Frame;
using textest::load;

ml::MeshImage image_of(int w, int h, uint32_t (*f)(int, int)) {
  ml::MeshImage im;
  im.width = w;
  im.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint32_t c = f(x, y);
      im.rgba.insert(im.rgba.end(), {uint8_t(c >> 16), uint8_t(c >> 8), uint8_t(c), 255});
    }
  return im;
}


// ---- compiler: formats ------------------------------------------------------------------------------

TEST(TextureEncode, AutoPicksTheFormatFromTheImage) {
  const ml::CompileOptions o;
  const ml::MeshSampler s;
  const auto grey = ml::encode_texture(image_of(16, 16, [](int x, int) { return uint32_t(x * 17) * 0x010101u; }), s, o);
  EXPECT_EQ(grey.info.format, uint8_t(ml::TexelFormat::Grey4));
  EXPECT_EQ(grey.info.bytes, 8u * 16u);
  const auto few = ml::encode_texture(image_of(16, 16, [](int x, int y) { return uint32_t((x / 4 + y) % 5) * 0x304050u; }), s, o);
  EXPECT_EQ(few.info.format, uint8_t(ml::TexelFormat::Palette8));
  EXPECT_LE(few.info.palette_size, 5u);
  EXPECT_EQ(few.info.bytes, few.info.palette_size * 2u + 256u);
  const auto many = ml::encode_texture(image_of(32, 32, [](int x, int y) { return uint32_t(x * 8) << 16 | uint32_t(y * 8) << 8 | 7; }), s, o);
  EXPECT_EQ(many.info.format, uint8_t(ml::TexelFormat::Rgb565));
  EXPECT_EQ(many.info.bytes, 32u * 32u * 2u);
  EXPECT_EQ(many.bytes.size(), many.info.bytes);
}

TEST(TextureEncode, FilterChoiceOverridesTheSampler) {
  const auto img = image_of(8, 8, [](int x, int y) { return uint32_t(x * 30) << 16 | uint32_t(y * 30); });
  ml::CompileOptions o;
  for (const ml::TextureFilter asked : {ml::TextureFilter::Nearest, ml::TextureFilter::Bilinear}) {
    ml::MeshSampler s;
    s.filter = asked;
    s.wrap_s = ml::TextureWrap::MirroredRepeat;
    o.texture_filter = ml::TextureFilterChoice::Model;
    EXPECT_EQ(ml::encode_texture(img, s, o).info.filter, uint8_t(asked));
    o.texture_filter = ml::TextureFilterChoice::Nearest;
    const auto nearest = ml::encode_texture(img, s, o);
    EXPECT_EQ(nearest.info.filter, uint8_t(ml::TextureFilter::Nearest));
    EXPECT_EQ(nearest.info.wrap_s, uint8_t(ml::TextureWrap::MirroredRepeat));  // the rest of the sampler kept
    o.texture_filter = ml::TextureFilterChoice::Bilinear;
    EXPECT_EQ(ml::encode_texture(img, s, o).info.filter, uint8_t(ml::TextureFilter::Bilinear));
  }
  // The banded scene (three nearest samplers, one bilinear) compiled bilinear and nearest.
  for (const auto choice : {ml::TextureFilterChoice::Nearest, ml::TextureFilterChoice::Bilinear}) {
    o.texture_filter = choice;
    const ml::CompileResult r = ml::compile_mesh(ml::make_banded_scene(), o);
    ml::Scene scene;
    ASSERT_TRUE(r.ok) << r.error;
    ASSERT_TRUE(scenetest::read(r.blob, &scene).ok());
    ASSERT_EQ(scene.texture_texels_count, 4u);
    const auto want = choice == ml::TextureFilterChoice::Nearest ? ml::TextureFilter::Nearest : ml::TextureFilter::Bilinear;
    for (uint32_t i = 0; i < scene.texture_texels_count; ++i) EXPECT_EQ(scene.texture_texels[i].filter, uint8_t(want)) << i;
  }
}

TEST(TextureEncode, PaletteOfTheSameColoursIsExact) {
  const ml::MeshSampler s;
  ml::CompileOptions o;
  const auto img = image_of(8, 8, [](int x, int y) { return (x + y) % 3 == 0 ? 0xF80000u : (x % 2 ? 0x00FC00u : 0x0000F8u); });
  const auto pal = ml::encode_texture(img, s, o);
  o.texture_format = ml::TextureFormatChoice::Rgb565;
  const auto direct = ml::encode_texture(img, s, o);
  ASSERT_EQ(pal.info.format, uint8_t(ml::TexelFormat::Palette8));
  ASSERT_EQ(direct.info.format, uint8_t(ml::TexelFormat::Rgb565));
  for (int i = 0; i < 64; ++i) {
    const uint8_t index = pal.bytes[2 * pal.info.palette_size + size_t(i)];
    EXPECT_EQ(pal.bytes[2 * index], direct.bytes[2 * size_t(i)]);
    EXPECT_EQ(pal.bytes[2 * index + 1], direct.bytes[2 * size_t(i) + 1]);
  }
}

TEST(TextureEncode, MedianCutKeepsAtMost256CloseColours) {
  ml::CompileOptions o;
  o.texture_format = ml::TextureFormatChoice::Palette8;
  const auto img = image_of(64, 64, [](int x, int y) { return uint32_t(x * 4) << 16 | uint32_t(y * 4) << 8 | uint32_t((x + y) * 2); });
  const auto e = ml::encode_texture(img, ml::MeshSampler(), o);
  ASSERT_EQ(e.info.format, uint8_t(ml::TexelFormat::Palette8));
  EXPECT_GT(e.info.palette_size, 200u);
  EXPECT_LE(e.info.palette_size, 256u);
  // Every texel is near its colour: 4096 colours in 256 boxes leave a few steps per channel.
  const uint8_t* idx = e.bytes.data() + 2 * e.info.palette_size;
  double worst = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const size_t i = size_t(idx[y * 64 + x]);
      const uint32_t v = e.bytes[2 * i] | uint32_t(e.bytes[2 * i + 1]) << 8;
      const int r = int((v >> 11) & 31) * 255 / 31, g = int((v >> 5) & 63) * 255 / 63;
      worst = std::max(worst, double(std::max(std::abs(r - x * 4), std::abs(g - y * 4))));
    }
  EXPECT_LT(worst, 40);
}

TEST(TextureEncode, SidesBecomePowersOfTwoWithinTheLimit) {
  ml::CompileOptions o;
  const auto e = ml::encode_texture(image_of(100, 30, [](int x, int) { return uint32_t(x) * 0x020301u; }), ml::MeshSampler(), o);
  EXPECT_EQ(e.info.width, 128u);
  EXPECT_EQ(e.info.height, 32u);
  o.texture_max_size = 64;
  const auto capped = ml::encode_texture(image_of(300, 300, [](int x, int y) { return uint32_t(x ^ y); }), ml::MeshSampler(), o);
  EXPECT_EQ(capped.info.width, 64u);
  EXPECT_EQ(capped.info.height, 64u);
  const auto none = ml::encode_texture(ml::MeshImage(), ml::MeshSampler(), o);
  EXPECT_EQ(none.info.format, uint8_t(ml::TexelFormat::None));
  EXPECT_EQ(none.info.bytes, 0u);
}

// ---- compiler: glTF images, samplers and KHR_texture_transform --------------------------------------

TEST(TextureImport, ImagesSamplersAndTextureTransform) {
  const std::string dir = scenetest::temp_dir();
  std::vector<ml::Pixel> px(4 * 2);
  for (size_t i = 0; i < px.size(); ++i) px[i] = ml::Pixel(i * 0x102030u);
  ASSERT_EQ(mlhost::write_png_rgb(dir + "/t.png", 4, 2, px), "");
  const std::vector<float> data = {0, 0, 0, 1, 0, 0, 0, 1, 0,  // positions
                                   0, 0, 1, 0, 0, 1};          // uvs
  std::vector<uint8_t> bytes(data.size() * 4);
  std::memcpy(bytes.data(), data.data(), bytes.size());
  const std::string json = std::string("{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_texture_transform\"],") +
      "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]," +
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]}]," +
      "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"extensions\":" +
      "{\"KHR_texture_transform\":{\"offset\":[0.5,0.25],\"scale\":[2,3]}}}}}]," +
      "\"textures\":[{\"source\":0,\"sampler\":0}],\"images\":[{\"uri\":\"t.png\"}]," +
      "\"samplers\":[{\"wrapS\":33648,\"wrapT\":33071,\"magFilter\":9728}]," +
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}," +
      "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}]," +
      "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}]," +
      "\"buffers\":[{\"byteLength\":60,\"uri\":\"data:application/octet-stream;base64," + scenetest::base64(bytes) + "\"}]}";
  scenetest::write_file(dir + "/t.gltf", json);
  ml::SceneMesh mesh;
  std::vector<std::string> warnings;
  std::string error;
  ASSERT_TRUE(ml::import_gltf_file(dir + "/t.gltf", &mesh, &warnings, &error)) << error;
  ASSERT_EQ(mesh.images.size(), 1u);
  EXPECT_EQ(mesh.images[0].width, 4);
  EXPECT_EQ(mesh.images[0].height, 2);
  EXPECT_EQ(mesh.images[0].rgba[4 * 3 + 0], 0x30);  // pixel 1 is 0x102030
  ASSERT_EQ(mesh.texture_samplers.size(), 1u);
  EXPECT_EQ(mesh.texture_samplers[0].wrap_s, ml::TextureWrap::MirroredRepeat);
  EXPECT_EQ(mesh.texture_samplers[0].wrap_t, ml::TextureWrap::ClampToEdge);
  EXPECT_EQ(mesh.texture_samplers[0].filter, ml::TextureFilter::Nearest);
  const auto& v = mesh.nodes.at(0).primitives.at(0).vertices;
  ASSERT_EQ(v.size(), 3u);
  const double expect[3][2] = {{0.5, 0.25}, {2.5, 0.25}, {0.5, 3.25}};  // uv' = offset + scale * uv
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(v[size_t(i)].uv[0], expect[i][0]);
    EXPECT_DOUBLE_EQ(v[size_t(i)].uv[1], expect[i][1]);
  }
  const ml::CompileResult r = ml::compile_gltf_file(dir + "/t.gltf");
  ASSERT_TRUE(r.ok) << r.error;
  ml::Scene scene;
  ASSERT_TRUE(scenetest::read(r.blob, &scene).ok());
  ASSERT_EQ(scene.texture_texels_count, 1u);
  EXPECT_EQ(scene.texture_texels[0].width, 4u);
  EXPECT_EQ(scene.texture_texels[0].height, 2u);
}

TEST(TextureImport, UndecodableImageDrawsTheMaterialColour) {
  const std::string dir = scenetest::temp_dir();
  scenetest::write_file(dir + "/bad.png", "not a png");
  const std::string src = textest::model("BoxTextured-glTF/BoxTextured.gltf");
  std::ifstream in(src);
  std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = json.find("CesiumLogoFlat.png");
  ASSERT_NE(at, std::string::npos);
  json.replace(at, 18, "bad.png");
  std::filesystem::copy_file(textest::model("BoxTextured-glTF/BoxTextured0.bin"), dir + "/BoxTextured0.bin");
  scenetest::write_file(dir + "/box.gltf", json);
  const ml::CompileResult r = ml::compile_gltf_file(dir + "/box.gltf");
  ASSERT_TRUE(r.ok) << r.error;
  bool warned = false;
  for (const auto& w : r.warnings) warned = warned || w.find("not a decodable image") != std::string::npos;
  EXPECT_TRUE(warned);
  ml::Scene scene;
  ASSERT_TRUE(scenetest::read(r.blob, &scene).ok());
  EXPECT_EQ(scene.texture_texels, nullptr);  // no texels at all: no sections
  const ml::Camera cam = ml::frame_sphere(ml::Vec3i{0, 0, 0}, scene.info->sphere_radius, 64, 48, 45 << 16);
  const Frame f = textest::render(scene, cam, textest::options(ml::RendererKind::Tiler));
  ASSERT_TRUE(f.status.ok());
  EXPECT_EQ(f.stats.texture_loads, 0u);
  EXPECT_EQ(std::set<ml::Pixel>(f.pixels.begin(), f.pixels.end()).size(), 2u);  // base colour + background
}

// ---- the blob: validation ---------------------------------------------------------------------------

TEST(TextureBlob, ReaderRejectsEveryBadTextureField) {
  const mlhost::LoadedScene& banded = load("builtin:banded");
  ASSERT_TRUE(banded.scene.texture_texels) << banded.name;
  struct Case {
    const char* message;
    void (*mutate)(ml::TextureTexels*);
  };
  const Case cases[] = {
      {"texture format invalid", [](ml::TextureTexels* t) { t->format = 4; }},
      {"texture wrap mode invalid", [](ml::TextureTexels* t) { t->wrap_t = 3; }},
      {"texture filter invalid", [](ml::TextureTexels* t) { t->filter = 2; }},
      {"texture reserved field not zero", [](ml::TextureTexels* t) { t->reserved = 1; }},
      {"texture size not a power of two up to limit", [](ml::TextureTexels* t) { t->width = 48; }},
      {"texture size not a power of two up to limit", [](ml::TextureTexels* t) { t->height = 2048; }},
      {"texture size not a power of two up to limit", [](ml::TextureTexels* t) { t->width = 0; }},
      {"texture byte count wrong", [](ml::TextureTexels* t) { t->bytes += 4; }},
      {"texture offset not 4-byte aligned", [](ml::TextureTexels* t) { t->offset += 2; }},
      {"texture texels outside texels section", [](ml::TextureTexels* t) { t->offset = 0xFFFFFFF0u; }},
      {"texture palette size invalid", [](ml::TextureTexels* t) { t->palette_size = 3; }},
      {"empty texture not zero", [](ml::TextureTexels* t) { t->format = 0; }},
  };
  for (const Case& c : cases) {
    ml::Blob blob = banded.blob;
    c.mutate(scenetest::section<ml::TextureTexels>(&blob, ml::SectionType::TextureTexels));
    scenetest::fix_crc(&blob);
    const ml::Status s = scenetest::read(blob);
    EXPECT_FALSE(s.ok()) << c.message;
    EXPECT_STREQ(s.message, c.message);
  }
  // Palette textures: the palette size must be 1..256 (texture 1 is a palette texture).
  ml::Blob blob = banded.blob;
  ml::TextureTexels* t = scenetest::section<ml::TextureTexels>(&blob, ml::SectionType::TextureTexels) + 1;
  ASSERT_EQ(t->format, uint8_t(ml::TexelFormat::Palette8));
  t->palette_size = 0;
  scenetest::fix_crc(&blob);
  EXPECT_STREQ(scenetest::read(blob).message, "texture palette size invalid");
  // One TextureTexels per TextureRef.
  blob = banded.blob;
  ml::SectionEntry* e = scenetest::find_section(&blob, ml::SectionType::TextureTexels);
  e->count -= 1;
  e->size -= sizeof(ml::TextureTexels);
  scenetest::fix_crc(&blob);
  EXPECT_STREQ(scenetest::read(blob).message, "texture texels count differs from textures");
}

// ---- sampler ----------------------------------------------------------------------------------------

struct TinyTexture {
  ml::TextureTexels t{};
  std::vector<uint8_t> bytes;
  // 4 x 2 RGB565 texels: texel (x, y) is red 8 * x, green 8 * y (exactly representable).
  TinyTexture(ml::TextureWrap s, ml::TextureWrap w, ml::TextureFilter f) {
    t.width = 4;
    t.height = 2;
    t.format = uint8_t(ml::TexelFormat::Rgb565);
    t.wrap_s = uint8_t(s);
    t.wrap_t = uint8_t(w);
    t.filter = uint8_t(f);
    t.bytes = 16;
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 4; ++x) {
        const uint16_t v = uint16_t(x << 11 | (y * 2) << 5);
        bytes.push_back(uint8_t(v));
        bytes.push_back(uint8_t(v >> 8));
      }
  }
  int texel_x(double u, double v = 0.25) const {
    const int32_t uv[2] = {int32_t(std::lround(u * 65536)), int32_t(std::lround(v * 65536))};
    return int(ml::red_of(ml::sample_texture(t, bytes.data(), uv)) / 8);
  }
};

TEST(TextureSampler, WrapModesPickTheGltfTexel) {
  using W = ml::TextureWrap;
  const TinyTexture repeat(W::Repeat, W::Repeat, ml::TextureFilter::Nearest);
  const TinyTexture mirror(W::MirroredRepeat, W::Repeat, ml::TextureFilter::Nearest);
  const TinyTexture clamp(W::ClampToEdge, W::Repeat, ml::TextureFilter::Nearest);
  const double us[] = {0.1, 0.3, 1.3, 1.8, -0.1, -0.3, -1.1, 2.6};
  const int want_repeat[] = {0, 1, 1, 3, 3, 2, 3, 2};
  const int want_mirror[] = {0, 1, 2, 0, 0, 1, 3, 2};
  const int want_clamp[] = {0, 1, 3, 3, 0, 0, 0, 3};
  for (size_t i = 0; i < sizeof(us) / sizeof(us[0]); ++i) {
    EXPECT_EQ(repeat.texel_x(us[i]), want_repeat[i]) << us[i];
    EXPECT_EQ(mirror.texel_x(us[i]), want_mirror[i]) << us[i];
    EXPECT_EQ(clamp.texel_x(us[i]), want_clamp[i]) << us[i];
  }
}

TEST(TextureSampler, BilinearBlendsNeighboursAndMatchesNearestAtCentres) {
  const TinyTexture bi(ml::TextureWrap::ClampToEdge, ml::TextureWrap::ClampToEdge, ml::TextureFilter::Bilinear);
  const TinyTexture near(ml::TextureWrap::ClampToEdge, ml::TextureWrap::ClampToEdge, ml::TextureFilter::Nearest);
  for (int x = 0; x < 4; ++x) {
    const int32_t uv[2] = {int32_t((2 * x + 1) * 65536 / 8), 65536 / 4};
    EXPECT_EQ(ml::sample_texture(bi.t, bi.bytes.data(), uv), ml::sample_texture(near.t, near.bytes.data(), uv));
  }
  const int32_t mid[2] = {65536 / 4, 65536 / 4};  // between texels 0 and 1: half of red 8
  EXPECT_EQ(ml::red_of(ml::sample_texture(bi.t, bi.bytes.data(), mid)), 4u);
}

// A small triangle's bilinear filtering blends the texels, then multiplies the blend by the colour
// once (docs/textures.md): every filtered level 0..255 (a black and a white texel blended at every
// fraction) times every level of each colour channel, decoded and through the white table, against
// modulate_texel of the filtered colour. Larger triangles multiply the texels first.
TEST(TextureSampler, SmallTrianglesBilinearFiltersThenModulates) {
  ml::TextureTexels t{};
  t.width = 2;
  t.height = 1;
  t.format = uint8_t(ml::TexelFormat::Rgb565);
  t.wrap_s = t.wrap_t = uint8_t(ml::TextureWrap::ClampToEdge);
  t.filter = uint8_t(ml::TextureFilter::Bilinear);
  t.bytes = 4;
  const uint8_t bytes[] = {0x00, 0x00, 0xFF, 0xFF};  // black, white
  std::vector<ml::Pixel> white(ml::kTexelLutEntries);
  ml::make_texel_lut(t, bytes, 0xFFFFFF, white.data());
  std::set<uint32_t> levels;
  for (int32_t f = 0; f <= 256; ++f) {
    const int32_t uv[2] = {16384 + f * 128, 32768};  // texel centres at u = 1/4, 3/4: blended by f / 256
    const ml::Pixel filtered = ml::sample_texture(t, bytes, uv);
    levels.insert(filtered & 0xFF);
    for (uint32_t c = 0; c < 256; ++c) {
      const ml::Pixel colour = ml::rgb(c, 255 - c, c ^ 0x5A);
      const ml::Pixel want = ml::modulate_texel(filtered, colour);
      ASSERT_EQ(ml::sample_texture(t, bytes, uv, colour, true), want) << f << " " << c;
      ASSERT_EQ(ml::sample_texture(t, bytes, white.data(), 0xFFFFFF, uv, colour, true), want) << f << " " << c;
    }
  }
  EXPECT_EQ(levels.size(), 256u);
  // Texels first: the blend of the two texels each multiplied (here black stays black).
  const int32_t half[2] = {16384 + 64 * 128, 32768};  // a quarter of the way: 64 / 256
  const ml::Pixel colour = ml::rgb(200, 100, 7);
  const ml::Pixel each = ml::rgb((200 * 64 + 128) >> 8, (100 * 64 + 128) >> 8, (7 * 64 + 128) >> 8);
  EXPECT_EQ(ml::sample_texture(t, bytes, half, colour, false), each);
  EXPECT_EQ(ml::sample_texture(t, bytes, half, colour, true), ml::modulate_texel(ml::rgb(64, 64, 64), colour));
}

TEST(TextureSampler, FormatsDecodeAndBadPaletteIndicesStayInside) {
  ml::TextureTexels t{};
  t.width = 2;
  t.height = 1;
  t.format = uint8_t(ml::TexelFormat::Grey4);
  t.bytes = 1;
  const uint8_t grey[] = {0xF3};
  const int32_t left[2] = {65536 / 4, 0}, right[2] = {3 * 65536 / 4, 0};
  EXPECT_EQ(ml::sample_texture(t, grey, left), 0x333333u);
  EXPECT_EQ(ml::sample_texture(t, grey, right), 0xFFFFFFu);
  t.format = uint8_t(ml::TexelFormat::Palette8);
  t.palette_size = 1;
  t.bytes = 4;
  const uint8_t pal[] = {0x00, 0xF8, 0, 200};  // one colour (red), indices 0 and 200 (past the palette)
  EXPECT_EQ(ml::sample_texture(t, pal, left), 0xFF0000u);
  EXPECT_EQ(ml::sample_texture(t, pal, right), 0xFF0000u);
  EXPECT_EQ(ml::modulate_texel(0xFFFFFF, 0x123456), 0x123456u);
  EXPECT_EQ(ml::modulate_texel(0x804020, 0xFFFFFF), 0x804020u);
  EXPECT_EQ(ml::modulate_texel(0x808080, 0x808080), 0x404040u);
}

// ---- both renderers choose the same texel ----------------------------------------------------------

// Unlit and flat: identical. Gouraud: the texel the same, the smooth colour it is multiplied by is
// each renderer's own interpolation of the vertex colours (the tiler's colour planes, the scanline
// renderer's weights), which agree within one level (docs/tiler.md, shading; OracleRenderersAgree's
// Gouraud tests): so within one level, and rare (the duck, whose normals are smooth, at 24x18 turned
// -40 degrees: one pixel of 432, one level of red).
TEST(TextureRender, TilerAndScanlineImagesAreIdentical) {
  size_t gouraud_pixels = 0, gouraud_off_by_one = 0;
  for (const std::string& path : textest::textured_scenes()) {
    const mlhost::LoadedScene& s = load(path);
    ASSERT_NE(s.scene.info, nullptr) << s.name;
    ASSERT_NE(s.scene.texture_texels, nullptr) << path;
    // 160x120, and 24x18 where every triangle is small (divided at every sample, texture/mapping.h).
    for (int frame = 0; frame < 6; ++frame) {
      const double turn = frame % 3 == 0 ? 0.0 : frame % 3 == 1 ? 25.0 : -40.0;
      const ml::Camera cam = frame < 3 ? textest::camera_for(s, 160, 120, turn) : textest::camera_for(s, 24, 18, turn);
      for (ml::ShadingMode mode : {ml::ShadingMode::Unlit, ml::ShadingMode::Flat, ml::ShadingMode::Gouraud}) {
        const Frame t = textest::render(s.scene, cam, textest::options(ml::RendererKind::Tiler, mode));
        const Frame l = textest::render(s.scene, cam, textest::options(ml::RendererKind::Scanline, mode));
        ASSERT_TRUE(t.status.ok() && l.status.ok()) << path << ": " << t.status.message << " / " << l.status.message;
        ASSERT_TRUE(t.contract && l.contract) << t.contract_error << l.contract_error;
        EXPECT_GT(t.stats.texture_loads, 0u) << path;
        const bool smooth = mode == ml::ShadingMode::Gouraud;
        size_t differ = 0, apart = 0;
        for (size_t i = 0; i < t.pixels.size(); ++i) {
          differ += t.pixels[i] != l.pixels[i];
          for (int shift : {0, 8, 16})
            if (std::abs(int((t.pixels[i] >> shift) & 255) - int((l.pixels[i] >> shift) & 255)) > 1) ++apart;
        }
        EXPECT_EQ(smooth ? apart : differ, 0u) << path << " frame " << frame << " shading " << int(mode);
        if (smooth) gouraud_pixels += t.pixels.size(), gouraud_off_by_one += differ;
      }
    }
  }
  EXPECT_LE(gouraud_off_by_one * 1000, gouraud_pixels) << gouraud_off_by_one << " of " << gouraud_pixels;
}

// Both renderers decide alike which triangles are small (TexturePlanes::exact: every sample divided
// out, texture/mapping.h), from their own view of the triangle: the scanline renderer's view_triangle
// and 1x1 sample lattice, the tiler's vertices transformed one by one (its vertex cache's
// view_vertex) at pixel centres, with the same planes (a boxed small triangle: the same box sums).
// Every textured triangle of every textured scene, at sizes where they are small, large and at the
// limit between. They choose the same mip level too.
TEST(TextureRender, RenderersDecideAlikeWhichTrianglesAreSmall) {
  size_t small = 0, large = 0, minified = 0;
  for (const std::string& path : textest::textured_scenes()) {
    const mlhost::LoadedScene& s = load(path);
    ASSERT_NE(s.scene.info, nullptr) << s.name;
    for (int frame = 0; frame < 12; ++frame) {
      const int width = 16 << (frame % 4);  // 16x12 .. 128x96
      const ml::Camera cam = textest::camera_for(s, width, width * 3 / 4, frame < 4 ? 0.0 : frame < 8 ? 25.0 : -40.0);
      ml::View view;
      ASSERT_TRUE(ml::make_view(cam, &view).ok());
      const ml::scan::Lattice lat = ml::scan::make_lattice(cam.width, cam.height, 1);
      for (uint32_t id = 0; id < s.scene.triangle_count; ++id) {
        const uint32_t texture = ml::triangle_texture(s.scene, id);
        if (texture == ml::kNone) continue;
        ml::Vec3i world[3];
        ml::triangle_world(s.scene, id, world);
        ml::ViewTriangle scanline_view, tiler_view;
        ml::view_triangle(view, world, &scanline_view);
        tiler_view.unclipped = true;
        for (int i = 0; i < 3; ++i) {
          ml::ViewVertex v;
          ml::view_vertex(view, world[i], &v);
          if (!ml::put_view_vertex(v, i, &tiler_view)) tiler_view.unclipped = false;
        }
        ml::TexturePlanes scanline_planes, tiler_planes;
        ml::triangle_texture_planes(s.scene, view, id, texture, lat.den, lat.ox, lat.oy, &scanline_planes,
                                    &scanline_view);
        ml::triangle_texture_planes(s.scene, view, id, texture, 1, ml::kSubpixelHalf, ml::kSubpixelHalf, &tiler_planes,
                                    &tiler_view);
        ASSERT_EQ(scanline_planes.exact, tiler_planes.exact) << path << " frame " << frame << " triangle " << id;
        ASSERT_EQ(scanline_planes.level, tiler_planes.level) << path << " frame " << frame << " triangle " << id;
        if (scanline_planes.level > 0) ++minified;
        ASSERT_EQ(scanline_planes.boxed, tiler_planes.boxed) << path << " frame " << frame << " triangle " << id;
        if (scanline_planes.boxed) {  // its sums in place of the planes (64-bit hosts: not written)
          const ml::BoxSums &a = scanline_planes.sums, &b = tiler_planes.sums;
          ASSERT_TRUE(a.x == b.x && a.y == b.y && a.w == b.w && a.h == b.h)
              << path << " frame " << frame << " triangle " << id;
          for (int k = 0; k < 3; ++k)
            ASSERT_TRUE(a.at[k] == b.at[k] && a.dx[k] == b.dx[k] && a.dy[k] == b.dy[k])
                << path << " frame " << frame << " triangle " << id;
          small += 1;
          continue;
        }
        for (int i = 0; i < 3; ++i) {
          ASSERT_EQ(scanline_planes.a[i], tiler_planes.a[i]) << path << " frame " << frame << " triangle " << id;
          ASSERT_EQ(scanline_planes.b[i], tiler_planes.b[i]) << path << " frame " << frame << " triangle " << id;
          ASSERT_EQ(scanline_planes.k[i], tiler_planes.k[i]) << path << " frame " << frame << " triangle " << id;
        }
        (scanline_planes.exact ? small : large) += 1;
      }
    }
  }
  EXPECT_GT(small, 20u);
  EXPECT_GT(minified, 20u);  // triangles of textures with mip levels that sample one
  EXPECT_GT(large, 20u);
}

// The tiler's texture planes kept from band to band (arena bytes to spare, render_spare_bytes) give
// the frame of the least arena: every textured scene in bands of a few rows, shaded each way, at
// 160x120 and at 24x18 (every triangle small). The kept planes (texture_planes_reused) are never used
// in the least arena (no room for them), and are used wherever the spare arena has the frame rendered
// in several passes of bands: a band at a time (OutputOptions::render_rows), or by default where its
// textures' residency keeps it to several (TexturePlan::band_peak: the four-texture banded scene; the
// others go in one pass, with nothing to keep).
TEST(TextureRender, TilerPlanesKeptAcrossBandsGiveTheSameFrame) {
  for (const std::string& path : textest::textured_scenes()) {
    const mlhost::LoadedScene& s = load(path);
    ASSERT_NE(s.scene.info, nullptr) << s.name;
    uint64_t reused = 0, several_passes = 0, one_pass_reused = 0;
    for (int frame = 0; frame < 4; ++frame) {
      const double turn = frame % 2 == 0 ? 0.0 : 25.0;
      const ml::Camera cam = frame < 2 ? textest::camera_for(s, 160, 120, turn) : textest::camera_for(s, 24, 18, turn);
      for (ml::ShadingMode mode : {ml::ShadingMode::Unlit, ml::ShadingMode::Flat, ml::ShadingMode::Gouraud}) {
        ml::RenderOptions o = textest::options(ml::RendererKind::Tiler, mode);
        o.output.band_rows = frame < 2 ? 8 : 4;
        const size_t least = ml::render_arena_bytes(s.scene, cam, o), spare = ml::render_spare_bytes(s.scene, cam, o);
        const Frame plain = textest::render(s.scene, cam, o, least);
        const Frame kept = textest::render(s.scene, cam, o, least + spare);
        ASSERT_TRUE(plain.status.ok() && kept.status.ok()) << path << ": " << plain.status.message << " / "
                                                           << kept.status.message;
        ASSERT_TRUE(kept.contract) << kept.contract_error;
        EXPECT_EQ(kept.pixels, plain.pixels) << path << " frame " << frame << " shading " << int(mode);
        EXPECT_EQ(kept.stats.texture_bytes_loaded, plain.stats.texture_bytes_loaded) << path;
        EXPECT_EQ(plain.stats.texture_planes_reused, 0u) << path << ": planes kept without the arena for them";
        if (kept.stats.render_bands > 1) {
          ++several_passes;
          reused += kept.stats.texture_planes_reused;
        } else {
          one_pass_reused += kept.stats.texture_planes_reused;  // a split triangle's pieces
        }
        // The spare bytes with a band at a time: every frame in several passes.
        ml::RenderOptions apart = o;
        apart.output.render_rows = o.output.band_rows;
        const Frame kept_apart = textest::render(s.scene, cam, apart, least + ml::render_spare_bytes(s.scene, cam, apart));
        ASSERT_TRUE(kept_apart.status.ok()) << path << ": " << kept_apart.status.message;
        EXPECT_EQ(kept_apart.pixels, plain.pixels) << path << " frame " << frame << " shading " << int(mode);
        ++several_passes;
        reused += kept_apart.stats.texture_planes_reused;
      }
    }
    if (several_passes > 0) {
      EXPECT_GT(reused, 0u) << path << ": the kept texture planes were never used";
    }
    if (path == "builtin:banded") {
      EXPECT_GT(several_passes, 0u) << "the banded scene is no longer rendered in several passes of bands";
    }
    // A frame rendered in one pass keeps the planes of the triangles the BSP split (the duck's).
    if (s.scene.bsp_split_count > s.scene.triangle_count / 4) {
      EXPECT_GT(one_pass_reused, 0u) << path << ": no split triangle's planes kept in one pass";
    }
  }
}

// With arena to spare the tiler renders a frame with paged textures in as many bands at once as keep
// the textures it plans to hold at once to a band at a time's (TexturePlan::band_peak): every textured
// scene gives the least arena's image and bytes read; a scene of one texture renders its whole frame
// at once; the banded scene's four textures in stripes keep it to fewer rows at once, its resident
// peak to the least arena's, and to half of its texture bytes (Woo and Chall's Fig. 10).
TEST(TextureRender, TilerRendersBandsAtOnceWithinTheirTextureResidency) {
  if (!ml::kRenderBands) GTEST_SKIP() << "a 32-bit target";
  for (const std::string& path : textest::textured_scenes()) {
    const mlhost::LoadedScene& s = load(path);
    ASSERT_NE(s.scene.info, nullptr) << s.name;
    const ml::Camera cam = textest::camera_for(s, 160, 120);
    ml::RenderOptions o = textest::options(ml::RendererKind::Tiler, ml::ShadingMode::Flat);
    o.output.band_rows = 8;
    const size_t least = ml::render_arena_bytes(s.scene, cam, o);
    const Frame plain = textest::render(s.scene, cam, o, least);
    const Frame roomy = textest::render(s.scene, cam, o, least + ml::render_spare_bytes(s.scene, cam, o));
    ASSERT_TRUE(plain.status.ok() && roomy.status.ok()) << path << ": " << plain.status.message << " / "
                                                       << roomy.status.message;
    EXPECT_EQ(roomy.pixels, plain.pixels) << path;
    EXPECT_EQ(roomy.stats.texture_bytes_loaded, plain.stats.texture_bytes_loaded) << path;
    EXPECT_EQ(plain.stats.render_bands, 15u) << path;
    if (s.scene.texture_texels_count == 1) {
      EXPECT_EQ(roomy.stats.render_bands, 1u) << path;
    }
    if (path == "builtin:banded") {
      EXPECT_GT(roomy.stats.render_bands, 1u);
      EXPECT_LT(roomy.stats.render_bands, 15u);
      EXPECT_EQ(roomy.stats.texture_bytes_peak, plain.stats.texture_bytes_peak);
      EXPECT_LE(2 * uint64_t(roomy.stats.texture_bytes_peak), ml::texture_pool_needs(s.scene).desired);
    }
  }
}

TEST(TextureRender, UnlitIsTexelTimesBaseColourAndLightingModulates) {
  const mlhost::LoadedScene& s = load("builtin:banded");
  const ml::Camera cam = textest::camera_for(s, 160, 120);
  const Frame unlit = textest::render(s.scene, cam, textest::options(ml::RendererKind::Tiler));
  const Frame flat = textest::render(s.scene, cam, textest::options(ml::RendererKind::Tiler, ml::ShadingMode::Flat));
  ASSERT_TRUE(unlit.status.ok() && flat.status.ok());
  // The bands face the eye: flat shading scales every texel by one light intensity (< 1 here).
  std::set<ml::Pixel> colours;
  size_t darker = 0, textured = 0;
  for (size_t i = 0; i < unlit.pixels.size(); ++i) {
    if (unlit.pixels[i] == 0x202830) continue;
    ++textured;
    colours.insert(unlit.pixels[i]);
    darker += ml::red_of(flat.pixels[i]) <= ml::red_of(unlit.pixels[i]) &&
              ml::green_of(flat.pixels[i]) <= ml::green_of(unlit.pixels[i]);
  }
  EXPECT_GT(colours.size(), 40u);  // many texels, not four base colours
  EXPECT_EQ(darker, textured);
}

TEST(TextureRender, SupersampledScanlineFiltersTexels) {
  const mlhost::LoadedScene& s = load("builtin:banded");
  const ml::Camera cam = textest::camera_for(s, 160, 120);
  const Frame one = textest::render(s.scene, cam, textest::options(ml::RendererKind::Scanline, ml::ShadingMode::Unlit, 1));
  const Frame three = textest::render(s.scene, cam, textest::options(ml::RendererKind::Scanline, ml::ShadingMode::Unlit, 3));
  ASSERT_TRUE(one.status.ok() && three.status.ok());
  // Filtering makes in-between colours at texel edges: more distinct colours than point sampling.
  const std::set<ml::Pixel> a(one.pixels.begin(), one.pixels.end()), b(three.pixels.begin(), three.pixels.end());
  EXPECT_GT(b.size(), a.size() * 2);
  EXPECT_GE(three.stats.shading_calls, three.stats.geometry_samples * 9 / 10);  // textured: every sample shaded
}

// The scanline renderer's supersampled textured runs (their colours made a run at a time) against
// each sample's own colour, as a shading call gives it (sample_texture at the sample's coordinates):
// a pixel whose l x l samples all lie in one textured triangle (its 3 x 3 pixel neighbourhood shows
// that triangle at the centres, so by convexity its whole square does) is their rounded mean.
TEST(TextureRender, SupersampledScanlineRunsGiveEachSampleItsOwnColour) {
  for (const std::string& path : {std::string("builtin:banded"), textest::model("BoxTextured-glTF/BoxTextured.gltf")}) {
    const mlhost::LoadedScene& s = load(path);
    ASSERT_NE(s.scene.info, nullptr) << s.name;
    const ml::Camera cam = textest::camera_for(s, 160, 120, 20.0);
    ml::View view;
    ASSERT_TRUE(ml::make_view(cam, &view).ok());
    const Frame ids = textest::render(s.scene, cam, textest::options(ml::RendererKind::Scanline, ml::ShadingMode::Ids));
    ASSERT_TRUE(ids.status.ok());
    for (int aa : {2, 3, 4}) {
      const Frame f = textest::render(s.scene, cam, textest::options(ml::RendererKind::Scanline, ml::ShadingMode::Unlit, aa));
      ASSERT_TRUE(f.status.ok());
      const ml::scan::Lattice lat = ml::scan::make_lattice(cam.width, cam.height, aa);
      std::map<uint32_t, ml::TexturePlanes> planes;
      size_t checked = 0;
      for (int y = 1; y + 1 < cam.height; ++y)
        for (int x = 1; x + 1 < cam.width; ++x) {
          const uint32_t id = ids.pixels[size_t(y) * cam.width + x];
          bool inside = id != 0;
          for (int dy = -1; dy <= 1 && inside; ++dy)
            for (int dx = -1; dx <= 1 && inside; ++dx) inside = ids.pixels[size_t(y + dy) * cam.width + x + dx] == id;
          const uint32_t tri = id - 1, texture = inside ? ml::triangle_texture(s.scene, tri) : ml::kNone;
          if (texture == ml::kNone) continue;
          if (!planes.count(tri))
            ml::triangle_texture_planes(s.scene, view, tri, texture, lat.den, lat.ox, lat.oy, &planes[tri]);
          const ml::TextureTexels& t = s.scene.texture_texels[texture];
          const ml::Material& m = s.scene.materials[s.scene.batches[ml::triangle_at(s.scene, tri).batch].material];
          const ml::Pixel colour = ml::rgb(m.base_color[0], m.base_color[1], m.base_color[2]);  // unlit
          uint32_t sum[3] = {0, 0, 0};
          for (int32_t sy = y * lat.q; sy <= y * lat.q + lat.q; ++sy)
            for (int32_t sx = x * lat.q; sx <= x * lat.q + lat.q; ++sx) {
              int32_t uv[2];
              ml::texture_uv(planes[tri], sx, sy, uv);
              uint32_t offset;  // the texels of the planes' mip level
              const ml::TextureTexels lt = ml::texture_level_texels(t, planes[tri].level, &offset);
              const ml::Pixel c =
                  ml::sample_texture(lt, s.scene.texels + t.offset + offset, uv, colour, planes[tri].exact);
              for (int k = 0; k < 3; ++k) sum[k] += (c >> (16 - 8 * k)) & 0xFF;
            }
          const uint32_t l2 = uint32_t(aa * aa);
          const ml::Pixel want = ml::rgb((sum[0] + l2 / 2) / l2, (sum[1] + l2 / 2) / l2, (sum[2] + l2 / 2) / l2);
          ASSERT_EQ(f.pixels[size_t(y) * cam.width + x], want) << path << " aa " << aa << " pixel " << x << "," << y;
          ++checked;
        }
      EXPECT_GT(checked, 1000u) << path << " aa " << aa;
    }
  }
}

TEST(TextureRender, OversampledTilerTexturesEveryPixel) {
  const mlhost::LoadedScene& s = load("builtin:banded");
  const ml::Camera cam = textest::camera_for(s, 160, 120);
  const Frame one = textest::render(s.scene, cam, textest::options(ml::RendererKind::Tiler));
  const Frame four = textest::render(s.scene, cam, textest::options(ml::RendererKind::Tiler, ml::ShadingMode::Unlit, 4));
  ASSERT_TRUE(four.status.ok() && four.contract) << four.status.message << four.contract_error;
  EXPECT_EQ(four.stats.texture_loads, 4u);
  // A pixel inside a piece takes its texel at the pixel centre, as without oversampling; only pixels
  // on piece edges blend.
  size_t same = 0;
  for (size_t i = 0; i < one.pixels.size(); ++i) same += one.pixels[i] == four.pixels[i];
  EXPECT_GT(same, one.pixels.size() * 9 / 10);
  EXPECT_LT(same, one.pixels.size());
}

// ---- the pager ----------------------------------------------------------------------------------------

uint32_t total_texture_bytes(const ml::Scene& s) {
  uint32_t total = 0;
  for (uint32_t i = 0; i < s.texture_texels_count; ++i) total += s.texture_texels[i].bytes;
  return total;
}

TEST(TexturePager, BandedSceneKeepsFewTexturesResident) {
  const mlhost::LoadedScene& s = load("builtin:banded");
  const ml::Camera cam = textest::camera_for(s, 320, 240);
  const uint32_t total = total_texture_bytes(s.scene);
  ASSERT_EQ(s.scene.texture_texels_count, 4u);
  for (ml::RendererKind r : {ml::RendererKind::Scanline, ml::RendererKind::Tiler}) {
    const Frame f = textest::render(s.scene, cam, textest::options(r));
    ASSERT_TRUE(f.status.ok());
    EXPECT_EQ(f.stats.texture_loads, 4u);
    EXPECT_EQ(f.stats.texture_reloads, 0u);
    EXPECT_EQ(f.stats.texture_evictions, 0u);
    EXPECT_LE(f.stats.textures_resident_peak, 3u);  // Woo & Chall's Fig. 10: never all four
    EXPECT_LE(uint64_t(f.stats.texture_bytes_peak) * 2, uint64_t(total)) << "peak " << f.stats.texture_bytes_peak;
  }
}

TEST(TexturePager, PoolSweepGivesTheSameImageWithMoreReloads) {
  const mlhost::LoadedScene& s = load("builtin:banded");
  const ml::Camera cam = textest::camera_for(s, 200, 150);
  const ml::TexturePoolNeeds needs = ml::texture_pool_needs(s.scene);
  ASSERT_GT(needs.minimum, 0u);
  ASSERT_LT(needs.minimum, needs.desired);
  for (ml::RendererKind r : {ml::RendererKind::Scanline, ml::RendererKind::Tiler}) {
    const Frame all = textest::render(s.scene, cam, textest::options(r));
    ASSERT_TRUE(all.status.ok());
    uint32_t previous_reloads = 0xFFFFFFFFu;
    bool any_reload = false;
    for (uint32_t pool = needs.minimum; pool <= needs.desired; pool += (needs.desired - needs.minimum) / 6) {
      ml::RenderOptions o = textest::options(r);
      o.texture_pool_bytes = pool;
      const Frame f = textest::render(s.scene, cam, o);
      ASSERT_TRUE(f.status.ok()) << pool;
      EXPECT_EQ(f.stats.texture_fallbacks, 0u);
      EXPECT_EQ(f.pixels, all.pixels) << "pool " << pool;
      EXPECT_LE(f.stats.texture_bytes_peak, pool);
      EXPECT_LE(f.stats.texture_reloads, previous_reloads) << "pool " << pool;
      previous_reloads = f.stats.texture_reloads;
      any_reload = any_reload || f.stats.texture_reloads > 0;
    }
    EXPECT_TRUE(any_reload);
    // Below the largest texture: that texture falls back, the frame still completes.
    ml::RenderOptions o = textest::options(r);
    o.texture_pool_bytes = needs.minimum - 4;
    const Frame small = textest::render(s.scene, cam, o);
    ASSERT_TRUE(small.status.ok());
    EXPECT_GE(small.stats.texture_fallbacks, 1u);
    o.texture_pool_bytes = 0;
    const Frame none = textest::render(s.scene, cam, o);
    ASSERT_TRUE(none.status.ok());
    EXPECT_EQ(none.stats.texture_fallbacks, 4u);
    EXPECT_EQ(none.stats.texture_bytes_loaded, 0u);
  }
}

// Small triangles of several textures in one row, with a pool of only the largest texture: the
// scanline renderer samples a row's small spans together, and must sample them before the pager loads
// another texture into their bytes (rows here alternate textures, so it reloads).
TEST(TexturePager, SmallTrianglesOfSeveralTexturesPerRowGiveTheSameImageWithReloads) {
  const mlhost::LoadedScene& s = load(textest::model("textureTransform/TextureTransformTest.gltf"));
  ASSERT_GE(s.scene.texture_count, 2u) << s.name;
  const ml::Camera cam = textest::camera_for(s, 160, 120);
  for (ml::RendererKind r : {ml::RendererKind::Scanline, ml::RendererKind::Tiler}) {
    const Frame all = textest::render(s.scene, cam, textest::options(r));
    ml::RenderOptions o = textest::options(r);
    o.texture_pool_bytes = ml::texture_pool_needs(s.scene).minimum;
    const Frame least = textest::render(s.scene, cam, o);
    ASSERT_TRUE(all.status.ok() && least.status.ok());
    EXPECT_EQ(least.stats.texture_fallbacks, 0u);
    EXPECT_EQ(least.pixels, all.pixels);
    if (r == ml::RendererKind::Scanline) {
      EXPECT_GT(least.stats.texture_reloads, 0u);
    }
  }
}

TEST(TexturePager, FailingSourceCompletesEveryFrame) {
  const mlhost::LoadedScene& s = load("builtin:banded");
  const ml::Camera cam = textest::camera_for(s, 160, 120);
  for (ml::RendererKind r : {ml::RendererKind::Scanline, ml::RendererKind::Tiler}) {
    const Frame good = textest::render(s.scene, cam, textest::options(r));
    for (uint32_t pool : {ml::kTexturePoolAll, ml::texture_pool_needs(s.scene).minimum}) {
      for (int n = 1; n <= 12; ++n) {
        textest::FailingSource source(s.scene, n);
        ml::RenderOptions o = textest::options(r);
        o.texture_source = &source;
        o.texture_pool_bytes = pool;
        const Frame f = textest::render(s.scene, cam, o);
        ASSERT_TRUE(f.status.ok()) << "read " << n;
        ASSERT_TRUE(f.contract);
        if (n <= source.reads) {
          EXPECT_EQ(f.stats.texture_fallbacks, 1u) << "read " << n;
          EXPECT_NE(f.pixels, good.pixels);  // one texture's triangles drew their material colour
        } else {
          EXPECT_EQ(f.stats.texture_fallbacks, 0u);
          EXPECT_EQ(f.pixels, good.pixels);
        }
      }
    }
  }
}

// Texture bytes read against the bytes of the textures that some visible pixel shows.
TEST(TexturePager, ReadsOnlyVisibleTexturesWhenThePoolHoldsThem) {
  for (const std::string& path : textest::textured_scenes()) {
    const mlhost::LoadedScene& s = load(path);
    for (double turn : {0.0, 60.0}) {
      const ml::Camera cam = textest::camera_for(s, 160, 120, turn);
      ml::RenderOptions ids = textest::options(ml::RendererKind::Tiler, ml::ShadingMode::Ids);
      const Frame id = textest::render(s.scene, cam, ids);
      ASSERT_TRUE(id.status.ok());
      std::set<uint32_t> visible;
      for (ml::Pixel p : id.pixels)
        if (p) {
          const ml::Material& m = s.scene.materials[s.scene.batches[ml::triangle_at(s.scene, p - 1).batch].material];
          if (m.texture != ml::kNone && s.scene.texture_texels[m.texture].format) visible.insert(m.texture);
        }
      uint64_t visible_bytes = 0;
      for (uint32_t t : visible) visible_bytes += s.scene.texture_texels[t].bytes;
      for (ml::RendererKind r : {ml::RendererKind::Scanline, ml::RendererKind::Tiler}) {
        const Frame f = textest::render(s.scene, cam, textest::options(r));
        ASSERT_TRUE(f.status.ok());
        EXPECT_LE(uint64_t(f.stats.texture_bytes_loaded) * 10, visible_bytes * 11) << path;
        EXPECT_EQ(f.stats.texture_loads, visible.size()) << path;
      }
    }
  }
}

// Four quads side by side, one behind the other (BSP front to back: A, B, C, A again), textures A, B
// and C of the same size: with a pool of two textures, at C the tiler must evict A or B. B is done
// for the frame while A comes back: the plan (its first and last piece in the walk) evicts B; the
// least recently sampled would be A, read again at the fourth quad.
ml::CompileResult cycling_quads() {
  ml::SceneMesh mesh;
  mesh.nodes.resize(1);
  mesh.nodes[0].name = "quads";
  for (int t = 0; t < 3; ++t) {
    ml::MeshImage im;
    im.width = im.height = 16;
    for (int i = 0; i < 256; ++i)  // more than 256 colours in all: each texture RGB565, 512 bytes
      im.rgba.insert(im.rgba.end(), {uint8_t(i), uint8_t(t * 80 + i % 7), uint8_t(255 - i), 255});
    mesh.images.push_back(im);
    mesh.texture_images.push_back(uint32_t(t));
    mesh.texture_samplers.push_back(ml::MeshSampler{});
  }
  const uint32_t textures[4] = {0, 1, 2, 0};
  for (int q = 0; q < 4; ++q) {
    ml::MeshMaterial m;
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 1.0;
    m.texture = textures[q];
    mesh.materials.push_back(m);
    ml::MeshPrimitive prim;
    prim.material = uint32_t(q);
    const double x0 = -2.0 + q * 1.0, z = -q * 1.0;
    const double corners[4][2] = {{x0, -0.4}, {x0 + 0.8, -0.4}, {x0 + 0.8, 0.4}, {x0, 0.4}};
    for (const auto& c : corners) {
      ml::MeshVertex v;
      v.position[0] = c[0] * (5.0 - z) / 5.0;  // the same size on screen at every depth
      v.position[1] = c[1] * (5.0 - z) / 5.0;
      v.position[2] = z;
      v.normal[2] = 1;
      v.uv[0] = c[0] - x0;
      v.uv[1] = c[1] + 0.4;
      prim.vertices.push_back(v);
    }
    prim.triangles.push_back({0, 1, 2});
    prim.triangles.push_back({0, 2, 3});
    mesh.nodes[0].primitives.push_back(prim);
  }
  mesh.camera.valid = true;
  mesh.camera.eye[2] = 5;
  return ml::compile_mesh(mesh);
}

TEST(TexturePager, TilerEvictsByItsBspOrder) {
  const ml::CompileResult r = cycling_quads();
  ASSERT_TRUE(r.ok) << r.error;
  ml::Scene scene;
  ASSERT_TRUE(scenetest::read(r.blob, &scene).ok());
  ASSERT_EQ(scene.texture_texels_count, 3u);
  ml::Camera cam;
  cam.eye = ml::Vec3i{int32_t(std::lround(r.camera.eye[0])), int32_t(std::lround(r.camera.eye[1])),
                      int32_t(std::lround(r.camera.eye[2]))};
  cam.target = ml::Vec3i{cam.eye.x, cam.eye.y, cam.eye.z - 1000};
  cam.width = 160;
  cam.height = 60;
  cam.near = 16;
  ml::RenderOptions o = textest::options(ml::RendererKind::Tiler);
  o.output.band_rows = 0;  // one band: the walk goes once, A B C A
  const Frame all = textest::render(scene, cam, o);
  ASSERT_TRUE(all.status.ok()) << all.status.message;
  EXPECT_EQ(all.stats.texture_loads, 3u);
  o.texture_pool_bytes = 2 * scene.texture_texels[0].bytes;
  const Frame two = textest::render(scene, cam, o);
  ASSERT_TRUE(two.status.ok() && two.contract) << two.contract_error;
  EXPECT_EQ(two.pixels, all.pixels);
  EXPECT_EQ(two.stats.texture_evictions, 1u);  // B, at C
  EXPECT_EQ(two.stats.texture_reloads, 0u);
  EXPECT_EQ(two.stats.texture_loads, 3u);
  // In bands of 16 rows the walk repeats per band: B and C are read again in each band after the
  // first, A stays (each band: B evicts C, C evicts B).
  o.output.band_rows = 16;
  const Frame banded = textest::render(scene, cam, o);
  ASSERT_TRUE(banded.status.ok());
  EXPECT_EQ(banded.pixels, all.pixels);
  // Bands the quads reach: the first reads A, B and C and evicts B; every later one starts with C and
  // A resident, keeps A (needed again in the band) and reads B and C once each.
  uint32_t reached = 0;
  for (int band = 0; band * 16 < cam.height; ++band) {
    bool textured = false;
    for (int y = band * 16; y < std::min(cam.height, band * 16 + 16); ++y)
      for (int x = 0; x < cam.width; ++x) textured |= all.pixels[size_t(y) * size_t(cam.width) + size_t(x)] != o.background;
    reached += textured;
  }
  ASSERT_GE(reached, 2u);
  EXPECT_EQ(banded.stats.texture_loads, 3 + 2 * (reached - 1));
  EXPECT_EQ(banded.stats.texture_reloads, 2 * (reached - 1));
}

// The white table is kept at hand from one white_lut call to the next only while no table is made:
// after its slot is taken by tables of other colours, white_lut makes it again, and every answer holds
// that texture's texels alone (a table make_texel_lut makes for white).
TEST(TexturePager, WhiteTableMemoFollowsEvictions) {
  const mlhost::LoadedScene& s = load("builtin:banded");
  ASSERT_GE(s.scene.texture_texels_count, 2u);
  textest::WholePoolPager whole(s.scene);
  ASSERT_TRUE(whole.began);
  ml::TexturePager& pager = whole.pager;
  const uint8_t* bytes[2] = {pager.get(0), pager.get(1)};
  ASSERT_TRUE(bytes[0] && bytes[1]);
  // The entries a table of texture t holds (the rest of its slot is never read).
  auto used = [&](uint32_t t) -> size_t {
    switch (ml::TexelFormat(s.scene.texture_texels[t].format)) {
      case ml::TexelFormat::Grey4: return 16;
      case ml::TexelFormat::Rgb565: return 128;
      default: return ml::kTexelLutEntries;
    }
  };
  auto white_of = [&](uint32_t t) {
    std::vector<ml::Pixel> lut(ml::kTexelLutEntries);
    ml::make_texel_lut(s.scene.texture_texels[t], bytes[t], 0xFFFFFF, lut.data());
    lut.resize(used(t));
    return lut;
  };
  auto table = [&](uint32_t t, const ml::Pixel* lut) { return std::vector<ml::Pixel>(lut, lut + used(t)); };
  const ml::Pixel* first = pager.white_lut(0, bytes[0]);
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(table(0, first), white_of(0));
  const uint32_t generation = pager.lut_generation();
  EXPECT_EQ(pager.white_lut(0, bytes[0]), first);  // the memo: nothing made
  EXPECT_EQ(pager.lut_generation(), generation);
  // Tables of texture 1 in as many colours as there are slots take every slot, the white one too.
  for (uint32_t i = 0; i < ml::TexturePager::kLutSlots; ++i) {
    ml::Pixel made_for = 0;
    ASSERT_NE(pager.texel_lut(1, 0x102030 + i, bytes[1], ml::TexturePager::kLutMinSamples, &made_for), nullptr);
    EXPECT_EQ(made_for, ml::Pixel(0x102030 + i));
  }
  EXPECT_EQ(pager.lut_generation(), generation + ml::TexturePager::kLutSlots);
  EXPECT_EQ(table(0, pager.white_lut(0, bytes[0])), white_of(0));
  EXPECT_EQ(pager.lut_generation(), generation + ml::TexturePager::kLutSlots + 1);  // made again
  EXPECT_EQ(table(1, pager.white_lut(1, bytes[1])), white_of(1));  // another texture: not the memo
  EXPECT_EQ(table(0, pager.white_lut(0, bytes[0])), white_of(0));
}

TEST(TexturePager, ArenaBytesIncludeThePool) {
  const mlhost::LoadedScene& s = load("builtin:banded");
  const ml::Camera cam = textest::camera_for(s, 96, 64);
  for (ml::RendererKind r : {ml::RendererKind::Scanline, ml::RendererKind::Tiler}) {
    for (uint32_t pool : {ml::kTexturePoolAll, 9000u, 0u}) {
      ml::RenderOptions o = textest::options(r);
      o.texture_pool_bytes = pool;
      const size_t need = ml::render_arena_bytes(s.scene, cam, o);
      EXPECT_TRUE(textest::render(s.scene, cam, o, need).status.ok());
      const Frame less = textest::render(s.scene, cam, o, need - 1);
      EXPECT_EQ(less.status.code, ml::StatusCode::ArenaTooSmall);
    }
    ml::RenderOptions small = textest::options(r), all = small;
    small.texture_pool_bytes = 9000;
    EXPECT_EQ(ml::render_arena_bytes(s.scene, cam, all) - ml::render_arena_bytes(s.scene, cam, small),
              size_t(ml::texture_pool_needs(s.scene).desired - 9000));
  }
}

// The blob sampled where it lies (a board's memory-mapped flash): no pool, nothing loaded, the same
// picture as the whole-set pool, in both renderers, with and without supersampling.
TEST(TexturePager, InPlaceBlobNeedsNoPoolAndGivesTheSameImage) {
  for (const std::string& name : {std::string("builtin:banded"), textest::model("BoxTextured-glTF/BoxTextured.gltf")}) {
    const mlhost::LoadedScene& s = load(name);
    ml::BlobTextureSource in_place(s.scene, ml::BlobTextureSource::Access::InPlace);
    const ml::Camera cam = textest::camera_for(s, 160, 120);
    for (ml::RendererKind r : {ml::RendererKind::Scanline, ml::RendererKind::Tiler}) {
      for (int aa : {1, 2}) {
        const ml::RenderOptions copied = textest::options(r, ml::ShadingMode::Flat, aa);
        ml::RenderOptions o = copied;
        o.texture_source = &in_place;
        o.texture_pool_bytes = 0;
        const Frame pooled = textest::render(s.scene, cam, copied);
        const Frame f = textest::render(s.scene, cam, o);
        ASSERT_TRUE(f.status.ok()) << name;
        EXPECT_TRUE(f.contract) << f.contract_error;
        EXPECT_EQ(f.pixels, pooled.pixels) << name << " aa " << aa;
        EXPECT_GT(pooled.stats.texture_loads, 0u) << name;
        EXPECT_EQ(f.stats.texture_loads, 0u);
        EXPECT_EQ(f.stats.texture_bytes_loaded, 0u);
        EXPECT_EQ(f.stats.texture_bytes_peak, 0u);
        EXPECT_EQ(f.stats.texture_fallbacks, 0u);
        EXPECT_LT(ml::render_arena_bytes(s.scene, cam, o), ml::render_arena_bytes(s.scene, cam, copied));
      }
    }
  }
}

TEST(TexturePager, FileSourceReadsTheSameTexels) {
  const mlhost::LoadedScene& s = load("builtin:banded");
  const std::string path = scenetest::temp_dir() + "/banded.mls";
  std::string error;
  ASSERT_TRUE(ml::save_blob_file(path, s.blob, &error)) << error;
  mlhost::FileTextureSource file(path, s.scene);
  ASSERT_TRUE(file.ok());
  const ml::Camera cam = textest::camera_for(s, 160, 120);
  ml::RenderOptions o = textest::options(ml::RendererKind::Scanline);
  const Frame blob = textest::render(s.scene, cam, o);
  o.texture_source = &file;
  const Frame from_file = textest::render(s.scene, cam, o);
  ASSERT_TRUE(from_file.status.ok());
  EXPECT_EQ(from_file.stats.texture_fallbacks, 0u);
  EXPECT_EQ(from_file.pixels, blob.pixels);
}

}  // namespace
