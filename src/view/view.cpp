#include "view/view.h"

#include "core/build.h"

namespace ml {
namespace {

Vec3i cross_q30(const Vec3i& a, const Vec3i& b) {
  // Both inputs Q1.30 unit vectors: each product < 2^60, the result Q1.30.
  return Vec3i{int32_t(shift_round(int64_t(a.y) * b.z - int64_t(a.z) * b.y, kUnitBits)),
               int32_t(shift_round(int64_t(a.z) * b.x - int64_t(a.x) * b.z, kUnitBits)),
               int32_t(shift_round(int64_t(a.x) * b.y - int64_t(a.y) * b.x, kUnitBits))};
}

bool in_world_range(const Vec3i& v) {
  return abs32(v.x) < kWorldLimit && abs32(v.y) < kWorldLimit && abs32(v.z) < kWorldLimit;
}

// A vertex during clipping: view-space position plus barycentric weights of the original triangle.
struct ClipVertex {
  Vec3i p;
  int32_t weight[3];
};

// Signed distance of a view-space point to one clip plane (>= 0 inside), int64 (< 2^58).
enum ClipPlane { kNear, kLeft, kRight, kTop, kBottom, kPlaneCount };

int64_t plane_distance(const View& view, ClipPlane plane, const Vec3i& p) {
  const int64_t guard = int64_t(kGuardBandPixels) << kSubpixelBits;  // subpixels from the centre
  switch (plane) {
    case kNear: return int64_t(p.z) - view.near;
    case kLeft: return guard * p.z + view.focal_q8 * p.x;
    case kRight: return guard * p.z - view.focal_q8 * p.x;
    case kTop: return guard * p.z + view.focal_q8 * p.y;
    default: return guard * p.z - view.focal_q8 * p.y;
  }
}

// Lexicographic order on positions: intersections are computed from the smaller endpoint so both
// triangles sharing an edge produce the same point.
bool position_less(const Vec3i& a, const Vec3i& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

ClipVertex intersect(const View& view, ClipPlane plane, const ClipVertex& in_a, const ClipVertex& in_b) {
  const bool swap = position_less(in_b.p, in_a.p);
  const ClipVertex& a = swap ? in_b : in_a;
  const ClipVertex& b = swap ? in_a : in_b;
  int64_t num = plane_distance(view, plane, a.p);
  int64_t den = num - plane_distance(view, plane, b.p);  // signs differ, so |den| >= |num| and den != 0
  // Keep den below 2^31 so that num << 30 fits; t = num / den in Q1.30, within [0, 1]. Endpoint
  // differences are below 2^31, so (b - a) * t stays below 2^61.
  while (abs64(den) >= (int64_t(1) << 31)) { num /= 2; den /= 2; }
  const int64_t t = div_round(shift_left(num, kUnitBits), den);
  ClipVertex out;
  out.p.x = int32_t(a.p.x + mul_shift(int64_t(b.p.x) - a.p.x, t, kUnitBits));
  out.p.y = int32_t(a.p.y + mul_shift(int64_t(b.p.y) - a.p.y, t, kUnitBits));
  out.p.z = int32_t(a.p.z + mul_shift(int64_t(b.p.z) - a.p.z, t, kUnitBits));
  if (plane == kNear) out.p.z = view.near;  // exactly on the plane, never a hair behind it
  for (int k = 0; k < 3; ++k)
    out.weight[k] = int32_t(a.weight[k] + mul_shift(int64_t(b.weight[k]) - a.weight[k], t, kUnitBits));
  return out;
}

// Sutherland–Hodgman against one plane. Polygons have at most 3 + kPlaneCount vertices.
constexpr int kMaxPolygon = 3 + kPlaneCount;

int clip_polygon(const View& view, ClipPlane plane, const ClipVertex* in, int count, ClipVertex* out) {
  int n = 0;
  for (int i = 0; i < count; ++i) {
    const ClipVertex& cur = in[i];
    const ClipVertex& next = in[(i + 1) % count];
    const bool cur_in = plane_distance(view, plane, cur.p) >= 0;
    const bool next_in = plane_distance(view, plane, next.p) >= 0;
    if (cur_in) out[n++] = cur;
    if (cur_in != next_in) out[n++] = intersect(view, plane, cur, next);
  }
  return n;
}

// Screen position offset from the centre, in subpixels, before any range check (|result| < 2^57).
// z > 0 (in front): a divisor below 2^31, so no 64-bit division on a 32-bit board (core/fixed.h).
inline int64_t project_offset(const View& view, int32_t c, int32_t z) {
  // div_round with the divisor's sign known: rounds the magnitude, then restores the sign.
  const int64_t n = view.focal_q8 * c;
  const uint64_t q = udiv64(magnitude(n) + uint32_t(z) / 2, uint32_t(z));
  return n < 0 ? -int64_t(q) : int64_t(q);
}

// |v| <= limit, as one unsigned comparison (limit < 2^62).
inline bool within(int64_t v, int64_t limit) { return uint64_t(v + limit) <= uint64_t(2 * limit); }

void set_screen_vertex(const View& view, int32_t z, const int32_t weight[3], int64_t offset_x, int64_t offset_y,
                       bool depth, ScreenVertex* s) {
  s->x = int32_t(view.center_x + offset_x);
  s->y = int32_t(view.center_y + offset_y);
  s->z = z;
  s->depth = depth ? uint32_t(udiv64(uint64_t(view.near) << kDepthBits, uint64_t(z))) : 0;
  ML_HOST_UNROLL for (int k = 0; k < 3; ++k) s->weight[k] = weight[k];
}

ScreenVertex make_screen_vertex(const View& view, const ClipVertex& c, int64_t offset_x, int64_t offset_y,
                                bool depth) {
  ScreenVertex s;
  set_screen_vertex(view, c.p.z, c.weight, offset_x, offset_y, depth, &s);
  return s;
}

ScreenVertex project(const View& view, const ClipVertex& c, bool depth) {
  return make_screen_vertex(view, c, project_offset(view, c.p.x, c.p.z), project_offset(view, c.p.y, c.p.z), depth);
}

int64_t signed_area2(const ScreenVertex& a, const ScreenVertex& b, const ScreenVertex& c) {
  return (int64_t(b.x) - a.x) * (int64_t(c.y) - a.y) - (int64_t(c.x) - a.x) * (int64_t(b.y) - a.y);
}

}  // namespace

Status make_view(const Camera& camera, View* out) {
  if (camera.width < 1 || camera.height < 1 || camera.width > kMaxScreenDim || camera.height > kMaxScreenDim)
    return error(StatusCode::InvalidArgument, "screen size must be 1..4096 per side");
  if (camera.fov_deg_q16 < (1 << kAngleBits) || camera.fov_deg_q16 > (170 << kAngleBits))
    return error(StatusCode::InvalidArgument, "field of view must be 1..170 degrees");
  if (camera.near <= 0 || camera.near >= (1 << (kViewLimitBits - kViewFractionBits)))
    return error(StatusCode::InvalidArgument, "near plane must be positive and below 2^26 world units");
  if (camera.sample_shift_x <= -kSubpixelOne || camera.sample_shift_x >= kSubpixelOne ||
      camera.sample_shift_y <= -kSubpixelOne || camera.sample_shift_y >= kSubpixelOne)
    return error(StatusCode::InvalidArgument, "sample shift must be less than a pixel");
  if (!in_world_range(camera.eye) || !in_world_range(camera.target))
    return error(StatusCode::InvalidArgument, "camera eye or target outside the world range");
  const Vec3i look{camera.target.x - camera.eye.x, camera.target.y - camera.eye.y, camera.target.z - camera.eye.z};
  View v;
  if (!normalize_q30(look, &v.forward))
    return error(StatusCode::InvalidArgument, "camera target equals eye");
  Vec3i up;
  if (!normalize_q30(camera.up, &up)) return error(StatusCode::InvalidArgument, "camera up is zero");
  const Vec3i side = cross_q30(v.forward, up);
  // |side| = sin(angle between forward and up); below ~0.001 the basis would be meaningless.
  if (dot64(side, side) < (int64_t(1) << 40))
    return error(StatusCode::InvalidArgument, "camera up is parallel to the view direction");
  normalize_q30(side, &v.right);
  normalize_q30(cross_q30(v.forward, v.right), &v.down);
  v.eye = camera.eye;
  v.near = camera.near << kViewFractionBits;
  const int64_t tan_half = tan_deg_q16(camera.fov_deg_q16 / 2);
  // focal length (pixels) = (height / 2) / tan(fov / 2); in 1/256 pixel.
  v.focal_q8 = div_round((int64_t(camera.height) << (kSubpixelBits - 1)) << kAngleBits, tan_half);
  v.center_x = (camera.width << (kSubpixelBits - 1)) - camera.sample_shift_x;
  v.center_y = (camera.height << (kSubpixelBits - 1)) - camera.sample_shift_y;
  v.width = camera.width;
  v.height = camera.height;
  *out = v;
  return ok_status();
}

Camera frame_sphere(const Vec3i& center, int32_t radius, int width, int height, int32_t fov_deg_q16) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fov_deg_q16 = fov_deg_q16;
  // The narrower of the two half-angles must hold the sphere: tan_h = tan_v * min(1, width / height).
  int64_t tan_half = tan_deg_q16(fov_deg_q16 / 2);
  if (width < height) tan_half = tan_half * width / height;
  if (tan_half < 1) tan_half = 1;
  // sin = tan / sqrt(1 + tan^2), Q16.
  const int64_t sin_half = div_round(tan_half << 16, int64_t(isqrt64(uint64_t((int64_t(1) << 32) + tan_half * tan_half))));
  int64_t distance = div_round(int64_t(radius) * 69 * 1024, max_of<int64_t>(sin_half, 1));  // 1.05 * r / sin
  // A very narrow image (1x4096) would put the eye hundreds of radii away, outside the world range:
  // stop at its edge (|eye| <= |centre| + distance on each axis). The image then shows a slice of the
  // sphere instead of all of it.
  const int64_t center_max = max_of<int64_t>(abs64(center.x), max_of<int64_t>(abs64(center.y), abs64(center.z)));
  distance = max_of<int64_t>(1, min_of<int64_t>(distance, int64_t(kWorldLimit) - 2 - center_max));
  // A three-quarter view from the front, right and above (glTF: +y up, models face +z).
  Vec3i dir;
  normalize_q30(Vec3i{5, 3, 8}, &dir);
  c.eye = Vec3i{int32_t(center.x + mul_shift(dir.x, distance, kUnitBits)),
                int32_t(center.y + mul_shift(dir.y, distance, kUnitBits)),
                int32_t(center.z + mul_shift(dir.z, distance, kUnitBits))};
  c.target = center;
  c.up = Vec3i{0, 1, 0};
  c.near = int32_t(max_of<int64_t>(16, (distance - radius) / 2));
  return c;
}

namespace {

// Orders a projected triangle so that area2 > 0. False when degenerate after snapping. (Facing is
// not read from the sign: snapping can flip a sliver, and facing must not depend on snapping.)
bool orient(ScreenTriangle* t) {
  const int64_t area2 = signed_area2(t->v[0], t->v[1], t->v[2]);
  if (area2 == 0) return false;
  if (area2 < 0) {
    const ScreenVertex tmp = t->v[1];
    t->v[1] = t->v[2];
    t->v[2] = tmp;
  }
  t->area2 = abs64(area2);
  return true;
}

}  // namespace

int triangle_facing(const View& view, const Vec3i world[3]) {
  // Edges and eye offset are below 2^25 (world points below 2^24), the cross product below 2^51 and
  // the triple product below 2^78: too wide for int64. Split each cross component c into
  // hi * 2^24 + lo with lo in [0, 2^24); the two partial dot products stay below 2^54.
  // The differences fit 32 bits (|world| < 2^24), so the cross products are 32-by-32-bit multiplies
  // (one instruction each on a Cortex-M3, where a 64-by-64-bit one takes three).
  const int32_t e1[3] = {world[1].x - world[0].x, world[1].y - world[0].y, world[1].z - world[0].z};
  const int32_t e2[3] = {world[2].x - world[0].x, world[2].y - world[0].y, world[2].z - world[0].z};
  const int32_t r[3] = {view.eye.x - world[0].x, view.eye.y - world[0].y, view.eye.z - world[0].z};
  auto mul = [](int32_t a, int32_t b) { return int64_t(a) * b; };
  const int64_t cross[3] = {mul(e1[1], e2[2]) - mul(e1[2], e2[1]), mul(e1[2], e2[0]) - mul(e1[0], e2[2]),
                            mul(e1[0], e2[1]) - mul(e1[1], e2[0])};
  // The common case (triangles small against the world, eye not too far): every product is below
  // 2^61 and the plain sum fits.
  constexpr int64_t c_limit = (int64_t(1) << 36) - 1, r_limit = (int64_t(1) << 25) - 1;
  if (within(cross[0], c_limit) && within(cross[1], c_limit) && within(cross[2], c_limit) &&
      within(r[0], r_limit) && within(r[1], r_limit) && within(r[2], r_limit)) {
    const int64_t det = cross[0] * r[0] + cross[1] * r[1] + cross[2] * r[2];
    return det > 0 ? 1 : (det < 0 ? -1 : 0);
  }
  constexpr int kLoBits = 24;
  int64_t hi = 0, lo = 0;
  for (int k = 0; k < 3; ++k) {
    const int64_t c_hi = div_floor(cross[k], int64_t(1) << kLoBits);
    const int64_t c_lo = cross[k] - shift_left(c_hi, kLoBits);
    hi += c_hi * r[k];
    lo += c_lo * r[k];
  }
  // Move lo's multiples of 2^24 into hi so that lo is in [0, 2^24): then hi decides the sign unless
  // it is zero.
  const int64_t carry = div_floor(lo, int64_t(1) << kLoBits);
  hi += carry;
  lo -= shift_left(carry, kLoBits);
  if (hi != 0) return hi > 0 ? 1 : -1;
  return lo > 0 ? 1 : 0;
}

int project_triangle(const View& view, const Vec3i world[3], ScreenTriangle out[kMaxClipTriangles]) {
  return project_triangle(view, world, triangle_facing(view, world), out);
}

namespace {

// A vertex in front of the near plane that projects inside the guard band: nothing to clip there.
// (A vertex this keeps but the clip planes would cut lies on the guard band, thousands of pixels off
// screen, so the two tests cannot disagree on any visible sample.) Offsets kViewVertexClipped
// otherwise. Inline in view_triangle's loop, writing straight into its ViewTriangle.
[[gnu::always_inline]] inline bool transform_vertex(const View& view, const Vec3i& world, Vec3i* p, int64_t* ox,
                                                    int64_t* oy) {
  *p = Vec3i{view_coordinate(view, view.right, world), view_coordinate(view, view.down, world),
             view_coordinate(view, view.forward, world)};
  *ox = *oy = kViewVertexClipped;
  if (p->z < view.near) return false;
  const int64_t guard = int64_t(kGuardBandPixels) << kSubpixelBits;
  const int64_t x = project_offset(view, p->x, p->z), y = project_offset(view, p->y, p->z);
  if (!within(x, guard) || !within(y, guard)) return false;
  *ox = x;
  *oy = y;
  return true;
}

}  // namespace

void view_vertex(const View& view, const Vec3i& world, ViewVertex* out) {
  int64_t ox, oy;
  transform_vertex(view, world, &out->p, &ox, &oy);
  out->ox = int32_t(ox);  // within the guard band, or kViewVertexClipped
  out->oy = int32_t(oy);
}

// Unclipped when all three vertices are: the common case.
void view_triangle(const View& view, const Vec3i world[3], ViewTriangle* out) {
  bool unclipped = true;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i)
    if (!transform_vertex(view, world[i], &out->p[i], &out->ox[i], &out->oy[i])) unclipped = false;
  out->unclipped = unclipped;
}

