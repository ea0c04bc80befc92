// Colliders in the surface stage (see collider_clip.h): their level sets by tools::meshToVolume, the water's
// extension into them and its clip by them. Only surfacer.cpp calls it, and only for a scene with colliders.
#include "surface/collider_clip.h"

#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/Clip.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Prune.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "core/errors.h"
#include "core/parallel.h"
#include "core/ply.h"
#include "geometry/mesh_sdf.h"
#include "geometry/triangle_mesh.h"

namespace surge {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatGrid;
using openvdb::Vec3d;
using Leaf = FloatGrid::TreeType::LeafNodeType;
constexpr int kLeafVoxels = int(Leaf::SIZE);
constexpr int kLeafDim = int(Leaf::DIM);

// The point of triangle abc nearest to p (Ericson, Real-Time Collision Detection, 5.1.5); not finite for a
// degenerate triangle.
Eigen::Vector3d closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double scale = 1 / (va + vb + vc);
  return a + ab * (vb * scale) + ac * (vc * scale);
}

// The signed distance to a collider's solid (negative in it), in world units, at voxels.
class SolidDistance {
 public:
  SolidDistance(const SurfaceCollider& c, double voxel) : c_(c), voxel_(voxel) {
    if (c.grid) accessor_.emplace(c.grid->getConstAccessor());
  }
  double at(const Coord& ijk) {
    if (c_.plane) return c_.normal.dot(ijk.asVec3d() * voxel_) - c_.offset;
    const double v = double(accessor_->getValue(c_.flat ? Coord(ijk.x(), ijk.y(), 0) : ijk));
    return c_.container ? -v : v;
  }
  // False if every voxel of the leaf-sized block holding voxel ijk lies on the fluid's side of the collider,
  // further from it than its band (the grid has no leaf there and its tile is outside the solid; a plane's
  // distance at the block's centre is over 12 voxels).
  bool mayReach(const Coord& ijk) {
    if (c_.plane) {
      const Vec3d centre =
          (Vec3d(ijk.x() & ~(kLeafDim - 1), ijk.y() & ~(kLeafDim - 1), ijk.z() & ~(kLeafDim - 1)) +
           Vec3d(0.5 * (kLeafDim - 1))) *
          voxel_;
      return c_.normal.dot(centre) - c_.offset < 12 * voxel_;  // half the block's diagonal and a band
    }
    const Coord flat = c_.flat ? Coord(ijk.x(), ijk.y(), 0) : ijk;
    return accessor_->probeConstLeaf(flat) != nullptr || at(flat) < 0;
  }
  // The unit gradient (out of the solid) by central differences; zero where they cancel.
  Vec3d normal(const Coord& ijk) {
    if (c_.plane) return c_.normal;
    Vec3d g;
    for (int a = 0; a < 3; ++a) {
      Coord plus = ijk, minus = ijk;
      ++plus[a];
      --minus[a];
      g[a] = at(plus) - at(minus);
    }
    const double length = g.length();
    return length > 1e-12 ? g / length : Vec3d(0, 0, 0);
  }

 private:
  const SurfaceCollider& c_;
  double voxel_;
  std::optional<FloatGrid::ConstAccessor> accessor_;
};

// The leaf-sized blocks within `region` holding a voxel whose distance to the solid lies in [lo, hi]: from
// the collider's leaves (its band covers both ranges the callers ask for), or for a plane from its distances
// at the block's corners (it is linear, so they bound it).
std::vector<Coord> blocksNear(const SurfaceCollider& c, const CoordBBox& region, double lo, double hi,
                              double voxel) {
  std::vector<Coord> origins;
  if (c.plane) {
    SolidDistance solid(c, voxel);
    const auto down = [](int x) { return x & ~(kLeafDim - 1); };
    for (int x = down(region.min().x()); x <= region.max().x(); x += kLeafDim)
      for (int y = down(region.min().y()); y <= region.max().y(); y += kLeafDim)
        for (int z = down(region.min().z()); z <= region.max().z(); z += kLeafDim) {
          double low = std::numeric_limits<double>::max(), high = -low;
          for (int corner = 0; corner < 8; ++corner) {
            const double d =
                solid.at(Coord(x + (corner & 1 ? kLeafDim - 1 : 0), y + (corner & 2 ? kLeafDim - 1 : 0),
                               z + (corner & 4 ? kLeafDim - 1 : 0)));
            low = std::min(low, d);
            high = std::max(high, d);
          }
          if (high >= lo && low <= hi) origins.emplace_back(x, y, z);
        }
    return origins;
  }
  const double sign = c.container ? -1 : 1;
  for (auto leaf = c.grid->tree().cbeginLeaf(); leaf; ++leaf) {
    CoordBBox box = leaf->getNodeBoundingBox();
    if (c.flat) {  // the leaves through z = 0, repeated along z
      if (leaf->origin().z() != 0) continue;
      box.min().z() = region.min().z();
      box.max().z() = region.max().z();
    }
    if (!region.hasOverlap(box)) continue;
    const auto [low, high] = std::minmax_element(leaf->buffer().data(), leaf->buffer().data() + kLeafVoxels);
    const double a = sign * double(*low), b = sign * double(*high);
    if (std::max(a, b) < lo || std::min(a, b) > hi) continue;
    if (!c.flat) {
      origins.push_back(leaf->origin());
      continue;
    }
    for (int z = region.min().z() & ~(kLeafDim - 1); z <= region.max().z(); z += kLeafDim)
      origins.emplace_back(leaf->origin().x(), leaf->origin().y(), z);
  }
  return origins;
}

