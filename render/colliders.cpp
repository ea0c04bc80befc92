#include "render/colliders.h"

#include "core/errors.h"

namespace surge {

namespace {

std::vector<Eigen::Vector3f> facingNormals(const TriangleMesh& mesh) {
  const bool hasNormals = mesh.normals.size() == mesh.positions.size();
  std::vector<Eigen::Vector3f> facing;
  facing.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.positions[t[0]];
    Eigen::Vector3f n = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);
    const float length = n.norm();
    n = length > 0 ? Eigen::Vector3f(n / length) : Eigen::Vector3f::Zero();
    if (hasNormals && n.dot(mesh.normals[t[0]] + mesh.normals[t[1]] + mesh.normals[t[2]]) < 0) n = -n;
    facing.push_back(n);
  }
  return facing;
}

TriangleMesh readColliderMesh(const fs::path& path) {
  std::error_code error;
  if (!fs::exists(path, error))
    throw InputError(path.string(), "missing: the simulation writes colliders/ and bodies/; run surge sim again");
  return readMeshPly(path);
}

}  // namespace

ColliderMesh makeColliderMesh(const ColliderSettings& settings, TriangleMesh mesh) {
  const size_t vertexCount = mesh.positions.size();
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (uint32_t v : mesh.triangles[t])
      if (v >= vertexCount)
        throw InputError("collider '" + settings.name + "'", "triangle " + std::to_string(t),
                         "names vertex " + std::to_string(v) + " of " + std::to_string(vertexCount));
  ColliderMesh collider;
  collider.name = settings.name;
  collider.albedo = settings.color.cast<float>();
  collider.plane = settings.shape == "plane";
  collider.oneSided = collider.plane || settings.container != 0;
  collider.facing = facingNormals(mesh);
  collider.mesh = std::move(mesh);
  return collider;
}

std::vector<std::array<uint32_t, 3>> trianglesFacing(const ColliderMesh& collider,
                                                     const Eigen::Vector3f& camera) {
  const TriangleMesh& mesh = collider.mesh;
  if (!collider.oneSided) return mesh.triangles;
  std::vector<std::array<uint32_t, 3>> kept;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3f centre =
        (mesh.positions[tri[0]] + mesh.positions[tri[1]] + mesh.positions[tri[2]]) / 3.0f;
    if (collider.facing[t].dot(centre - camera) < 0) kept.push_back(tri);
  }
  return kept;
}

ColliderMeshes::ColliderMeshes(const fs::path& dir, const Scene& scene) : dir_(dir) {
  for (const SolidFiles& solid : solidFiles(scene))
    if (solid.settings.visible) visible_.push_back(solid);
  for (const SolidFiles& solid : visible_)
    meshes_.push_back(
        makeColliderMesh(solid.settings, readColliderMesh(dir_ / solid.folder / (solid.settings.name + ".ply"))));
}

const std::vector<ColliderMesh>& ColliderMeshes::atFrame(int frame) {
  if (frame == loadedFrame_) return meshes_;
  for (size_t c = 0; c < visible_.size(); ++c) {
    const SolidFiles& solid = visible_[c];
    if (!solid.moving) continue;  // standing still: read once by the constructor
    std::error_code error;
    fs::path path = framePath(dir_ / solid.folder, solid.settings.name, frame, "ply");
    if (!fs::exists(path, error)) path = dir_ / solid.folder / (solid.settings.name + ".ply");
    meshes_[c] = makeColliderMesh(solid.settings, readColliderMesh(path));
  }
  loadedFrame_ = frame;
  return meshes_;
}

std::vector<fs::path> ColliderMeshes::frameFiles(int frame) const {
  std::vector<fs::path> files;
  for (const SolidFiles& solid : visible_) {
    std::error_code error;
    const fs::path path = framePath(dir_ / solid.folder, solid.settings.name, frame, "ply");
    if (solid.moving && fs::exists(path, error)) files.push_back(path);
  }
  return files;
}

}  // namespace surge
