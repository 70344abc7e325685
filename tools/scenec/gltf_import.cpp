// glTF 2.0 -> SceneMesh (issue #2 item 5): the default scene's nodes depth-first, transforms flattened
// to world space, primitives triangulated in order. Every accessor, buffer view and index is checked
// here before it is read; tinygltf's own checks are not relied on.
#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <type_traits>

#include <nlohmann/json.hpp>
#include <stb/stb_image.h>
#include <tiny_gltf.h>

#include "tools/scenec/limits.h"
#include "tools/scenec/scenec.h"

namespace ml {
namespace {

// What the raw JSON text of a glTF will cost the parsers, measured before they run: nesting depth
// ('[' and '{' outside strings, escapes respected) and values (each ',', ':' and '[' outside strings
// counts 1, each '{' counts kJsonObjectCost). The scan stops as soon as either limit is passed.
struct JsonShape {
  int depth = 0;
  uint64_t values = 0;
};

JsonShape json_shape(const unsigned char* text, size_t n) {
  JsonShape shape;
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;   // the escaped character cannot end the string
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > shape.depth) shape.depth = depth;
      shape.values += c == '{' ? kJsonObjectCost : 1;
      if (shape.depth > kMaxJsonDepth || shape.values > kMaxJsonValues) return shape;
    } else if (c == ']' || c == '}') {
      if (depth > 0) --depth;
    } else if (c == ',' || c == ':') {
      if (++shape.values > kMaxJsonValues) return shape;
    }
  }
  return shape;
}

// The JSON text of a .glb (its first chunk), clamped to the bytes present; empty when too short.
void glb_json_chunk(const unsigned char* bytes, size_t size, const unsigned char** json, size_t* length) {
  *json = nullptr;
  *length = 0;
  if (size < 20) return;
  uint32_t chunk_length;
  std::memcpy(&chunk_length, bytes + 12, 4);
  *json = bytes + 20;
  *length = std::min<size_t>(chunk_length, size - 20);
}

// Whether a GLB's BIN chunk, when it has one, lies inside the file (and inside the length its header
// states). tinygltf checks the chunk's length without the chunk's own 8-byte header and then copies up
// to 8 bytes past the end of the buffer it was given (a fuzzer's find): refused before it sees them.
// json_length: glb_json_chunk's (a JSON chunk clamped to the file leaves no room for a BIN chunk).
bool glb_bin_chunk_fits(const unsigned char* bytes, size_t size, size_t json_length) {
  if (size < 20) return true;  // (tinygltf refuses a GLB shorter than its header)
  uint32_t stated;
  std::memcpy(&stated, bytes + 8, 4);
  const uint64_t end = std::min<uint64_t>(stated, size), bin = 20 + uint64_t(json_length);
  if (bin + 8 > end) return true;  // no BIN chunk header: none, or tinygltf refuses the file
  uint32_t bin_length;
  std::memcpy(&bin_length, bytes + bin, 4);
  return bin + 8 + bin_length <= end;
}

// The version a JSON's "asset" states ("" when none): read when the glTF parser refused the file,
// which it does for glTF 1.0 files that write the version as a number ("asset object not found").
// The JSON's depth and size are checked before (json_shape).
std::string stated_asset_version(const unsigned char* json, size_t length) {
  const nlohmann::json j = nlohmann::json::parse(json, json + length, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) return "";
  const auto asset = j.find("asset");
  if (asset == j.end() || !asset->is_object()) return "";
  const auto version = asset->find("version");
  if (version == asset->end()) return "";
  if (version->is_string()) return version->get<std::string>();
  if (version->is_number_integer()) return version->dump() + ".0";
  return version->is_number() ? version->dump() : "";
}

// External files (buffers and images given by path) are read like the input itself: regular files
// of at most kMaxGltfFileBytes. With external files off (compiling from memory), none is read.
bool read_external_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
  std::string error;
  if (read_input_file(path, kMaxGltfFileBytes, out, &error)) return true;
  if (err) *err += error + "\n";
  return false;
}
// A file the glTF names exists for it only at its URI relative to the glTF (paths starting with the
// glTF's directory, `beside`: joined with "" as tinygltf joins paths; a URI may still go up with
// "../"): tinygltf also looks in the current directory, where a stray file of that name is not the
// model's.
bool file_beside_gltf(const std::string& path, void* beside) {
  const std::string& dir = *static_cast<const std::string*>(beside);
  return path.compare(0, dir.size(), dir) == 0 && tinygltf::FileExists(path, nullptr);
}
// A URI is joined to the glTF's directory as it is, but for backslashes in the URI's part, read as
// slashes: URIs separate with "/", yet exporters on Windows write ".\t.png" (assimp does), which
// names no file here.
std::string uri_path_with_slashes(const std::string& path, void* beside) {
  const std::string& dir = *static_cast<const std::string*>(beside);
  if (path.compare(0, dir.size(), dir) != 0) return path;
  std::string out = path;
  std::replace(out.begin() + std::ptrdiff_t(dir.size()), out.end(), '\\', '/');
  return out;
}
bool no_file_exists(const std::string&, void*) { return false; }
bool no_file_read(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
  if (err) *err += "external file " + path + " is not read here\n";
  return false;
}
bool no_file_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "files are not written here\n";
  return false;
}

// The length of the well-formed UTF-8 sequence at text[i] (2 to 4 bytes; no overlong form, no
// surrogate, at most U+10FFFF), or 0.
size_t utf8_sequence(const unsigned char* text, size_t size, size_t i) {
  const unsigned char c = text[i];
  const size_t n = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
  if (n == 0 || i + n > size) return 0;
  const unsigned char c1 = text[i + 1];
  const unsigned char lo = c == 0xE0 ? 0xA0 : c == 0xF0 ? 0x90 : 0x80;
  const unsigned char hi = c == 0xED ? 0x9F : c == 0xF4 ? 0x8F : 0xBF;
  if (c1 < lo || c1 > hi) return 0;
  for (size_t k = 2; k < n; ++k)
    if ((text[i + k] & 0xC0) != 0x80) return 0;
  return n;
}