bool nearRegion(const SurfaceCollider& c, const CoordBBox& region) {
  return c.plane || c.container || (!c.bounds.empty() && c.bounds.hasOverlap(region));
}

TriangleMesh checkedMesh(const ColliderSettings& settings, TriangleMesh mesh) {
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (uint32_t v : mesh.triangles[t])
      if (v >= mesh.positions.size())
        throw InputError(
            "collider '" + settings.name + "'", "triangle " + std::to_string(t),
            "names vertex " + std::to_string(v) + " of " + std::to_string(mesh.positions.size()));
  if (mesh.triangles.empty())
    throw InputError("collider '" + settings.name + "'", "its mesh has no triangle");
  return mesh;
}

TriangleMesh readCollider(const ColliderSettings& settings, const fs::path& path) {
  std::error_code error;
  if (!fs::exists(path, error))
    throw InputError(path.string(), "missing: the simulation writes colliders/ and bodies/; run surge sim again");
  return checkedMesh(settings, readMeshPly(path));
}

}  // namespace

SurfaceCollider makeSurfaceCollider(const ColliderSettings& settings, const TriangleMesh& mesh,
                                    const ColliderGrids& grids, double thickness) {
  SurfaceCollider c;
  c.name = settings.name;
  c.container = settings.container != 0;
  if (settings.shape == "plane") {
    // A half-space: its triangles' normals point into the fluid (for a container too: the simulator turns
    // them), their vertices lie on its boundary.
    c.plane = true;
    c.container = false;
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3f& v : mesh.normals) n += v.cast<double>();
    if (n.norm() < 1e-12) {
      const auto& t = mesh.triangles.front();
      const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
      n = (mesh.positions[t[1]].cast<double>() - a).cross(mesh.positions[t[2]].cast<double>() - a);
    }
    if (n.norm() < 1e-12) throw InputError("collider '" + settings.name + "'", "its plane has no normal");
    n.normalize();
    c.normal = Vec3d(n.x(), n.y(), n.z());
    c.offset = n.dot(mesh.positions[mesh.triangles.front()[0]].cast<double>());
    return c;
  }
  // The level set by OpenVDB's mesh to volume (geometry/mesh_sdf.h), with the nearest triangle of every voxel;
  // in 2D the mesh is first cut to the region along z.
  const double voxel = grids.voxel;
  const auto transform = openvdb::math::Transform::createLinearTransform(voxel);
  auto triangles = std::make_shared<ColliderTriangles>();
  TriangleMesh clamped;
  const bool clampZ = grids.flat && !grids.region.isEmpty();
  if (clampZ) {
    clamped = mesh;
    for (Eigen::Vector3f& p : clamped.positions)
      p.z() = float(std::clamp(double(p.z()), grids.region.min().z(), grids.region.max().z()));
  }
  const TriangleMesh& placed = clampZ ? clamped : mesh;
  for (const Eigen::Vector3f& p : placed.positions) triangles->positions.push_back(p.cast<double>());
  const bool hasNormals = mesh.normals.size() == mesh.positions.size();
  for (const auto& t : mesh.triangles) {
    triangles->triangles.push_back(t);
    const Eigen::Vector3d& a = triangles->positions[t[0]];
    Eigen::Vector3d n = (triangles->positions[t[1]] - a).cross(triangles->positions[t[2]] - a);
    if (hasNormals &&
        n.dot((mesh.normals[t[0]] + mesh.normals[t[1]] + mesh.normals[t[2]]).cast<double>()) < 0)
      n = -n;
    triangles->facing.push_back(n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero());
  }
  triangles->nearest = openvdb::Int32Grid::create();
  FloatGrid::Ptr grid;
  if (settings.shape == "mesh" && !isClosedManifold(mesh)) {
    // An open mesh: a shell `thickness` thick about its triangles, the unsigned distance less half of it.
    c.shell = thickness;
    const float half = float(0.5 * thickness);
    grid = meshLevelSet(placed, *transform, float(half / voxel) + grids.fluid, 0.0f, /*unsignedDistance=*/true,
                        triangles->nearest.get());
    for (auto value = grid->beginValueAll(); value; ++value) value.setValue(*value - half);
    grid->tree().root().setBackground(grid->background() - half, /*updateChildNodes=*/false);
    c.container = false;
  } else {
    const float exterior = c.container ? grids.solid : grids.fluid;
    const float interior = c.container ? grids.fluid : grids.solid;
    grid = meshLevelSet(placed, *transform, exterior, interior, /*unsignedDistance=*/false,
                        triangles->nearest.get());
  }
  // Cut to the region, when the mesh's bands reach beyond it.
  Eigen::AlignedBox3d reach;
  for (const Eigen::Vector3d& p : triangles->positions) reach.extend(p);
  reach.min().array() -= (std::max(grids.fluid, grids.solid) + 1) * voxel;
  reach.max().array() += (std::max(grids.fluid, grids.solid) + 1) * voxel;
  if (!grids.region.isEmpty() && !grids.region.contains(reach)) {
    const Eigen::AlignedBox3d cut = reach.intersection(grids.region);
    const openvdb::BBoxd box(Vec3d(cut.min().data()), Vec3d(cut.max().data()));
    grid = openvdb::tools::clip(*grid, box);
    triangles->nearest = openvdb::tools::clip(*triangles->nearest, box);
  }
  grid->setTransform(transform);  // clip copies it; all grids share the surface's voxels
  c.bounds = grid->evalActiveVoxelBoundingBox();
  if (grids.flat) {
    c.flat = true;
    c.bounds.min().z() = -(1 << 28);
    c.bounds.max().z() = 1 << 28;
  }
  c.grid = grid;
  c.triangles = triangles;

  // The VDB's grid: the band trimmed to +-output voxels, as the surface's.
  const float band = float(grids.output * voxel);
  FloatGrid::Ptr output = grid->deepCopy();
  for (auto value = output->beginValueOn(); value; ++value)
    if (std::abs(*value) >= band) value.setValueOff();
  openvdb::tools::changeLevelSetBackground(output->tree(), band, -band);
  openvdb::tools::pruneLevelSet(output->tree());
  output->setName("collider_" + settings.name);
  output->setGridClass(openvdb::GRID_LEVEL_SET);
  output->insertMeta("container", openvdb::BoolMetadata(c.container));
  c.output = output;
  return c;
}

