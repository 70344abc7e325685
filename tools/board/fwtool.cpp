// fwtool: the host side of the firmware builds and their checks (docs/firmware.md).
//
//   fwtool scene default|knot:N|office:L|FILE.glb -o OUT.mls     a scene blob for a firmware's flash
//   fwtool config [render options] [--scene S.mls] -o CONFIG.h    the firmware's compiled-in options
//   fwtool ref SCENE.mls [render options] -o OUT.raw [--stats]    the host's packed band bytes
//   fwtool topng RAW --size WxH --format F -o OUT.png [--zoom N]  packed bytes -> PNG
//   fwtool crc FILE                                               CRC-32 of a file (as ml::crc32), 0x%08x
//   fwtool same A B                                               two pictures (PNG or PPM) pixel for pixel
//
// Render options (as `maskline render`): --renderer tiler|scanline --size WxH --format rgb565|grey4|...
// --shading unlit|flat|gouraud --aa N --dither on|off --band-rows N --eye X,Y,Z --target X,Y,Z
// --up X,Y,Z --fov DEG --near DIST. The camera is the CLI's: ml::frame_sphere of the scene's bounding
// sphere, with --eye/--target/--up/--near applied the way `maskline render` applies them.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "core/arena.h"
#include "core/band.h"
#include "core/pixel_format.h"
#include "platform/host/format_names.h"
#include "platform/host/png_io.h"
#include "platform/host/scene_load.h"
#include "platform/host/stats_json.h"
#include "render/render.h"
#include "tools/scenec/scenec.h"

namespace {

[[noreturn]] void die(const std::string& m, int code = 1) {
  fprintf(stderr, "fwtool: %s\n", m.c_str());
  exit(code);
}

struct Options {
  std::vector<std::string> positional;
  std::map<std::string, std::string> valued;
  bool stats = false;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--stats") o.stats = true;
    else if (a.size() > 1 && a[0] == '-' && !(a[1] >= '0' && a[1] <= '9')) {
      if (i + 1 >= argc) die(a + ": needs a value", 2);
      o.valued[a] = argv[++i];
    } else o.positional.push_back(a);
  }
  return o;
}

const std::string* get(const Options& o, const char* k) {
  auto it = o.valued.find(k);
  return it == o.valued.end() ? nullptr : &it->second;
}

void vec3(const std::string& name, const std::string& v, double out[3]) {
  if (sscanf(v.c_str(), "%lf,%lf,%lf", &out[0], &out[1], &out[2]) != 3) die(name + ": expected X,Y,Z", 2);
}

struct Render {
  int width = 320, height = 240;
  int renderers = 1;  // bit 0 tiler, bit 1 scanline
  ml::RenderOptions opt;
  bool has_eye = false, has_target = false, has_up = false, has_near = false;
  double eye[3], target[3], up[3], near = 0, fov = 45;
};

Render parse_render(const Options& o, bool renderer_default_both) {
  Render r;
  r.renderers = renderer_default_both ? 3 : 1;
  for (const auto& kv : o.valued) {
    const std::string& n = kv.first;
    const std::string& v = kv.second;
    if (n == "--renderer") {
      if (v == "tiler") r.renderers = 1;
      else if (v == "scanline") r.renderers = 2;
      else if (v == "both") r.renderers = 3;
      else die("--renderer: expected tiler, scanline or both", 2);
    } else if (n == "--size") {
      if (sscanf(v.c_str(), "%dx%d", &r.width, &r.height) != 2 || r.width < 1 || r.height < 1 || r.width > 4096 ||
          r.height > 4096)
        die("--size: expected WxH", 2);
    } else if (n == "--format") {
      if (!mlhost::parse_format(v, &r.opt.output.format) || r.opt.output.format == ml::PixelFormat::Mono1)
        die("--format: expected rgb565, rgb565le, xrgb8888, grey8 or grey4", 2);
    } else if (n == "--shading") {
      if (v == "unlit") r.opt.shading = ml::ShadingMode::Unlit;
      else if (v == "flat") r.opt.shading = ml::ShadingMode::Flat;
      else if (v == "gouraud") r.opt.shading = ml::ShadingMode::Gouraud;
      else die("--shading: expected unlit, flat or gouraud", 2);
    } else if (n == "--aa") r.opt.aa = atoi(v.c_str());
    else if (n == "--band-rows") r.opt.output.band_rows = atoi(v.c_str());
    else if (n == "--eye") { vec3(n, v, r.eye); r.has_eye = true; }
    else if (n == "--target") { vec3(n, v, r.target); r.has_target = true; }
    else if (n == "--up") { vec3(n, v, r.up); r.has_up = true; }
    else if (n == "--near") { r.near = atof(v.c_str()); r.has_near = true; }
    else if (n == "--fov") {
      r.fov = atof(v.c_str());
      if (!(r.fov >= 1 && r.fov <= 170)) die("--fov: expected 1..170 degrees", 2);
    } else if (n == "--dither") continue;
    else if (n == "-o" || n == "--scene" || n == "--zoom") continue;
    else die("unknown option " + n, 2);
  }
  if (r.opt.aa < 1 || r.opt.aa > 8) die("--aa: expected 1..8", 2);
  const std::string* d = get(o, "--dither");
  r.opt.output.dither = d ? *d == "on" : ml::format_dithers_by_default(r.opt.output.format);
  return r;
}