// The input with its JSON's bytes that are not UTF-8 read as Latin-1 (ISO 8859-1) and written as
// UTF-8, two bytes each: JSON must be UTF-8, but exporters write names in the encoding they were
// given (assimp's glTF export writes an OBJ's Latin-1 material name as it is), and the JSON parser
// refuses the whole file for one such byte. A .glb gets its JSON chunk and lengths rewritten, its other
// chunks kept. Returns how many bytes were re-encoded: 0 (and *out untouched) for well-formed UTF-8.
size_t utf8_from_latin1(const unsigned char* bytes, size_t size, bool binary, const unsigned char* json,
                        size_t json_length, std::vector<unsigned char>* out) {
  if (!json) return 0;
  // Bytes that begin no well-formed sequence, counted first: a well-formed JSON is not copied.
  const auto sequence = [&](size_t i) { return json[i] < 0x80 ? 1 : utf8_sequence(json, json_length, i); };
  size_t count = 0;
  for (size_t i = 0; i < json_length;) {
    const size_t n = sequence(i);
    count += n == 0 ? 1 : 0;
    i += n == 0 ? 1 : n;
  }
  if (count == 0) return 0;
  std::vector<unsigned char> fixed;
  fixed.reserve(json_length + count + 3);
  for (size_t i = 0; i < json_length;) {
    const size_t n = sequence(i);
    if (n > 0) {
      fixed.insert(fixed.end(), json + i, json + i + n);
      i += n;
      continue;
    }
    fixed.push_back(uint8_t(0xC0 | (json[i] >> 6)));
    fixed.push_back(uint8_t(0x80 | (json[i] & 0x3F)));
    ++i;
  }
  if (!binary) {
    *out = std::move(fixed);
    return count;
  }
  // glb: header (magic, version, total length), then the JSON chunk (length, "JSON", its bytes padded
  // with spaces to a multiple of 4), then the rest as it was.
  while (fixed.size() % 4 != 0) fixed.push_back(' ');
  uint32_t stated = 0;
  std::memcpy(&stated, bytes + 12, 4);
  const size_t rest = 20 + size_t(stated) < size ? 20 + size_t(stated) : size;
  const uint32_t chunk = uint32_t(fixed.size()), total = uint32_t(20 + fixed.size() + (size - rest));
  out->assign(bytes, bytes + 20);
  std::memcpy(out->data() + 8, &total, 4);
  std::memcpy(out->data() + 12, &chunk, 4);
  out->insert(out->end(), fixed.begin(), fixed.end());
  out->insert(out->end(), bytes + rest, bytes + size);
  return count;
}

// Text fit for a terminal line: well-formed UTF-8 kept, any other byte below 0x20 (tab aside), 0x7F or
// not part of a well-formed sequence written as \xNN (a parser's message quotes the bytes it choked
// on; a model's names may be in another encoding).
std::string printable(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const size_t n = c >= 0x80 ? utf8_sequence(reinterpret_cast<const unsigned char*>(text.data()), text.size(), i)
                     : (c >= 0x20 && c != 0x7F) || c == '\t' ? 1 : 0;
    if (n == 0) {
      static const char kHex[] = "0123456789abcdef";
      out += {'\\', 'x', kHex[c >> 4], kHex[c & 15]};
      ++i;
      continue;
    }
    out.append(text, i, n);
    i += n;
  }
  return out;
}

// One line: newlines become "; ", trailing separators and blanks go, the rest printable().
std::string one_line(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\n' || c == '\r') {
      if (!out.empty() && out.compare(out.size() < 2 ? 0 : out.size() - 2, 2, "; ") != 0) out += "; ";
    } else {
      out += c;
    }
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  return printable(out);
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::string line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) lines.push_back(printable(line));
  }
  return lines;
}

// What decode_image is given besides the image: the pixels the file's images may still decode to, and
// the model being loaded (its buffers and buffer views are read before its images).
struct ImageLoad {
  uint64_t budget;
  const tinygltf::Model* model;
};

// Whether an image stored in a buffer view lies inside its buffer: tinygltf hands the loader the view's
// bytes without checking its offset and length against the buffer.
bool view_inside_buffer(const tinygltf::Model& model, const tinygltf::Image& image, const unsigned char* bytes,
                        int size) {
  if (image.bufferView < 0) return true;  // a data: or file URI, decoded by tinygltf into its own bytes
  if (size_t(image.bufferView) >= model.bufferViews.size()) return false;
  const tinygltf::BufferView& view = model.bufferViews[size_t(image.bufferView)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) return false;
  const std::vector<unsigned char>& data = model.buffers[size_t(view.buffer)].data;
  return view.byteOffset <= data.size() && view.byteLength <= data.size() - view.byteOffset &&
         uint64_t(size) == view.byteLength && bytes == data.data() + view.byteOffset;
}

// Whether every chunk of a PNG fits in the bytes given (true for anything that is not a PNG): stb_image
// grows its buffer to a chunk's stated length before it reads the chunk, so a short file stating a
// gigabyte would make it allocate a gigabyte. A chunk is length (4 bytes, big-endian), type (4), data,
// CRC (4).
bool png_chunks_fit(const unsigned char* bytes, size_t size) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (size < 8 || memcmp(bytes, kSignature, 8) != 0) return true;
  for (size_t at = 8; size - at >= 12;) {
    const uint64_t length = uint64_t(bytes[at]) << 24 | uint64_t(bytes[at + 1]) << 16 | uint64_t(bytes[at + 2]) << 8 |
                            uint64_t(bytes[at + 3]);
    if (length > size - at - 12) return false;
    if (memcmp(bytes + at + 4, "IEND", 4) == 0) return true;
    at += 12 + size_t(length);
  }
  return true;
}

// Decodes an image (PNG, JPEG, ... through stb_image) to RGBA8, after checking its size in the header.
// An image that cannot be decoded is left empty with a warning: its textures draw the material colour.
bool decode_image(tinygltf::Image* image, const int index, std::string*, std::string* warn, int, int,
                  const unsigned char* bytes, int size, void* user) {
  ImageLoad& load = *static_cast<ImageLoad*>(user);
  uint64_t& budget = load.budget;
  const std::string which = "image " + std::to_string(index);
  if (!view_inside_buffer(*load.model, *image, bytes, size)) {
    if (warn) *warn += which + ": its buffer view reaches past its buffer, texture ignored\n";
    return true;
  }
  if (size > 0 && !png_chunks_fit(bytes, size_t(size))) {
    if (warn) *warn += which + ": a PNG chunk runs past the end of the image, texture ignored\n";
    return true;
  }
  int w = 0, h = 0, comp = 0;
  if (size <= 0 || !stbi_info_from_memory(bytes, size, &w, &h, &comp)) {
    if (warn) *warn += which + ": not a decodable image, texture ignored\n";
    return true;
  }
  if (w <= 0 || h <= 0 || uint64_t(w) * uint64_t(h) > budget) {
    if (warn) *warn += which + ": " + std::to_string(w) + "x" + std::to_string(h) + " is above the " +
                       std::to_string(kMaxImagePixels) + "-pixel limit of a file's images, texture ignored\n";
    return true;
  }
  budget -= uint64_t(w) * uint64_t(h);
  unsigned char* pixels = stbi_load_from_memory(bytes, size, &w, &h, &comp, 4);
  if (!pixels) {
    if (warn) *warn += which + ": decoding failed (" + std::string(stbi_failure_reason()) + "), texture ignored\n";
    return true;
  }
  image->width = w;
  image->height = h;
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image->image.assign(pixels, pixels + size_t(w) * size_t(h) * 4);
  stbi_image_free(pixels);
  return true;
}

