// Writing a surface frame's VDB: the level set, the optional velocity grid and the optional PointDataGrid.
// The only file of Surge that includes OpenVDB's points headers.
#include "surface/vdb_output.h"

#include <openvdb/io/File.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <unistd.h>

#include <string>

#include "core/errors.h"

namespace surge {
namespace {

// The velocity grid on the given blocks (the surface's leaves): every voxel active, background zero.
openvdb::Vec3SGrid::Ptr velocityGrid(const BlockField& blocks, const openvdb::math::Transform& transform) {
  openvdb::Vec3SGrid::Ptr grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0, 0, 0));
  grid->setTransform(transform.copy());
  grid->setName("v");
  grid->setGridClass(openvdb::GRID_UNKNOWN);
  grid->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
  auto& tree = grid->tree();
  for (size_t b = 0; b < blocks.origins.size(); ++b) {
    const Eigen::Vector3i& o = blocks.origins[b];
    auto* leaf = new openvdb::Vec3SGrid::TreeType::LeafNodeType(openvdb::Coord(o.x(), o.y(), o.z()),
                                                                 openvdb::Vec3s(0, 0, 0), true);
    const float* v = &blocks.values[b * 3 * kBlockVoxels];
    for (int a = 0; a < kBlockVoxels; ++a) leaf->setValueOnly(openvdb::Index(a), openvdb::Vec3s(v[3 * a], v[3 * a + 1], v[3 * a + 2]));
    tree.addLeaf(leaf);
  }
  return grid;
}

// The particles as a PointDataGrid "points" (positions stored relative to their voxel, 16-bit fixed point as
// Houdini does by default, error under voxel / 2^16) with a float vector attribute "v".
openvdb::points::PointDataGrid::Ptr pointsGrid(const std::vector<Eigen::Vector3f>& x,
                                               const std::vector<Eigen::Vector3f>& v, double voxel) {
  std::vector<openvdb::Vec3R> positions(x.size());
  std::vector<openvdb::Vec3s> velocities(v.size());
  for (size_t i = 0; i < x.size(); ++i) positions[i] = openvdb::Vec3R(x[i].x(), x[i].y(), x[i].z());
  for (size_t i = 0; i < v.size(); ++i) velocities[i] = openvdb::Vec3s(v[i].x(), v[i].y(), v[i].z());
  const openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(voxel);
  const openvdb::points::PointAttributeVector<openvdb::Vec3R> positionWrapper(positions);
  const auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positionWrapper, *transform);
  auto grid = openvdb::points::createPointDataGrid<openvdb::points::FixedPointCodec</*1-byte=*/false>,
                                                   openvdb::points::PointDataGrid>(*index, positionWrapper, *transform);
  openvdb::points::appendAttribute<openvdb::Vec3s>(grid->tree(), "v");
  const openvdb::points::PointAttributeVector<openvdb::Vec3s> velocityWrapper(velocities);
  openvdb::points::populateAttribute<openvdb::points::PointDataTree, openvdb::tools::PointIndexTree,
                                     openvdb::points::PointAttributeVector<openvdb::Vec3s>>(
      grid->tree(), index->tree(), "v", velocityWrapper);
  grid->setName("points");
  return grid;
}

}  // namespace

void writeSurfaceVdb(const fs::path& path, const openvdb::FloatGrid::Ptr& surface, const VdbExtras& extras) {
  openvdb::GridCPtrVec grids{surface};
  if (extras.velocity) grids.push_back(velocityGrid(*extras.velocity, surface->transform()));
  if (extras.pointPositions && !extras.pointPositions->empty())
    grids.push_back(pointsGrid(*extras.pointPositions, *extras.pointVelocities, extras.pointVoxel));
  else if (extras.pointPositions) {  // no particle: an empty points grid still names the channel
    auto grid = openvdb::points::PointDataGrid::create();
    grid->setTransform(openvdb::math::Transform::createLinearTransform(extras.pointVoxel));
    grid->setName("points");
    grids.push_back(grid);
  }
  grids.insert(grids.end(), extras.colliders.begin(), extras.colliders.end());

  // openvdb::io::File writes to a path, not a stream, so the atomic write is done here: a temporary name in
  // the same folder (same file system, so the rename is atomic), then rename.
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  fs::path temporary = path;
  temporary += ".tmp" + std::to_string(::getpid());
  try {
    openvdb::io::File file(temporary.string());
    file.write(grids);
    file.close();
    fs::rename(temporary, path);
  } catch (const openvdb::Exception& e) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw RunError("cannot write " + path.string() + ": " + e.what());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
}

}  // namespace surge
