// The procedural scenes: sizes, winding against their normals, determinism, camera hints; prints the
// compile report of each (and of 2CylinderEngine) for the record.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/scene/scene_test_util.h"

using namespace ml;

namespace {

// Fraction of non-degenerate triangles whose geometric normal agrees with their vertex normals.
double winding_agreement(const Scene& s) {
  size_t agree = 0, counted = 0;
  for (uint32_t t = 0; t < s.triangle_count; ++t) {
    Vec3i p[3];
    triangle_world(s, t, p);
    const double ux = p[1].x - p[0].x, uy = p[1].y - p[0].y, uz = p[1].z - p[0].z;
    const double vx = p[2].x - p[0].x, vy = p[2].y - p[0].y, vz = p[2].z - p[0].z;
    const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    if (std::sqrt(nx * nx + ny * ny + nz * nz) < 1.0) continue;
    double sx = 0, sy = 0, sz = 0;
    for (uint32_t v : ml::triangle_at(s, t).v) {
      sx += s.vertices[v].normal[0];
      sy += s.vertices[v].normal[1];
      sz += s.vertices[v].normal[2];
    }
    if (sx == 0 && sy == 0 && sz == 0) continue;
    ++counted;
    if (nx * sx + ny * sy + nz * sz > 0) ++agree;
  }
  return counted ? double(agree) / double(counted) : 0.0;
}

void report(const char* name, const CompileResult& r) {
  std::printf("[   INFO   ] %-12s %7u triangles, %5u nodes, %3u materials, %6u bsp nodes, %7u pieces, "
              "split ratio %.3f, depth %3u, %zu bytes, %.2f s (bsp %.2f s)\n",
              name, r.report.triangles, r.report.nodes, r.report.materials, r.report.bsp_nodes,
              r.report.bsp_pieces, r.report.split_ratio, r.report.bsp_depth, r.report.blob_bytes,
              r.report.seconds, r.report.bsp_seconds);
}

}  // namespace

TEST(SceneProcedural, DefaultScene) {
  const CompileResult& r = scenetest::cached("default");
  ASSERT_TRUE(r.ok) << r.error;
  report("default", r);
  EXPECT_GE(r.report.triangles, 300u);
  EXPECT_LE(r.report.triangles, 5000u);
  EXPECT_GE(r.report.materials, 5u);
  EXPECT_TRUE(r.camera.valid);
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  EXPECT_GT(winding_agreement(s), 0.999);
  // The camera hint looks at the scene from outside it.
  const double d = std::hypot(r.camera.eye[0] - s.info->sphere_center[0], r.camera.eye[1] - s.info->sphere_center[1],
                              r.camera.eye[2] - s.info->sphere_center[2]);
  EXPECT_GT(d, s.info->sphere_radius * 0.8);
}

TEST(SceneProcedural, OfficeScene) {
  const CompileResult& r = scenetest::cached("office8");
  ASSERT_TRUE(r.ok) << r.error;
  report("office(8)", r);
  EXPECT_GE(r.report.triangles, 5000u);
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  EXPECT_GT(winding_agreement(s), 0.999);
  // The camera stands inside the building, looking down the rows.
  ASSERT_TRUE(r.camera.valid);
  for (int a = 0; a < 3; ++a) {
    EXPECT_GT(r.camera.eye[a], s.info->bounds_min[a]);
    EXPECT_LT(r.camera.eye[a], s.info->bounds_max[a]);
  }
  // More layers, more triangles.
  const CompileResult& small = scenetest::cached("office2");
  ASSERT_TRUE(small.ok);
  EXPECT_LT(small.report.triangles, r.report.triangles);
}

TEST(SceneProcedural, TessellatedScene) {
  const CompileResult& r = scenetest::cached("tessellated");
  ASSERT_TRUE(r.ok) << r.error;
  report("tessellated", r);
  EXPECT_GE(r.report.triangles, 100000u);
  EXPECT_LT(r.report.triangles, 110000u);
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  EXPECT_GT(winding_agreement(s), 0.999);
  EXPECT_GE(make_tessellated_scene(5000).nodes[0].primitives[0].triangles.size(), 5000u);
}

TEST(SceneProcedural, CylinderEngineReport) {
  if (!scenetest::file_exists(scenetest::engine_path())) GTEST_SKIP();
  const CompileResult& r = scenetest::cached("engine");
  ASSERT_TRUE(r.ok) << r.error;
  report("2CylEngine", r);
}

TEST(SceneProcedural, Deterministic) {
  const CompileResult a = build_default_scene(), b = build_default_scene();
  ASSERT_TRUE(a.ok && b.ok);
  ASSERT_EQ(a.blob.size, b.blob.size);
  EXPECT_EQ(std::memcmp(a.blob.data(), b.blob.data(), a.blob.size), 0);
}

TEST(SceneProcedural, MeshValidation) {
  SceneMesh empty;
  EXPECT_EQ(compile_mesh(empty).error, "scene has no triangles");
  SceneMesh bad = make_default_scene();
  bad.nodes[1].primitives[0].triangles[0][1] = 1u << 30;
  EXPECT_NE(compile_mesh(bad).error.find("out of range"), std::string::npos);
  SceneMesh nan = make_default_scene();
  nan.nodes[2].primitives[0].vertices[3].position[1] = std::nan("");
  EXPECT_NE(compile_mesh(nan).error.find("non-finite"), std::string::npos);
  SceneMesh parent = make_default_scene();
  parent.nodes[1].parent = 3;
  EXPECT_NE(compile_mesh(parent).error.find("parent"), std::string::npos);
  SceneMesh material = make_default_scene();
  material.nodes[1].primitives[0].material = 99;
  EXPECT_NE(compile_mesh(material).error.find("material"), std::string::npos);
  // A single point of a scene (zero extent) still compiles.
  SceneMesh point;
  point.materials.resize(1);
  point.nodes.resize(1);
  point.nodes[0].primitives.resize(1);
  point.nodes[0].primitives[0].vertices.resize(3);
  point.nodes[0].primitives[0].triangles.push_back({0, 1, 2});
  const CompileResult r = compile_mesh(point);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(scenetest::read(r.blob).ok());
}