int project_triangle(const View& view, const Vec3i world[3], int facing, ScreenTriangle out[kMaxClipTriangles],
                     bool depths) {
  if (facing == 0) return 0;  // seen edge-on: covers nothing
  ViewTriangle t;
  view_triangle(view, world, &t);
  return project_triangle(view, t, facing, out, depths);
}

int project_triangle(const View& view, const ViewTriangle& tri, int facing, ScreenTriangle out[kMaxClipTriangles],
                     bool depths) {
  if (facing == 0) return 0;  // seen edge-on: covers nothing
  static constexpr int32_t kVertexWeights[3][3] = {{kWeightOne, 0, 0}, {0, kWeightOne, 0}, {0, 0, kWeightOne}};
  if (tri.unclipped) {  // straight into the output: no clip polygon
    ML_HOST_UNROLL for (int i = 0; i < 3; ++i)
      set_screen_vertex(view, tri.p[i].z, kVertexWeights[i], tri.ox[i], tri.oy[i], depths, &out[0].v[i]);
    out[0].front_facing = facing > 0;
    return orient(&out[0]) ? 1 : 0;
  }
  ClipVertex buffers[2][kMaxPolygon];
  ClipVertex* poly = buffers[0];
  for (int i = 0; i < 3; ++i) {
    poly[i].p = tri.p[i];
    for (int k = 0; k < 3; ++k) poly[i].weight[k] = kVertexWeights[i][k];
  }

  int count = 3;
  for (int plane = 0; plane < kPlaneCount && count > 0; ++plane) {
    int inside = 0;
    for (int i = 0; i < count; ++i) inside += plane_distance(view, ClipPlane(plane), poly[i].p) >= 0;
    if (inside == count) continue;
    ClipVertex* next = (poly == buffers[0]) ? buffers[1] : buffers[0];
    count = inside == 0 ? 0 : clip_polygon(view, ClipPlane(plane), poly, count, next);
    poly = next;
  }
  if (count < 3) return 0;

  ScreenVertex projected[kMaxPolygon];
  for (int i = 0; i < count; ++i) projected[i] = project(view, poly[i], depths);

  int n = 0;
  for (int i = 1; i + 1 < count; ++i) {
    ScreenTriangle& t = out[n];
    t.v[0] = projected[0];
    t.v[1] = projected[i];
    t.v[2] = projected[i + 1];
    t.front_facing = facing > 0;
    if (orient(&t)) ++n;
  }
  return n;
}