TextureWrap wrap_mode(int gl) {
  if (gl == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return TextureWrap::MirroredRepeat;
  if (gl == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return TextureWrap::ClampToEdge;
  return TextureWrap::Repeat;
}

// The number at value[i] (or value itself when i < 0), or fallback.
double number_at(const tinygltf::Value& value, int i, double fallback) {
  const tinygltf::Value& v = i < 0 ? value : (value.IsArray() && i < int(value.ArrayLen()) ? value.Get(i) : value);
  if ((i >= 0 && !(value.IsArray() && i < int(value.ArrayLen()))) || !v.IsNumber()) return fallback;
  const double d = v.GetNumberAsDouble();
  return std::isfinite(d) ? d : fallback;
}

// v / |v| into out, scaled by the largest component first so the squares neither overflow (1e200)
// nor underflow (1e-200, e.g. a normal under a tiny node scale). Leaves out alone for a zero or
// non-finite vector.
void normalize3(const double v[3], double out[3]) {
  const double largest = std::max(std::fabs(v[0]), std::max(std::fabs(v[1]), std::fabs(v[2])));
  if (!(largest > 0) || !std::isfinite(largest)) return;
  const double u[3] = {v[0] / largest, v[1] / largest, v[2] / largest};
  const double len = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);   // 1..sqrt(3)
  for (int k = 0; k < 3; ++k) out[k] = u[k] / len;
}

// ---- 4x4 column-major affine matrices ----------------------------------------------------------------

using Mat4 = std::array<double, 16>;   // m[col * 4 + row]

Mat4 identity() {
  Mat4 m{};
  m[0] = m[5] = m[10] = m[15] = 1;
  return m;
}

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c) {
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
      r[c * 4 + row] = s;
    }
  }
  return r;
}

bool local_transform(const tinygltf::Node& node, int index, Mat4* out, std::string* error) {
  const std::string where = "node " + std::to_string(index);
  auto finite_all = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16) {
      *error = where + ": matrix must have 16 values";
      return false;
    }
    if (!finite_all(node.matrix)) {
      *error = where + ": non-finite transform";
      return false;
    }
    std::copy(node.matrix.begin(), node.matrix.end(), out->begin());
    return true;
  }
  if ((!node.translation.empty() && node.translation.size() != 3) ||
      (!node.rotation.empty() && node.rotation.size() != 4) || (!node.scale.empty() && node.scale.size() != 3)) {
    *error = where + ": translation, rotation or scale has the wrong number of values";
    return false;
  }
  if (!finite_all(node.translation) || !finite_all(node.rotation) || !finite_all(node.scale)) {
    *error = where + ": non-finite transform";
    return false;
  }
  double t[3] = {0, 0, 0}, s[3] = {1, 1, 1}, q[4] = {0, 0, 0, 1};
  for (size_t i = 0; i < node.translation.size(); ++i) t[i] = node.translation[i];
  for (size_t i = 0; i < node.scale.size(); ++i) s[i] = node.scale[i];
  for (size_t i = 0; i < node.rotation.size(); ++i) q[i] = node.rotation[i];
  const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(len > 0) || !std::isfinite(len)) {
    q[0] = q[1] = q[2] = 0;
    q[3] = 1;
  } else {
    for (double& c : q) c /= len;
  }
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  const double r[9] = {// column-major rotation
                       1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                       2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                       2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  Mat4 m{};
  for (int c = 0; c < 3; ++c) {
    for (int row = 0; row < 3; ++row) m[c * 4 + row] = r[c * 3 + row] * s[c];
  }
  m[12] = t[0];
  m[13] = t[1];
  m[14] = t[2];
  m[15] = 1;
  *out = m;
  return true;
}

// ---- accessors ---------------------------------------------------------------------------------------

// One component of type T, unaligned. A normalized signed integer maps to [-1, 1] (the most negative
// value clamps to -1), an unsigned one to [0, 1], as the glTF specification says.
template <typename T>
double load_component(const unsigned char* p, bool normalized) {
  T v;
  std::memcpy(&v, p, sizeof v);
  if (!normalized || !std::is_integral<T>::value) return double(v);
  const double scaled = double(v) / double(std::numeric_limits<T>::max());
  return std::is_signed<T>::value ? std::max(scaled, -1.0) : scaled;
}

double component_value(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return load_component<int8_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return load_component<uint8_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_SHORT: return load_component<int16_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load_component<uint16_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_INT: return load_component<int32_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return load_component<uint32_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return load_component<float>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: return load_component<double>(p, normalized);
  }
  return 0;
}

class Importer {
 public:
  Importer(const tinygltf::Model& model, SceneMesh* mesh, std::vector<std::string>* warnings)
      : model_(model), mesh_(*mesh), warnings_(*warnings) {}

  bool run(std::string* error) {
    error_ = error;
    if (!check_extensions()) return false;
    std::vector<int> roots;
    if (!choose_roots(&roots)) return false;
    for (const tinygltf::Material& m : model_.materials) mesh_.materials.push_back(convert_material(m));
    for (size_t i = 0; i < model_.textures.size(); ++i) {
      const int source = model_.textures[i].source;
      mesh_.texture_images.push_back(source >= 0 ? uint32_t(source) : kNone);
      MeshSampler sampler;
      const int si = model_.textures[i].sampler;
      if (si >= 0 && size_t(si) < model_.samplers.size()) {
        const tinygltf::Sampler& gl = model_.samplers[size_t(si)];
        sampler.wrap_s = wrap_mode(gl.wrapS);
        sampler.wrap_t = wrap_mode(gl.wrapT);
        if (gl.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) sampler.filter = TextureFilter::Nearest;
        sampler.mipmaps = gl.minFilter >= TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST &&
                          gl.minFilter <= TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
      }
      mesh_.texture_samplers.push_back(sampler);
    }
    for (const tinygltf::Image& image : model_.images) {
      MeshImage out;
      if (image.component == 4 && image.bits == 8 && !image.image.empty() &&
          image.image.size() == size_t(image.width) * size_t(image.height) * 4) {
        out.width = image.width;
        out.height = image.height;
        out.rgba = image.image;
      }
      mesh_.images.push_back(std::move(out));
    }
    for (size_t m = 0; m < mesh_.materials.size(); ++m) {
      const uint32_t t = mesh_.materials[m].texture;
      if (t != kNone && t >= mesh_.texture_images.size()) {
        warn("material " + std::to_string(m) + ": texture index out of range, ignored");
        mesh_.materials[m].texture = kNone;
      }
    }
    if (!check_totals(roots)) return false;
    on_path_.assign(model_.nodes.size(), 0);
    for (int root : roots) {
      if (!visit(root)) return false;
    }
    if (total_triangles_ == 0) return fail("scene has no triangles: " + why_no_triangles(roots));
    leave_out_unsampled_textures();
    return true;
  }

 private:
  struct Frame {
    int node;
    uint32_t mesh_node;
    Mat4 world;
    size_t next_child;
  };

  // maskline samples a material's base colour texture only: the file's other textures (normal,
  // occlusion, emissive or metallic-roughness maps) and those of materials no drawn primitive uses
  // would take the blob's flash for nothing. They stay in the texture table without texels.
  void leave_out_unsampled_textures() {
    std::vector<bool> sampled(mesh_.texture_images.size(), false);
    for (const MeshNode& node : mesh_.nodes) {
      for (const MeshPrimitive& prim : node.primitives) {
        if (prim.triangles.empty() || prim.material >= mesh_.materials.size()) continue;
        const uint32_t t = mesh_.materials[prim.material].texture;
        if (t != kNone) sampled[t] = true;
      }
    }
    std::string left_out;
    int count = 0;
    for (size_t t = 0; t < sampled.size(); ++t) {
      if (sampled[t] || mesh_.texture_images[t] == kNone) continue;
      left_out += (count++ ? ", " : "") + std::to_string(t);
      mesh_.texture_images[t] = kNone;
    }
    if (count > 0)
      warn((count == 1 ? "texture " : "textures ") + left_out +
           ": not the base colour of a drawn primitive's material, texels left out of the scene");
  }

