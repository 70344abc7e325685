// maskline: the host command line (compile, info, render). docs/cli.md is the reference.
// Exit codes: 0 success, 1 a file could not be read or a render failed, 2 bad usage (unknown option,
// bad value). Every error is one line on stderr, "maskline: ...".
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/arena.h"
#include "core/fixed.h"
#include "core/band.h"
#include "core/pixel_format.h"
#include "platform/host/displays.h"
#include "platform/host/file_texture_source.h"
#include "platform/host/format_names.h"
#include "platform/host/image_sink.h"
#include "platform/host/png_io.h"
#include "platform/host/png_stream_sink.h"
#include "platform/host/scene_load.h"
#include "platform/host/stats_json.h"
#include "render/render.h"
#include "texture/pager.h"
#include "tools/scenec/scenec.h"
#include "view/view.h"

namespace {

// Thrown to end the program with a one-line message and an exit code.
struct Exit {
  int code;
  std::string message;
};

[[noreturn]] void usage_error(const std::string& message) { throw Exit{2, message}; }
[[noreturn]] void failure(const std::string& message) { throw Exit{1, message}; }

const char* const kMainHelp =
    "usage: maskline COMMAND [ARGS]\n"
    "\n"
    "commands:\n"
    "  compile IN.glb|IN.gltf -o OUT.mls   compile a glTF 2.0 file into a scene blob\n"
    "  info [SCENE] [--size WxH] [--aa N] [--renderer R]\n"
    "                                      triangles, nodes, materials, bounds, BSP, arena bytes\n"
    "  render [SCENE] [options]            render to PNG (see maskline render --help)\n"
    "  show [SCENE] --display SPEC [options]\n"
    "                                      draw on a framebuffer, an SPI panel or a panel emulator\n"
    "  help [COMMAND]                      this text, or a command's\n"
    "\n"
    "SCENE is a .glb/.gltf file (compiled in memory) or a .mls blob; without it the bundled default\n"
    "scene is used. Exit codes: 0 ok, 1 read or render failure, 2 bad usage.\n";

const char* const kCompileHelp =
    "usage: maskline compile IN.glb|IN.gltf -o OUT.mls [--texture-format F] [--texture-max N] [--mips M]\n"
    "                        [--texture-filter F]\n"
    "\n"
    "Compiles a glTF 2.0 file into a scene blob (.mls): every node of the default scene with its\n"
    "transform, triangle primitives, materials, textures, a BSP tree. Prints a summary; warnings go to\n"
    "stderr.\n"
    "  --texture-format F   auto (default: grey4 for grey images of <= 16 levels, palette8 for <= 256\n"
    "                       colours, else rgb565), rgb565, palette8 (median cut), grey4, or none (no\n"
    "                       texels: base colours, for a board built without textures)\n"
    "  --texture-max N      longest texture side after resampling to powers of two, 1..1024 (default 256)\n"
    "  --mips M             mip levels down to 1x1, sampled one a triangle: auto (default: for textures\n"
    "                       whose glTF sampler asks for them, minFilter *_MIPMAP_*), on or off\n"
    "  --texture-filter F   model (default: as each glTF sampler asks, NEAREST magnification nearest,\n"
    "                       else bilinear), nearest (one texel a sample: the cheaper on a board) or\n"
    "                       bilinear, for every texture\n";

const char* const kInfoHelp =
    "usage: maskline info [SCENE] [--size WxH] [--aa N] [--renderer tiler|scanline]\n"
    "\n"
    "Prints triangles, nodes, materials, bounds (world and glTF units), the BSP (nodes, pieces, split\n"
    "ratio) and the arena bytes a render at --size (default 320x240) needs, for both renderers or the\n"
    "one given. --aa: samples per pixel per axis (the tiler takes 1, 2, 4 or 8; ids are point-sampled).\n"
    "Lists each texture (size, format, bytes, sampler) and the texture pool a frame would like and needs\n"
    "at least.\n";

const char* const kRenderHelp =
    "usage: maskline render [SCENE] [options]\n"
    "\n"
    "  --renderer tiler|scanline   visibility algorithm (default tiler)\n"
    "  --size WxH                  image size in pixels, 1..4096 each (default 320x240)\n"
    "  --aa N                      N x N samples per pixel (default 1): scanline 1..8, tiler 1, 2, 4\n"
    "                              or 8 (on a regular grid)\n"
    "  --filter box|cosine         tiler with --aa 2, 4 or 8: the mean of a pixel's own samples (box,\n"
    "                              default) or a cosine-hump kernel over the 3x3 pixels around it\n"
    "  --samples regular|jittered  tiler with --aa 2, 4 or 8: samples at their sub-cells' centres\n"
    "                              (default) or jittered inside them, the pattern per pixel by --seed\n"
    "  --shading unlit|flat|gouraud|lines\n"
    "                              base colours; + one directional light; per-vertex lighting;\n"
    "                              hidden-line drawing (scanline only). Default flat\n"
    "  --eye X,Y,Z --target X,Y,Z --up X,Y,Z\n"
    "                              camera in glTF units (default: frame the bounding sphere)\n"
    "  --fov DEG                   vertical field of view, 1..170 (default 45)\n"
    "  --near DIST                 near plane distance in glTF units (default: from the framing)\n"
    "  --background RRGGBB         background colour (default 202830)\n"
    "  --seed N                    seed for stochastic shading choices (default 1)\n"
    "  -o OUT.png                  colour image\n"
    "  --ids OUT.png               per pixel the visible triangle id + 1 as little-endian RGBA8\n"
    "                              (0 = background), point-sampled at pixel centres\n"
    "  --work OUT.png              Greene's work image: pyramid cells visited per pixel, log-scale\n"
    "                              heatmap (tiler only)\n"
    "  --stats                     print one JSON object of frame statistics on stdout\n"
    "  --arena BYTES               use an arena of this size instead of the need plus the renderer's\n"
    "                              spare bytes (info prints both): the tiler's bands rendered at once,\n"
    "                              band plan and vertex cache, the scanline renderer's vertex cache\n"
    "                              (the same image either way)\n"
    "  --texture-pool BYTES|all    texture pool in the arena (default all: every texture fits; smaller\n"
    "                              pools evict and reload, below the largest texture some fall back)\n"
    "  --texture-source blob|file  texels from the scene in memory (default) or read from the .mls file\n"
    "                              when first needed\n"
    "\n"
    "output (how pixels leave the renderer; the PNG shows what such a display would show):\n"
    "  --format F                  xrgb8888 (default), rgb565 (panel byte order), rgb565le, grey8,\n"
    "                              grey4, mono1\n"
    "  --dither on|off             4x4 ordered dither (default: on for grey and mono, off otherwise)\n"
    "  --band-rows N               rows per band buffer, 0 = the whole frame (default 16)\n"
    "  --buffers 1|2               band buffers (2 lets a display send one band while the next renders)\n"
    "  --render-rows N             tiler: rows it may render at once when the arena has room, each band\n"
    "                              still sent on its own (default 0: the whole frame with one buffer,\n"
    "                              a band at a time with two)\n"
    "\n"
    "Bands stream into the PNG as they leave the renderer: no frame buffer is held.\n";

const char* const kShowHelp =
    "usage: maskline show [SCENE] --display SPEC [render options] [-o OUT.png] [--stats]\n"
    "                     [--frames N --orbit DEG]\n"
    "\n"
    "Draws the frame on a display, band by band, in the display's own pixel format.\n"
    "  --display fb:/dev/fbN         a Linux framebuffer (the frame is centred on its screen)\n"
    "  --display spi:PANEL[,key=value...]\n"
    "                                a panel on spidev with D/C and RESET on GPIO lines; keys: rotation,\n"
    "                                device, speed, mode, bits, chip, dc, reset, max (docs/panels.md)\n"
    "  --display emu:PANEL[,rotation=DEG]\n"
    "                                a panel emulator decoding the exact bytes the panel would receive\n"
    "  PANEL: ili9341, st7789, st7789-240, ssd1306, ssd0323. Without rotation= the panel is mounted so\n"
    "  it shows --size (320x240 on an ILI9341: rotation 90); without --size, at its own size.\n"
    "  -o OUT.png                    what the display shows (emulators: the decoded panel; others: the\n"
    "                                frame in the display's format); with %d in the name, every frame\n"
    "  --zoom N                      magnify an emulator's picture N times in OUT.png (1..16, default 1)\n"
    "  --frames N --orbit DEG        N frames, the camera turning DEG degrees a frame about the target;\n"
    "                                prints each frame's time and the frames per second\n"
    "  --stats                       one JSON line of statistics per frame (display_bytes and\n"
    "                                display_windows count what went to the display)\n"
    "The render options are those of maskline render (--renderer, --size, --aa, --shading, --eye,\n"
    "--target, --up, --fov, --near, --background, --seed, --dither, --band-rows, --buffers, --render-rows,\n"
    "--arena, "
    "--texture-pool, --texture-source);\n"
    "--format, when given, must be the display's.\n";

// ---- argument parsing ---------------------------------------------------------------------------

struct Args {
  std::vector<std::string> positional;
  std::vector<std::pair<std::string, std::string>> options;  // name (with dashes) -> value
  bool help = false;
};

// Options that take a value, per command; flags listed separately.
Args parse_args(int argc, char** argv, int first, const std::vector<std::string>& valued,
                const std::vector<std::string>& flags, const std::string& command) {
  Args a;
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      a.help = true;
      continue;
    }
    if (arg.size() > 1 && arg[0] == '-') {
      std::string name = arg, value;
      bool has_value = false;
      const size_t eq = arg.find('=');
      if (arg.compare(0, 2, "--") == 0 && eq != std::string::npos) {
        name = arg.substr(0, eq);
        value = arg.substr(eq + 1);
        has_value = true;
      }
      bool is_valued = false, is_flag = false;
      for (const auto& v : valued) is_valued |= v == name;
      for (const auto& f : flags) is_flag |= f == name;
      if (!is_valued && !is_flag) usage_error("unknown option '" + name + "' for " + command + " (see maskline " + command + " --help)");
      if (is_flag) {
        if (has_value) usage_error("option " + name + " takes no value");
        a.options.push_back({name, ""});
        continue;
      }
      if (!has_value) {
        if (i + 1 >= argc) usage_error("option " + name + " needs a value");
        value = argv[++i];
      }
      a.options.push_back({name, value});
      continue;
    }
    a.positional.push_back(arg);
  }
  return a;
}