SurfaceColliders::SurfaceColliders(const fs::path& dir, const std::vector<SolidFiles>& solids, double spacing,
                                   const ColliderGrids& grids)
    : dir_(dir), solids_(solids), grids_(grids) {
  for (const SolidFiles& s : solids_) {
    thickness_.push_back(s.settings.thickness > 0 ? s.settings.thickness : spacing);
    SurfaceCollider c;
    c.name = s.settings.name;
    if (!s.moving)
      c = makeSurfaceCollider(s.settings, readCollider(s.settings, dir_ / s.folder / (c.name + ".ply")), grids_,
                              thickness_.back());
    standing_.push_back(std::move(c));
  }
}

std::vector<SurfaceCollider> SurfaceColliders::atFrame(int frame) const {
  std::vector<SurfaceCollider> colliders = standing_;
  for (size_t c = 0; c < solids_.size(); ++c) {
    const SolidFiles& s = solids_[c];
    if (!s.moving) continue;
    std::error_code error;
    fs::path path = framePath(dir_ / s.folder, s.settings.name, frame, "ply");
    if (!fs::exists(path, error)) path = dir_ / s.folder / (s.settings.name + ".ply");
    colliders[c] = makeSurfaceCollider(s.settings, readCollider(s.settings, path), grids_, thickness_[c]);
  }
  return colliders;
}

std::vector<fs::path> colliderFrameFiles(const fs::path& dir, const Scene& scene, int frame) {
  std::vector<fs::path> files;
  for (const SolidFiles& s : solidFiles(scene)) {
    std::error_code error;
    const fs::path path = framePath(dir / s.folder, s.settings.name, frame, "ply");
    if (s.moving && fs::exists(path, error)) files.push_back(path);
  }
  return files;
}