  void warn(const std::string& w) {
    if (warnings_.size() < 100) warnings_.push_back(printable(w));
  }
  bool fail(const std::string& e) {
    *error_ = e;
    return false;
  }

  // Why the default scene gave no triangle, for the refusal's one line.
  std::string why_no_triangles(const std::vector<int>& roots) const {
    if (model_.meshes.empty()) return "the file has no meshes";
    if (roots.empty()) return model_.scenes.empty() ? "the file has no nodes" : "the scene has no nodes";
    if (meshes_used_ == 0) return "no node of the scene has a mesh";
    if (primitives_ == 0) return "its meshes have no primitives";
    if (skipped_ == primitives_) {
      return first_skip_ + (skipped_ > 1 ? " (and " + std::to_string(skipped_ - 1) + " more primitive(s) skipped)" : "");
    }
    return "its primitives hold no whole triangle (fewer than 3 indices or vertices)";
  }
  // A primitive left out of the scene, with the warning that says why.
  void skip_primitive(const std::string& why) {
    if (skipped_++ == 0) first_skip_ = why;
    warn(why);
  }

  bool check_extensions() {
    for (const std::string& ext : model_.extensionsRequired) {
      if (ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression" ||
          ext == "KHR_meshopt_compression") {
        return fail("required extension " + ext + " is not supported");
      }
      if (ext != "KHR_mesh_quantization" && ext != "KHR_texture_transform")
        warn("required extension " + ext + " ignored");
    }
    return true;
  }

  bool choose_roots(std::vector<int>* roots) {
    const int count = int(model_.nodes.size());
    int scene = -1;
    if (model_.defaultScene >= 0 && size_t(model_.defaultScene) < model_.scenes.size()) {
      scene = model_.defaultScene;
    } else {
      if (model_.defaultScene >= 0) {
        warn(model_.scenes.empty() ? "default scene " + std::to_string(model_.defaultScene) +
                                         " named, but the file has no scenes: every root node used"
                                   : "default scene index out of range, using scene 0");
      }
      if (!model_.scenes.empty()) scene = 0;
    }
    if (scene >= 0) {
      for (int n : model_.scenes[size_t(scene)].nodes) {
        if (n < 0 || n >= count) return fail("scene " + std::to_string(scene) + ": node index out of range");
        roots->push_back(n);
      }
      return true;
    }
    // No scene: every node that no node lists as a child.
    std::vector<char> is_child(model_.nodes.size(), 0);
    for (const tinygltf::Node& node : model_.nodes) {
      for (int c : node.children) {
        if (c >= 0 && c < count) is_child[size_t(c)] = 1;
      }
    }
    for (int n = 0; n < count; ++n) {
      if (!is_child[size_t(n)]) roots->push_back(n);
    }
    return true;
  }

  MeshMaterial convert_material(const tinygltf::Material& m) {
    MeshMaterial out;
    const std::vector<double>& f = m.pbrMetallicRoughness.baseColorFactor;
    if (f.size() == 4) {
      for (int c = 0; c < 4; ++c) out.base_color[c] = std::isfinite(f[size_t(c)]) ? f[size_t(c)] : 1.0;
    } else {
      for (double& c : out.base_color) c = 1.0;
    }
    const tinygltf::TextureInfo& info = m.pbrMetallicRoughness.baseColorTexture;
    const int tex = info.index;
    out.texture = tex >= 0 ? uint32_t(tex) : kNone;
    uv_transforms_.push_back(texture_transform(info, m.name));
    out.double_sided = m.doubleSided;
    if (m.alphaMode == "OPAQUE" || m.alphaMode.empty()) {
      out.alpha_mode = AlphaMode::Opaque;
    } else if (m.alphaMode == "MASK") {
      out.alpha_mode = AlphaMode::Mask;
    } else if (m.alphaMode == "BLEND") {
      out.alpha_mode = AlphaMode::Blend;
    } else {
      warn("material alphaMode '" + m.alphaMode + "' unknown, using OPAQUE");
      out.alpha_mode = AlphaMode::Opaque;
    }
    out.alpha_cutoff = std::isfinite(m.alphaCutoff) ? m.alphaCutoff : 0.5;
    return out;
  }

  // KHR_texture_transform of a base-colour texture as a 2x3 matrix on (u, v, 1): uv' = T R S uv.
  // The compiler applies it to the vertices of the primitives using the material.
  std::array<double, 6> texture_transform(const tinygltf::TextureInfo& info, const std::string& name) {
    std::array<double, 6> m = {1, 0, 0, 0, 1, 0};
    int tex_coord = info.texCoord;
    const auto it = info.extensions.find("KHR_texture_transform");
    if (it != info.extensions.end() && it->second.IsObject()) {
      const tinygltf::Value& t = it->second;
      const tinygltf::Value offset = t.Get("offset"), scale = t.Get("scale"), rotation = t.Get("rotation");
      const double ox = number_at(offset, 0, 0), oy = number_at(offset, 1, 0);
      const double sx = number_at(scale, 0, 1), sy = number_at(scale, 1, 1);
      const double r = number_at(rotation, -1, 0);
      m = {std::cos(r) * sx, std::sin(r) * sy, ox, -std::sin(r) * sx, std::cos(r) * sy, oy};
      if (t.Has("texCoord")) tex_coord = int(number_at(t.Get("texCoord"), -1, 0));
    } else if (info.extensions_json_string.find("\"KHR_texture_transform\"") != std::string::npos) {
      warn("material '" + name + "': its KHR_texture_transform is not an object, ignored");
    }
    if (tex_coord != 0 && info.index >= 0)
      warn("material '" + name + "': base colour texture uses TEXCOORD_" + std::to_string(tex_coord) +
           ", only TEXCOORD_0 is supported (used instead)");
    return m;
  }

  uint32_t default_material() {
    if (default_material_ == kNone) {
      MeshMaterial m;   // light grey, opaque, single-sided
      m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.8;
      m.base_color[3] = 1.0;
      default_material_ = uint32_t(mesh_.materials.size());
      mesh_.materials.push_back(m);
    }
    return default_material_;
  }

  // Accessor element count, or 0 when the index is out of range (reported when it is read).
  size_t accessor_count(int index) const {
    return index >= 0 && size_t(index) < model_.accessors.size() ? model_.accessors[size_t(index)].count : 0;
  }

