#include "geometry/collider_shape.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "geometry/pose.h"
#include "geometry/shapes.h"

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

ColliderShape buildColliderShape(const Scene& scene, size_t index) {
  return buildSolidShape(scene, scene.colliders.at(index), "colliders[" + std::to_string(index) + "]", false);
}

ColliderShape buildBodyShape(const Scene& scene, size_t index) {
  return buildSolidShape(scene, scene.bodies.at(index).solid, "bodies[" + std::to_string(index) + "]", true);
}

Eigen::AlignedBox3d worldBounds(const ColliderShape& shape, const Pose& pose) {
  Eigen::AlignedBox3d world;
  for (int corner = 0; corner < 8; ++corner)
    world.extend(pose.toWorld(shape.bounds.corner(Eigen::AlignedBox3f::CornerType(corner)).cast<double>()));
  return world;
}

// Along a periodic axis (domain.periodic) a solid is not wrapped: it must stay a kernel radius clear of the seam
// at every keyframe, or span the axis (a plate the length of the domain, which looks the same from either side).
// Bodies move freely and are refused.
static void checkPeriodicSeams(const Scene& scene, const ColliderSettings& c, const ColliderShape& s,
                               const std::string& key, const std::string& where, bool body, float support) {
  if (scene.periodicAxes() == 0) return;
  if (body) throw InputError(where, key, "a body cannot cross a periodic seam: remove it or domain.periodic");
  // At time 0, at each keyframe and at 7 times between two (a translation moves the bounds linearly, so its
  // keyframes decide; a rotation between keyframes can sweep a corner across the seam, seen at 1/8 of the turn).
  std::vector<double> times = {0.0};
  for (const ColliderKeyframe& k : c.motion) {
    for (int step = 1; step < 8 && k.time > times.back(); ++step)
      times.push_back(times.back() + (k.time - times.back()) / (9 - step));
    times.push_back(k.time);
  }
  for (double time : times) {
    const Pose pose = colliderPose(c, time);
    for (int k = 0; k < scene.dimensions; ++k) {
      if (!scene.isPeriodic(k)) continue;
      double lo, hi;
      if (s.kind == ShapeKind::Plane) {
        const Eigen::Vector3d n = pose.rotation * s.planeNormal.cast<double>();
        if (std::abs(n[k]) < 1e-9) continue;  // the plane runs along the axis
        lo = hi = pose.translation[k];
      } else {
        const Eigen::AlignedBox3d world = worldBounds(s, pose);
        lo = world.min()[k];
        hi = world.max()[k];
      }
      const double min = scene.domain.min[k], max = scene.domain.max[k];
      const bool inside = lo >= min + support && hi <= max - support;
      const bool spans = lo <= min - support && hi >= max + support;
      if (!inside && !spans) {
        const std::string axis(1, char('x' + k));
        throw InputError(where, key,
                         "crosses the periodic seam along " + axis + " unclosed: keep it a kernel radius inside the "
                         "domain along " + axis + " at every time, or make it span the domain along " + axis);
      }
    }
  }
}

ColliderShape buildSolidShape(const Scene& scene, const ColliderSettings& c, const std::string& key, bool body) {
  const std::string where = scene.source.empty() ? "scene" : scene.source;
  const float spacing = float(scene.particle_spacing);
  const float support = float(scene.solver.kernel_radius > 0 ? scene.solver.kernel_radius : 2 * spacing);
  const Vec3 domainExtent = (scene.domain.max - scene.domain.min).cast<float>();
  const float domainSize = domainExtent.norm();
  const ShapeType* type = findShapeType(c.shape);
  if (!type) throw InputError(where, key + ".shape", "unknown shape '" + c.shape + "'");
  if (!body && !type->collider) throw InputError(where, key + ".shape", "a " + c.shape + " cannot be a collider");
  if (body && !type->body) throw InputError(where, key + ".shape", "a " + c.shape + " cannot be a body");
  if (body && scene.dimensions == 2 && !type->body2d)
    throw InputError(where, key + ".shape", "a " + c.shape + " body needs 3 dimensions");
  ColliderShape s;
  s.kind = type->kind;
  s.container = c.container != 0;
  type->build(s, ShapeInput{scene, c, key, where, body, spacing, support, domainSize});
  if (s.container)
    for (Vec3& n : s.mesh.normals) n = -n;

  // A collider that the domain does not reach would do nothing: surely a mistake in the scene.
  if (s.kind != ShapeKind::Plane) {
    Eigen::AlignedBox3d world = worldBounds(s, colliderPose(c, 0.0));
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
  checkPeriodicSeams(scene, c, s, key, where, body, support);
  return s;
}

}  // namespace surge
