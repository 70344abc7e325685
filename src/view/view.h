// The view pipeline: camera → view space → near-plane and guard-band clipping → screen coordinates
// with subpixel precision → integer edge functions with the top-left fill rule.
//
// Conventions (written down once, here):
// - Screen: pixel (x, y) covers [x, x+1) x [y, y+1), x to the right, y downwards. Screen coordinates
//   are in subpixels (1/256 pixel, core/fixed.h). A point-sampled pixel samples its centre,
//   (x * 256 + 128, y * 256 + 128).
// - View space: x right, y down, z forward (away from the eye), in 1/16 world unit (kViewFractionBits).
// - Orientation: glTF front faces are counter-clockwise seen from the front. Whether a triangle
//   faces the eye is decided once, exactly, in world space (triangle_facing: the side of the
//   triangle's plane the eye is on), never from snapped screen coordinates, so every renderer culls
//   the same triangles and can do so before projecting. After projection a triangle is handed on with
//   its vertices ordered so that area2 > 0 (y-down screen), i.e. all edge functions are positive
//   inside.
// - Edge function of the edge P→Q: E(p) = (Q.x-P.x)(p.y-P.y) - (Q.y-P.y)(p.x-P.x) = a p.x + b p.y + c.
// - Fill rule (top-left): a sample exactly on an edge (E == 0) is covered only if the edge is a left
//   edge (a > 0) or a top edge (a == 0 and b > 0). EdgeFunction::c has the rule folded in (it is one
//   smaller for edges that are neither), so "covered" is simply E >= 0 for all three edges. Two
//   triangles sharing an edge therefore never both cover a sample on it, and never both miss one.
#pragma once
#include <stdint.h>

#include "core/build.h"
#include "core/fixed.h"
#include "core/status.h"