const std::string* find_option(const Args& a, const std::string& name) {
  const std::string* found = nullptr;
  for (const auto& o : a.options)
    if (o.first == name) found = &o.second;  // the last one wins
  return found;
}

bool has_flag(const Args& a, const std::string& name) { return find_option(a, name) != nullptr; }

long long parse_integer(const std::string& option, const std::string& text, long long lo, long long hi) {
  errno = 0;
  char* end = nullptr;
  const long long v = strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || v < lo || v > hi)
    usage_error(option + ": expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got '" + text + "'");
  return v;
}

double parse_number(const std::string& option, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = strtod(text.c_str(), &end);
  // ERANGE on underflow (1e-310, a subnormal) still gives a usable value; only overflow is refused.
  const bool range_error = errno != 0 && !(errno == ERANGE && std::fabs(v) <= 1.0);
  if (text.empty() || *end != '\0' || range_error || !std::isfinite(v))
    usage_error(option + ": expected a finite number, got '" + text + "'");
  return v;
}

void parse_size(const std::string& text, int* w, int* h) {
  const size_t x = text.find('x');
  if (x == std::string::npos) usage_error("--size: expected WxH, got '" + text + "'");
  const std::string ws = text.substr(0, x), hs = text.substr(x + 1);
  for (const std::string* s : {&ws, &hs}) {
    if (s->empty() || s->find_first_not_of("0123456789") != std::string::npos)
      usage_error("--size: expected WxH with positive integers, got '" + text + "'");
  }
  if (ws.size() > 9 || hs.size() > 9 || std::stol(ws) < 1 || std::stol(hs) < 1 || std::stol(ws) > ml::kMaxScreenDim ||
      std::stol(hs) > ml::kMaxScreenDim)
    usage_error("--size: each side must be 1.." + std::to_string(ml::kMaxScreenDim) + ", got '" + text + "'");
  *w = int(std::stol(ws));
  *h = int(std::stol(hs));
}

void parse_vec3(const std::string& option, const std::string& text, double out[3]) {
  size_t start = 0;
  for (int i = 0; i < 3; ++i) {
    const size_t comma = text.find(',', start);
    if ((i < 2) != (comma != std::string::npos)) usage_error(option + ": expected X,Y,Z, got '" + text + "'");
    out[i] = parse_number(option, text.substr(start, i < 2 ? comma - start : std::string::npos));
    start = comma + 1;
  }
}