int32_t fov_q16(const Render& r) { return int32_t(llround(r.fov * 65536.0)); }

// The camera exactly as platform/host/main.cpp make_camera builds it.
ml::Camera make_camera(const ml::Scene& scene, const Render& r) {
  const ml::SceneInfo& info = *scene.info;
  const ml::Vec3i center{info.sphere_center[0], info.sphere_center[1], info.sphere_center[2]};
  ml::Camera cam = ml::frame_sphere(center, info.sphere_radius, r.width, r.height, fov_q16(r));
  const mlhost::GltfMapping map = mlhost::gltf_mapping(scene);
  if (r.has_eye && !mlhost::gltf_point_to_world(map, r.eye, &cam.eye)) die("--eye: outside the world range", 2);
  if (r.has_target && !mlhost::gltf_point_to_world(map, r.target, &cam.target)) die("--target: outside the world range", 2);
  if (r.has_eye && !r.has_target) cam.target = center;
  if (r.has_up) {
    const double len = sqrt(r.up[0] * r.up[0] + r.up[1] * r.up[1] + r.up[2] * r.up[2]);
    if (!(len > 0)) die("--up: must not be zero", 2);
    cam.up = ml::Vec3i{int32_t(llround(r.up[0] / len * (1 << 20))), int32_t(llround(r.up[1] / len * (1 << 20))),
                       int32_t(llround(r.up[2] / len * (1 << 20)))};
  }
  if (r.has_near) {
    const double n = r.near * map.to_world;
    if (!(r.near > 0) || !(n < double(1 << ml::kViewLimitBits))) die("--near: out of range", 2);
    cam.near = int32_t(std::max(1.0, std::round(n)));
  } else if (r.has_eye) {
    const double dx = double(cam.eye.x) - center.x, dy = double(cam.eye.y) - center.y, dz = double(cam.eye.z) - center.z;
    const int64_t d = int64_t(llround(sqrt(dx * dx + dy * dy + dz * dz)));
    const int64_t rad = info.sphere_radius;
    cam.near = int32_t(std::max<int64_t>(1, d > rad ? (d - rad) / 2 : rad / 1024));
  }
  ml::View view;
  const ml::Status s = ml::make_view(cam, &view);
  if (!s.ok()) die(std::string("camera: ") + s.message, 2);
  return cam;
}

mlhost::LoadedScene load(const std::string& path) {
  mlhost::LoadedScene loaded;
  std::string error;
  if (!mlhost::load_scene(path, &loaded, &error)) die(error);
  return loaded;
}

// Collects the packed rows of every band, in order: the bytes a display would receive.
class BytesSink : public ml::Sink {
 public:
  bool begin_frame(const ml::FrameInfo& f) override {
    row_bytes_ = ml::format_stride(f.format, f.width);
    return true;
  }
  bool flush(const ml::Flush& b) override {
    for (int r = 0; r < b.height; ++r) bytes.insert(bytes.end(), b.bytes + size_t(r) * b.stride, b.bytes + size_t(r) * b.stride + row_bytes_);
    flush_ready(b.buffer);
    return true;
  }
  std::vector<uint8_t> bytes;

 private:
  uint32_t row_bytes_ = 0;
};

// A glTF file compiled without its images: every material in its base colour, as a build without
// textures (ML_TEXTURES=0) draws it.
ml::CompileResult compile_without_images(const std::string& path) {
  ml::CompileOptions options;
  options.texture_format = ml::TextureFormatChoice::None;
  return ml::compile_gltf_file(path, options);
}

int cmd_scene(const Options& o) {
  const std::string* out = get(o, "-o");
  if (o.positional.size() != 1 || !out)
    die("usage: fwtool scene default|knot:N|office:L|FILE.glb|plain:FILE.glb -o OUT.mls", 2);
  const std::string& spec = o.positional[0];
  ml::CompileResult result;
  if (spec == "default") result = ml::build_default_scene();
  else if (spec.rfind("knot:", 0) == 0) result = ml::build_tessellated_scene(uint32_t(atoi(spec.c_str() + 5)));
  else if (spec.rfind("office:", 0) == 0) result = ml::build_office_scene(atoi(spec.c_str() + 7));
  else if (spec.rfind("plain:", 0) == 0) result = compile_without_images(spec.substr(6));
  else result = ml::compile_gltf_file(spec);
  if (!result.ok) die(spec + ": " + result.error);
  std::string error;
  if (!ml::save_blob_file(*out, result.blob, &error)) die(error);
  printf("%s: %zu bytes, %u triangles, %u BSP pieces\n", out->c_str(), result.blob.size, result.report.triangles,
         result.report.bsp_pieces);
  return 0;
}