namespace {

// view_outside_rows, inline in both its entries (the boards link only triangle_outside_rows).
inline bool outside_rows(const View& view, const Vec3i p[3], int32_t row0, int32_t row1) {
  // Vertex i projects to y_i = center_y + focal y / z (before rounding by at most half a subpixel).
  // Above the band: every y_i < row0 * 256, so no sample centre (row0 * 256 + 128 and below) is
  // reached; below: every y_i > (row1 + 1) * 256. Compared as focal y + (center_y - limit) z, z > 0:
  // |focal y| < 2^57 and |(center_y - limit) z| < 2^53, so nothing overflows.
  const int64_t top = int64_t(view.center_y) - int64_t(row0) * kSubpixelOne;
  const int64_t bottom = int64_t(view.center_y) - (int64_t(row1) + 1) * kSubpixelOne;
  bool above = true, below = true;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    const int64_t z = p[i].z;
    if (z < view.near) return false;  // clipped: the projection is not the vertices' hull
    const int64_t fy = view.focal_q8 * p[i].y;
    above = above && fy + top * z < 0;
    below = below && fy + bottom * z > 0;
  }
  return above || below;
}

// The view-space depth and height of a world triangle's vertices (x left 0), as far as the row tests
// read them: false when a vertex lies behind the near plane (then neither test rules anything out).
inline bool view_rows_of(const View& view, const Vec3i world[3], Vec3i p[3]) {
  for (int i = 0; i < 3; ++i) {
    p[i].x = 0;
    p[i].z = view_coordinate(view, view.forward, world[i]);
    if (p[i].z < view.near) return false;
    p[i].y = view_coordinate(view, view.down, world[i]);
  }
  return true;
}

}  // namespace