namespace ml {

struct Camera {
  Vec3i eye{0, 0, 0};           // world units, |c| < kWorldLimit
  Vec3i target{0, 0, -1};       // world units, != eye
  Vec3i up{0, 1, 0};            // any length, not parallel to target - eye
  int32_t fov_deg_q16 = 45 << 16;  // vertical field of view, [1, 170] degrees
  int32_t near = 1;             // near plane distance, world units, > 0
  int width = 0, height = 0;    // screen in pixels (or samples, when a renderer oversamples), 1..kMaxScreenDim
  // Where a pixel samples the scene: subpixel (256 px + 128 + sample_shift_x, ...) of the unshifted
  // picture, |shift| < 256 (the screen moves by whole subpixels after projection, so coverage is the
  // unshifted edge functions' at the shifted point exactly). A renderer at one sample a pixel draws
  // any one sample of a pattern this way (core/jitter.h).
  int32_t sample_shift_x = 0, sample_shift_y = 0;
};

struct View {
  Vec3i eye;
  Vec3i right, down, forward;   // Q1.30 rows of the world→view rotation
  int32_t near;                 // view units (1/16 world unit)
  int64_t focal_q8;             // focal length in 1/256 pixel per unit of x/z
  int32_t center_x, center_y;   // screen centre in subpixels
  int width, height;
};

// Builds the view; InvalidArgument for an out-of-range camera (message says which field).
Status make_view(const Camera& camera, View* out);

// A camera that frames a bounding sphere (world units) from a pleasant three-quarter view.
Camera frame_sphere(const Vec3i& center, int32_t radius, int width, int height, int32_t fov_deg_q16);

struct ScreenVertex {
  int32_t x, y;       // subpixels
  int32_t z;          // view-space depth, view units (1/16 world unit), >= near
  uint32_t depth;     // near * 2^30 / z (core/fixed.h), larger = nearer
  int32_t weight[3];  // barycentric weights Q16 with respect to the original triangle's vertices 0,1,2
};

struct ScreenTriangle {
  ScreenVertex v[3];  // ordered so that area2 > 0
  int64_t area2;      // twice the signed area, subpixels^2, > 0
  bool front_facing;  // triangle_facing() of the input triangle was +1
};

// Most triangles one input triangle becomes after clipping (near plane + four guard-band planes).
constexpr int kMaxClipTriangles = 6;

// +1 when the eye is on the front side of the world-space triangle's plane (the triangle is
// counter-clockwise seen from the eye), -1 on the back side, 0 in the plane or degenerate. Exact:
// the sign of the triple product (v1 - v0) x (v2 - v0) . (eye - v0) in integer arithmetic.
int triangle_facing(const View& view, const Vec3i world[3]);

// Transforms a world-space triangle, clips it, projects it and orders it. Writes up to
// kMaxClipTriangles triangles to out and returns how many. Triangles wholly behind the near plane,
// outside the guard band, seen edge-on (facing 0) or degenerate after snapping (area2 == 0) give 0.
// Back faces are returned with front_facing == false: culling is the caller's choice (it depends on
// the material); callers that cull can call triangle_facing first and skip the projection.
// Intersection points are computed from the edge's endpoints in a canonical order, so two triangles
// sharing an edge get identical clipped vertices (watertight).
int project_triangle(const View& view, const Vec3i world[3], ScreenTriangle out[kMaxClipTriangles]);

// The same with the facing already known: triangle_facing() of this triangle, or of the triangle it
// is a piece of (BSP pieces take their original triangle's facing). depths == false leaves every
// ScreenVertex::depth 0 and saves its division per vertex (the tiler never reads depths).
int project_triangle(const View& view, const Vec3i world[3], int facing, ScreenTriangle out[kMaxClipTriangles],
                     bool depths = true);

// One world point in view space and, when it lies in front of the near plane and projects inside the
// guard band, its screen offset from the centre (subpixels) exactly as project_triangle rounds it:
// what view_triangle works out for each vertex, on its own, so that a vertex several triangles share
// can be transformed once (view/vertex_cache.h).
struct ViewVertex {
  Vec3i p;                  // view space, 1/16 world unit
  int32_t ox, oy;           // |ox|, |oy| <= the guard band (2^21 subpixels); ox == kViewVertexClipped otherwise
};
constexpr int32_t kViewVertexClipped = INT32_MIN;
void view_vertex(const View& view, const Vec3i& world, ViewVertex* out);

// A world triangle in view space, each vertex transformed once, and, when project_triangle would not
// clip it (every vertex in front of the near plane and inside the guard band), its vertices' screen
// offsets from the centre (subpixels) exactly as project_triangle rounds them. A caller that first
// looks at where a triangle lands (a band plan, a row test) and then projects it pays for one
// transform.
struct ViewTriangle {
  Vec3i p[3];               // view space, 1/16 world unit
  int64_t ox[3], oy[3];     // valid when unclipped
  bool unclipped;
};
void view_triangle(const View& view, const Vec3i world[3], ViewTriangle* out);

// Vertex i of a ViewTriangle from its view_vertex; true when it lies unclipped (the triangle's
// `unclipped` is the three answers together). A caller holding the vertices' view_vertex builds
// view_triangle's ViewTriangle this way.
inline bool put_view_vertex(const ViewVertex& v, int i, ViewTriangle* out) {
  out->p[i] = v.p;
  out->ox[i] = v.ox;
  out->oy[i] = v.oy;
  return v.ox != kViewVertexClipped;
}

// project_triangle of the world triangle that view_triangle transformed.
int project_triangle(const View& view, const ViewTriangle& tri, int facing, ScreenTriangle out[kMaxClipTriangles],
                     bool depths = true);

// The screen positions (subpixels) project_triangle gives a triangle it does not clip (t.unclipped),
// before it orders them (area2 > 0) and without depths or weights: a cheap first look for callers that
// may drop the triangle.
inline void unclipped_positions(const View& view, const ViewTriangle& t, int32_t x[3], int32_t y[3]) {
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    x[i] = int32_t(view.center_x + t.ox[i]);
    y[i] = int32_t(view.center_y + t.oy[i]);
  }
}

