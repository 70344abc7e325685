// Procedural scenes. Each one fills a SceneMesh and goes through compile_mesh like a glTF file does.
// Units are metre-like; y is up; front faces are counter-clockwise seen from outside.
#include <algorithm>
#include <cmath>

#include "tools/scenec/scenec.h"

namespace ml {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct V3 {
  double x, y, z;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 normalized(V3 a) {
  const double l = std::sqrt(dot(a, a));
  return l > 0 ? a * (1.0 / l) : V3{0, 0, 0};
}

class Builder {
 public:
  uint32_t material(double r, double g, double b, bool double_sided = false) {
    MeshMaterial m;
    m.base_color[0] = r;
    m.base_color[1] = g;
    m.base_color[2] = b;
    m.base_color[3] = 1.0;
    m.double_sided = double_sided;
    mesh_.materials.push_back(m);
    return uint32_t(mesh_.materials.size() - 1);
  }

  uint32_t node(const std::string& name, uint32_t parent) {
    MeshNode n;
    n.name = name;
    n.parent = parent;
    mesh_.nodes.push_back(std::move(n));
    return uint32_t(mesh_.nodes.size() - 1);
  }

  // The primitive of `node` with `material`, created on first use (primitives keep creation order).
  MeshPrimitive& prim(uint32_t node, uint32_t material) {
    for (MeshPrimitive& p : mesh_.nodes[node].primitives) {
      if (p.material == material) return p;
    }
    mesh_.nodes[node].primitives.emplace_back();
    mesh_.nodes[node].primitives.back().material = material;
    return mesh_.nodes[node].primitives.back();
  }

  static uint32_t vertex(MeshPrimitive& p, V3 pos, V3 normal, double u, double v) {
    MeshVertex mv;
    mv.position[0] = pos.x;
    mv.position[1] = pos.y;
    mv.position[2] = pos.z;
    mv.normal[0] = normal.x;
    mv.normal[1] = normal.y;
    mv.normal[2] = normal.z;
    mv.uv[0] = u;
    mv.uv[1] = v;
    p.vertices.push_back(mv);
    return uint32_t(p.vertices.size() - 1);
  }

  // Quad a-b-c-d, counter-clockwise seen from the side its flat normal points to.
  static void quad(MeshPrimitive& p, V3 a, V3 b, V3 c, V3 d) {
    const V3 n = normalized(cross(b - a, c - a));
    const uint32_t i0 = vertex(p, a, n, 0, 0), i1 = vertex(p, b, n, 1, 0), i2 = vertex(p, c, n, 1, 1),
                   i3 = vertex(p, d, n, 0, 1);
    p.triangles.push_back({i0, i1, i2});
    p.triangles.push_back({i0, i2, i3});
  }

