#include "geometry/collider_shape.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/errors.h"
#include "geometry/pose.h"
#include "geometry/shape_files.h"

namespace surge {
namespace {

using Vec3 = Eigen::Vector3f;

// Box (Quilez's exact box distance): q' = |q| - h; outside, |max(q', 0)|; inside, the largest q'.
float boxDistance(const Vec3& q, const Vec3& half, Vec3& normal) {
  const Vec3 d = q.cwiseAbs() - half;
  const Vec3 outside = d.cwiseMax(0.0f);
  const float outsideLength = outside.norm();
  if (outsideLength > 0) {
    normal = outside.cwiseProduct(q.cwiseSign()) / outsideLength;
    return outsideLength;
  }
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (d[a] > d[axis]) axis = a;
  normal = Vec3::Zero();
  normal[axis] = q[axis] < 0 ? -1.0f : 1.0f;
  return d[axis];
}

// Distance to a point set at `centre` of radius r (sphere, capsule); a centre hit exactly points up.
float roundDistance(const Vec3& q, const Vec3& centre, float r, Vec3& normal) {
  const Vec3 offset = q - centre;
  const float length = offset.norm();
  normal = length > 0 ? Vec3(offset / length) : Vec3::UnitY();
  return length - r;
}

// A cylinder along y: the radial and axial excesses combined like the box's.
float cylinderDistance(const Vec3& q, float r, float halfHeight, Vec3& normal) {
  const float radial = std::hypot(q.x(), q.z());
  const Vec3 outward = radial > 0 ? Vec3(q.x() / radial, 0, q.z() / radial) : Vec3::UnitX();
  const float dr = radial - r, dy = std::abs(q.y()) - halfHeight;
  const Vec3 up(0, q.y() < 0 ? -1.0f : 1.0f, 0);
  if (dr > 0 && dy > 0) {
    const float length = std::hypot(dr, dy);
    normal = (dr * outward + dy * up) / length;
    return length;
  }
  if (dr > dy) {
    normal = outward;
    return dr;
  }
  normal = up;
  return dy;
}

}  // namespace

float Heightfield::heightAt(float x, float z, float& slopeX, float& slopeZ) const {
  const float cellX = sizeX / float(width - 1), cellZ = sizeZ / float(depth - 1);
  float u = (x + 0.5f * sizeX) / cellX, v = (z + 0.5f * sizeZ) / cellZ;
  const bool insideX = u > 0 && u < width - 1, insideZ = v > 0 && v < depth - 1;
  u = std::min(std::max(u, 0.0f), float(width - 1));
  v = std::min(std::max(v, 0.0f), float(depth - 1));
  const int i = std::min(int(u), width - 2), j = std::min(int(v), depth - 2);
  const float fu = u - i, fv = v - j;
  const float h00 = heights[size_t(j) * width + i], h10 = heights[size_t(j) * width + i + 1];
  const float h01 = heights[size_t(j + 1) * width + i], h11 = heights[size_t(j + 1) * width + i + 1];
  // Held beyond the edges: no slope across them.
  slopeX = insideX ? ((1 - fv) * (h10 - h00) + fv * (h11 - h01)) / cellX : 0.0f;
  slopeZ = insideZ ? ((1 - fu) * (h01 - h00) + fu * (h11 - h10)) / cellZ : 0.0f;
  return (1 - fv) * ((1 - fu) * h00 + fu * h10) + fv * ((1 - fu) * h01 + fu * h11);
}

float Heightfield::minHeight() const { return *std::min_element(heights.begin(), heights.end()); }
float Heightfield::maxHeight() const { return *std::max_element(heights.begin(), heights.end()); }

float ColliderShape::distance(const Vec3& q, Vec3& normal) const {
  float d = 0;
  switch (kind) {
    case ShapeKind::Plane:
      normal = planeNormal;
      d = q.dot(planeNormal);
      break;
    case ShapeKind::Box:
      d = boxDistance(q, halfExtents, normal);
      break;
    case ShapeKind::Sphere:
      d = roundDistance(q, Vec3::Zero(), radius, normal);
      break;
    case ShapeKind::Capsule:
      d = roundDistance(q, Vec3(0, std::min(std::max(q.y(), -halfHeight), halfHeight), 0), radius, normal);
      break;
    case ShapeKind::Cylinder:
      d = cylinderDistance(q, radius, halfHeight, normal);
      break;
    case ShapeKind::Heightfield: {
      // First order: the height above the surface times the cosine of its slope (exact on a plane).
      float sx = 0, sz = 0;
      const float h = heightfield.heightAt(q.x(), q.z(), sx, sz);
      const float length = std::sqrt(1 + sx * sx + sz * sz);
      normal = Vec3(-sx, 1, -sz) / length;
      d = (q.y() - h) / length;
      break;
    }
    case ShapeKind::Mesh: {
      Vec3 gradient;
      d = grid.sample(q, gradient);
      const float length = gradient.norm();
      normal = length > 0 ? Vec3(gradient / length) : Vec3::UnitY();
      break;
    }
  }
  if (container) {
    normal = -normal;
    return -d;
  }
  return d;
}

size_t ColliderShape::memoryBytes() const {
  return grid.memoryBytes() + heightfield.heights.capacity() * sizeof(float) +
         mesh.positions.capacity() * sizeof(Vec3) * 2 + mesh.triangles.capacity() * 12;
}

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

ColliderShape buildColliderShape(const Scene& scene, size_t index) {
  return buildSolidShape(scene, scene.colliders.at(index), "colliders[" + std::to_string(index) + "]", false);
}

ColliderShape buildBodyShape(const Scene& scene, size_t index) {
  return buildSolidShape(scene, scene.bodies.at(index).solid, "bodies[" + std::to_string(index) + "]", true);
}

ColliderShape buildSolidShape(const Scene& scene, const ColliderSettings& c, const std::string& key, bool body) {
  const std::string where = scene.source.empty() ? "scene" : scene.source;
  const float spacing = float(scene.particle_spacing);
  const float support = float(scene.solver.kernel_radius > 0 ? scene.solver.kernel_radius : 2 * spacing);
  const Vec3 domainExtent = (scene.domain.max - scene.domain.min).cast<float>();
  const float domainSize = domainExtent.norm();
  ColliderShape s;
  s.container = c.container != 0;
  if (c.shape == "plane") {
    s.kind = ShapeKind::Plane;
    s.planeNormal = c.normal.cast<float>().normalized();
    // Drawn as a square four times the domain's size across, about the point.
    const Vec3 n = s.planeNormal;
    const Vec3 a = (std::abs(n.x()) < 0.9f ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
    const Vec3 b = n.cross(a);
    const float half = 2 * domainSize;
    s.mesh.positions = {-half * a - half * b, half * a - half * b, half * a + half * b, -half * a + half * b};
    s.mesh.normals.assign(4, n);
    s.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
    s.bounds = Eigen::AlignedBox3f(Vec3::Constant(-half), Vec3::Constant(half));
  } else if (c.shape == "box") {
    s.kind = ShapeKind::Box;
    Eigen::Vector3d size = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < c.size.size(); ++k) size[k] = c.size[k];
    // In 2D a box is a prism through the plane, deep enough to draw.
    if (scene.dimensions == 2) size.z() = std::max(size.x(), size.y());
    s.halfExtents = (0.5 * size).cast<float>();
    s.mesh = boxMesh(s.halfExtents);
  } else if (c.shape == "sphere") {
    s.kind = ShapeKind::Sphere;
    s.radius = float(c.radius);
    s.mesh = sphereMesh(s.radius);
  } else if (c.shape == "capsule") {
    s.kind = ShapeKind::Capsule;
    s.radius = float(c.radius);
    s.halfHeight = float(0.5 * c.height);
    s.mesh = capsuleMesh(s.radius, s.halfHeight);
  } else if (c.shape == "cylinder") {
    s.kind = ShapeKind::Cylinder;
    s.radius = float(c.radius);
    s.halfHeight = float(0.5 * c.height);
    s.mesh = cylinderMesh(s.radius, s.halfHeight);
  } else if (c.shape == "heightfield") {
    s.kind = ShapeKind::Heightfield;
    s.heightfield = readHeightfieldPng(c.file, float(c.size[0]), float(c.size[1]), float(c.height), where,
                                       key + ".file");
    // The solid reaches a domain's size below its lowest point (the fluid stays above it everywhere).
    s.mesh = heightfieldMesh(s.heightfield, s.heightfield.minHeight() - domainSize, spacing / float(c.scale));
  } else {
    s.kind = ShapeKind::Mesh;
    s.mesh = readMeshFile(c.file, where, key + ".file");
    if (s.mesh.triangles.empty()) throw InputError(where, key + ".file", "'" + c.file + "' has no triangles");
    for (const Vec3& p : s.mesh.positions)
      if (!p.allFinite()) throw InputError(where, key + ".file", "'" + c.file + "' has a vertex that is not finite");
    // The grid's voxel is half a particle spacing in the world, the band covers the kernel and a spacing more.
    const float scale = float(c.scale);
    const float voxel = 0.5f * spacing / scale, band = (support + 2 * spacing) / scale;
    const bool closed = isClosedManifold(s.mesh);
    const float shell = closed ? 0.0f : float(c.thickness) / scale;
    Eigen::AlignedBox3f box;
    for (const Vec3& p : s.mesh.positions) box.extend(p);
    const Eigen::Array3f cells = ((box.sizes().array() + 2 * band + shell) / voxel).ceil() + 1;
    const double bytes = 4.0 * cells.cast<double>().prod();
    if (bytes > 2e9)
      throw InputError(where, key + ".file",
                       "the mesh's distance grid would need " + std::to_string(int(bytes / 1e9)) +
                           " GB at a voxel of half particle_spacing; scale the mesh down or coarsen the spacing");
    if (!closed && body)
      throw InputError(where, key + ".file",
                       "'" + c.file + "' is open or non-manifold: a body needs a closed mesh for its volume");
    if (!closed) {
      char line[256];
      std::snprintf(line, sizeof line, "is open or non-manifold: treated as a shell %.4g m thick", c.thickness);
      s.note = key + " (" + fs::path(c.file).filename().string() + ") " + line;
      if (s.container) throw InputError(where, key + ".container", "an open mesh cannot hold fluid");
    }
    s.grid = bakeMeshDistance(s.mesh, voxel, band, shell);
  }
  if (s.kind == ShapeKind::Heightfield) {
    const Heightfield& h = s.heightfield;
    s.bounds = Eigen::AlignedBox3f(Vec3(-0.5f * h.sizeX, h.minHeight() - domainSize, -0.5f * h.sizeZ),
                                   Vec3(0.5f * h.sizeX, h.maxHeight(), 0.5f * h.sizeZ));
  } else if (s.kind != ShapeKind::Plane) {
    s.bounds = Eigen::AlignedBox3f();
    for (const Vec3& p : s.mesh.positions) s.bounds.extend(p);
  }
  if (s.container)
    for (Vec3& n : s.mesh.normals) n = -n;

  // A collider that the domain does not reach would do nothing: surely a mistake in the scene.
  if (s.kind != ShapeKind::Plane) {
    const Pose pose = colliderPose(c, 0.0);
    Eigen::AlignedBox3d world;
    for (int corner = 0; corner < 8; ++corner)
      world.extend(pose.toWorld(s.bounds.corner(Eigen::AlignedBox3f::CornerType(corner)).cast<double>()));
    Eigen::AlignedBox3d domain(scene.domain.min, scene.domain.max);
    if (scene.dimensions == 2) {
      world.min().z() = std::min(world.min().z(), 0.0);
      world.max().z() = std::max(world.max().z(), 0.0);
      domain.min().z() = domain.max().z() = 0;
    }
    if (!isMoving(c) && !world.intersects(domain))
      throw InputError(where, key, "lies entirely outside the domain");
    // A body starts inside the tank (its box may reach past a wall by less than a particle radius).
    const double slack = 0.5 * scene.particle_spacing;
    for (int k = 0; body && k < scene.dimensions; ++k)
      if (world.min()[k] < domain.min()[k] - slack || world.max()[k] > domain.max()[k] + slack)
        throw InputError(where, key + ".position", "the body must start inside the domain");
  }
  return s;
}

}  // namespace surge