int cmd_config(const Options& o) {
  const std::string* out = get(o, "-o");
  if (!out) die("config: -o CONFIG.h is required", 2);
  const Render r = parse_render(o, true);
  std::string h = "// Generated by tools/board/fwtool config: the options compiled into a firmware image.\n#pragma once\n";
  auto def = [&h](const std::string& k, const std::string& v) { h += "#define " + k + " " + v + "\n"; };
  def("FW_WIDTH", std::to_string(r.width));
  def("FW_HEIGHT", std::to_string(r.height));
  def("FW_RENDERERS", std::to_string(r.renderers));
  def("FW_SHADING", std::to_string(int(r.opt.shading)));
  def("FW_AA", std::to_string(r.opt.aa));
  def("FW_FORMAT", std::to_string(int(r.opt.output.format)));
  def("FW_DITHER", r.opt.output.dither ? "1" : "0");
  def("FW_BAND_ROWS", std::to_string(r.opt.output.band_rows));
  def("FW_FOV_Q16", std::to_string(fov_q16(r)));
  if (r.has_eye || r.has_target || r.has_up || r.has_near) {
    // Explicit camera fields need the scene (glTF units -> world units).
    const std::string* scene = get(o, "--scene");
    if (!scene) die("config: --eye/--target/--up/--near need --scene S.mls", 2);
    const mlhost::LoadedScene loaded = load(*scene);
    const ml::Camera c = make_camera(loaded.scene, r);
    auto v3 = [](const ml::Vec3i& v) { return std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z); };
    def("FW_CAMERA_EYE", v3(c.eye));
    def("FW_CAMERA_TARGET", v3(c.target));
    def("FW_CAMERA_UP", v3(c.up));
    def("FW_CAMERA_NEAR", std::to_string(c.near));
  }
  FILE* f = fopen(out->c_str(), "w");
  if (!f || fputs(h.c_str(), f) < 0 || fclose(f) != 0) die(*out + ": cannot write");
  return 0;
}

int cmd_ref(const Options& o) {
  const std::string* out = get(o, "-o");
  if (o.positional.size() != 1 || !out) die("usage: fwtool ref SCENE.mls [options] -o OUT.raw", 2);
  Render r = parse_render(o, false);
  if (r.renderers == 3) die("ref: one --renderer", 2);
  const mlhost::LoadedScene loaded = load(o.positional[0]);
  const ml::Camera camera = make_camera(loaded.scene, r);
  ml::RenderOptions opt = r.opt;
  opt.renderer = r.renderers == 2 ? ml::RendererKind::Scanline : ml::RendererKind::Tiler;
  const size_t need = ml::render_arena_bytes(loaded.scene, camera, opt);
  std::vector<uint64_t> storage((need + 7) / 8);
  ml::Arena arena(storage.data(), need);
  BytesSink sink;
  ml::Stats stats;
  const ml::Status s = ml::render(loaded.scene, camera, opt, arena, sink, &stats);
  if (!s.ok()) die(std::string("render failed: ") + s.message);
  FILE* f = fopen(out->c_str(), "wb");
  if (!f || fwrite(sink.bytes.data(), 1, sink.bytes.size(), f) != sink.bytes.size() || fclose(f) != 0)
    die(*out + ": cannot write");
  if (o.stats) {
    mlhost::RunInfo info;
    info.width = r.width;
    info.height = r.height;
    info.renderer = opt.renderer == ml::RendererKind::Tiler ? "tiler" : "scanline";
    info.aa = opt.aa;
    info.shading = opt.shading == ml::ShadingMode::Unlit ? "unlit" : opt.shading == ml::ShadingMode::Gouraud ? "gouraud" : "flat";
    info.scene = loaded.name;
    info.band_rows = ml::band_rows_for(opt.output, r.height);
    info.format = mlhost::format_name(opt.output.format);
    info.display = "memory";
    printf("%s\n", mlhost::stats_json(stats, info).c_str());
  }
  return 0;
}

std::vector<uint8_t> read_file(const std::string& path) {
  FILE* f = fopen(path.c_str(), "rb");
  if (!f) die(path + ": cannot open");
  std::vector<uint8_t> d;
  uint8_t buf[65536];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) d.insert(d.end(), buf, buf + n);
  fclose(f);
  return d;
}