ml::RendererKind parse_renderer(const std::string& text) {
  if (text == "tiler") return ml::RendererKind::Tiler;
  if (text == "scanline") return ml::RendererKind::Scanline;
  usage_error("--renderer: expected tiler or scanline, got '" + text + "'");
}

const char* renderer_name(ml::RendererKind k) { return k == ml::RendererKind::Tiler ? "tiler" : "scanline"; }

const char* shading_name(ml::ShadingMode m) {
  switch (m) {
    case ml::ShadingMode::Unlit: return "unlit";
    case ml::ShadingMode::Flat: return "flat";
    case ml::ShadingMode::Gouraud: return "gouraud";
    case ml::ShadingMode::Ids: return "ids";
    case ml::ShadingMode::Lines: return "lines";
  }
  return "?";
}

std::string status_text(const ml::Status& s) {
  if (s.code == ml::StatusCode::ArenaTooSmall) return std::string(s.message) + " (" + std::to_string(s.value) + " bytes needed)";
  return s.message;
}

// The scene at `path` (the bundled one for ""), or exit with one line. A glTF input's compiler
// warnings go to stderr first: a texture that did not decode draws its material colour, and the
// warning says why.
ml::Scene require_scene(const std::string& path, mlhost::LoadedScene* loaded,
                        const ml::CompileOptions& options = ml::CompileOptions()) {
  std::string error;
  if (!mlhost::load_scene(path, loaded, &error, true, options)) failure(error);
  for (const auto& w : loaded->warnings) fprintf(stderr, "maskline: warning: %s\n", w.c_str());
  return loaded->scene;
}

// Whether a material is an alpha BLEND the scanline renderer blends and the tiler draws opaque.
bool translucent_blend(const ml::Material& m) {
  return m.alpha_mode == uint8_t(ml::AlphaMode::Blend) && m.base_color[3] != 0 && m.base_color[3] != 255;
}

// The tiler draws alpha BLEND materials opaque (docs/tiler.md), where the scanline renderer blends
// them: one note on stderr naming the translucent ones (0 < alpha < 1; alpha 0 is left out by both),
// so that a picture unlike the scanline renderer's says why.
void note_opaque_blends(const ml::Scene& scene, ml::RendererKind renderer) {
  if (renderer != ml::RendererKind::Tiler) return;
  std::string names;
  uint32_t count = 0;
  for (uint32_t m = 0; m < scene.material_count; ++m)
    if (translucent_blend(scene.materials[m])) names += (count++ ? ", " : "") + std::to_string(m);
  if (count == 0) return;
  fprintf(stderr,
          "maskline: note: material%s %s: alphaMode BLEND, translucent: the tiler draws %s opaque "
          "(--renderer scanline blends %s)\n",
          count == 1 ? "" : "s", names.c_str(), count == 1 ? "it" : "them", count == 1 ? "it" : "them");
}

// ---- camera ---------------------------------------------------------------------------------------

struct CameraArgs {
  bool has_eye = false, has_target = false, has_up = false, has_near = false;
  double eye[3], target[3], up[3], near = 0;
  double fov = 45;
};

int64_t length_of(const ml::Vec3i& a, const ml::Vec3i& b) {
  const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
  return int64_t(std::llround(std::sqrt(dx * dx + dy * dy + dz * dz)));
}

ml::Camera make_camera(const ml::Scene& scene, const CameraArgs& c, int width, int height) {
  const ml::SceneInfo& info = *scene.info;
  const ml::Vec3i center{info.sphere_center[0], info.sphere_center[1], info.sphere_center[2]};
  const int32_t fov_q16 = int32_t(std::llround(c.fov * 65536.0));
  ml::Camera cam = ml::frame_sphere(center, info.sphere_radius, width, height, fov_q16);
  const mlhost::GltfMapping map = mlhost::gltf_mapping(scene);
  if (c.has_eye && !mlhost::gltf_point_to_world(map, c.eye, &cam.eye)) usage_error("--eye: outside the world range of this scene");
  if (c.has_target && !mlhost::gltf_point_to_world(map, c.target, &cam.target))
    usage_error("--target: outside the world range of this scene");
  if (c.has_eye && !c.has_target) cam.target = center;
  if (c.has_up) {
    // Scale by the largest component first: squaring 1e300 overflows and squaring 1e-300 underflows.
    const double largest = std::max(std::fabs(c.up[0]), std::max(std::fabs(c.up[1]), std::fabs(c.up[2])));
    if (!(largest > 0)) usage_error("--up: must not be zero");
    const double u[3] = {c.up[0] / largest, c.up[1] / largest, c.up[2] / largest};
    const double len = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);   // 1..sqrt(3)
    cam.up = ml::Vec3i{int32_t(std::llround(u[0] / len * (1 << 20))), int32_t(std::llround(u[1] / len * (1 << 20))),
                       int32_t(std::llround(u[2] / len * (1 << 20)))};
  }
  if (c.has_near) {
    const double n = c.near * map.to_world;
    if (!(c.near > 0)) usage_error("--near: must be positive");
    if (!(n < double(1 << ml::kViewLimitBits))) usage_error("--near: too far for this scene");
    cam.near = int32_t(std::max(1.0, std::round(n)));
  } else if (c.has_eye) {
    // The framing's near plane assumes its own eye; recompute it for the user's.
    const int64_t d = length_of(cam.eye, center);
    const int64_t r = info.sphere_radius;
    cam.near = int32_t(std::max<int64_t>(1, d > r ? (d - r) / 2 : r / 1024));
  }
  ml::View view;
  const ml::Status s = ml::make_view(cam, &view);
  if (!s.ok()) usage_error(std::string("camera: ") + s.message);
  return cam;
}

// Anonymous zero pages for an arena larger than a render asks for (render --arena).
struct MappedArena {
  void* base = MAP_FAILED;
  size_t bytes = 0;
  MappedArena() = default;
  MappedArena(const MappedArena&) = delete;
  MappedArena& operator=(const MappedArena&) = delete;
  ~MappedArena() { reset(); }
  void reset() {
    if (base != MAP_FAILED) munmap(base, bytes);
    base = MAP_FAILED;
    bytes = 0;
  }
};

// ---- commands -------------------------------------------------------------------------------------

