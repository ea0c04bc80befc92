// Writing a surface frame's VDB: the level set, the optional velocity grid and the optional PointDataGrid.
// The only file of Surge that includes OpenVDB's points headers.
#include "surface/vdb_output.h"

#include <openvdb/io/Archive.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <fstream>
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

// Points as a PointDataGrid `name` (positions stored relative to their voxel, 16-bit fixed point as Houdini does
// by default, error under voxel / 2^16) with a float vector attribute "v", and for whitewater its id, type and
// lifetime.
openvdb::points::PointDataGrid::Ptr pointsGrid(const std::string& name, const std::vector<Eigen::Vector3f>& x,
                                               const std::vector<Eigen::Vector3f>& v, double voxel,
                                               const DiffuseFrame* whitewater = nullptr) {
  const openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(voxel);
  if (x.empty()) {  // no point: an empty grid still names the channel
    auto grid = openvdb::points::PointDataGrid::create();
    grid->setTransform(transform);
    grid->setName(name);
    return grid;
  }
  std::vector<openvdb::Vec3R> positions(x.size());
  std::vector<openvdb::Vec3s> velocities(v.size());
  for (size_t i = 0; i < x.size(); ++i) positions[i] = openvdb::Vec3R(x[i].x(), x[i].y(), x[i].z());
  for (size_t i = 0; i < v.size(); ++i) velocities[i] = openvdb::Vec3s(v[i].x(), v[i].y(), v[i].z());
  const openvdb::points::PointAttributeVector<openvdb::Vec3R> positionWrapper(positions);
  const auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positionWrapper, *transform);
  auto grid = openvdb::points::createPointDataGrid<openvdb::points::FixedPointCodec</*1-byte=*/false>,
                                                   openvdb::points::PointDataGrid>(*index, positionWrapper, *transform);
  auto add = [&](const char* attribute, const auto& values) {
    using T = typename std::decay_t<decltype(values)>::value_type;
    openvdb::points::appendAttribute<T>(grid->tree(), attribute);
    const openvdb::points::PointAttributeVector<T> wrapper(values);
    openvdb::points::populateAttribute<openvdb::points::PointDataTree, openvdb::tools::PointIndexTree,
                                       openvdb::points::PointAttributeVector<T>>(grid->tree(), index->tree(),
                                                                                 attribute, wrapper);
  };
  add("v", velocities);
  if (whitewater) {
    const size_t n = whitewater->size();
    std::vector<int32_t> ids(n), types(n);
    for (size_t i = 0; i < n; ++i) ids[i] = int32_t(whitewater->id[i]), types[i] = whitewater->type[i];
    add("id", ids);
    add("type", types);
    add("lifetime", whitewater->lifetime);
  }
  grid->setName(name);
  return grid;
}

// OpenVDB stamps every file it writes with a random UUID (36 characters at byte 21 of the header: the magic
// number, the file version, the library's major and minor versions and the grid-offsets flag come first), so two
// writes of the same grids differ in those bytes. Surge's outputs are the same bytes whatever the thread count
// and after a resume, so the UUID is replaced by one made from the file's other bytes (two FNV-1a hashes with
// different offsets): still different for different content, which is what readers compare it for.
void stampContentUuid(const fs::path& file) {
  constexpr std::streamoff kOffset = 21, kLength = 36;
  std::fstream stream(file, std::ios::binary | std::ios::in | std::ios::out);
  std::uint64_t a = 14695981039346656037ull, b = 1099511628211ull * 31;
  std::vector<char> buffer(1 << 20);
  std::streamoff position = 0;
  while (stream.read(buffer.data(), std::streamsize(buffer.size())) || stream.gcount() > 0) {
    for (std::streamsize i = 0; i < stream.gcount(); ++i, ++position) {
      if (position >= kOffset && position < kOffset + kLength) continue;
      a = (a ^ std::uint8_t(buffer[i])) * 1099511628211ull;
      b = (b ^ std::uint8_t(buffer[i])) * 1099511628211ull;
    }
  }
  if (position < kOffset + kLength) throw RunError("cannot write " + file.string() + ": short VDB header");
  char uuid[40];
  std::snprintf(uuid, sizeof uuid, "%08x-%04x-%04x-%04x-%012llx", unsigned(a >> 32), unsigned(a >> 16) & 0xffff,
                unsigned(a) & 0xffff, unsigned(b >> 48), static_cast<unsigned long long>(b & 0xffffffffffffull));
  stream.clear();
  stream.seekp(kOffset);
  stream.write(uuid, kLength);
  if (!stream.flush()) throw RunError("cannot write " + file.string() + ": " + writeFailure(errno));
}

// What openvdb::io::File::write does (a seekable archive, so readers can load one grid without the others),
// but into a stream of our own: File ignores the stream's state, so a write that fails (a full disk) would
// leave a cut-short file and no error.
class SeekableArchive : public openvdb::io::Archive {
 public:
  void writeTo(std::ostream& out, const openvdb::GridCPtrVec& grids) const {
    write(out, grids, /*seekable=*/true);
  }
};

}  // namespace

void writeSurfaceVdb(const fs::path& path, const openvdb::FloatGrid::Ptr& surface, const VdbExtras& extras) {
  openvdb::GridCPtrVec grids{surface};
  grids.insert(grids.end(), extras.fluids.begin(), extras.fluids.end());
  if (extras.velocity) grids.push_back(velocityGrid(*extras.velocity, surface->transform()));
  if (extras.pointPositions)
    grids.push_back(pointsGrid("points", *extras.pointPositions, *extras.pointVelocities, extras.pointVoxel));
  if (extras.whitewater)
    grids.push_back(pointsGrid("whitewater", extras.whitewater->position, extras.whitewater->velocity,
                               std::max(extras.pointVoxel, 1e-6), extras.whitewater));
  grids.insert(grids.end(), extras.colliders.begin(), extras.colliders.end());

  // The atomic write is done here, as the UUID is stamped once the file is whole: a temporary name in the same
  // folder (same file system, so the rename is atomic), then rename.
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  fs::path temporary = path;
  temporary += ".tmp" + std::to_string(::getpid());
  try {
    {
      errno = 0;
      std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
      if (file) SeekableArchive().writeTo(file, grids);
      if (file) file.close();
      if (!file) throw RunError("cannot write " + path.string() + ": " + writeFailure(errno));
    }
    stampContentUuid(temporary);
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