int cmd_topng(const Options& o) {
  const std::string* out = get(o, "-o");
  if (o.positional.size() != 1 || !out) die("usage: fwtool topng RAW --size WxH --format F -o OUT.png", 2);
  const Render r = parse_render(o, false);
  const int zoom = get(o, "--zoom") ? atoi(get(o, "--zoom")->c_str()) : 1;
  if (zoom < 1 || zoom > 16) die("--zoom: expected 1..16", 2);
  const std::vector<uint8_t> raw = read_file(o.positional[0]);
  const ml::PixelFormat f = r.opt.output.format;
  const uint32_t stride = ml::format_stride(f, r.width);
  if (raw.size() != size_t(stride) * size_t(r.height))
    die(o.positional[0] + ": " + std::to_string(raw.size()) + " bytes, expected " + std::to_string(size_t(stride) * r.height));
  std::vector<ml::Pixel> px(size_t(r.width) * zoom * r.height * zoom);
  for (int y = 0; y < r.height * zoom; ++y)
    for (int x = 0; x < r.width * zoom; ++x)
      px[size_t(y) * r.width * zoom + x] = ml::expand_stored(f, ml::load_pixel(f, raw.data(), stride, x / zoom, y / zoom));
  const std::string e = mlhost::write_png_rgb(*out, r.width * zoom, r.height * zoom, px);
  if (!e.empty()) die(e);
  return 0;
}

// PPM (P6, maxval 255) or PNG, as 0x00RRGGBB.
void read_picture(const std::string& path, int* w, int* h, std::vector<uint32_t>* px) {
  const std::vector<uint8_t> d = read_file(path);
  if (d.size() > 2 && d[0] == 'P' && d[1] == '6') {
    size_t i = 2;
    int fields[3], n = 0;
    while (n < 3) {
      while (i < d.size() && (isspace(d[i]) || d[i] == '#')) {
        if (d[i] == '#') while (i < d.size() && d[i] != '\n') ++i;
        else ++i;
      }
      int v = 0;
      if (i >= d.size() || !isdigit(d[i])) die(path + ": bad PPM header");
      while (i < d.size() && isdigit(d[i])) v = v * 10 + (d[i++] - '0');
      fields[n++] = v;
    }
    ++i;  // one whitespace byte
    *w = fields[0];
    *h = fields[1];
    if (fields[2] != 255 || d.size() < i + size_t(*w) * *h * 3) die(path + ": unsupported or short PPM");
    px->resize(size_t(*w) * *h);
    for (size_t p = 0; p < px->size(); ++p)
      (*px)[p] = ml::rgb(d[i + 3 * p], d[i + 3 * p + 1], d[i + 3 * p + 2]);
    return;
  }
  const std::string e = mlhost::read_png(path, w, h, px, false);
  if (!e.empty()) die(e);
}

int cmd_same(const Options& o) {
  if (o.positional.size() != 2) die("usage: fwtool same A B", 2);
  int wa, ha, wb, hb;
  std::vector<uint32_t> a, b;
  read_picture(o.positional[0], &wa, &ha, &a);
  read_picture(o.positional[1], &wb, &hb, &b);
  if (wa != wb || ha != hb) {
    printf("different sizes: %dx%d and %dx%d\n", wa, ha, wb, hb);
    return 1;
  }
  size_t diff = 0, first = 0;
  for (size_t i = 0; i < a.size(); ++i)
    if ((a[i] & 0xFFFFFF) != (b[i] & 0xFFFFFF) && diff++ == 0) first = i;
  if (diff) {
    printf("%zu of %zu pixels differ; first at (%zu, %zu): %06x vs %06x\n", diff, a.size(), first % wa, first / wa,
           a[first] & 0xFFFFFF, b[first] & 0xFFFFFF);
    return 1;
  }
  std::vector<uint32_t> colours(a);
  std::sort(colours.begin(), colours.end());
  const size_t distinct = size_t(std::unique(colours.begin(), colours.end()) - colours.begin());
  printf("same: %dx%d, %zu pixels, %zu colours\n", wa, ha, a.size(), distinct);
  return 0;
}

int cmd_crc(const Options& o) {
  if (o.positional.size() != 1) die("usage: fwtool crc FILE", 2);
  const std::vector<uint8_t> d = read_file(o.positional[0]);
  printf("0x%08x\n", unsigned(ml::crc32(d.data(), d.size())));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) die("usage: fwtool scene|config|ref|topng|same ... (see tools/board/fwtool.cpp)", 2);
  const std::string cmd = argv[1];
  const Options o = parse(argc, argv);
  if (cmd == "scene") return cmd_scene(o);
  if (cmd == "config") return cmd_config(o);
  if (cmd == "ref") return cmd_ref(o);
  if (cmd == "topng") return cmd_topng(o);
  if (cmd == "same") return cmd_same(o);
  if (cmd == "crc") return cmd_crc(o);
  die("unknown command " + cmd, 2);
}