  // Axis-aligned box [lo, hi], faces outward.
  static void box(MeshPrimitive& p, V3 lo, V3 hi) {
    const V3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                     {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    quad(p, c[4], c[5], c[6], c[7]);   // +z
    quad(p, c[1], c[0], c[3], c[2]);   // -z
    quad(p, c[5], c[1], c[2], c[6]);   // +x
    quad(p, c[0], c[4], c[7], c[3]);   // -x
    quad(p, c[7], c[6], c[2], c[3]);   // +y
    quad(p, c[0], c[1], c[5], c[4]);   // -y
  }

  // Grid surface: f(u, v) -> position and normal for u, v in [0, 1]; nu x nv cells, two triangles each.
  template <typename F>
  static void grid(MeshPrimitive& p, int nu, int nv, F f) {
    const uint32_t base = uint32_t(p.vertices.size());
    for (int j = 0; j <= nv; ++j) {
      for (int i = 0; i <= nu; ++i) {
        V3 pos, n;
        f(double(i) / nu, double(j) / nv, &pos, &n);
        vertex(p, pos, n, double(i) / nu, double(j) / nv);
      }
    }
    const uint32_t row = uint32_t(nu + 1);
    for (int j = 0; j < nv; ++j) {
      for (int i = 0; i < nu; ++i) {
        const uint32_t a = base + uint32_t(j) * row + uint32_t(i), b = a + 1, c = a + row + 1, d = a + row;
        p.triangles.push_back({a, b, c});
        p.triangles.push_back({a, c, d});
      }
    }
  }

  SceneMesh& mesh() { return mesh_; }

 private:
  SceneMesh mesh_;
};

void set_camera(SceneMesh* mesh, V3 eye, V3 target) {
  mesh->camera.valid = true;
  mesh->camera.eye[0] = eye.x;
  mesh->camera.eye[1] = eye.y;
  mesh->camera.eye[2] = eye.z;
  mesh->camera.target[0] = target.x;
  mesh->camera.target[1] = target.y;
  mesh->camera.target[2] = target.z;
}

}  // namespace

SceneMesh make_default_scene() {
  Builder b;
  const uint32_t light = b.material(0.85, 0.85, 0.80);
  const uint32_t dark = b.material(0.25, 0.28, 0.33);
  const uint32_t red = b.material(0.85, 0.20, 0.15);
  const uint32_t blue = b.material(0.20, 0.45, 0.90);
  const uint32_t gold = b.material(0.95, 0.70, 0.20);
  const uint32_t green = b.material(0.25, 0.75, 0.35);
  const uint32_t root = b.node("default_scene", kNone);

  // Checkered ground: 12 x 12 tiles over [-9, 9]^2 at y = 0.
  const uint32_t ground = b.node("ground", root);
  const int tiles = 12;
  const double size = 18.0, tile = size / tiles;
  b.prim(ground, light);
  b.prim(ground, dark);
  for (int j = 0; j < tiles; ++j) {
    for (int i = 0; i < tiles; ++i) {
      const double x0 = -size / 2 + i * tile, z0 = -size / 2 + j * tile;
      MeshPrimitive& p = b.prim(ground, ((i + j) & 1) ? dark : light);
      Builder::quad(p, {x0, 0, z0 + tile}, {x0 + tile, 0, z0 + tile}, {x0 + tile, 0, z0}, {x0, 0, z0});
    }
  }

  // Cube.
  const uint32_t cube = b.node("cube", root);
  Builder::box(b.prim(cube, red), {-5.5, 0, -1.0}, {-3.5, 2.0, 1.0});

  // Smooth sphere.
  const uint32_t sphere = b.node("sphere", root);
  const V3 sc{0, 1.6, -2.0};
  const double sr = 1.6;
  Builder::grid(b.prim(sphere, blue), 40, 20, [&](double u, double v, V3* p, V3* n) {
    const double phi = u * 2 * kPi, theta = v * kPi;   // theta from the bottom pole up
    const V3 d{-std::sin(theta) * std::cos(phi), -std::cos(theta), std::sin(theta) * std::sin(phi)};
    *n = d;
    *p = sc + d * sr;
  });

  // Torus, standing up and turned towards the viewer.
  const uint32_t torus = b.node("torus", root);
  const V3 tc{4.5, 1.75, 0.5};
  const double big = 1.2, small = 0.45, tilt = 0.5;
  Builder::grid(b.prim(torus, gold), 48, 20, [&](double u, double v, V3* p, V3* n) {
    const double a = u * 2 * kPi, c = -v * 2 * kPi;   // this direction keeps the outside counter-clockwise
    // torus around the z axis, then rotated about y by `tilt`
    const V3 ring{std::cos(a), std::sin(a), 0};
    V3 d = ring * std::cos(c) + V3{0, 0, -std::sin(c)};
    V3 q = ring * (big + small * std::cos(c)) + V3{0, 0, -small * std::sin(c)};
    auto rot = [&](V3 w) { return V3{w.x * std::cos(tilt) + w.z * std::sin(tilt), w.y, -w.x * std::sin(tilt) + w.z * std::cos(tilt)}; };
    *n = rot(d);
    *p = tc + rot(q);
  });

  // Pyramid.
  const uint32_t pyramid = b.node("pyramid", root);
  {
    MeshPrimitive& p = b.prim(pyramid, green);
    const V3 base[4] = {{-1.3, 0, 5.3}, {1.3, 0, 5.3}, {1.3, 0, 2.7}, {-1.3, 0, 2.7}};
    const V3 apex{0, 2.4, 4.0};
    for (int i = 0; i < 4; ++i) {
      const V3 a = base[i], c = base[(i + 1) % 4];
      const V3 nrm = normalized(cross(c - a, apex - a));
      const uint32_t i0 = Builder::vertex(p, a, nrm, 0, 0), i1 = Builder::vertex(p, c, nrm, 1, 0),
                     i2 = Builder::vertex(p, apex, nrm, 0.5, 1);
      p.triangles.push_back({i0, i1, i2});
    }
    Builder::quad(p, base[3], base[2], base[1], base[0]);   // bottom, facing down
  }
  set_camera(&b.mesh(), {0, 7.5, 15.0}, {0, 1.0, 0});
  return b.mesh();
}

SceneMesh make_office_scene(int layers) {
  layers = std::max(1, std::min(layers, 256));
  Builder b;
  const uint32_t floor_m = b.material(0.45, 0.50, 0.58);
  const uint32_t wall_m = b.material(0.86, 0.82, 0.72);
  const uint32_t desk_m = b.material(0.55, 0.36, 0.20);
  const uint32_t chair_m = b.material(0.65, 0.15, 0.15);
  const uint32_t cabinet_m = b.material(0.55, 0.57, 0.60);
  const uint32_t root = b.node("office", kNone);

  const int columns = 4;
  const double room = 8.0, height = 3.0, wall = 0.2, door = 1.4, door_h = 2.2;
  uint32_t seed = 12345;
  auto rnd = [&seed]() {
    seed = seed * 1664525u + 1013904223u;
    return double(seed >> 8) / double(1u << 24);
  };
  for (int layer = 0; layer < layers; ++layer) {
    for (int col = 0; col < columns; ++col) {
      const uint32_t n = b.node("room", root);
      const double x0 = (col - columns / 2.0) * room, z1 = -layer * room, z0 = z1 - room;
      // Floor.
      Builder::quad(b.prim(n, floor_m), {x0, 0, z1}, {x0 + room, 0, z1}, {x0 + room, 0, z0}, {x0, 0, z0});
      MeshPrimitive& w = b.prim(n, wall_m);
      // Back wall (at z0) with a doorway at a varying position.
      const double dx = x0 + 1.0 + rnd() * (room - 2.0 - door);
      Builder::box(w, {x0, 0, z0 - wall / 2}, {dx, height, z0 + wall / 2});
      Builder::box(w, {dx + door, 0, z0 - wall / 2}, {x0 + room, height, z0 + wall / 2});
      Builder::box(w, {dx, door_h, z0 - wall / 2}, {dx + door, height, z0 + wall / 2});
      // Side wall (at x0 + room) with a doorway, except at the outer edge which is closed.
      const double sx = x0 + room;
      if (col + 1 < columns) {
        const double dz = z0 + 1.0 + rnd() * (room - 2.0 - door);
        Builder::box(w, {sx - wall / 2, 0, z0}, {sx + wall / 2, height, dz});
        Builder::box(w, {sx - wall / 2, 0, dz + door}, {sx + wall / 2, height, z1});
        Builder::box(w, {sx - wall / 2, door_h, dz}, {sx + wall / 2, height, dz + door});
      } else {
        Builder::box(w, {sx - wall / 2, 0, z0}, {sx + wall / 2, height, z1});
      }
      if (col == 0) Builder::box(w, {x0 - wall / 2, 0, z0}, {x0 + wall / 2, height, z1});
      // Furniture: two desks with legs and chairs, a cabinet.
      for (int d = 0; d < 2; ++d) {
        const double cx = x0 + 2.0 + d * 3.5 + rnd() * 0.5, cz = z0 + 2.5 + rnd() * 3.0;
        MeshPrimitive& desk = b.prim(n, desk_m);
        Builder::box(desk, {cx - 0.8, 0.72, cz - 0.4}, {cx + 0.8, 0.78, cz + 0.4});
        for (int leg = 0; leg < 4; ++leg) {
          const double lx = cx + ((leg & 1) ? 0.72 : -0.78), lz = cz + ((leg & 2) ? 0.32 : -0.38);
          Builder::box(desk, {lx, 0, lz}, {lx + 0.06, 0.72, lz + 0.06});
        }
        MeshPrimitive& chair = b.prim(n, chair_m);
        Builder::box(chair, {cx - 0.25, 0.42, cz + 0.55}, {cx + 0.25, 0.48, cz + 1.05});
        Builder::box(chair, {cx - 0.25, 0.48, cz + 1.0}, {cx + 0.25, 1.0, cz + 1.06});
        Builder::box(chair, {cx - 0.04, 0, cz + 0.76}, {cx + 0.04, 0.42, cz + 0.84});
      }
      Builder::box(b.prim(n, cabinet_m), {x0 + room - 1.2, 0, z0 + 0.3}, {x0 + room - 0.4, 1.9, z0 + 0.9});
    }
  }
  // Standing in the first row, looking down the rows.
  set_camera(&b.mesh(), {-room / 2 + 1.0, 1.6, -0.5}, {-room / 2 + 1.5, 1.4, -room * layers});
  return b.mesh();
}

SceneMesh make_tessellated_scene(uint32_t min_triangles) {
  Builder b;
  const uint32_t mat = b.material(0.80, 0.45, 0.85);
  const uint32_t root = b.node("torus_knot", kNone);
  const int sides = 32;
  const int segments = std::max(8, int((uint64_t(std::max<uint32_t>(min_triangles, 1)) + 2 * sides - 1) / (2 * sides)));
  const double tube = 0.4;
  // (2,3) torus knot.
  auto curve = [](double t) {
    const double r = 2.0 + std::cos(3 * t);
    return V3{r * std::cos(2 * t), r * std::sin(2 * t), std::sin(3 * t)};
  };
  Builder::grid(b.prim(root, mat), sides, segments, [&](double u, double v, V3* p, V3* n) {
    const double t = v * 2 * kPi, h = 1e-4;
    const V3 c = curve(t);
    const V3 d1 = (curve(t + h) - curve(t - h)) * (1 / (2 * h));
    const V3 d2 = (curve(t + h) - c * 2 + curve(t - h)) * (1 / (h * h));
    const V3 tangent = normalized(d1);
    const V3 binormal = normalized(cross(d1, d2));
    const V3 normal = cross(binormal, tangent);
    const double a = u * 2 * kPi;   // this direction keeps the outside counter-clockwise
    const V3 dir = normal * std::cos(a) + binormal * std::sin(a);
    *n = dir;
    *p = c + dir * tube;
  });
  set_camera(&b.mesh(), {0, 2.5, 9.0}, {0, 0, 0});
  return b.mesh();
}

CompileResult build_default_scene(const CompileOptions& options) { return compile_mesh(make_default_scene(), options); }

// An RGBA8 image of w x h from f(x, y) -> 0xRRGGBB.
template <typename F>
MeshImage make_image(int w, int h, F f) {
  MeshImage image;
  image.width = w;
  image.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint32_t c = f(x, y);
      image.rgba.insert(image.rgba.end(), {uint8_t(c >> 16), uint8_t(c >> 8), uint8_t(c), 255});
    }
  return image;
}

SceneMesh make_banded_scene() {
  Builder b;
  SceneMesh& mesh = b.mesh();
  const uint32_t root = b.node("bands", kNone);
  // Four textures, top band first. Sizes are chosen so that neighbours sum to half of the total:
  // 64x64 RGB565 (8192 B), 64x64 8-colour palette (4112 B), 128x64 grey (4096 B), 128x64 8-colour
  // palette (8208 B). Formats follow from the images under TextureFormatChoice::Auto.
  static const uint32_t kStripes[8] = {0xE6194B, 0x3CB44B, 0xFFE119, 0x4363D8, 0xF58231, 0x911EB4, 0x46F0F0, 0xF032E6};
  mesh.images.push_back(make_image(64, 64, [](int x, int y) {
    const bool check = ((x / 8) + (y / 8)) % 2 == 0;
    return uint32_t(check ? (x * 4) << 16 | (y * 4) << 8 | 0x40 : 0xF0F0F0 - uint32_t(x + y));
  }));
  mesh.images.push_back(make_image(64, 64, [](int x, int y) { return kStripes[((x + y) / 8) % 8]; }));
  mesh.images.push_back(make_image(128, 64, [](int x, int y) {
    const int dx = x - 64, dy = y - 32;
    const uint32_t g = uint32_t(((dx * dx + dy * dy) / 40) % 16) * 17;
    return g << 16 | g << 8 | g;
  }));
  mesh.images.push_back(make_image(128, 64, [](int x, int y) { return kStripes[(x / 16 + (y / 16) * 3) % 8]; }));
  const MeshSampler samplers[4] = {{TextureWrap::Repeat, TextureWrap::Repeat, TextureFilter::Nearest},
                                   {TextureWrap::MirroredRepeat, TextureWrap::MirroredRepeat, TextureFilter::Nearest},
                                   {TextureWrap::ClampToEdge, TextureWrap::ClampToEdge, TextureFilter::Nearest},
                                   {TextureWrap::Repeat, TextureWrap::Repeat, TextureFilter::Bilinear}};
  // Bands 1.0 high with 0.12 of overlap; odd bands sit slightly in front so the overlap is decided.
  const double repeat_u[4] = {3, 2.5, 1.3, 2}, repeat_v[4] = {0.75, 0.6, 1.2, 0.5};
  for (int k = 0; k < 4; ++k) {
    mesh.texture_images.push_back(uint32_t(k));
    mesh.texture_samplers.push_back(samplers[k]);
    const uint32_t m = b.material(1.0, 1.0, 1.0);
    mesh.materials[m].texture = uint32_t(k);
    MeshPrimitive& p = b.prim(b.node("band" + std::to_string(k), root), m);
    const double top = 2.0 - k * 1.0 + 0.06, bottom = top - 1.12, z = (k % 2) * 0.05, x0 = -2.6, x1 = 2.6;
    const V3 n{0, 0, 1};
    const double ru = repeat_u[k], rv = repeat_v[k];
    // Texture coordinates start a little left of and above 0 so that wrap modes matter.
    const uint32_t i0 = Builder::vertex(p, {x0, bottom, z}, n, -0.25, rv);
    const uint32_t i1 = Builder::vertex(p, {x1, bottom, z}, n, ru, rv);
    const uint32_t i2 = Builder::vertex(p, {x1, top, z}, n, ru, -0.2);
    const uint32_t i3 = Builder::vertex(p, {x0, top, z}, n, -0.25, -0.2);
    p.triangles.push_back({i0, i1, i2});
    p.triangles.push_back({i0, i2, i3});
  }
  set_camera(&mesh, {0.4, 0.3, 5.6}, {0, 0, 0});
  return std::move(mesh);
}

CompileResult build_banded_scene(const CompileOptions& options) {
  return compile_mesh(make_banded_scene(), options);
}

CompileResult build_office_scene(int layers, const CompileOptions& options) {
  return compile_mesh(make_office_scene(layers), options);
}

CompileResult build_tessellated_scene(uint32_t min_triangles, const CompileOptions& options) {
  return compile_mesh(make_tessellated_scene(min_triangles), options);
}

}  // namespace ml
