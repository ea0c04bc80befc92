#include "geometry/triangle_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <utility>

namespace surge {

bool isClosedManifold(const TriangleMesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  if (edges.empty()) return false;
  for (const auto& [edge, count] : edges)
    if (count != 2) return false;
  return true;
}

void computeVertexNormals(TriangleMesh& mesh) {
  using Vec3 = Eigen::Vector3f;
  mesh.normals.assign(mesh.positions.size(), Vec3::Zero());
  for (const auto& t : mesh.triangles) {
    const Vec3 n = (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    for (int k = 0; k < 3; ++k) mesh.normals[t[k]] += n;
  }
  for (Vec3& n : mesh.normals) n = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitY();
}

}  // namespace surge
