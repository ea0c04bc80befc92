// A mesh's level set by OpenVDB's mesh to volume (the only OpenVDB in geometry/), and the simulator's mesh
// distance: that level set copied into a dense DistanceGrid, which the simulator reads without OpenVDB.
#include "geometry/mesh_sdf.h"

#include <openvdb/tools/Dense.h>
#include <openvdb/tools/MeshToVolume.h>

#include <cmath>

#include "geometry/collider_shape.h"

namespace surge {

openvdb::FloatGrid::Ptr meshLevelSet(const TriangleMesh& mesh, const openvdb::math::Transform& transform,
                                     float exterior, float interior, bool unsignedDistance,
                                     openvdb::Int32Grid* nearest) {
  // Points in index space, as OpenVDB's own meshToSignedDistanceField makes them.
  std::vector<openvdb::Vec3s> points;
  points.reserve(mesh.positions.size());
  for (const Eigen::Vector3f& p : mesh.positions)
    points.emplace_back(transform.worldToIndex(openvdb::Vec3d(p.x(), p.y(), p.z())));
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  const openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(points, triangles);
  return openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      adapter, transform, exterior, interior, unsignedDistance ? openvdb::tools::UNSIGNED_DISTANCE_FIELD : 0,
      nearest);
}

DistanceGrid bakeMeshDistance(const TriangleMesh& mesh, float voxel, float band, float shellThickness) {
  openvdb::initialize();
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : mesh.positions) box.extend(p);
  const auto transform = openvdb::math::Transform::createLinearTransform(voxel);
  const float reach = band + 0.5f * shellThickness;
  const float bandVoxels = std::ceil(reach / voxel) + 2;
  const openvdb::FloatGrid::Ptr grid =
      meshLevelSet(mesh, *transform, bandVoxels, bandVoxels, /*unsignedDistance=*/shellThickness > 0);
  // The dense box: the mesh's box plus the band, in whole voxels.
  openvdb::Coord lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = int(std::floor((box.min()[a] - reach) / voxel)) - 1;
    hi[a] = int(std::ceil((box.max()[a] + reach) / voxel)) + 1;
  }
  const Eigen::Array3i counts(hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1);
  std::vector<float> samples(size_t(counts.prod()));
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(openvdb::CoordBBox(lo, hi), samples.data());
  openvdb::tools::copyToDense(*grid, dense);
  // Voxels of the open mesh's unsigned field are in world units (grid values); the shell is half its thickness.
  if (shellThickness > 0)
    for (float& value : samples) value -= 0.5f * shellThickness;
  return DistanceGrid(Eigen::Vector3f(lo[0], lo[1], lo[2]) * voxel, voxel, counts, std::move(samples));
}

}  // namespace surge
