#include "geometry/mass_properties.h"

#include <cmath>
#include <stdexcept>

#include "geometry/shapes.h"

namespace surge {

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
  const ShapeType& type = shapeType(shape.kind);
  MassProperties (*unitMass)(const ColliderShape&) = dimensions == 2 ? type.mass2d : type.mass3d;
  if (!unitMass)
    throw std::invalid_argument(std::string("massProperties: a ") + type.name + " has no finite mass" +
                                (dimensions == 2 ? " in 2D" : ""));
  MassProperties p = unitMass(shape);
  // Scaling by s: volume s^D, centre s, second moments s^(D+2).
  p.volume *= std::pow(scale, dimensions);
  p.mass = density * p.volume;
  p.centre *= scale;
  p.inertia *= density * std::pow(scale, dimensions + 2);
  return p;
}

}  // namespace surge