  // Node instances, vertices and triangles of the whole scene from accessor counts alone, before
  // anything is read: a small file whose nodes share a mesh many times is refused up front instead of
  // after allocating its way to a limit. Malformed graphs (cycles, bad indices) are left to visit().
  bool check_totals(const std::vector<int>& roots) {
    std::vector<size_t> mesh_vertices(model_.meshes.size(), 0), mesh_triangles(model_.meshes.size(), 0);
    for (size_t m = 0; m < model_.meshes.size(); ++m) {
      for (const tinygltf::Primitive& prim : model_.meshes[m].primitives) {
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        const auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) continue;
        const size_t v = std::min(accessor_count(pos->second), kMaxAccessorCount);
        const size_t n = std::min(prim.indices >= 0 ? accessor_count(prim.indices) : v, kMaxAccessorCount);
        size_t t = 0;
        if (mode == TINYGLTF_MODE_TRIANGLES) t = n / 3;
        else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP || mode == TINYGLTF_MODE_TRIANGLE_FAN) t = n > 2 ? n - 2 : 0;
        else continue;
        mesh_vertices[m] += v;
        mesh_triangles[m] += t;
      }
    }
    std::vector<char> on_path(model_.nodes.size(), 0);
    size_t instances = 0, vertices = 0, triangles = 0;
    struct Item {
      int node;
      size_t next_child;
    };
    std::vector<Item> stack;
    auto enter_node = [&](int n) {
      if (n < 0 || size_t(n) >= model_.nodes.size() || on_path[size_t(n)]) return false;
      const tinygltf::Node& node = model_.nodes[size_t(n)];
      ++instances;
      if (node.mesh >= 0 && size_t(node.mesh) < model_.meshes.size()) {
        vertices += mesh_vertices[size_t(node.mesh)];
        triangles += mesh_triangles[size_t(node.mesh)];
      }
      on_path[size_t(n)] = 1;
      stack.push_back(Item{n, 0});
      return true;
    };
    for (int root : roots) {
      if (!enter_node(root)) return true;
      while (!stack.empty()) {
        if (instances > kMaxNodeInstances) return fail("too many node instances (node graph too large)");
        if (triangles > kMaxTriangles) return fail("too many triangles (" + std::to_string(triangles) + " or more)");
        if (vertices > kMaxVertices) return fail("too many vertices (" + std::to_string(vertices) + " or more)");
        Item& top = stack.back();
        const tinygltf::Node& node = model_.nodes[size_t(top.node)];
        if (top.next_child < node.children.size()) {
          if (!enter_node(node.children[top.next_child++])) return true;
        } else {
          on_path[size_t(top.node)] = 0;
          stack.pop_back();
        }
      }
    }
    if (triangles > kMaxTriangles) return fail("too many triangles (" + std::to_string(triangles) + ")");
    if (vertices > kMaxVertices) return fail("too many vertices (" + std::to_string(vertices) + ")");
    return true;
  }

  // Depth-first pre-order over the node graph from `root`, children in order, with an explicit stack.
  bool visit(int root) {
    std::vector<Frame> stack;
    if (!enter(root, kNone, identity(), &stack)) return false;
    while (!stack.empty()) {
      Frame& top = stack.back();
      const tinygltf::Node& node = model_.nodes[size_t(top.node)];
      if (top.next_child < node.children.size()) {
        const int child = node.children[top.next_child++];
        const Mat4 world = top.world;
        const uint32_t parent = top.mesh_node;
        if (!enter(child, parent, world, &stack)) return false;
      } else {
        on_path_[size_t(top.node)] = 0;
        stack.pop_back();
      }
    }
    return true;
  }

  bool enter(int index, uint32_t parent, const Mat4& parent_world, std::vector<Frame>* stack) {
    if (index < 0 || size_t(index) >= model_.nodes.size()) {
      return fail("node index " + std::to_string(index) + " out of range");
    }
    if (on_path_[size_t(index)]) return fail("node graph has a cycle through node " + std::to_string(index));
    if (mesh_.nodes.size() >= kMaxNodeInstances) return fail("too many node instances (node graph too large)");
    const tinygltf::Node& node = model_.nodes[size_t(index)];
    Mat4 local;
    if (!local_transform(node, index, &local, error_)) return false;
    const Mat4 world = multiply(parent_world, local);
    for (double v : world) {
      if (!std::isfinite(v)) return fail("node " + std::to_string(index) + ": world transform is not finite");
    }
    const uint32_t mesh_node = uint32_t(mesh_.nodes.size());
    mesh_.nodes.emplace_back();
    mesh_.nodes.back().parent = parent;
    mesh_.nodes.back().name = node.name;
    if (node.skin >= 0 && !warned_skin_) {
      warn("skins are ignored (meshes drawn in their bind pose)");
      warned_skin_ = true;
    }
    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size()) {
        return fail("node " + std::to_string(index) + ": mesh index out of range");
      }
      if (!add_mesh(node.mesh, world, mesh_node)) return false;
    } else if (node.mesh < -1) {
      return fail("node " + std::to_string(index) + ": mesh index out of range");
    }
    on_path_[size_t(index)] = 1;
    stack->push_back(Frame{index, mesh_node, world, 0});
    return true;
  }

  // An attribute the primitive can be drawn without (NORMAL, TEXCOORD_0), read as read_accessor does,
  // `components` per element, one per vertex (`count` of them). Another element type or another
  // count leaves it out with a warning (*out empty) instead of refusing the model; a TEXCOORD_0 of
  // three components (UVW, as assimp's glTF exporter writes them) keeps its first two. An element with
  // a non-finite value (NaN or infinity, as some exporters write for a degenerate face's normal) is
  // left out with a warning: its vertex has no normal (shading takes its face's) or texture
  // coordinates (0, 0). A bad index or bytes still refuse it.
  bool read_optional(int index, int components, const std::string& semantic, size_t count, const std::string& where,
                     const std::string& what, std::vector<double>* out) {
    size_t read = 0;
    if (index < 0 || size_t(index) >= model_.accessors.size())
      return read_accessor(index, components, semantic, out, &read);  // refused there (index out of range)
    const int have = tinygltf::GetNumComponentsInType(uint32_t(model_.accessors[size_t(index)].type));
    const bool uvw = semantic == "TEXCOORD_0" && have == 3;
    if (have != components && !uvw) {
      const std::string kind = have > 0 ? std::to_string(have) + " component(s)" : "an unknown element type";
      warn(where + ": " + semantic + " has " + kind + ", not " + std::to_string(components) + ": " + what + " ignored");
      return true;
    }
    size_t non_finite = 0;
    if (!read_accessor(index, have, semantic, out, &read, false, &non_finite)) return false;
    if (non_finite > 0) {  // those elements are zeros (a normal of (0, 0, 0) is none: normalize3 leaves it so)
      warn(where + ": " + std::to_string(non_finite) + " " + semantic + " element(s) not finite: " +
           (semantic == "NORMAL" ? "those vertices shaded with their face's normal" : "(0, 0) used there"));
    }
    if (read != count) {
      warn(where + ": " + semantic + " count differs from POSITION count, " + what + " ignored");
      out->clear();
      return true;
    }
    if (uvw) {
      for (size_t i = 0; i < count; ++i) {
        (*out)[2 * i] = (*out)[3 * i];
        (*out)[2 * i + 1] = (*out)[3 * i + 1];
      }
      out->resize(2 * count);
      warn(where + ": TEXCOORD_0 has 3 components (UVW): the first two used");
    }
    return true;
  }

  // Reads accessor `index` as doubles, `components` per element. Checks everything first.
  // Non-finite values refuse the model, unless finite_only is false: then an element holding one is
  // made all zeros (*non_finite: how many; read_optional's attributes).
  bool read_accessor(int index, int components, const std::string& semantic, std::vector<double>* out,
                     size_t* count_out, bool finite_only = true, size_t* non_finite = nullptr) {
    const std::string where = "accessor " + std::to_string(index) + " (" + semantic + ")";
    if (index < 0 || size_t(index) >= model_.accessors.size()) return fail(where + ": index out of range");
    const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
    const int csize = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
    if (csize <= 0) return fail(where + ": invalid component type");
    if (tinygltf::GetNumComponentsInType(uint32_t(acc.type)) != components) {
      return fail(where + ": wrong element type");
    }
    if (acc.count > kMaxAccessorCount) return fail(where + ": count too large");
    const size_t count = acc.count;
    const size_t elem = size_t(csize) * size_t(components);
    // Every check on the sizes comes before the allocation: a small file may claim a huge count.
    const unsigned char* data = nullptr;
    size_t length = 0, stride = 0;
    if (acc.bufferView >= 0) {
      if (!view_bytes(acc.bufferView, where, &data, &length, &stride)) return false;
      if (stride == 0) stride = elem;
      if (stride < elem || stride > 252 || stride % size_t(csize) != 0) return fail(where + ": bad byte stride");
      if (count > 0) {
        if (acc.byteOffset > length) return fail(where + ": data outside its buffer view");
        const uint64_t need = uint64_t(acc.byteOffset) + uint64_t(count - 1) * stride + elem;
        if (need > length) return fail(where + ": data outside its buffer view");
      }
    } else if (acc.bufferView < -1) {
      return fail(where + ": buffer view index out of range");
    } else {
      // No buffer view: zeros (and sparse values) that nothing in the file backs.
      unbacked_elements_ += count;
      if (unbacked_elements_ > kMaxUnbackedElements) return fail(where + ": too many elements without a buffer view");
    }
    out->assign(count * size_t(components), 0.0);
    if (acc.bufferView >= 0) {
      for (size_t i = 0; i < count; ++i) {
        const unsigned char* p = data + acc.byteOffset + i * stride;
        for (int c = 0; c < components; ++c) {
          (*out)[i * size_t(components) + size_t(c)] =
              component_value(p + size_t(c) * size_t(csize), acc.componentType, acc.normalized);
        }
      }
    }
    if (acc.sparse.isSparse && !apply_sparse(acc, components, csize, where, out)) return false;
    size_t bad = 0;
    for (size_t i = 0; i < count; ++i) {
      bool finite = true;
      for (int c = 0; c < components; ++c) finite = finite && std::isfinite((*out)[i * size_t(components) + size_t(c)]);
      if (finite) continue;
      if (finite_only) return fail(where + ": non-finite value");
      std::fill_n(out->begin() + std::ptrdiff_t(i * size_t(components)), components, 0.0);
      ++bad;
    }
    if (non_finite) *non_finite = bad;
    *count_out = count;
    return true;
  }

  bool apply_sparse(const tinygltf::Accessor& acc, int components, int csize, const std::string& where,
                    std::vector<double>* out) {
    const int n = acc.sparse.count;
    if (n < 0 || size_t(n) > acc.count) return fail(where + ": bad sparse count");
    const int itype = acc.sparse.indices.componentType;
    const int isize = tinygltf::GetComponentSizeInBytes(uint32_t(itype));
    if (itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      return fail(where + ": bad sparse index type");
    }
    const unsigned char *idata = nullptr, *vdata = nullptr;
    size_t ilen = 0, vlen = 0, unused = 0;
    if (!view_bytes(acc.sparse.indices.bufferView, where, &idata, &ilen, &unused)) return false;
    if (!view_bytes(acc.sparse.values.bufferView, where, &vdata, &vlen, &unused)) return false;
    const int64_t ioff = acc.sparse.indices.byteOffset, voff = acc.sparse.values.byteOffset;
    const size_t elem = size_t(csize) * size_t(components);
    if (ioff < 0 || voff < 0 || uint64_t(ioff) + uint64_t(n) * uint64_t(isize) > ilen ||
        uint64_t(voff) + uint64_t(n) * elem > vlen) {
      return fail(where + ": sparse data outside its buffer view");
    }
    for (int i = 0; i < n; ++i) {
      const double target = component_value(idata + ioff + size_t(i) * size_t(isize), itype, false);
      if (!(target >= 0) || target >= double(acc.count)) return fail(where + ": sparse index out of range");
      const size_t t = size_t(target);
      for (int c = 0; c < components; ++c) {
        (*out)[t * size_t(components) + size_t(c)] = component_value(
            vdata + voff + size_t(i) * elem + size_t(c) * size_t(csize), acc.componentType, acc.normalized);
      }
    }
    return true;
  }

  bool view_bytes(int view, const std::string& where, const unsigned char** data, size_t* length,
                  size_t* stride) {
    if (view < 0 || size_t(view) >= model_.bufferViews.size()) return fail(where + ": buffer view index out of range");
    const tinygltf::BufferView& bv = model_.bufferViews[size_t(view)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size()) {
      return fail(where + ": buffer view " + std::to_string(view) + " names a missing buffer");
    }
    const std::vector<unsigned char>& buffer = model_.buffers[size_t(bv.buffer)].data;
    if (bv.byteOffset > buffer.size() || bv.byteLength > buffer.size() - bv.byteOffset) {
      return fail(where + ": buffer view " + std::to_string(view) + " outside buffer " + std::to_string(bv.buffer));
    }
    *data = buffer.data() + bv.byteOffset;
    *length = bv.byteLength;
    *stride = bv.byteStride;
    return true;
  }

  bool read_indices(int index, size_t vertex_count, std::vector<uint32_t>* out) {
    const std::string where = "accessor " + std::to_string(index) + " (indices)";
    if (index < 0 || size_t(index) >= model_.accessors.size()) return fail(where + ": index out of range");
    const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
    if (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      return fail(where + ": indices must be unsigned byte, short or int");
    }
    std::vector<double> values;
    size_t count = 0;
    if (!read_accessor(index, 1, "indices", &values, &count)) return false;
    out->resize(count);
    for (size_t i = 0; i < count; ++i) {
      if (values[i] >= double(vertex_count)) {
        return fail(where + ": index " + std::to_string(uint64_t(values[i])) + " out of range (vertex count " +
                    std::to_string(vertex_count) + ")");
      }
      (*out)[i] = uint32_t(values[i]);
    }
    return true;
  }

  bool add_mesh(int mesh_index, const Mat4& world, uint32_t mesh_node) {
    const tinygltf::Mesh& mesh = model_.meshes[size_t(mesh_index)];
    ++meshes_used_;
    // Normals: the inverse-transpose of the linear part, as the cofactor matrix times sign(det).
    const double* m = world.data();
    auto at = [&](int row, int col) { return m[col * 4 + row]; };
    double cof[3][3];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        const int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
        cof[r][c] = at(r1, c1) * at(r2, c2) - at(r1, c2) * at(r2, c1);
      }
    }
    const double det = at(0, 0) * cof[0][0] + at(0, 1) * cof[0][1] + at(0, 2) * cof[0][2];
    const double nsign = det < 0 ? -1.0 : 1.0;
    const bool flip = det < 0;

    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const tinygltf::Primitive& prim = mesh.primitives[pi];
      const std::string where = "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(pi);
      ++primitives_;
      const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
      if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        static const char* const kNames[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
        const std::string name = mode >= 0 && mode <= 3 ? kNames[mode] : "unknown mode " + std::to_string(mode);
        skip_primitive(where + ": mode " + name + " skipped (only triangles are drawn)");
        continue;
      }
      if (prim.extensions.count("KHR_draco_mesh_compression")) {
        return fail(where + ": KHR_draco_mesh_compression is not supported");
      }
      const auto pos_it = prim.attributes.find("POSITION");
      if (pos_it == prim.attributes.end()) {
        skip_primitive(where + ": no POSITION attribute, skipped");
        continue;
      }
      std::vector<double> pos, nrm, uv;
      size_t count = 0;
      if (!read_accessor(pos_it->second, 3, "POSITION", &pos, &count)) return false;
      const auto n_it = prim.attributes.find("NORMAL");
      if (n_it != prim.attributes.end() && !read_optional(n_it->second, 3, "NORMAL", count, where, "normals", &nrm))
        return false;
      const auto uv_it = prim.attributes.find("TEXCOORD_0");
      if (uv_it != prim.attributes.end() &&
          !read_optional(uv_it->second, 2, "TEXCOORD_0", count, where, "texture coordinates", &uv))
        return false;
      std::vector<uint32_t> indices;
      if (prim.indices >= 0) {
        if (!read_indices(prim.indices, count, &indices)) return false;
      } else {
        if (prim.indices < -1) return fail(where + ": indices accessor out of range");
        indices.resize(count);
        for (size_t i = 0; i < count; ++i) indices[i] = uint32_t(i);
      }

      MeshPrimitive out;
      if (prim.material >= 0 && size_t(prim.material) < model_.materials.size()) {
        out.material = uint32_t(prim.material);
      } else {
        if (prim.material >= 0 || prim.material < -1) warn(where + ": material index out of range, default used");
        out.material = default_material();
      }
      out.vertices.resize(count);
      for (size_t i = 0; i < count; ++i) {
        MeshVertex& v = out.vertices[i];
        const double* p = &pos[i * 3];
        for (int r = 0; r < 3; ++r) v.position[r] = at(r, 0) * p[0] + at(r, 1) * p[1] + at(r, 2) * p[2] + at(r, 3);
        if (!std::isfinite(v.position[0]) || !std::isfinite(v.position[1]) || !std::isfinite(v.position[2])) {
          return fail(where + ": transformed POSITION is not finite");
        }
        if (!nrm.empty()) {
          const double* n = &nrm[i * 3];
          double t[3];
          for (int r = 0; r < 3; ++r) t[r] = nsign * (cof[r][0] * n[0] + cof[r][1] * n[1] + cof[r][2] * n[2]);
          normalize3(t, v.normal);
        }
        if (!uv.empty()) {
          const std::array<double, 6>& t = out.material < uv_transforms_.size() ? uv_transforms_[out.material]
                                                                                : kIdentityUv;
          const double u0 = uv[i * 2], v0 = uv[i * 2 + 1];
          v.uv[0] = t[0] * u0 + t[1] * v0 + t[2];
          v.uv[1] = t[3] * u0 + t[4] * v0 + t[5];
        }
      }
      const size_t n = indices.size();
      auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
        out.triangles.push_back(flip ? std::array<uint32_t, 3>{a, c, b} : std::array<uint32_t, 3>{a, b, c});
      };
      if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (n % 3 != 0) warn(where + ": index count not a multiple of 3, extra indices ignored");
        for (size_t i = 0; i + 2 < n; i += 3) emit(indices[i], indices[i + 1], indices[i + 2]);
      } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        // glTF: triangle i = {v_i, v_(i+1+i%2), v_(i+2-i%2)}
        for (size_t i = 0; i + 2 < n; ++i) {
          emit(indices[i], indices[i + 1 + i % 2], indices[i + 2 - i % 2]);
        }
      } else {
        // glTF: triangle i = {v_(i+1), v_(i+2), v_0}
        for (size_t i = 0; i + 2 < n; ++i) emit(indices[i + 1], indices[i + 2], indices[0]);
      }
      total_triangles_ += out.triangles.size();
      if (total_triangles_ > kMaxTriangles) return fail("too many triangles");
      mesh_.nodes[mesh_node].primitives.push_back(std::move(out));
    }
    return true;
  }

  const tinygltf::Model& model_;
  SceneMesh& mesh_;
  std::vector<std::string>& warnings_;
  std::string* error_ = nullptr;
  std::vector<char> on_path_;
  std::vector<std::array<double, 6>> uv_transforms_;  // per glTF material (texture_transform)
  static constexpr std::array<double, 6> kIdentityUv = {1, 0, 0, 0, 1, 0};
  uint32_t default_material_ = kNone;
  bool warned_skin_ = false;
  size_t total_triangles_ = 0;
  size_t unbacked_elements_ = 0;
  // Mesh instances of the scene, their primitives, those skipped, and the first skip's warning
  // (why_no_triangles).
  size_t meshes_used_ = 0, primitives_ = 0, skipped_ = 0;
  std::string first_skip_;
};

