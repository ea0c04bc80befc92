#include "geometry/mass_properties.h"

#include <cmath>
#include <stdexcept>

namespace surge {
namespace {

// Inertia about the centre of a solid of mass m with the principal moments (a, b, c) about x, y, z.
Eigen::Matrix3d diagonal(double a, double b, double c) { return Eigen::Vector3d(a, b, c).asDiagonal(); }

// 3D closed forms at unit density, unscaled (the shapes' own frames: capsule and cylinder along y).
MassProperties solid3d(const ColliderShape& s) {
  MassProperties p;
  const double r = s.radius, h = s.halfHeight;
  switch (s.kind) {
    case ShapeKind::Box: {
      const Eigen::Vector3d e = s.halfExtents.cast<double>();
      p.volume = 8 * e.x() * e.y() * e.z();
      const double m = p.volume;
      p.inertia = diagonal(m * (e.y() * e.y() + e.z() * e.z()) / 3, m * (e.x() * e.x() + e.z() * e.z()) / 3,
                           m * (e.x() * e.x() + e.y() * e.y()) / 3);
      break;
    }
    case ShapeKind::Sphere: {
      p.volume = 4.0 / 3.0 * M_PI * r * r * r;
      const double i = 0.4 * p.volume * r * r;
      p.inertia = diagonal(i, i, i);
      break;
    }
    case ShapeKind::Cylinder: {
      p.volume = M_PI * r * r * 2 * h;
      const double m = p.volume, across = m * (3 * r * r + 4 * h * h) / 12;
      p.inertia = diagonal(across, 0.5 * m * r * r, across);
      break;
    }
    case ShapeKind::Capsule: {
      // A cylinder and two hemispheres; a hemisphere's centre is 3r/8 from its flat face, and its moment
      // about an axis through that centre across the symmetry axis is 83/320 m r^2.
      const double cylinder = M_PI * r * r * 2 * h, cap = 2.0 / 3.0 * M_PI * r * r * r;
      p.volume = cylinder + 2 * cap;
      const double offset = h + 3.0 * r / 8.0;
      const double across =
          cylinder * (3 * r * r + 4 * h * h) / 12 + 2 * cap * (83.0 / 320.0 * r * r + offset * offset);
      const double along = 0.5 * cylinder * r * r + 2 * 0.4 * cap * r * r;
      p.inertia = diagonal(across, along, across);
      break;
    }
    case ShapeKind::Mesh:
      return meshMassProperties(s.mesh);
    default:
      throw std::invalid_argument("massProperties: a plane or a heightfield has no finite mass");
  }
  return p;
}

// 2D cross-sections at z = 0 at unit density per area, unscaled: only the moment about z is filled.
MassProperties solid2d(const ColliderShape& s) {
  MassProperties p;
  const double r = s.radius, h = s.halfHeight;
  double izz = 0;
  switch (s.kind) {
    case ShapeKind::Box: {
      const double a = s.halfExtents.x(), b = s.halfExtents.y();
      p.volume = 4 * a * b;
      izz = p.volume * (a * a + b * b) / 3;
      break;
    }
    case ShapeKind::Sphere:
      p.volume = M_PI * r * r;
      izz = 0.5 * p.volume * r * r;
      break;
    case ShapeKind::Cylinder:  // a rectangle 2r across, 2h along y
      p.volume = 4 * r * h;
      izz = p.volume * (r * r + h * h) / 3;
      break;
    case ShapeKind::Capsule: {
      // A rectangle and two half discs; a half disc's centre is 4r/(3 pi) from its straight edge.
      const double rectangle = 4 * r * h, half = 0.5 * M_PI * r * r;
      p.volume = rectangle + 2 * half;
      const double c = 4 * r / (3 * M_PI), offset = h + c;
      izz = rectangle * (r * r + h * h) / 3 + 2 * half * (0.5 * r * r - c * c + offset * offset);
      break;
    }
    default:
      throw std::invalid_argument("massProperties: only a box, sphere, capsule or cylinder in 2D");
  }
  p.inertia = diagonal(0, 0, izz);
  return p;
}

}  // namespace

MassProperties meshMassProperties(const TriangleMesh& mesh) {
  // Each triangle (a, b, c) with the origin spans a tetrahedron of signed volume det / 6, det = a . (b x c);
  // its second moment sum_x x x^T dV is det / 120 (sum_i x_i x_i^T + (sum_i x_i)(sum_i x_i)^T).
  double volume = 0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                          c = mesh.positions[t[2]].cast<double>();
    const double det = a.dot(b.cross(c));
    const Eigen::Vector3d sum = a + b + c;
    volume += det / 6;
    first += det / 24 * sum;
    second += det / 120 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose());
  }
  MassProperties p;
  p.volume = volume;
  if (!(volume > 0)) return p;
  p.mass = volume;
  p.centre = first / volume;
  const Eigen::Matrix3d central = second - volume * p.centre * p.centre.transpose();
  p.inertia = central.trace() * Eigen::Matrix3d::Identity() - central;
  return p;
}

MassProperties massProperties(const ColliderShape& shape, double scale, int dimensions, double density) {
  MassProperties p = dimensions == 2 ? solid2d(shape) : solid3d(shape);
  // Scaling by s: volume s^D, centre s, second moments s^(D+2).
  p.volume *= std::pow(scale, dimensions);
  p.mass = density * p.volume;
  p.centre *= scale;
  p.inertia *= density * std::pow(scale, dimensions + 2);
  return p;
}

}  // namespace surge