void extendIntoColliders(FloatGrid& raw, const std::vector<SurfaceCollider>& colliders,
                         const ExtensionParameters& e) {
  const double voxel = raw.voxelSize()[0];
  CoordBBox region = raw.evalActiveVoxelBoundingBox();
  if (region.empty()) return;
  const double reach = e.depth + e.band;  // the deepest voxel set: the end of the water in the solid, banded
  region.expand(int(std::ceil((reach + e.far) / voxel)) + 2);
  const float band = float(e.band), unset = std::numeric_limits<float>::quiet_NaN();
  const double offsets[2] = {e.near, e.far};

  // Each collider's values are computed from the raw field as it came (in parallel over blocks), then merged,
  // the lower value where two solids overlap, and written (serially: the tree gains leaves).
  std::map<Coord, std::vector<float>> merged;
  for (const SurfaceCollider& c : colliders) {
    if (!nearRegion(c, region)) continue;
    const std::vector<Coord> origins = blocksNear(c, region, -reach, e.far, voxel);
    std::vector<std::vector<float>> values(origins.size());
    parallelFor(0, origins.size(), [&](size_t begin, size_t end) {
      SolidDistance solid(c, voxel);
      const auto water = raw.getConstAccessor();
      for (size_t b = begin; b < end; ++b) {
        std::vector<float> v(kLeafVoxels, unset);
        bool any = false;
        for (int i = 0; i < kLeafVoxels; ++i) {
          const Coord ijk = origins[b] + Leaf::offsetToLocalCoord(openvdb::Index(i));
          const double s = solid.at(ijk);  // negative in the solid
          if (!(s > -reach && s < e.far)) continue;
          const Vec3d n = solid.normal(ijk);
          if (n.lengthSqr() == 0) continue;
          double w = s < 0 ? std::numeric_limits<double>::max() : double(water.getValue(ijk));
          for (int o = 0; o < (e.far > e.near ? 2 : 1); ++o)
            if (const double offset = offsets[o]; offset > s)
              w = std::min(w, double(openvdb::tools::BoxSampler::sample(
                                  water, ijk.asVec3d() + n * ((offset - s) / voxel))));
          if (s < 0) w = std::max(w, -s - e.depth);  // the end of the water in the solid
          v[size_t(i)] = std::clamp(float(w), -band, band);
          any = true;
        }
        if (any) values[b] = std::move(v);
      }
    });
    for (size_t b = 0; b < origins.size(); ++b) {
      if (values[b].empty()) continue;
      auto [it, inserted] = merged.try_emplace(origins[b], std::move(values[b]));
      if (inserted) continue;
      for (int i = 0; i < kLeafVoxels; ++i) {
        float& to = it->second[size_t(i)];
        const float from = values[b][size_t(i)];
        if (std::isnan(to) || from < to) to = from;
      }
    }
  }
  auto& tree = raw.tree();
  for (const auto& [origin, v] : merged) {
    Leaf* leaf = tree.probeLeaf(origin);
    if (!leaf) {
      // A tile: a leaf is needed only if some value is not that tile's (the clamp on the tile's side).
      const bool outside = tree.getValue(origin) > 0;
      if (std::none_of(v.begin(), v.end(), [&](float w) { return outside ? w < band : w > -band; })) continue;
      leaf = tree.touchLeaf(origin);
      leaf->setValuesOn();  // a raw field's leaves are active throughout
    }
    for (int i = 0; i < kLeafVoxels; ++i)
      if (!std::isnan(v[size_t(i)])) leaf->setValueOnly(openvdb::Index(i), v[size_t(i)]);
  }
}