// The glTF parser's warnings, an image file it could not read said in one line that names the file
// (the parser's own two: "File not found : F", then "Failed to load external 'uri' for image[N] name =
// [...]", which does not).
std::vector<std::string> image_file_warnings(const std::vector<std::string>& lines, const tinygltf::Model& model) {
  static const std::string kNotFound = "File not found : ", kFailed = "Failed to load external 'uri' for image[";
  std::vector<std::string> out;
  for (const std::string& line : lines) {
    if (line.compare(0, kNotFound.size(), kNotFound) == 0) {
      const std::string file = line.substr(kNotFound.size());
      const bool an_image = std::any_of(model.images.begin(), model.images.end(), [&](const tinygltf::Image& i) {
        return !i.uri.empty() && i.uri == file;
      });
      if (an_image) continue;  // said by the image's line below
    } else if (line.compare(0, kFailed.size(), kFailed) == 0) {
      const size_t index = size_t(std::strtoul(line.c_str() + kFailed.size(), nullptr, 10));
      if (index < model.images.size()) {
        out.push_back("image " + std::to_string(index) + ": its file '" + printable(model.images[index].uri) +
                      "' not read (missing beside the glTF, or unreadable), texture ignored");
        continue;
      }
    }
    out.push_back(line);
  }
  return out;
}