int cmd_compile(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"-o", "--texture-format", "--texture-max", "--mips", "--texture-filter"}, {},
                            "compile");
  if (a.help) {
    fputs(kCompileHelp, stdout);
    return 0;
  }
  if (a.positional.size() != 1) usage_error("compile: expected one input file (see maskline compile --help)");
  const std::string* out = find_option(a, "-o");
  if (!out || out->empty()) usage_error("compile: -o OUT.mls is required");
  const std::string& in = a.positional[0];
  ml::CompileOptions options;
  if (const auto* v = find_option(a, "--texture-format")) {
    if (*v == "auto") options.texture_format = ml::TextureFormatChoice::Auto;
    else if (*v == "rgb565") options.texture_format = ml::TextureFormatChoice::Rgb565;
    else if (*v == "palette8") options.texture_format = ml::TextureFormatChoice::Palette8;
    else if (*v == "grey4") options.texture_format = ml::TextureFormatChoice::Grey4;
    else if (*v == "none") options.texture_format = ml::TextureFormatChoice::None;
    else usage_error("--texture-format: expected auto, rgb565, palette8, grey4 or none, got '" + *v + "'");
  }
  if (const auto* v = find_option(a, "--texture-max"))
    options.texture_max_size = int(parse_integer("--texture-max", *v, 1, ml::kMaxTextureDim));
  if (const auto* v = find_option(a, "--mips")) {
    if (*v == "auto") options.texture_mips = ml::TextureMipChoice::Auto;
    else if (*v == "on") options.texture_mips = ml::TextureMipChoice::On;
    else if (*v == "off") options.texture_mips = ml::TextureMipChoice::Off;
    else usage_error("--mips: expected auto, on or off, got '" + *v + "'");
  }
  if (const auto* v = find_option(a, "--texture-filter")) {
    if (*v == "model") options.texture_filter = ml::TextureFilterChoice::Model;
    else if (*v == "nearest") options.texture_filter = ml::TextureFilterChoice::Nearest;
    else if (*v == "bilinear") options.texture_filter = ml::TextureFilterChoice::Bilinear;
    else usage_error("--texture-filter: expected model, nearest or bilinear, got '" + *v + "'");
  }
  mlhost::LoadedScene loaded;
  const ml::Scene s = require_scene(in, &loaded, options);
  std::string error;
  if (!ml::save_blob_file(*out, loaded.blob, &error)) failure(error);
  printf("wrote %s: %zu bytes, %u triangles, %u nodes, %u materials, %u BSP nodes, %u pieces\n", out->c_str(),
         loaded.blob.size, s.triangle_count, s.node_count, s.material_count, s.bsp_node_count, s.bsp_piece_count);
  return 0;
}

const char* texel_format_name(uint8_t f) {
  switch (ml::TexelFormat(f)) {
    case ml::TexelFormat::Rgb565: return "rgb565";
    case ml::TexelFormat::Palette8: return "palette8";
    case ml::TexelFormat::Grey4: return "grey4";
    default: return "none";
  }
}

// One line per material: its colour, alpha mode and what the renderers make of it, sides, texture.
void print_materials(const ml::Scene& scene) {
  for (uint32_t i = 0; i < scene.material_count; ++i) {
    const ml::Material& m = scene.materials[i];
    printf("material %u: base colour %02x%02x%02x", i, m.base_color[0], m.base_color[1], m.base_color[2]);
    if (m.alpha_mode == uint8_t(ml::AlphaMode::Mask))
      printf(", alpha %u/255, MASK cutoff %u/255", m.base_color[3], m.alpha_cutoff);
    else if (m.alpha_mode == uint8_t(ml::AlphaMode::Blend))
      printf(", alpha %u/255, BLEND", m.base_color[3]);
    else
      printf(", OPAQUE");
    if (ml::material_hidden(m)) printf(" (invisible: not drawn)");
    if (translucent_blend(m)) printf(" (the tiler draws it opaque)");
    printf(", %s", m.double_sided ? "double-sided" : "single-sided");
    if (m.texture == ml::kNone) printf(", no texture\n");
    else printf(", texture %u\n", m.texture);
  }
}

// One line per texture, then the pool sizes (texture/pager.h).
void print_textures(const ml::Scene& scene) {
  static const char* const kWrap[] = {"repeat", "mirrored", "clamp"};
  if (scene.texture_count > 0 && scene.texture_texels_count == 0)
    printf("%s: no texels stored (images missing or not decodable, or compiled with --texture-format none): material colours\n",
           scene.texture_count == 1 ? "texture 0" : ("textures 0.." + std::to_string(scene.texture_count - 1)).c_str());
  for (uint32_t i = 0; i < scene.texture_texels_count; ++i) {
    const ml::TextureTexels& t = scene.texture_texels[i];
    if (t.format == uint8_t(ml::TexelFormat::None)) {
      printf("texture %u: no texels (image missing or not decodable, or not a base colour texture): material colour\n", i);
      continue;
    }
    printf("texture %u: %ux%u %s", i, t.width, t.height, texel_format_name(t.format));
    if (t.format == uint8_t(ml::TexelFormat::Palette8)) printf(" (%u colours)", t.palette_size);
    printf(", %u bytes", t.bytes);
    if (t.levels > 0) printf(" with %u mip levels", t.levels);
    printf(", wrap %s/%s, %s\n", kWrap[t.wrap_s], kWrap[t.wrap_t],
           t.filter == uint8_t(ml::TextureFilter::Bilinear) ? "bilinear" : "nearest");
  }
  const ml::TexturePoolNeeds needs = ml::texture_pool_needs(scene);
  if (needs.desired) printf("texture pool bytes: desired %u (every texture), minimum %u (the largest)\n",
                            needs.desired, needs.minimum);
}

