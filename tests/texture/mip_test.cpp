// Mip levels (docs/textures.md, "Mip levels"): what the compiler stores, the level a triangle
// samples, and the reader's checks of them. Both renderers' images with levels are compared with each
// other and with the reference texturer by the tests of every textured scene (textured_scenes()
// holds BoxTextured, whose sampler asks for levels, and the duck and banded scene compiled with them).
#include <gtest/gtest.h>

#include <cstdlib>

#include "tests/oracle/scene_triangles.h"
#include "tests/oracle/texturer.h"
#include "tests/scene/scene_test_util.h"
#include "tests/texture/texture_test_util.h"
#include "texture/mapping.h"
#include "texture/pager.h"
#include "tools/scenec/scenec.h"

namespace {

ml::Scene read_scene_of(const ml::CompileResult& r) {
  ml::Scene scene;
  EXPECT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(scenetest::read(r.blob, &scene).ok());
  return scene;
}

// ---- the compiler --------------------------------------------------------------------------------

TEST(TextureMips, CompilerStoresLevelsWhereTheSamplerAsksOrWhenTold) {
  ml::CompileOptions options;
  // BoxTextured's sampler has minFilter NEAREST_MIPMAP_LINEAR: levels down to 1 x 1.
  const ml::CompileResult box = ml::compile_gltf_file(textest::model("BoxTextured-glTF/BoxTextured.gltf"), options);
  const ml::Scene with = read_scene_of(box);
  ASSERT_EQ(with.texture_texels_count, 1u);
  const ml::TextureTexels& t = with.texture_texels[0];
  EXPECT_EQ(t.levels, ml::texture_max_levels(t.width, t.height));
  EXPECT_EQ(t.bytes, ml::texture_chain_bytes(ml::TexelFormat(t.format), t.width, t.height, t.palette_size, t.levels));
  // --mips off: none.
  options.texture_mips = ml::TextureMipChoice::Off;
  const ml::CompileResult box_off = ml::compile_gltf_file(textest::model("BoxTextured-glTF/BoxTextured.gltf"), options);
  const ml::Scene without = read_scene_of(box_off);
  EXPECT_EQ(without.texture_texels[0].levels, 0u);
  EXPECT_EQ(without.texture_texels[0].bytes,
            ml::texture_bytes(ml::TexelFormat(t.format), t.width, t.height, without.texture_texels[0].palette_size));
  // The banded scene's samplers do not ask; --mips on gives every texture its levels.
  const ml::Scene& banded = textest::load("builtin:banded").scene;
  for (uint32_t i = 0; i < banded.texture_texels_count; ++i) EXPECT_EQ(banded.texture_texels[i].levels, 0u);
  const ml::Scene& banded_mips = textest::load("mips:builtin:banded").scene;
  ASSERT_EQ(banded_mips.texture_texels_count, banded.texture_texels_count);
  for (uint32_t i = 0; i < banded_mips.texture_texels_count; ++i) {
    const ml::TextureTexels& m = banded_mips.texture_texels[i];
    EXPECT_EQ(m.levels, ml::texture_max_levels(m.width, m.height)) << i;
    EXPECT_EQ(m.width, banded.texture_texels[i].width);
  }
}

TEST(TextureMips, EachLevelIsTheTwoByTwoMeanOfTheOneBefore) {
  // Every format: each texel of level L within a quantization step of the mean of the (up to) 2 x 2
  // texels of level L - 1 it covers, read back as the reference texturer reads the blob.
  const struct {
    ml::TextureFormatChoice format;
    int slack;  // per 8-bit channel: about an RGB565 step; a palette's nearest entry; a grey4 step (17)
  } formats[] = {{ml::TextureFormatChoice::Rgb565, 10}, {ml::TextureFormatChoice::Palette8, 20},
                 {ml::TextureFormatChoice::Grey4, 17}};
  for (const auto& f : formats) {
    ml::CompileOptions options;
    options.texture_format = f.format;
    options.texture_mips = ml::TextureMipChoice::On;
    const ml::CompileResult r = ml::build_banded_scene(options);
    const ml::Scene scene = read_scene_of(r);
    const std::vector<oracle::Texture> textures = oracle::scene_textures(scene);
    for (size_t i = 0; i < textures.size(); ++i) {
      const oracle::Texture& base = textures[i];
      ASSERT_EQ(base.levels.size(), size_t(ml::texture_max_levels(uint32_t(base.width), uint32_t(base.height))));
      const oracle::Texture* above = &base;
      for (const oracle::Texture& level : base.levels) {
        EXPECT_EQ(level.width, std::max(1, above->width / 2));
        EXPECT_EQ(level.height, std::max(1, above->height / 2));
        const int kx = above->width > 1 ? 2 : 1, ky = above->height > 1 ? 2 : 1;
        for (int y = 0; y < level.height; ++y)
          for (int x = 0; x < level.width; ++x)
            for (int k = 0; k < 3; ++k) {
              int sum = 0;
              for (int j = 0; j < ky; ++j)
                for (int c = 0; c < kx; ++c) {
                  const uint32_t p = above->rgb[size_t(y * ky + j) * size_t(above->width) + size_t(x * kx + c)];
                  sum += int((p >> (16 - 8 * k)) & 0xFF);
                }
              const int mean = sum / (kx * ky);
              const int got = int((level.rgb[size_t(y) * size_t(level.width) + size_t(x)] >> (16 - 8 * k)) & 0xFF);
              ASSERT_LE(std::abs(got - mean), f.slack)
                  << "format " << int(f.format) << " texture " << i << " level " << (above - &base) + 1 << " texel " << x
                  << "," << y << " channel " << k;
            }
        above = &level;
      }
    }
  }
}

// ---- the level a triangle samples ------------------------------------------------------------------

// A right triangle with legs of `legs` pixels (its vertices at whole subpixels) mapped onto the whole
// of a 256 x 256 texture's lower-left half: texels / pixels = 65536 / legs^2.
uint32_t level_for_legs(const ml::TextureTexels& t, int64_t legs_subpixels, bool unclipped = true, int32_t den = 1) {
  ml::ViewTriangle v{};
  v.ox[0] = 0, v.oy[0] = 0;
  v.ox[1] = legs_subpixels, v.oy[1] = 0;
  v.ox[2] = 0, v.oy[2] = legs_subpixels;
  v.unclipped = unclipped;
  const int32_t uv[3][2] = {{0, 0}, {65536, 0}, {0, 65536}};
  return ml::texture_level(t, v, uv, den);
}

TEST(TextureMips, LevelIsTheNearestToATexelASample) {
  ml::TextureTexels t{};
  t.width = t.height = 256;
  t.format = uint8_t(ml::TexelFormat::Rgb565);
  t.levels = uint8_t(ml::texture_max_levels(256, 256));
  ASSERT_EQ(t.levels, 8u);
  const int64_t px = ml::kSubpixelOne;
  // legs n: lambda = log2(65536 / n^2) / 2 + 1/2 = 8.5 - log2(n), the level its floor.
  EXPECT_EQ(level_for_legs(t, 256 * px), 0u);  // 0.5
  EXPECT_EQ(level_for_legs(t, 128 * px), 1u);  // 1.5
  EXPECT_EQ(level_for_legs(t, 64 * px), 2u);
  EXPECT_EQ(level_for_legs(t, 2 * px), 7u);
  EXPECT_EQ(level_for_legs(t, 1 * px), 8u);
  EXPECT_EQ(level_for_legs(t, px / 4), 8u);    // beyond the last level: the last
  EXPECT_EQ(level_for_legs(t, 1024 * px), 0u);  // magnified: the texture itself
  // The boundary between levels 0 and 1 lies at legs 256 / sqrt(2) = 181.02 pixels.
  EXPECT_EQ(level_for_legs(t, 181 * px), 1u);
  EXPECT_EQ(level_for_legs(t, 182 * px), 0u);
  // Levels never go up as the triangle grows, subpixel by subpixel across a range.
  uint32_t last = 8;
  for (int64_t legs = px / 2; legs <= 300 * px; legs += 37) {
    const uint32_t l = level_for_legs(t, legs);
    ASSERT_LE(l, last) << legs;
    last = l;
  }
  // den samples a pixel side: the texels per sample grow as if the triangle were den times larger.
  EXPECT_EQ(level_for_legs(t, 64 * px, true, 2), 1u);
  EXPECT_EQ(level_for_legs(t, 64 * px, true, 4), 0u);
  // A clipped triangle, or a texture without levels: level 0.
  EXPECT_EQ(level_for_legs(t, 2 * px, false), 0u);
  t.levels = 0;
  EXPECT_EQ(level_for_legs(t, 2 * px), 0u);
}

TEST(TextureMips, LevelTexelsReadAsATextureOfTheirOwn) {
  for (ml::TexelFormat format : {ml::TexelFormat::Rgb565, ml::TexelFormat::Palette8, ml::TexelFormat::Grey4}) {
    ml::TextureTexels t{};
    t.width = 64, t.height = 8;
    t.format = uint8_t(format);
    t.palette_size = format == ml::TexelFormat::Palette8 ? 200 : 0;
    t.levels = uint8_t(ml::texture_max_levels(64, 8));
    ASSERT_EQ(t.levels, 6u);
    t.offset = 16;
    uint32_t next = 0;
    for (uint32_t l = 0; l <= t.levels; ++l) {
      uint32_t offset;
      const ml::TextureTexels lt = ml::texture_level_texels(t, l, &offset);
      EXPECT_EQ(offset, next) << l;
      EXPECT_EQ(lt.offset, t.offset + offset);
      EXPECT_EQ(lt.width, std::max(1u, 64u >> l));
      EXPECT_EQ(lt.height, std::max(1u, 8u >> l));
      EXPECT_EQ(lt.bytes, ml::texture_bytes(format, lt.width, lt.height, t.palette_size));
      EXPECT_EQ(lt.levels, 0u);
      next += lt.bytes;
    }
    EXPECT_EQ(next, ml::texture_chain_bytes(format, 64, 8, t.palette_size, t.levels));
  }
}

// TextureLevels keeps the last level asked for: asked in turn about textures and levels, each answer is
// texture_level_texels' (sides, offset and bytes), the bytes moved by its offset; level 0 is the scene's own.
TEST(TextureMips, LevelsKeptAnswerForTheTextureAndLevelAsked) {
  const mlhost::LoadedScene& s = textest::load("mips:builtin:banded");
  ASSERT_TRUE(s.scene.texture_texels) << s.name;
  ASSERT_GE(s.scene.texture_texels_count, 2u);
  ASSERT_GE(s.scene.texture_texels[0].levels, 2u);
  ASSERT_GE(s.scene.texture_texels[1].levels, 2u);
  static const uint8_t base[1] = {};
  ml::TextureLevels levels;
  const uint32_t asked[][2] = {{0, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 0}, {0, 2}, {0, 1}, {1, 1}};
  for (const auto& a : asked) {
    const uint32_t texture = a[0], level = a[1];
    uint32_t offset;
    const ml::TextureTexels want = ml::texture_level_texels(s.scene.texture_texels[texture], level, &offset);
    const uint8_t* bytes = levels.bytes(s.scene, texture, level, base);
    const ml::TextureTexels& got = levels.texels(s.scene, texture, level);
    EXPECT_EQ(bytes, base + offset) << texture << " " << level;
    EXPECT_EQ(got.width, want.width) << texture << " " << level;
    EXPECT_EQ(got.height, want.height) << texture << " " << level;
    EXPECT_EQ(got.offset, want.offset) << texture << " " << level;
    if (level == 0) {  // the scene's own, its bytes those of the whole chain
      EXPECT_EQ(&got, &s.scene.texture_texels[texture]);
    } else {
      EXPECT_EQ(got.bytes, want.bytes) << texture << " " << level;
    }
  }
  EXPECT_EQ(levels.bytes(s.scene, 0, 1, nullptr), nullptr);  // a texture the pager could not load
}

// Small triangles' sampling is kept from one to the next by texture and bytes (64-bit hosts); after
// the pager moves a texture, the same bytes may hold another of its levels, whose sides must not be
// the kept ones'.
#if UINTPTR_MAX > 0xFFFFFFFFu
TEST(TextureMips, KeptSamplingTellsLevelsAtTheSameBytesApart) {
  const mlhost::LoadedScene& s = textest::load("mips:builtin:banded");
  ASSERT_TRUE(s.scene.texture_texels) << s.name;
  textest::WholePoolPager whole(s.scene);
  ASSERT_TRUE(whole.began);
  ml::TexturePager& pager = whole.pager;
  const uint8_t* bytes = pager.get(0);
  ASSERT_NE(bytes, nullptr);
  uint32_t offset;
  const ml::TextureTexels one = ml::texture_level_texels(s.scene.texture_texels[0], 1, &offset);
  const ml::TextureTexels two = ml::texture_level_texels(s.scene.texture_texels[0], 2, &offset);
  ml::TexturePlanes planes{};
  planes.exact = planes.boxed = true;
  ml::KeptSampling kept;
  EXPECT_EQ(kept.for_texture(pager, one, 0, bytes, planes, 0xFFFFFF).texture->width, one.width);
  EXPECT_EQ(kept.for_texture(pager, two, 0, bytes, planes, 0xFFFFFF).texture->width, two.width);
  EXPECT_EQ(kept.for_texture(pager, two, 0, bytes, planes, 0xFFFFFF).texture->height, two.height);
}
#endif

// ---- the reader ----------------------------------------------------------------------------------

TEST(TextureMips, ReaderRejectsLevelsTheBytesDoNotHold) {
  const mlhost::LoadedScene& mips = textest::load("mips:builtin:banded");
  ASSERT_TRUE(mips.scene.texture_texels) << mips.name;
  const auto read_with = [&](void (*mutate)(ml::TextureTexels*)) {
    ml::Blob blob = mips.blob;
    mutate(scenetest::section<ml::TextureTexels>(&blob, ml::SectionType::TextureTexels));
    scenetest::fix_crc(&blob);
    return scenetest::read(blob);
  };
  EXPECT_STREQ(read_with([](ml::TextureTexels* t) { t->levels = uint8_t(t->levels + 1); }).message,
               "texture mip levels invalid");
  EXPECT_STREQ(read_with([](ml::TextureTexels* t) { t->levels = uint8_t(t->levels - 1); }).message,
               "texture byte count wrong");
  EXPECT_STREQ(read_with([](ml::TextureTexels* t) { t->levels = 0; }).message, "texture byte count wrong");
  // Without levels, the texture itself is what it was.
  EXPECT_TRUE(read_with([](ml::TextureTexels* t) {
                t->levels = 0;
                t->bytes = ml::texture_bytes(ml::TexelFormat(t->format), t->width, t->height, t->palette_size);
              }).ok());
}

}  // namespace