// The directory written without leading "./" (and the slashes after it): tinygltf's second lookup is
// "./" + the file's URI, which the prefix test of file_beside_gltf would let through for "./dir/"
// (a URI "dir/t.png" would be read from "./dir/t.png", not from beside the glTF: "./dir/dir/t.png").
std::string without_leading_dot_slash(std::string dir) {
  while (dir.size() > 2 && dir[0] == '.' && dir[1] == '/') {
    size_t n = 2;
    while (n < dir.size() && dir[n] == '/') ++n;
    if (n == dir.size()) return ".";  // "./", ".//": the current directory
    dir.erase(0, n);
  }
  return dir;
}

std::string base_dir_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);  // (empty would read no external file)
}

}  // namespace

bool import_gltf_memory(const unsigned char* bytes, size_t size, const std::string& base_dir, SceneMesh* mesh,
                        std::vector<std::string>* warnings, std::string* error) {
  *mesh = SceneMesh();
  try {
    if (size == 0) {
      *error = "file is empty";
      return false;
    }
    if (size > kMaxGltfFileBytes) {
      *error = "file too large for glTF";
      return false;
    }
    const bool binary = size >= 4 && std::memcmp(bytes, "glTF", 4) == 0;
    if (binary && size >= 8) {  // glTF 1.0's binary files (KHR_binary_glTF) are version 1: another layout
      uint32_t glb_version;
      std::memcpy(&glb_version, bytes + 4, 4);
      if (glb_version != 2) {
        *error = "GLB version " + std::to_string(glb_version) + " is not supported (glTF 2.0 only)";
        return false;
      }
    }
    // The JSON parsers recurse once per nesting level, and the glTF parser turns each small object
    // into a large structure: refuse deep or very large JSON before they see it.
    const unsigned char* json = bytes;
    size_t json_length = size;
    if (binary) glb_json_chunk(bytes, size, &json, &json_length);
    std::vector<unsigned char> reencoded;
    if (const size_t n = utf8_from_latin1(bytes, size, binary, json, json_length, &reencoded)) {
      if (reencoded.size() > kMaxGltfFileBytes) {
        *error = "file too large for glTF";
        return false;
      }
      warnings->push_back("the JSON holds " + std::to_string(n) + " byte(s) that are not UTF-8: read as Latin-1");
      bytes = reencoded.data();
      size = reencoded.size();
      json = bytes;
      json_length = size;
      if (binary) glb_json_chunk(bytes, size, &json, &json_length);
    }
    if (binary && !glb_bin_chunk_fits(bytes, size, json_length)) {
      *error = "invalid glTF: the GLB's BIN chunk runs past the end of the file";
      return false;
    }
    const JsonShape shape = json_shape(json, json_length);
    if (shape.depth > kMaxJsonDepth) {
      *error = "invalid glTF: JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels";
      return false;
    }
    if (shape.values > kMaxJsonValues) {
      *error = "JSON too large: more than " + std::to_string(kMaxJsonValues) + " values (an object counts " +
               std::to_string(kJsonObjectCost) + ")";
      return false;
    }
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    ImageLoad image_load{kMaxImagePixels, &model};
    loader.SetImageLoader(&decode_image, &image_load);
    // The extensions' JSON as written: tinygltf drops an extension that is not an object, which the
    // importer then names (texture_transform).
    loader.SetStoreOriginalJSONForExtrasAndExtensions(true);
    tinygltf::FsCallbacks fs{};
    const std::string dir = without_leading_dot_slash(base_dir);  // (empty stays empty: no file read)
    std::string beside = dir.empty() || dir.back() == '/' ? dir : dir + "/";
    fs.user_data = &beside;
    fs.ExpandFilePath = &uri_path_with_slashes;
    fs.WriteWholeFile = &no_file_write;
    if (dir.empty()) {
      fs.FileExists = &no_file_exists;
      fs.ReadWholeFile = &no_file_read;
    } else {
      fs.FileExists = &file_beside_gltf;
      fs.ReadWholeFile = &read_external_file;
    }
    loader.SetFsCallbacks(fs);
    std::string err, warn;
    bool ok;
    if (binary) {
      ok = loader.LoadBinaryFromMemory(&model, &err, &warn, bytes, unsigned(size), dir);
    } else {
      ok = loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes), unsigned(size),
                                      dir);
    }
    for (const std::string& w : image_file_warnings(split_lines(warn), model)) {
      if (warnings->size() < 100) warnings->push_back(w);
    }
    const std::string version = ok ? model.asset.version : stated_asset_version(json, json_length);
    if (!version.empty() && version[0] != '2') {  // glTF 1.0: meshes are an object, not found as an array
      *error = "glTF " + one_line(version) + " is not supported (glTF 2.0 only)";
      return false;
    }
    if (!ok) {
      const std::string e = one_line(err);
      *error = e.empty() ? std::string("invalid glTF") : "invalid glTF: " + e;
      static const char kDraco[] = "KHR_draco_mesh_compression";
      if (std::search(bytes, bytes + size, kDraco, kDraco + sizeof(kDraco) - 1) != bytes + size) {
        *error = std::string(kDraco) + " is not supported (" + (e.empty() ? std::string("invalid glTF") : e) + ")";
      }
      return false;
    }
    Importer importer(model, mesh, warnings);
    if (!importer.run(error)) {
      *error = one_line(*error);
      return false;
    }
    return true;
  } catch (const std::bad_alloc&) {
    *error = "out of memory while reading glTF";
  } catch (const std::exception& e) {
    *error = "invalid glTF: " + one_line(e.what());
  } catch (...) {
    *error = "invalid glTF: unknown parse failure";
  }
  return false;
}

