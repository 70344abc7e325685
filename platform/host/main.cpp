// maskline: the host command line (compile, info, render). docs/cli.md is the reference.
// Exit codes: 0 success, 1 a file could not be read or a render failed, 2 bad usage (unknown option,
// bad value). Every error is one line on stderr, "maskline: ...".
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/arena.h"
#include "core/fixed.h"
#include "platform/host/image_sink.h"
#include "platform/host/png_io.h"
#include "platform/host/scene_load.h"
#include "platform/host/stats_json.h"
#include "render/render.h"
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
    "  help [COMMAND]                      this text, or a command's\n"
    "\n"
    "SCENE is a .glb/.gltf file (compiled in memory) or a .mls blob; without it the bundled default\n"
    "scene is used. Exit codes: 0 ok, 1 read or render failure, 2 bad usage.\n";

const char* const kCompileHelp =
    "usage: maskline compile IN.glb|IN.gltf -o OUT.mls\n"
    "\n"
    "Compiles a glTF 2.0 file into a scene blob (.mls): every node of the default scene with its\n"
    "transform, triangle primitives, materials, a BSP tree. Prints a summary; warnings go to stderr.\n";

const char* const kInfoHelp =
    "usage: maskline info [SCENE] [--size WxH] [--aa N] [--renderer tiler|scanline]\n"
    "\n"
    "Prints triangles, nodes, materials, bounds (world and glTF units), the BSP (nodes, pieces, split\n"
    "ratio) and the arena bytes a render at --size (default 320x240) needs, for both renderers or the\n"
    "one given. --aa applies to the scanline renderer (the tiler samples once per pixel).\n";

const char* const kRenderHelp =
    "usage: maskline render [SCENE] [options]\n"
    "\n"
    "  --renderer tiler|scanline   visibility algorithm (default tiler)\n"
    "  --size WxH                  image size in pixels, 1..4096 each (default 320x240)\n"
    "  --aa N                      N x N samples per pixel, 1..8 (scanline only; default 1)\n"
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
    "  --arena BYTES               use an arena of this size instead of the exact need\n";

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

ml::Scene require_scene(const std::string& path, mlhost::LoadedScene* loaded) {
  std::string error;
  if (!mlhost::load_scene(path, loaded, &error, true)) failure(error);
  return loaded->scene;
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
  const Args a = parse_args(argc, argv, 2, {"-o"}, {}, "compile");
  if (a.help) {
    fputs(kCompileHelp, stdout);
    return 0;
  }
  if (a.positional.size() != 1) usage_error("compile: expected one input file (see maskline compile --help)");
  const std::string* out = find_option(a, "-o");
  if (!out || out->empty()) usage_error("compile: -o OUT.mls is required");
  const std::string& in = a.positional[0];
  mlhost::LoadedScene loaded;
  std::string error;
  if (!mlhost::load_scene(in, &loaded, &error, true)) failure(error);
  for (const auto& w : loaded.warnings) fprintf(stderr, "maskline: warning: %s\n", w.c_str());
  if (!ml::save_blob_file(*out, loaded.blob, &error)) failure(error);
  const ml::Scene& s = loaded.scene;
  printf("wrote %s: %zu bytes, %u triangles, %u nodes, %u materials, %u BSP nodes, %u pieces\n", out->c_str(),
         loaded.blob.size, s.triangle_count, s.node_count, s.material_count, s.bsp_node_count, s.bsp_piece_count);
  return 0;
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
  if (only && which == ml::RendererKind::Tiler && aa != 1) usage_error("--aa: the tiler samples once per pixel (use --aa 1)");
  mlhost::LoadedScene loaded;
  const ml::Scene scene = require_scene(a.positional.empty() ? "" : a.positional[0], &loaded);
  const ml::SceneInfo& info = *scene.info;
  const mlhost::GltfMapping map = mlhost::gltf_mapping(scene);
  printf("scene: %s (%zu bytes)\n", loaded.name.c_str(), loaded.blob.size);
  printf("triangles: %u\n", scene.triangle_count);
  printf("nodes: %u\n", scene.node_count);
  printf("materials: %u\n", scene.material_count);
  printf("batches: %u, vertices: %u, textures: %u\n", scene.batch_count, scene.vertex_count, scene.texture_count);
  if (!loaded.warnings.empty()) printf("compiler warnings: %zu (maskline compile prints them)\n", loaded.warnings.size());
  printf("bounds (world units): min %d,%d,%d max %d,%d,%d\n", info.bounds_min[0], info.bounds_min[1], info.bounds_min[2],
         info.bounds_max[0], info.bounds_max[1], info.bounds_max[2]);
  printf("bounds (glTF units): min %g,%g,%g max %g,%g,%g\n", mlhost::world_to_gltf(map, 0, info.bounds_min[0]),
         mlhost::world_to_gltf(map, 1, info.bounds_min[1]), mlhost::world_to_gltf(map, 2, info.bounds_min[2]),
         mlhost::world_to_gltf(map, 0, info.bounds_max[0]), mlhost::world_to_gltf(map, 1, info.bounds_max[1]),
         mlhost::world_to_gltf(map, 2, info.bounds_max[2]));
  printf("bounding sphere (world units): centre %d,%d,%d radius %d\n", info.sphere_center[0], info.sphere_center[1],
         info.sphere_center[2], info.sphere_radius);
  const double split = scene.triangle_count ? double(scene.bsp_piece_count) / scene.triangle_count : 0.0;
  printf("bsp: %u nodes, %u pieces, split ratio %.4f, depth %u\n", scene.bsp_node_count, scene.bsp_piece_count, split,
         info.bsp_depth);
  CameraArgs none;
  const ml::Camera base = make_camera(scene, none, width, height);
  for (ml::RendererKind k : {ml::RendererKind::Tiler, ml::RendererKind::Scanline}) {
    if (only && k != which) continue;
    ml::RenderOptions o;
    o.renderer = k;
    o.aa = k == ml::RendererKind::Tiler ? 1 : aa;
    const size_t bytes = ml::render_arena_bytes(scene, base, o);
    printf("arena bytes (%s, %dx%d, aa %d): %zu\n", renderer_name(k), width, height, o.aa, bytes);
  }
  return 0;
}