void clipByColliders(FloatGrid& water, const std::vector<SurfaceCollider>& colliders, double band) {
  const double voxel = water.voxelSize()[0];
  CoordBBox region = water.evalActiveVoxelBoundingBox();
  if (region.empty()) return;
  region.expand(kLeafDim);
  const float limit = float(band);
  auto& tree = water.tree();
  for (const SurfaceCollider& c : colliders) {
    if (!nearRegion(c, region)) continue;
    // Where the collider's surface runs through the water's inside tiles, leaves for its face.
    for (const Coord& origin : blocksNear(c, region, -band, band, voxel))
      if (!tree.probeLeaf(origin) && tree.getValue(origin) < 0) tree.touchLeaf(origin);
    std::vector<Leaf*> leaves;
    tree.getNodes(leaves);
    parallelFor(0, leaves.size(), [&](size_t begin, size_t end) {
      SolidDistance solid(c, voxel);
      for (size_t l = begin; l < end; ++l) {
        Leaf& leaf = *leaves[l];
        if (!c.plane && !c.container && !c.bounds.hasOverlap(leaf.getNodeBoundingBox())) continue;
        if (!solid.mayReach(leaf.origin())) continue;
        for (int i = 0; i < kLeafVoxels; ++i) {
          const openvdb::Index n = openvdb::Index(i);
          const float before = leaf.getValue(n);
          const float v =
              std::clamp(std::max(before, float(-solid.at(leaf.offsetToGlobalCoord(n)))), -limit, limit);
          if (v == before) continue;
          leaf.setValueOnly(n, v);
          leaf.setActiveState(n, std::abs(v) < limit);
        }
      }
    });
  }
  openvdb::tools::pruneLevelSet(tree);
}

void snapOutOfColliders(TriangleMesh& mesh, const std::vector<SurfaceCollider>& colliders, double voxel) {
  for (const SurfaceCollider& c : colliders) {
    if (!c.plane && (c.bounds.empty() || !c.triangles)) continue;
    const openvdb::BBoxd box(c.bounds.min().asVec3d() - 1.0, c.bounds.max().asVec3d() + 1.0);
    parallelFor(0, mesh.positions.size(), [&](size_t begin, size_t end) {
      SolidDistance solid(c, voxel);
      std::optional<FloatGrid::ConstAccessor> distances;
      std::optional<openvdb::Int32Grid::ConstAccessor> nearest;
      if (!c.plane) {
        distances.emplace(c.grid->getConstAccessor());
        nearest.emplace(c.triangles->nearest->getConstAccessor());
      }
      std::vector<int32_t> candidates;
      for (size_t i = begin; i < end; ++i) {
        Eigen::Vector3d x = mesh.positions[i].cast<double>();
        const double z = x.z();
        if (c.flat) x.z() = 0;  // the cross-section at z = 0, and back to the vertex's z at the end
        Eigen::Vector3d to = x;
        if (c.plane) {
          const double d = c.normal.dot(Vec3d(x.x(), x.y(), x.z())) - c.offset;
          if (!(d < 0 && d > -voxel)) continue;
          to = x - d * Eigen::Vector3d(c.normal.x(), c.normal.y(), c.normal.z());
        } else {
          const Vec3d ijk(x.x() / voxel, x.y() / voxel, x.z() / voxel);
          if (!c.container && !box.isInside(ijk)) continue;
          if (!solid.mayReach(Coord::floor(ijk))) continue;
          const double d =
              double(openvdb::tools::BoxSampler::sample(*distances, ijk)) * (c.container ? -1 : 1);
          if (!(std::abs(d) < voxel)) continue;  // well inside or outside: nothing near to move to
          candidates.clear();
          const Coord base = Coord::floor(ijk);
          for (int corner = 0; corner < 8; ++corner) {
            int32_t t;
            const Coord at = base.offsetBy(corner & 1, (corner >> 1) & 1, corner >> 2);
            if (nearest->probeValue(at, t) && t >= 0 && size_t(t) < c.triangles->triangles.size())
              candidates.push_back(t);
          }
          double best = std::numeric_limits<double>::max();
          int32_t which = -1;
          for (int32_t t : candidates) {
            const auto& tri = c.triangles->triangles[size_t(t)];
            const Eigen::Vector3d q =
                closestOnTriangle(x, c.triangles->positions[tri[0]], c.triangles->positions[tri[1]],
                                  c.triangles->positions[tri[2]]);
            if (q.allFinite() && (q - x).squaredNorm() < best) {
              best = (q - x).squaredNorm();
              to = q;
              which = t;
            }
          }
          if (which < 0) continue;
          const Eigen::Vector3d away = x - to;
          if (c.shell > 0) {  // the solid is the shell about the triangles: out to its face
            if (away.norm() >= 0.5 * c.shell) continue;
            const Eigen::Vector3d n =
                away.norm() > 1e-12 ? Eigen::Vector3d(away.normalized()) : c.triangles->facing[size_t(which)];
            to += 0.5 * c.shell * n;
          } else if (away.dot(c.triangles->facing[size_t(which)]) >= 0) {
            continue;  // on the fluid's side of its nearest triangle
          }
        }
        if ((to - x).norm() > voxel) continue;
        if (c.flat) to.z() = z;
        mesh.positions[i] = to.cast<float>();
      }
    });
  }
}

}  // namespace surge