bool view_outside_rows(const View& view, const Vec3i p[3], int32_t row0, int32_t row1) {
  return outside_rows(view, p, row0, row1);
}

bool triangle_outside_rows(const View& view, const Vec3i world[3], int32_t row0, int32_t row1) {
  Vec3i p[3];
  return view_rows_of(view, world, p) && outside_rows(view, p, row0, row1);
}

bool view_row_span(const View& view, const Vec3i p[3], int64_t* first, int64_t* last) {
  // Vertex i lies at Y_i = center_y + focal y_i / z_i subpixels (exactly, before rounding). The band
  // test calls the triangle above row0 when every Y_i < row0 * 256, i.e. floor(max Y) < row0 * 256, and
  // below row1 when every Y_i > (row1 + 1) * 256, i.e. ceil(min Y) - 1 >= (row1 + 1) * 256. z_i is
  // below 2^31: one 64-by-32-bit division a vertex (core/fixed.h).
  int64_t floor_max = INT64_MIN, ceil_min = INT64_MAX;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    const int64_t z = p[i].z;
    if (z < view.near) return false;
    const int64_t fy = view.focal_q8 * p[i].y;
    const int64_t q = div_floor(fy, z);
    floor_max = max_of(floor_max, view.center_y + q);
    ceil_min = min_of(ceil_min, view.center_y + q + (q * z != fy ? 1 : 0));
  }
  *last = floor_shift(floor_max, kSubpixelBits);
  *first = floor_shift(ceil_min - 1, kSubpixelBits);
  return true;
}