bool import_gltf_file(const std::string& path, SceneMesh* mesh, std::vector<std::string>* warnings,
                      std::string* error) {
  *mesh = SceneMesh();
  std::vector<unsigned char> bytes;
  if (!read_input_file(path, kMaxGltfFileBytes, &bytes, error)) return false;
  return import_gltf_memory(bytes.data(), bytes.size(), base_dir_of(path), mesh, warnings, error);
}

CompileResult compile_gltf_memory(const unsigned char* bytes, size_t size, const CompileOptions& options) {
  SceneMesh mesh;
  std::vector<std::string> warnings;
  std::string error;
  CompileResult result;
  if (!import_gltf_memory(bytes, size, "", &mesh, &warnings, &error)) {
    result.error = error;
    result.warnings = std::move(warnings);
    return result;
  }
  result = compile_mesh(mesh, options);
  result.warnings.insert(result.warnings.begin(), warnings.begin(), warnings.end());
  return result;
}

CompileResult compile_gltf_file(const std::string& path, const CompileOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SceneMesh mesh;
  std::vector<std::string> warnings;
  std::string error;
  CompileResult result;
  if (!import_gltf_file(path, &mesh, &warnings, &error)) {
    result.error = error;
    result.warnings = std::move(warnings);
    return result;
  }
  result = compile_mesh(mesh, options);
  result.warnings.insert(result.warnings.begin(), warnings.begin(), warnings.end());
  result.camera = CameraHint();
  result.report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace ml
