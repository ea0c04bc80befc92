// The shapes' entries (shapes.h): each one's builder from its scene settings and its mass properties in closed
// form (a mesh's by its volume integrals, mass_properties.cpp).
#include "geometry/shapes.h"

#include <cmath>
#include <cstdio>
#include <utility>

#include "core/errors.h"
#include "geometry/shape_files.h"
#include "geometry/triangle_mesh.h"

namespace surge {
namespace {

using Vec3 = Eigen::Vector3f;

// Inertia about the centre of a solid of mass m with the principal moments (a, b, c) about x, y, z.
Eigen::Matrix3d diagonal(double a, double b, double c) {
  return Eigen::Vector3d(a, b, c).asDiagonal();
}

Eigen::AlignedBox3f meshBounds(const TriangleMesh& mesh) {
  Eigen::AlignedBox3f bounds;
  for (const Vec3& p : mesh.positions) bounds.extend(p);
  return bounds;
}

// An analytic shape's drawing mesh, which bounds it.
void setMesh(ColliderShape& s, TriangleMesh mesh) {
  s.mesh = std::move(mesh);
  s.bounds = meshBounds(s.mesh);
}

// Plane: a half-space, drawn as a square four times the domain's size across, about the point.
void buildPlane(ColliderShape& s, const ShapeInput& in) {
  s.planeNormal = in.settings.normal.cast<float>().normalized();
  const Vec3 n = s.planeNormal;
  const Vec3 a = (std::abs(n.x()) < 0.9f ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 b = n.cross(a);
  const float half = 2 * in.domainSize;
  s.mesh.positions = {-half * a - half * b, half * a - half * b, half * a + half * b, -half * a + half * b};
  s.mesh.normals.assign(4, n);
  s.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.bounds = Eigen::AlignedBox3f(Vec3::Constant(-half), Vec3::Constant(half));
}

// Box: in 2D a prism through the plane, deep enough to draw.
void buildBox(ColliderShape& s, const ShapeInput& in) {
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < in.settings.size.size(); ++k) size[k] = in.settings.size[k];
  if (in.scene.dimensions == 2) size.z() = std::max(size.x(), size.y());
  s.halfExtents = (0.5 * size).cast<float>();
  setMesh(s, boxMesh(s.halfExtents));
}

MassProperties boxMass3d(const ColliderShape& s) {
  MassProperties p;
  const Eigen::Vector3d e = s.halfExtents.cast<double>();
  p.volume = 8 * e.x() * e.y() * e.z();
  const double m = p.volume;
  p.inertia = diagonal(m * (e.y() * e.y() + e.z() * e.z()) / 3, m * (e.x() * e.x() + e.z() * e.z()) / 3,
                       m * (e.x() * e.x() + e.y() * e.y()) / 3);
  return p;
}

MassProperties boxMass2d(const ColliderShape& s) {
  MassProperties p;
  const double a = s.halfExtents.x(), b = s.halfExtents.y();
  p.volume = 4 * a * b;
  p.inertia = diagonal(0, 0, p.volume * (a * a + b * b) / 3);
  return p;
}

void buildSphere(ColliderShape& s, const ShapeInput& in) {
  s.radius = float(in.settings.radius);
  setMesh(s, sphereMesh(s.radius));
}

MassProperties sphereMass3d(const ColliderShape& s) {
  MassProperties p;
  const double r = s.radius;
  p.volume = 4.0 / 3.0 * M_PI * r * r * r;
  const double i = 0.4 * p.volume * r * r;
  p.inertia = diagonal(i, i, i);
  return p;
}

MassProperties sphereMass2d(const ColliderShape& s) {
  MassProperties p;
  const double r = s.radius;
  p.volume = M_PI * r * r;
  p.inertia = diagonal(0, 0, 0.5 * p.volume * r * r);
  return p;
}

// Capsule and cylinder: a radius, and a half height along local y.
void setRadiusAndHalfHeight(ColliderShape& s, const ShapeInput& in) {
  s.radius = float(in.settings.radius);
  s.halfHeight = float(0.5 * in.settings.height);
}

void buildCapsule(ColliderShape& s, const ShapeInput& in) {
  setRadiusAndHalfHeight(s, in);
  setMesh(s, capsuleMesh(s.radius, s.halfHeight));
}

// A cylinder and two hemispheres; a hemisphere's centre is 3r/8 from its flat face, and its moment about an
// axis through that centre across the symmetry axis is 83/320 m r^2.
MassProperties capsuleMass3d(const ColliderShape& s) {
  MassProperties p;
  const double r = s.radius, h = s.halfHeight;
  const double cylinder = M_PI * r * r * 2 * h, cap = 2.0 / 3.0 * M_PI * r * r * r;
  p.volume = cylinder + 2 * cap;
  const double offset = h + 3.0 * r / 8.0;
  const double across = cylinder * (3 * r * r + 4 * h * h) / 12 + 2 * cap * (83.0 / 320.0 * r * r + offset * offset);
  const double along = 0.5 * cylinder * r * r + 2 * 0.4 * cap * r * r;
  p.inertia = diagonal(across, along, across);
  return p;
}

// A rectangle and two half discs; a half disc's centre is 4r/(3 pi) from its straight edge.
MassProperties capsuleMass2d(const ColliderShape& s) {
  MassProperties p;
  const double r = s.radius, h = s.halfHeight;
  const double rectangle = 4 * r * h, half = 0.5 * M_PI * r * r;
  p.volume = rectangle + 2 * half;
  const double c = 4 * r / (3 * M_PI), offset = h + c;
  p.inertia = diagonal(0, 0, rectangle * (r * r + h * h) / 3 + 2 * half * (0.5 * r * r - c * c + offset * offset));
  return p;
}

void buildCylinder(ColliderShape& s, const ShapeInput& in) {
  setRadiusAndHalfHeight(s, in);
  setMesh(s, cylinderMesh(s.radius, s.halfHeight));
}

MassProperties cylinderMass3d(const ColliderShape& s) {
  MassProperties p;
  const double r = s.radius, h = s.halfHeight;
  p.volume = M_PI * r * r * 2 * h;
  const double m = p.volume, across = m * (3 * r * r + 4 * h * h) / 12;
  p.inertia = diagonal(across, 0.5 * m * r * r, across);
  return p;
}

// A rectangle 2r across, 2h along y.
MassProperties cylinderMass2d(const ColliderShape& s) {
  MassProperties p;
  const double r = s.radius, h = s.halfHeight;
  p.volume = 4 * r * h;
  p.inertia = diagonal(0, 0, p.volume * (r * r + h * h) / 3);
  return p;
}

// Heightfield: the solid reaches a domain's size below its lowest point (the fluid stays above it everywhere).
void buildHeightfield(ColliderShape& s, const ShapeInput& in) {
  const ColliderSettings& c = in.settings;
  s.heightfield =
      readHeightfieldPng(c.file, float(c.size[0]), float(c.size[1]), float(c.height), in.where, in.key + ".file");
  const Heightfield& h = s.heightfield;
  s.mesh = heightfieldMesh(h, h.minHeight() - in.domainSize, in.spacing / float(c.scale));
  s.bounds = Eigen::AlignedBox3f(Vec3(-0.5f * h.sizeX, h.minHeight() - in.domainSize, -0.5f * h.sizeZ),
                                 Vec3(0.5f * h.sizeX, h.maxHeight(), 0.5f * h.sizeZ));
}

// Mesh: its distance baked on a grid whose voxel is half a particle spacing in the world, its band the kernel
// and a spacing more; an open mesh becomes a shell (not for a body or a container).
void buildMesh(ColliderShape& s, const ShapeInput& in) {
  const ColliderSettings& c = in.settings;
  const std::string& where = in.where;
  const std::string fileKey = in.key + ".file";
  s.mesh = readMeshFile(c.file, where, fileKey);
  if (s.mesh.triangles.empty()) throw InputError(where, fileKey, "'" + c.file + "' has no triangles");
  for (const Vec3& p : s.mesh.positions)
    if (!p.allFinite()) throw InputError(where, fileKey, "'" + c.file + "' has a vertex that is not finite");
  const float scale = float(c.scale);
  const float voxel = 0.5f * in.spacing / scale, band = (in.support + 2 * in.spacing) / scale;
  const bool closed = isClosedManifold(s.mesh);
  const float shell = closed ? 0.0f : float(c.thickness) / scale;
  const Eigen::AlignedBox3f box = meshBounds(s.mesh);
  const Eigen::Array3f cells = ((box.sizes().array() + 2 * band + shell) / voxel).ceil() + 1;
  const double bytes = 4.0 * cells.cast<double>().prod();
  if (bytes > 2e9)
    throw InputError(where, fileKey,
                     "the mesh's distance grid would need " + std::to_string(int(bytes / 1e9)) +
                         " GB at a voxel of half particle_spacing; scale the mesh down or coarsen the spacing");
  if (!closed && in.body)
    throw InputError(where, fileKey,
                     "'" + c.file + "' is open or non-manifold: a body or a fluid needs a closed mesh for its volume");
  if (!closed) {
    char line[256];
    std::snprintf(line, sizeof line, "is open or non-manifold: treated as a shell %.4g m thick", c.thickness);
    s.note = in.key + " (" + fs::path(c.file).filename().string() + ") " + line;
    if (s.container) throw InputError(where, in.key + ".container", "an open mesh cannot hold fluid");
  }
  s.grid = bakeMeshDistance(s.mesh, voxel, band, shell);
  s.bounds = box;
}

MassProperties meshMass3d(const ColliderShape& s) {
  return meshMassProperties(s.mesh);
}

// In ShapeKind's order (checked below).
constexpr std::array<ShapeType, kShapeKinds> kShapes = {{
    {"plane", ShapeKind::Plane, true, false, false, buildPlane, nullptr, nullptr},
    {"box", ShapeKind::Box, true, true, true, buildBox, boxMass3d, boxMass2d},
    {"sphere", ShapeKind::Sphere, true, true, true, buildSphere, sphereMass3d, sphereMass2d},
    {"capsule", ShapeKind::Capsule, true, true, true, buildCapsule, capsuleMass3d, capsuleMass2d},
    {"cylinder", ShapeKind::Cylinder, true, true, true, buildCylinder, cylinderMass3d, cylinderMass2d},
    {"heightfield", ShapeKind::Heightfield, true, false, false, buildHeightfield, nullptr, nullptr},
    {"mesh", ShapeKind::Mesh, true, true, false, buildMesh, meshMass3d, nullptr},
}};

constexpr bool inKindOrder() {
  for (size_t k = 0; k < kShapes.size(); ++k)
    if (kShapes[k].kind != ShapeKind(k) || !kShapes[k].build) return false;
  return true;
}
static_assert(inKindOrder(), "kShapes must hold every ShapeKind once, in order, each with its builder");

}  // namespace

const std::array<ShapeType, kShapeKinds>& shapeTypes() {
  return kShapes;
}

const ShapeType& shapeType(ShapeKind kind) {
  return kShapes[size_t(kind)];
}

const ShapeType* findShapeType(const std::string& name) {
  for (const ShapeType& t : kShapes)
    if (name == t.name) return &t;
  return nullptr;
}

}  // namespace surge
