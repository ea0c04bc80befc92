// The colliders as the render stage draws them. `surge sim` leaves each collider's triangle mesh, placed in
// the world, in DIR/colliders/<name>.ply (at time 0) and a moving collider's mesh at every frame in
// DIR/colliders/<name>/frame_NNNNN.ply; the renderers read only these, never the scene's own mesh or
// heightfield files, so a render sees exactly what was simulated.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/files.h"
#include "core/ply.h"
#include "core/scene.h"

namespace surge {

struct ColliderMesh {
  std::string name;
  TriangleMesh mesh;  // in the world; vertex normals point out of the solid, into the fluid
  Eigen::Vector3f albedo = Eigen::Vector3f::Constant(0.6f);
  bool plane = false;
  // A container or a plane keeps only the triangles whose normals face the camera (trianglesFacing): its
  // outside would otherwise hide the water it holds, a plane everything behind it.
  bool oneSided = false;
  // Per triangle, the unit face normal turned to the side its vertex normals point to (the winding of a mesh
  // file is not to be trusted, a container's normals are turned inwards without rewinding); from the winding
  // when the mesh has no vertex normals, zero for a degenerate triangle.
  std::vector<Eigen::Vector3f> facing;
};

// A collider to draw from its settings and its world mesh. Throws InputError if a triangle names a vertex the
// mesh does not have.
ColliderMesh makeColliderMesh(const ColliderSettings& settings, TriangleMesh mesh);

// The triangles both renderers draw of a collider seen from `camera`: all of them, or of a one-sided collider
// those whose facing normal points back at the camera (from the triangle's centre). The rest are left out of
// the scene for every ray, not only the camera's: a container is drawn cut open towards the camera, as a real
// open vessel, and the sky and the sun reach the water it holds through the opening.
std::vector<std::array<uint32_t, 3>> trianglesFacing(const ColliderMesh& collider,
                                                     const Eigen::Vector3f& camera);

// The visible colliders and bodies of an output folder (core/scene.h's solidFiles), frame by frame: the
// standing ones are read once, a moving one's mesh at every frame (its <name>.ply when that frame's file is
// missing).
class ColliderMeshes {
 public:
  // Reads the standing colliders' meshes. Throws InputError naming the file if one is missing or unreadable.
  ColliderMeshes(const fs::path& dir, const Scene& scene);

  // Every visible collider as it stands at `frame`, in the scene's order.
  const std::vector<ColliderMesh>& atFrame(int frame);

  // The per-frame files of the moving colliders that exist for `frame`: inputs of that frame's image.
  std::vector<fs::path> frameFiles(int frame) const;

 private:
  fs::path dir_;
  std::vector<SolidFiles> visible_;
  std::vector<ColliderMesh> meshes_;  // one per visible collider
  int loadedFrame_ = -1;
};

}  // namespace surge
