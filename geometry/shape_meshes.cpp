// Triangle meshes of the analytic shapes, in their own frames, with outward normals: what the renderers draw
// and what the output folder holds for Blender.
#include <cmath>

#include "geometry/collider_shape.h"

namespace surge {
namespace {

using Vec3 = Eigen::Vector3f;

// A surface of revolution about y from a profile of (radius, y, normal radial part, normal y) points, bottom to
// top; the first and last points on the axis close it.
struct ProfilePoint {
  float radius, y, normalRadial, normalY;
};

TriangleMesh revolve(const std::vector<ProfilePoint>& profile, int segments) {
  TriangleMesh mesh;
  const int rings = int(profile.size());
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      const float angle = 2 * float(M_PI) * s / segments;
      const float c = std::cos(angle), sn = std::sin(angle);
      const ProfilePoint& p = profile[r];
      mesh.positions.emplace_back(p.radius * c, p.y, p.radius * sn);
      mesh.normals.push_back(Vec3(p.normalRadial * c, p.normalY, p.normalRadial * sn).normalized());
    }
  const uint32_t stride = uint32_t(segments + 1);
  for (int r = 0; r + 1 < rings; ++r) {
    if (profile[r].y == profile[r + 1].y && profile[r].radius == profile[r + 1].radius) continue;  // a crease
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = r * stride + s, b = a + 1, c = a + stride, d = c + 1;
      mesh.triangles.push_back({a, c, b});  // outward: counter-clockwise seen from outside
      mesh.triangles.push_back({b, c, d});
    }
  }
  return mesh;
}

}  // namespace

TriangleMesh boxMesh(const Vec3& h) {
  TriangleMesh mesh;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = -1; side <= 1; side += 2) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Vec3 normal = Vec3::Zero();
      normal[axis] = float(side);
      const uint32_t base = uint32_t(mesh.positions.size());
      for (int corner = 0; corner < 4; ++corner) {
        Vec3 p;
        p[axis] = side * h[axis];
        p[u] = (corner == 1 || corner == 2 ? 1 : -1) * h[u];
        p[v] = (corner >= 2 ? 1 : -1) * h[v];
        mesh.positions.push_back(p);
        mesh.normals.push_back(normal);
      }
      // Corners go (-u,-v), (+u,-v), (+u,+v), (-u,+v): counter-clockwise about +axis; flipped for -axis.
      if (side > 0) {
        mesh.triangles.push_back({base, base + 1, base + 2});
        mesh.triangles.push_back({base, base + 2, base + 3});
      } else {
        mesh.triangles.push_back({base, base + 2, base + 1});
        mesh.triangles.push_back({base, base + 3, base + 2});
      }
    }
  return mesh;
}

TriangleMesh sphereMesh(float radius, int segments) {
  return capsuleMesh(radius, 0.0f, segments);
}

TriangleMesh capsuleMesh(float radius, float halfHeight, int segments) {
  std::vector<ProfilePoint> profile;
  const int quarter = segments / 4;
  for (int k = -quarter; k <= quarter; ++k) {
    const float angle = float(M_PI) / 2 * k / quarter;  // -pi/2 (bottom) to pi/2 (top)
    const float c = std::cos(angle), s = std::sin(angle);
    const float offset = halfHeight > 0 ? (k < 0 ? -halfHeight : k > 0 ? halfHeight : 0.0f) : 0.0f;
    if (k == 0 && halfHeight > 0) {
      profile.push_back({radius, -halfHeight, 1, 0});
      profile.push_back({radius, halfHeight, 1, 0});
      continue;
    }
    profile.push_back({radius * c, offset + radius * s, c, s});
  }
  return revolve(profile, segments);
}

TriangleMesh cylinderMesh(float radius, float halfHeight, int segments) {
  // Creases at the rims: each rim point twice, once with the cap's normal and once with the side's.
  return revolve({{0, -halfHeight, 0, -1},
                  {radius, -halfHeight, 0, -1},
                  {radius, -halfHeight, 1, 0},
                  {radius, halfHeight, 1, 0},
                  {radius, halfHeight, 0, 1},
                  {0, halfHeight, 0, 1}},
                 segments);
}

}  // namespace surge