// One view-space coordinate (1/16 world unit) of a world point: the world→view row `axis` (Q1.30)
// dotted with the offset from the eye. |offset| < 2^25, so the dot product stays below 2^56. Rounds
// half up (an arithmetic shift of the biased value): cheaper than symmetric rounding, as exact.
inline int32_t view_coordinate(const View& view, const Vec3i& axis, const Vec3i& world) {
  constexpr int shift = kUnitBits - kViewFractionBits;
  constexpr int64_t half = int64_t(1) << (shift - 1);
  const Vec3i d{world.x - view.eye.x, world.y - view.eye.y, world.z - view.eye.z};
  return int32_t((dot64(axis, d) + half) >> shift);
}

// True when the triangle certainly covers no sample centre in pixel rows row0..row1: all three
// vertices lie in front of the near plane and project above row0 or below row1 (with a pixel of
// margin for rounding). Costs six dot products and no division: the band renderer rejects pieces
// outside its band with it before projecting them. False when unsure.
bool triangle_outside_rows(const View& view, const Vec3i world[3], int32_t row0, int32_t row1);
// The same from the triangle's view-space points (ViewTriangle::p): no dot product at all.
bool view_outside_rows(const View& view, const Vec3i p[3], int32_t row0, int32_t row1);

// The rows triangle_outside_rows keeps, worked out once: false when a vertex lies behind the near
// plane (then no row can be ruled out); otherwise triangle_outside_rows(view, world, row0, row1) is
// exactly row1 < *first || row0 > *last (first > last when no row is kept). One division per vertex
// instead of six dot products per band: a renderer that visits a triangle in many bands asks once.
bool triangle_row_span(const View& view, const Vec3i world[3], int64_t* first, int64_t* last);
// The same from the triangle's view-space points (ViewTriangle::p).
bool view_row_span(const View& view, const Vec3i p[3], int64_t* first, int64_t* last);

// The fill rule for an edge with E(x, y) = a x + b y + c: samples exactly on it are covered only if it
// is a left edge (a > 0) or a top edge (a == 0, b > 0).
inline bool is_top_left(int64_t a, int64_t b) { return a > 0 || (a == 0 && b > 0); }

struct EdgeFunction {
  int64_t a, b, c;    // E(x, y) = a x + b y + c, x and y in subpixels, fill rule folded into c
  int64_t at(int64_t x, int64_t y) const { return a * x + b * y + c; }
};

// The edge P -> Q (subpixels) as a plane without the fill rule: a = P.y - Q.y, b = Q.x - P.x,
// c = -(a P.x + b P.y), zero on the edge; over a triangle's doubled area it is the barycentric weight of
// the opposite vertex. |a|, |b| < 2^23 and |c| < 2^46 inside the guard band.
inline EdgeFunction edge_plane(int32_t px, int32_t py, int32_t qx, int32_t qy) {
  EdgeFunction e;
  e.a = int64_t(py) - qy;
  e.b = int64_t(qx) - px;
  e.c = -(e.a * px + e.b * py);
  return e;
}

// The edge function of coverage: edge_plane with c one smaller when the edge is not top-left (fill rule
// above). The one derivation every renderer uses.
inline EdgeFunction edge_function(int32_t px, int32_t py, int32_t qx, int32_t qy) {
  EdgeFunction e = edge_plane(px, py, qx, qy);
  if (!is_top_left(e.a, e.b)) e.c -= 1;  // E == 0 on this edge is outside
  return e;
}

struct TriangleSetup {
  EdgeFunction edge[3];
  // Pixel bounding box of the samples that can be covered, clipped to the screen, inclusive.
  // Empty (min > max) when no pixel centre can be covered.
  int32_t min_x, min_y, max_x, max_y;
};

// Edge functions and bounding box of a projected triangle on a width x height screen.
void setup_triangle(const ScreenTriangle& tri, int width, int height, TriangleSetup* out);

inline bool covers_point(const TriangleSetup& s, int64_t x, int64_t y) {
  return s.edge[0].at(x, y) >= 0 && s.edge[1].at(x, y) >= 0 && s.edge[2].at(x, y) >= 0;
}

// Whether the triangle covers the centre of pixel (px, py).
inline bool covers_pixel(const TriangleSetup& s, int32_t px, int32_t py) {
  return covers_point(s, int64_t(px) * kSubpixelOne + kSubpixelHalf,
                      int64_t(py) * kSubpixelOne + kSubpixelHalf);
}

}  // namespace ml
