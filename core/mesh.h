// A triangle mesh: the one mesh type of every stage (collider and body meshes, surfaces). It lives in core
// because core's PLY files and render, which may not use geometry/, hold it too; what is computed on a mesh
// (closed or not, normals, its level set) is in geometry/triangle_mesh.h.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace surge {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;  // one per vertex, or empty
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<Eigen::Vector3f> velocities;  // one per vertex (a surface's, for motion blur), or empty
  std::vector<uint8_t> fluid;  // one per triangle where a mesh joins several fluids' surfaces (the renderers), or empty
};

}  // namespace surge