int cmd_render(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2,
                            {"--renderer", "--size", "--aa", "--eye", "--target", "--up", "--fov", "--near", "--shading",
                             "-o", "--ids", "--work", "--seed", "--background", "--arena"},
                            {"--stats"}, "render");
  if (a.help) {
    fputs(kRenderHelp, stdout);
    return 0;
  }
  if (a.positional.size() > 1) usage_error("render: expected at most one scene, got '" + a.positional[1] + "'");
  ml::RenderOptions opt;
  int width = 320, height = 240;
  CameraArgs cam_args;
  long long arena_override = -1;
  for (const auto& o : a.options) {
    const std::string& n = o.first;
    const std::string& v = o.second;
    if (n == "--renderer") opt.renderer = parse_renderer(v);
    else if (n == "--size") parse_size(v, &width, &height);
    else if (n == "--aa") opt.aa = int(parse_integer(n, v, 1, 8));
    else if (n == "--eye") { parse_vec3(n, v, cam_args.eye); cam_args.has_eye = true; }
    else if (n == "--target") { parse_vec3(n, v, cam_args.target); cam_args.has_target = true; }
    else if (n == "--up") { parse_vec3(n, v, cam_args.up); cam_args.has_up = true; }
    else if (n == "--fov") {
      cam_args.fov = parse_number(n, v);
      if (cam_args.fov < 1 || cam_args.fov > 170) usage_error("--fov: expected 1..170 degrees, got '" + v + "'");
    } else if (n == "--near") { cam_args.near = parse_number(n, v); cam_args.has_near = true; }
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
    } else if (n == "--arena") arena_override = parse_integer(n, v, 0, 1ll << 40);
    else if ((n == "-o" || n == "--ids" || n == "--work") && v.empty()) usage_error(n + ": needs a file name");
  }
  const std::string* out_png = find_option(a, "-o");
  const std::string* ids_png = find_option(a, "--ids");
  const std::string* work_png = find_option(a, "--work");
  const bool want_stats = has_flag(a, "--stats");
  const bool tiler = opt.renderer == ml::RendererKind::Tiler;
  if (opt.shading == ml::ShadingMode::Lines && tiler) usage_error("--shading lines: needs --renderer scanline");
  if (tiler && opt.aa != 1) usage_error("--aa: the tiler samples once per pixel (use --aa 1 or --renderer scanline)");
  if (work_png && !tiler) usage_error("--work: the work image comes from the tiler (--renderer tiler)");

  mlhost::LoadedScene loaded;
  const ml::Scene scene = require_scene(a.positional.empty() ? "" : a.positional[0], &loaded);
  const ml::Camera camera = make_camera(scene, cam_args, width, height);

  std::vector<uint64_t> arena_storage;
  MappedArena arena_map;
  // Renders once into an in-memory image that checks the once-per-pixel contract.
  auto run = [&](const ml::RenderOptions& o, mlhost::ImageSink* sink, ml::Stats* stats) {
    const size_t need = ml::render_arena_bytes(scene, camera, o);
    const size_t bytes = arena_override >= 0 ? size_t(arena_override) : need;
    void* base = nullptr;
    if (bytes <= need) {
      arena_storage.assign((bytes + 7) / 8, 0);
      base = arena_storage.data();
    } else {
      // More than the render needs (--arena): mapped, not allocated, so the pages the render never
      // touches cost nothing and a size the system cannot provide is one error line.
      arena_map.reset();
      arena_map.base = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
      if (arena_map.base == MAP_FAILED) failure("out of memory: cannot map an arena of " + std::to_string(bytes) + " bytes");
      arena_map.bytes = bytes;
      base = arena_map.base;
    }
    ml::Arena arena(base, bytes);
    const ml::Status s = ml::render(scene, camera, o, arena, *sink, stats);
    if (s.code == ml::StatusCode::ArenaTooSmall)
      failure("render failed: arena too small: " + std::to_string(s.value) + " bytes needed, " + std::to_string(bytes) + " given");
    if (!s.ok()) failure(std::string("render failed: ") + status_text(s));
    if (!sink->contract_ok()) failure("render failed: the renderer broke the sink contract: " + sink->contract_error());
  };

  ml::Stats stats;
  const bool colour_pass = out_png || work_png || want_stats || !ids_png;
  if (colour_pass) {
    std::vector<uint32_t> work;
    ml::WorkImage work_image;
    if (work_png) {
      work.assign(size_t(width) * size_t(height), 0);
      work_image.q16 = work.data();
      work_image.width = width;
      work_image.height = height;
      opt.work = &work_image;
    }
    mlhost::ImageSink sink;
    run(opt, &sink, &stats);
    opt.work = nullptr;
    if (out_png) {
      const std::string e = mlhost::write_png_rgb(*out_png, sink.width(), sink.height(), sink.pixels());
      if (!e.empty()) failure(e);
    }
    if (work_png) {
      const std::string e = mlhost::write_png_rgb(*work_png, width, height, mlhost::work_heatmap(work));
      if (!e.empty()) failure(e);
    }
  }
  if (ids_png) {
    ml::RenderOptions ido = opt;
    ido.shading = ml::ShadingMode::Ids;
    ido.aa = 1;  // ids are point-sampled at pixel centres
    ido.background = 0;
    mlhost::ImageSink sink;
    ml::Stats id_stats;
    run(ido, &sink, &id_stats);
    if (!colour_pass) stats = id_stats;
    const std::string e = mlhost::write_png_rgba_le(*ids_png, sink.width(), sink.height(), sink.pixels());
    if (!e.empty()) failure(e);
  }
  if (want_stats) {
    mlhost::RunInfo run_info;
    run_info.width = width;
    run_info.height = height;
    run_info.renderer = renderer_name(opt.renderer);
    run_info.aa = opt.aa;
    run_info.shading = colour_pass ? shading_name(opt.shading) : "ids";
    run_info.scene = loaded.name;
    run_info.bsp_split_ratio = scene.triangle_count ? double(scene.bsp_piece_count) / scene.triangle_count : 0.0;
    printf("%s\n", mlhost::stats_json(stats, run_info).c_str());
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
    else if (topic.empty() || cmd != "help") fputs(kMainHelp, stdout);
    else usage_error("help: unknown command '" + topic + "'");
    return 0;
  }
  if (cmd == "compile") return cmd_compile(argc, argv);
  if (cmd == "info") return cmd_info(argc, argv);
  if (cmd == "render") return cmd_render(argc, argv);
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