int cmd_info(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"--size", "--aa", "--renderer"}, {}, "info");
  if (a.help) {
    fputs(kInfoHelp, stdout);
    return 0;
  }
  if (a.positional.size() > 1) usage_error("info: expected at most one scene (see maskline info --help)");
  int width = 320, height = 240, aa = 1;
  bool only = false;
  ml::RendererKind which = ml::RendererKind::Tiler;
  if (const auto* v = find_option(a, "--size")) parse_size(*v, &width, &height);
  if (const auto* v = find_option(a, "--aa")) aa = int(parse_integer("--aa", *v, 1, 8));
  if (const auto* v = find_option(a, "--renderer")) {
    which = parse_renderer(*v);
    only = true;
  }
  const bool tiler_aa = aa == 1 || aa == 2 || aa == 4 || aa == 8;
  if (only && which == ml::RendererKind::Tiler && !tiler_aa) usage_error("--aa: the tiler takes 1, 2, 4 or 8");
  mlhost::LoadedScene loaded;
  const ml::Scene scene = require_scene(a.positional.empty() ? "" : a.positional[0], &loaded);
  const ml::SceneInfo& info = *scene.info;
  const mlhost::GltfMapping map = mlhost::gltf_mapping(scene);
  printf("scene: %s (%zu bytes)\n", loaded.name.c_str(), loaded.blob.size);
  printf("triangles: %u\n", scene.triangle_count);
  printf("nodes: %u\n", scene.node_count);
  printf("materials: %u\n", scene.material_count);
  printf("batches: %u, vertices: %u, textures: %u\n", scene.batch_count, scene.vertex_count, scene.texture_count);
  if (!loaded.warnings.empty()) printf("compiler warnings: %zu (on stderr)\n", loaded.warnings.size());
  printf("bounds (world units): min %d,%d,%d max %d,%d,%d\n", info.bounds_min[0], info.bounds_min[1], info.bounds_min[2],
         info.bounds_max[0], info.bounds_max[1], info.bounds_max[2]);
  printf("bounds (glTF units): min %g,%g,%g max %g,%g,%g\n", mlhost::world_to_gltf(map, 0, info.bounds_min[0]),
         mlhost::world_to_gltf(map, 1, info.bounds_min[1]), mlhost::world_to_gltf(map, 2, info.bounds_min[2]),
         mlhost::world_to_gltf(map, 0, info.bounds_max[0]), mlhost::world_to_gltf(map, 1, info.bounds_max[1]),
         mlhost::world_to_gltf(map, 2, info.bounds_max[2]));
  printf("bounding sphere (world units): centre %d,%d,%d radius %d\n", info.sphere_center[0], info.sphere_center[1],
         info.sphere_center[2], info.sphere_radius);
  const double split = scene.triangle_count ? double(scene.bsp_piece_count) / scene.triangle_count : 0.0;
  uint32_t cones = 0;
  for (uint32_t i = 0; scene.bsp_cones && i < scene.bsp_node_count; ++i) cones += scene.bsp_cones[i].spread != ml::kNoCone;
  printf("bsp: %u nodes, %u pieces, split ratio %.4f, depth %u, %u normal cones\n", scene.bsp_node_count,
         scene.bsp_piece_count, split, info.bsp_depth, cones);
  print_materials(scene);
  print_textures(scene);
  CameraArgs none;
  const ml::Camera base = make_camera(scene, none, width, height);
  for (ml::RendererKind k : {ml::RendererKind::Tiler, ml::RendererKind::Scanline}) {
    if (only && k != which) continue;
    ml::RenderOptions o;
    o.renderer = k;
    if (k == ml::RendererKind::Tiler && !tiler_aa) continue;
    o.aa = aa;
    const size_t bytes = ml::render_arena_bytes(scene, base, o);
    printf("arena bytes (%s, %dx%d, aa %d): %zu", renderer_name(k), width, height, o.aa, bytes);
    const ml::TexturePoolNeeds pool = ml::texture_pool_needs(scene);
    if (pool.minimum < pool.desired) {  // textures: the smallest arena that draws every texture too
      ml::RenderOptions least_pool = o;
      least_pool.texture_pool_bytes = pool.minimum;
      printf(" (%zu with the minimum texture pool)", ml::render_arena_bytes(scene, base, least_pool));
    }
    printf("\n");
    printf("spare bytes (%s, %dx%d, aa %d): %zu\n", renderer_name(k), width, height, o.aa,
           ml::render_spare_bytes(scene, base, o));
  }
  return 0;
}

// ---- render options shared by render and show ---------------------------------------------------

const std::vector<std::string> kRenderValued = {"--renderer", "--size", "--aa", "--eye", "--target", "--up",
                                                "--fov", "--near", "--shading", "--seed", "--background",
                                                "--arena", "--format", "--dither", "--band-rows", "--buffers",
                                                "--render-rows", "--texture-pool", "--texture-source", "--filter",
                                                "--samples"};

struct RenderArgs {
  ml::RenderOptions opt;
  int width = 320, height = 240;
  bool has_size = false, has_format = false, has_dither = false;
  CameraArgs camera;
  long long arena_override = -1;
  bool texture_file = false;  // --texture-source file
};