bool triangle_row_span(const View& view, const Vec3i world[3], int64_t* first, int64_t* last) {
  Vec3i p[3];
  return view_rows_of(view, world, p) && view_row_span(view, p, first, last);
}

void setup_triangle(const ScreenTriangle& tri, int width, int height, TriangleSetup* out) {
  int32_t min_x = tri.v[0].x, max_x = tri.v[0].x, min_y = tri.v[0].y, max_y = tri.v[0].y;
  for (int i = 0; i < 3; ++i) {
    const ScreenVertex& p = tri.v[i];
    const ScreenVertex& q = tri.v[(i + 1) % 3];
    out->edge[i] = edge_function(p.x, p.y, q.x, q.y);
    min_x = min_of(min_x, p.x); max_x = max_of(max_x, p.x);
    min_y = min_of(min_y, p.y); max_y = max_of(max_y, p.y);
  }
  // Pixel centres px*256+128 inside [min, max]: px >= ceil((min-128)/256), px <= floor((max-128)/256).
  // Floors by 256 as arithmetic shifts (no division helper on a 32-bit board).
  out->min_x = int32_t(max_of<int64_t>(0, -floor_shift(-(int64_t(min_x) - kSubpixelHalf), kSubpixelBits)));
  out->min_y = int32_t(max_of<int64_t>(0, -floor_shift(-(int64_t(min_y) - kSubpixelHalf), kSubpixelBits)));
  out->max_x = int32_t(min_of<int64_t>(width - 1, floor_shift(int64_t(max_x) - kSubpixelHalf, kSubpixelBits)));
  out->max_y = int32_t(min_of<int64_t>(height - 1, floor_shift(int64_t(max_y) - kSubpixelHalf, kSubpixelBits)));
}

}  // namespace ml
