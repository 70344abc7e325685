// Building small SceneMeshes in tests: one node, a primitive per material, triangles of their own
// three vertices.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "tools/scenec/scenec.h"

namespace meshtest {

// A mesh of one node whose primitive i draws with materials[i].
inline ml::SceneMesh one_node_mesh(std::vector<ml::MeshMaterial> materials, const std::string& name = "") {
  ml::SceneMesh mesh;
  mesh.materials = std::move(materials);
  mesh.nodes.resize(1);
  mesh.nodes[0].name = name;
  for (uint32_t m = 0; m < mesh.materials.size(); ++m) {
    ml::MeshPrimitive prim;
    prim.material = m;
    mesh.nodes[0].primitives.push_back(prim);
  }
  return mesh;
}

// Appends a triangle of three new vertices to primitive `primitive` of the mesh's one node.
inline void add_triangle(ml::SceneMesh* mesh, size_t primitive, const ml::MeshVertex (&v)[3]) {
  ml::MeshPrimitive& prim = mesh->nodes[0].primitives[primitive];
  const uint32_t base = uint32_t(prim.vertices.size());
  prim.vertices.insert(prim.vertices.end(), v, v + 3);
  prim.triangles.push_back({base, base + 1, base + 2});
}

}  // namespace meshtest