// Applies one option of kRenderValued; false when the name is not one of them.
bool parse_render_option(const std::string& n, const std::string& v, RenderArgs* r) {
  ml::RenderOptions& opt = r->opt;
  CameraArgs& cam = r->camera;
  if (n == "--renderer") opt.renderer = parse_renderer(v);
  else if (n == "--size") { parse_size(v, &r->width, &r->height); r->has_size = true; }
  else if (n == "--aa") opt.aa = int(parse_integer(n, v, 1, 8));
  else if (n == "--filter") {
    if (v == "box") opt.filter = ml::FilterKind::Box;
    else if (v == "cosine") opt.filter = ml::FilterKind::Cosine;
    else usage_error("--filter: expected box or cosine, got '" + v + "'");
  } else if (n == "--samples") {
    if (v == "regular") opt.samples = ml::SamplePattern::Regular;
    else if (v == "jittered") opt.samples = ml::SamplePattern::Jittered;
    else usage_error("--samples: expected regular or jittered, got '" + v + "'");
  } else if (n == "--eye") { parse_vec3(n, v, cam.eye); cam.has_eye = true; }
  else if (n == "--target") { parse_vec3(n, v, cam.target); cam.has_target = true; }
  else if (n == "--up") { parse_vec3(n, v, cam.up); cam.has_up = true; }
  else if (n == "--fov") {
    cam.fov = parse_number(n, v);
    if (cam.fov < 1 || cam.fov > 170) usage_error("--fov: expected 1..170 degrees, got '" + v + "'");
  } else if (n == "--near") { cam.near = parse_number(n, v); cam.has_near = true; }
  else if (n == "--shading") {
    if (v == "unlit") opt.shading = ml::ShadingMode::Unlit;
    else if (v == "flat") opt.shading = ml::ShadingMode::Flat;
    else if (v == "gouraud") opt.shading = ml::ShadingMode::Gouraud;
    else if (v == "lines") opt.shading = ml::ShadingMode::Lines;
    else usage_error("--shading: expected unlit, flat, gouraud or lines, got '" + v + "'");
  } else if (n == "--seed") opt.seed = uint32_t(parse_integer(n, v, 0, 0xFFFFFFFFll));
  else if (n == "--background") {
    if (v.size() != 6 || v.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
      usage_error("--background: expected RRGGBB in hex, got '" + v + "'");
    opt.background = ml::Pixel(strtoul(v.c_str(), nullptr, 16));
  } else if (n == "--arena") r->arena_override = parse_integer(n, v, 0, 1ll << 40);
  else if (n == "--format") {
    if (!mlhost::parse_format(v, &opt.output.format))
      usage_error("--format: expected xrgb8888, rgb565, rgb565le, grey8, grey4 or mono1, got '" + v + "'");
    r->has_format = true;
  } else if (n == "--dither") {
    if (v != "on" && v != "off") usage_error("--dither: expected on or off, got '" + v + "'");
    opt.output.dither = v == "on";
    r->has_dither = true;
  } else if (n == "--band-rows") opt.output.band_rows = int(parse_integer(n, v, 0, ml::kMaxScreenDim));
  else if (n == "--buffers") opt.output.buffers = int(parse_integer(n, v, 1, ml::kMaxBandBuffers));
  else if (n == "--render-rows") opt.output.render_rows = int(parse_integer(n, v, 0, ml::kMaxScreenDim));
  else if (n == "--texture-pool") {
    opt.texture_pool_bytes = v == "all" ? ml::kTexturePoolAll : uint32_t(parse_integer(n, v, 0, 0xFFFFFFFEll));
  } else if (n == "--texture-source") {
    if (v != "blob" && v != "file") usage_error("--texture-source: expected blob or file, got '" + v + "'");
    r->texture_file = v == "file";
  }
  else return false;
  return true;
}

// Checks that need all options; fills in defaults that depend on others.
void finish_render_args(RenderArgs* r) {
  const bool tiler = r->opt.renderer == ml::RendererKind::Tiler;
  if (r->opt.shading == ml::ShadingMode::Lines && tiler) usage_error("--shading lines: needs --renderer scanline");
  const int aa = r->opt.aa;
  if (tiler && aa != 1 && aa != 2 && aa != 4 && aa != 8)
    usage_error("--aa: the tiler takes 1, 2, 4 or 8 samples per pixel per axis (or use --renderer scanline)");
  if (r->opt.filter == ml::FilterKind::Cosine && (!tiler || aa == 1))
    usage_error("--filter cosine: needs the tiler and --aa 2, 4 or 8");
  if (r->opt.samples == ml::SamplePattern::Jittered && (!tiler || aa == 1))
    usage_error("--samples jittered: needs the tiler and --aa 2, 4 or 8");
  if (!r->has_dither) r->opt.output.dither = ml::format_dithers_by_default(r->opt.output.format);
}

// The arena the CLI gives a render unless told otherwise (--arena): what it needs plus the spare bytes
// that make it faster (render_spare_bytes: the tiler's bands rendered at once, its band plan and vertex
// cache; the scanline renderer's vertex cache), as a board with RAM to spare does.
// The image is the same with or without them.
size_t default_arena_bytes(const ml::Scene& scene, const ml::Camera& camera, const ml::RenderOptions& o) {
  return ml::render_arena_bytes(scene, camera, o) + ml::render_spare_bytes(scene, camera, o);
}

// An arena kept from frame to frame (show): sized once by default_arena_bytes, which projects the whole
// scene, and after that only grown when a render reports ArenaTooSmall (which it does before touching
// the sink), so a frame does not pay for a sizing pass besides its own render.
struct FrameArena {
  std::vector<uint64_t> storage;
  size_t bytes = 0;
};

ml::Status render_reusing(const ml::Scene& scene, const ml::Camera& camera, const ml::RenderOptions& o,
                          FrameArena* frame, ml::Sink& sink, ml::Stats* stats) {
  if (frame->bytes == 0) {
    frame->bytes = default_arena_bytes(scene, camera, o);
    frame->storage.assign(frame->bytes / 8 + 1, 0);
  }
  for (;;) {
    ml::Arena arena(frame->storage.data(), frame->bytes);
    const ml::Status s = ml::render(scene, camera, o, arena, sink, stats);
    if (s.code != ml::StatusCode::ArenaTooSmall || s.value <= frame->bytes) return s;
    frame->bytes = size_t(s.value);
    frame->storage.assign(frame->bytes / 8 + 1, 0);
  }
}

// One render into `sink` with the default arena (or --arena, or `frame` reused from the previous
// frame); failures exit with one line. A sink's own message (sink_error, read after the
// render) explains a SinkFailed better than the status.
ml::Stats render_into(const ml::Scene& scene, const ml::Camera& camera, const ml::RenderOptions& o,
                      long long arena_override, ml::Sink& sink, const std::string* sink_error = nullptr,
                      FrameArena* frame = nullptr) {
  if (frame && arena_override < 0) {
    ml::Stats stats;
    const ml::Status s = render_reusing(scene, camera, o, frame, sink, &stats);
    if (s.code == ml::StatusCode::SinkFailed && sink_error && !sink_error->empty()) failure(*sink_error);
    if (!s.ok()) failure(std::string("render failed: ") + status_text(s));
    return stats;
  }
  const size_t given = default_arena_bytes(scene, camera, o);
  const size_t bytes = arena_override >= 0 ? size_t(arena_override) : given;
  std::vector<uint64_t> storage;
  MappedArena mapped;
  void* base = nullptr;
  if (bytes <= given) {
    storage.assign((bytes + 7) / 8, 0);
    base = storage.data();
  } else {
    // More than the render can use (--arena): mapped, not allocated, so the pages the render never
    // touches cost nothing and a size the system cannot provide is one error line.
    mapped.base = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (mapped.base == MAP_FAILED) failure("out of memory: cannot map an arena of " + std::to_string(bytes) + " bytes");
    mapped.bytes = bytes;
    base = mapped.base;
  }
  ml::Arena arena(base, bytes);
  ml::Stats stats;
  const ml::Status s = ml::render(scene, camera, o, arena, sink, &stats);
  if (s.code == ml::StatusCode::ArenaTooSmall)
    failure("render failed: arena too small: " + std::to_string(s.value) + " bytes needed, " + std::to_string(bytes) + " given");
  if (s.code == ml::StatusCode::SinkFailed && sink_error && !sink_error->empty()) failure(*sink_error);
  if (!s.ok()) failure(std::string("render failed: ") + status_text(s));
  return stats;
}

// --texture-source file: the texels are read from the .mls file as the pager asks (sets r->opt).
std::unique_ptr<mlhost::FileTextureSource> open_texture_file(RenderArgs& r, const mlhost::LoadedScene& loaded) {
  if (!r.texture_file) return nullptr;
  const std::string& name = loaded.name;
  if (name.size() < 4 || name.compare(name.size() - 4, 4, ".mls") != 0)
    usage_error("--texture-source file: needs a .mls scene (maskline compile writes one)");
  auto source = std::make_unique<mlhost::FileTextureSource>(name, loaded.scene);
  if (!source->ok()) failure("cannot open " + name + " for its texels");
  r.opt.texture_source = source.get();
  return source;
}

mlhost::RunInfo run_info_for(const ml::Scene& scene, const mlhost::LoadedScene& loaded, const RenderArgs& r,
                             const char* shading, const std::string& display) {
  mlhost::RunInfo info;
  info.width = r.width;
  info.height = r.height;
  info.renderer = renderer_name(r.opt.renderer);
  info.aa = r.opt.aa;
  info.shading = shading;
  info.scene = loaded.name;
  info.bsp_split_ratio = scene.triangle_count ? double(scene.bsp_piece_count) / scene.triangle_count : 0.0;
  info.band_rows = ml::band_rows_for(r.opt.output, r.height);
  info.format = mlhost::format_name(std::string(shading) == "ids" ? ml::PixelFormat::Id32 : r.opt.output.format);
  info.display = display;
  return info;
}

int cmd_render(int argc, char** argv) {
  std::vector<std::string> valued = kRenderValued;
  for (const char* v : {"-o", "--ids", "--work"}) valued.push_back(v);
  const Args a = parse_args(argc, argv, 2, valued, {"--stats"}, "render");
  if (a.help) {
    fputs(kRenderHelp, stdout);
    return 0;
  }
  if (a.positional.size() > 1) usage_error("render: expected at most one scene, got '" + a.positional[1] + "'");
  RenderArgs r;
  for (const auto& o : a.options) {
    if (parse_render_option(o.first, o.second, &r)) continue;
    if ((o.first == "-o" || o.first == "--ids" || o.first == "--work") && o.second.empty())
      usage_error(o.first + ": needs a file name");
  }
  finish_render_args(&r);
  const std::string* out_png = find_option(a, "-o");
  const std::string* ids_png = find_option(a, "--ids");
  const std::string* work_png = find_option(a, "--work");
  const bool want_stats = has_flag(a, "--stats");
  if (work_png && r.opt.renderer != ml::RendererKind::Tiler)
    usage_error("--work: the work image comes from the tiler (--renderer tiler)");

  mlhost::LoadedScene loaded;
  const ml::Scene scene = require_scene(a.positional.empty() ? "" : a.positional[0], &loaded);
  const ml::Camera camera = make_camera(scene, r.camera, r.width, r.height);
  const auto texture_file = open_texture_file(r, loaded);

  ml::Stats stats;
  const bool colour_pass = out_png || work_png || want_stats || !ids_png;
  if (colour_pass) note_opaque_blends(scene, r.opt.renderer);
  if (colour_pass) {
    std::vector<uint32_t> work;
    ml::WorkImage work_image;
    ml::RenderOptions o = r.opt;
    if (work_png) {
      work.assign(size_t(r.width) * size_t(r.height), 0);
      work_image.q16 = work.data();
      work_image.width = r.width;
      work_image.height = r.height;
      o.work = &work_image;
    }
    if (out_png) {
      // Bands stream into the PNG file as they leave the renderer: no frame buffer.
      mlhost::PngStreamSink sink(*out_png);
      stats = render_into(scene, camera, o, r.arena_override, sink, &sink.error());
    } else {
      mlhost::ImageSink sink;
      stats = render_into(scene, camera, o, r.arena_override, sink);
      if (!sink.contract_ok()) failure("render failed: the renderer broke the sink contract: " + sink.contract_error());
    }
    if (work_png) {
      const std::string e = mlhost::write_png_rgb(*work_png, r.width, r.height, mlhost::work_heatmap(work));
      if (!e.empty()) failure(e);
    }
  }
  if (ids_png) {
    ml::RenderOptions ido = r.opt;
    ido.shading = ml::ShadingMode::Ids;
    ido.aa = 1;  // ids are point-sampled at pixel centres
    ido.background = 0;
    mlhost::PngStreamSink sink(*ids_png);
    const ml::Stats id_stats = render_into(scene, camera, ido, r.arena_override, sink, &sink.error());
    if (!colour_pass) stats = id_stats;
  }
  if (want_stats) {
    const char* shading = colour_pass ? shading_name(r.opt.shading) : "ids";
    printf("%s\n", mlhost::stats_json(stats, run_info_for(scene, loaded, r, shading, out_png ? "png" : "memory")).c_str());
  }
  return 0;
}

// ---- show: frames on a display ------------------------------------------------------------------

// The camera turned by `degrees` about the up axis through its target (host code: doubles are fine).
ml::Camera orbit(const ml::Camera& c, double degrees) {
  const double pi = 3.14159265358979323846;
  const double a = degrees * pi / 180.0, cs = std::cos(a), sn = std::sin(a);
  double u[3] = {double(c.up.x), double(c.up.y), double(c.up.z)};
  const double len = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  for (double& x : u) x /= len;
  const double v[3] = {double(c.eye.x) - c.target.x, double(c.eye.y) - c.target.y, double(c.eye.z) - c.target.z};
  const double dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  const double cross[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  double r[3];
  for (int i = 0; i < 3; ++i) r[i] = v[i] * cs + cross[i] * sn + u[i] * dot * (1 - cs);  // Rodrigues
  ml::Camera out = c;
  out.eye = ml::Vec3i{int32_t(std::llround(c.target.x + r[0])), int32_t(std::llround(c.target.y + r[1])),
                      int32_t(std::llround(c.target.z + r[2]))};
  return out;
}

// OUT.png for the last frame, or one file per frame when the name holds a printf %d.
std::string frame_file(const std::string& pattern, int frame) {
  if (pattern.find('%') == std::string::npos) return pattern;
  char name[4096];
  snprintf(name, sizeof name, pattern.c_str(), frame);
  return name;
}

// Writes what the display shows (an emulator's glass) or, for real hardware, the frame rendered again
// into a PNG in the display's format.
void write_shown(mlhost::Display& display, const std::string& path, int zoom, const ml::Scene& scene,
                 const ml::Camera& camera, const ml::RenderOptions& o, long long arena_override) {
  std::vector<ml::Pixel> pixels;
  int w = 0, h = 0;
  if (display.picture(&pixels, &w, &h)) {
    std::vector<ml::Pixel> big(pixels.size() * size_t(zoom) * size_t(zoom));
    for (size_t y = 0; y < size_t(h) * size_t(zoom); ++y)
      for (size_t x = 0; x < size_t(w) * size_t(zoom); ++x)
        big[y * size_t(w) * size_t(zoom) + x] = pixels[(y / size_t(zoom)) * size_t(w) + x / size_t(zoom)];
    const std::string e = mlhost::write_png_rgb(path, w * zoom, h * zoom, big);
    if (!e.empty()) failure(e);
    return;
  }
  mlhost::PngStreamSink png(path);
  render_into(scene, camera, o, arena_override, png, &png.error());
}

int cmd_show(int argc, char** argv) {
  std::vector<std::string> valued = kRenderValued;
  for (const char* v : {"--display", "-o", "--frames", "--orbit", "--zoom"}) valued.push_back(v);
  const Args a = parse_args(argc, argv, 2, valued, {"--stats"}, "show");
  if (a.help) {
    fputs(kShowHelp, stdout);
    return 0;
  }
  if (a.positional.size() > 1) usage_error("show: expected at most one scene, got '" + a.positional[1] + "'");
  RenderArgs r;
  int frames = 1, zoom = 1;
  double orbit_deg = 0;
  for (const auto& o : a.options) {
    if (parse_render_option(o.first, o.second, &r)) continue;
    if (o.first == "--frames") frames = int(parse_integer(o.first, o.second, 1, 100000));
    else if (o.first == "--orbit") orbit_deg = parse_number(o.first, o.second);
    else if (o.first == "--zoom") zoom = int(parse_integer(o.first, o.second, 1, 16));
    else if ((o.first == "-o" || o.first == "--display") && o.second.empty()) usage_error(o.first + ": needs a value");
  }
  const std::string* spec = find_option(a, "--display");
  if (!spec) usage_error("show: --display SPEC is required (see maskline show --help)");
  const std::string kind = spec->substr(0, spec->find(':'));
  if (spec->find(':') == std::string::npos || (kind != "fb" && kind != "spi" && kind != "emu"))
    usage_error("--display: expected fb:/dev/fbN, spi:PANEL[,key=value...] or emu:PANEL[,rotation=DEG], got '" +
                *spec + "'");
  const std::string* out_png = find_option(a, "-o");
  const bool want_stats = has_flag(a, "--stats");

  std::string error;
  std::unique_ptr<mlhost::Display> display =
      mlhost::open_display(*spec, r.has_size ? r.width : 0, r.has_size ? r.height : 0, &error);
  if (!display) failure(error);
  if (r.has_format && r.opt.output.format != display->format())
    usage_error(std::string("--format: ") + display->describe() + " takes " + mlhost::format_name(display->format()));
  r.opt.output.format = display->format();
  if (!r.has_size) {
    r.width = std::min(display->width(), int(ml::kMaxScreenDim));
    r.height = std::min(display->height(), int(ml::kMaxScreenDim));
  }
  finish_render_args(&r);

  mlhost::LoadedScene loaded;
  const ml::Scene scene = require_scene(a.positional.empty() ? "" : a.positional[0], &loaded);
  const ml::Camera base = make_camera(scene, r.camera, r.width, r.height);
  const auto texture_file = open_texture_file(r, loaded);
  note_opaque_blends(scene, r.opt.renderer);
  double seconds = 0;
  FrameArena frame_arena;
  for (int f = 0; f < frames; ++f) {
    const ml::Camera camera = orbit_deg != 0 ? orbit(base, orbit_deg * f) : base;
    const auto start = std::chrono::steady_clock::now();
    const ml::Stats stats =
        render_into(scene, camera, r.opt, r.arena_override, display->sink(), nullptr, &frame_arena);
    const double frame_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    seconds += frame_s;
    if (!display->error().empty()) failure(display->error());
    if (want_stats)
      printf("%s\n", mlhost::stats_json(stats, run_info_for(scene, loaded, r, shading_name(r.opt.shading), *spec)).c_str());
    else if (frames > 1)
      printf("frame %d: %.1f ms, %llu display bytes, %u windows\n", f, frame_s * 1000.0,
             (unsigned long long)stats.display_bytes, stats.display_windows);
    if (out_png && (f + 1 == frames || out_png->find('%') != std::string::npos))
      write_shown(*display, frame_file(*out_png, f), zoom, scene, camera, r.opt, r.arena_override);
  }
  if (!want_stats) {
    printf("shown on %s\n", display->describe().c_str());
    if (frames > 1)
      printf("%d frames in %.2f s: %.1f frames per second\n", frames, seconds, seconds > 0 ? frames / seconds : 0.0);
  }
  return 0;
}

int dispatch(int argc, char** argv) {
  if (argc < 2) usage_error("missing command (see maskline --help)");
  const std::string cmd = argv[1];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    const std::string topic = argc > 2 ? argv[2] : "";
    if (cmd == "help" && argc > 3) usage_error("help: expected at most one command");
    if (topic == "compile") fputs(kCompileHelp, stdout);
    else if (topic == "info") fputs(kInfoHelp, stdout);
    else if (topic == "render") fputs(kRenderHelp, stdout);
    else if (topic == "show") fputs(kShowHelp, stdout);
    else if (topic.empty() || cmd != "help") fputs(kMainHelp, stdout);
    else usage_error("help: unknown command '" + topic + "'");
    return 0;
  }
  if (cmd == "compile") return cmd_compile(argc, argv);
  if (cmd == "info") return cmd_info(argc, argv);
  if (cmd == "render") return cmd_render(argc, argv);
  if (cmd == "show") return cmd_show(argc, argv);
  usage_error("unknown command '" + cmd + "' (see maskline --help)");
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return dispatch(argc, argv);
  } catch (const Exit& e) {
    std::string m = e.message;
    for (char& c : m)
      if (c == '\n' || c == '\r') c = ' ';
    fprintf(stderr, "maskline: %s\n", m.c_str());
    return e.code;
  } catch (const std::bad_alloc&) {
    fprintf(stderr, "maskline: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    fprintf(stderr, "maskline: %s\n", e.what());
    return 1;
  }
}
