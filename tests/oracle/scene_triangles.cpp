#include "tests/oracle/scene_triangles.h"

namespace oracle {

std::vector<Triangle> scene_triangles(const ml::Scene& scene) {
  std::vector<Triangle> out(scene.triangle_count);
  for (uint32_t id = 0; id < scene.triangle_count; ++id) {
    ml::Vec3i w[3];
    ml::triangle_world(scene, id, w);
    for (int k = 0; k < 3; ++k) out[id].v[k] = {double(w[k].x), double(w[k].y), double(w[k].z)};
    const ml::Batch& batch = scene.batches[ml::triangle_at(scene, id).batch];
    out[id].double_sided = scene.materials[batch.material].double_sided != 0;
  }
  return out;
}

Camera to_oracle_camera(const ml::Camera& c) {
  Camera o;
  o.eye = {double(c.eye.x), double(c.eye.y), double(c.eye.z)};
  o.target = {double(c.target.x), double(c.target.y), double(c.target.z)};
  o.up = {double(c.up.x), double(c.up.y), double(c.up.z)};
  o.vfov_deg = c.fov_deg_q16 / 65536.0;
  o.width = c.width;
  o.height = c.height;
  o.near = c.near;
  return o;
}

}  // namespace oracle
