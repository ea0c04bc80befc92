#include "sim/colliders.h"

#include <cmath>
#include <limits>

#include "geometry/pose.h"

namespace surge {

std::shared_ptr<const ColliderShapes> buildColliderShapes(const Scene& scene) {
  auto shapes = std::make_shared<ColliderShapes>();
  for (size_t i = 0; i < scene.colliders.size(); ++i) shapes->push_back(buildColliderShape(scene, i));
  return shapes;
}

template <int Dim>
Colliders<Dim>::Colliders(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes,
                          const TankWalls<Dim>& tank)
    : shapes_(std::move(shapes)), settings_(scene.colliders), tank_(&tank) {
  if (!shapes_ && !scene.colliders.empty()) shapes_ = buildColliderShapes(scene);
  support_ = static_cast<float>(scene.solver.kernel_radius);
  radius_ = static_cast<float>(0.5 * scene.particle_spacing);
  placed_.resize(settings_.size());
  extra_.assign(settings_.size(), Wrench{});
  for (size_t c = 0; c < placed_.size(); ++c) {
    placed_[c].shape = &(*shapes_)[c];
    placed_[c].friction = static_cast<float>(settings_[c].friction);
    placed_[c].moving = isMoving(settings_[c]);
    hasFriction_ = hasFriction_ || settings_[c].friction > 0;
  }
  beginStep(0.0, 0.0f);
}

template <int Dim>
void Colliders<Dim>::beginStep(double time, float dt) {
  dt_ = dt;
  for (size_t c = 0; c < placed_.size(); ++c) {
    Placed& k = placed_[c];
    const ColliderShape& shape = *k.shape;
    const Pose end = colliderPose(settings_[c], time + dt);
    const Pose start = k.moving ? colliderPose(settings_[c], time) : end;
    k.rotation = end.rotation.toRotationMatrix().cast<float>();
    k.translation = end.translation.cast<float>();
    k.previousRotation = start.rotation.toRotationMatrix().cast<float>();
    k.previousTranslation = start.translation.cast<float>();
    k.scale = static_cast<float>(end.scale);
    k.centre = k.translation.template head<Dim>();
    // The near box: the shape's box at both ends of the step, grown by the support. A plane and a container
    // reach everywhere.
    constexpr float kEverywhere = std::numeric_limits<float>::infinity();
    if (shape.kind == ShapeKind::Plane || shape.container) {
      k.near = Eigen::AlignedBox<float, Dim>(Vec<Dim>::Constant(-kEverywhere), Vec<Dim>::Constant(kEverywhere));
      continue;
    }
    Eigen::AlignedBox3f world;
    for (const Pose* pose : {&start, &end})
      for (int corner = 0; corner < 8; ++corner)
        world.extend(pose->toWorld(shape.bounds.corner(Eigen::AlignedBox3f::CornerType(corner)).cast<double>())
                         .cast<float>());
    const float grow = support_ + radius_;
    k.near = Eigen::AlignedBox<float, Dim>(world.min().template head<Dim>() - Vec<Dim>::Constant(grow),
                                           world.max().template head<Dim>() + Vec<Dim>::Constant(grow));
  }
}

template <int Dim>
float Colliders<Dim>::distance(size_t c, const VecD& p, VecD& normal) const {
  const Placed& k = placed_[c];
  Eigen::Vector3f world = Eigen::Vector3f::Zero();
  world.template head<Dim>() = p;
  const Eigen::Vector3f local = k.rotation.transpose() * (world - k.translation) / k.scale;
  Eigen::Vector3f localNormal;
  const float d = k.shape->distance(local, localNormal) * k.scale;
  const Eigen::Vector3f n = k.rotation * localNormal;
  if constexpr (Dim == 3) {
    normal = n;
  } else {
    // In 2D the shape is cut by the plane z = 0; its normal there lies in the plane for every shape placed
    // by rotations about z, and is renormalised otherwise.
    const float length = n.head<2>().norm();
    normal = length > 1e-6f ? Vec<2>(n.head<2>() / length) : Vec<2>(0, 1);
  }
  return d;
}

template <int Dim>
bool Colliders<Dim>::sweep(size_t c, const VecD& from, const VecD& p, VecD& delta) const {
  const Placed& k = placed_[c];
  const Eigen::AlignedBox<float, Dim> segment(from.cwiseMin(p), from.cwiseMax(p));
  if (!k.near.intersects(segment)) return false;
  const VecD move = p - from;
  const float length = move.norm();
  if (!std::isfinite(length)) return false;  // a diverged particle is reported, not moved
  VecD normal;
  const float atEnd = distance(c, p, normal);
  // Every point of the segment is at least atEnd - length from the solid (a distance is 1-Lipschitz).
  if (atEnd >= radius_ + length) return false;
  // Sphere tracing from `from`: steps as long as the distance allows, and at least half a radius. A wall one
  // spacing (two radii) thick has a band four radii deep closer than a radius, which no step can cross.
  const float shortest = 0.5f * radius_;
  float t = 0, d = 0;
  VecD at = from;
  while (true) {
    at = length > 0 ? VecD(from + (t / length) * move) : from;
    d = distance(c, at, normal);
    if (d < radius_) break;
    if (t >= length) return false;
    t = std::min(length, t + std::max(d - radius_, shortest));
  }
  // Stop on the surface at a radius and keep the rest of the move along it.
  VecD target = at + (radius_ - d) * normal;
  VecD rest = p - at;
  rest -= rest.dot(normal) * normal;
  target += rest;
  VecD after;
  const float landed = distance(c, target, after);
  if (landed < radius_) target += (radius_ - landed) * after;
  delta = target - p;
  return true;
}

template <int Dim>
typename Colliders<Dim>::VecD Colliders<Dim>::wallVelocity(size_t c, const VecD& p) const {
  const Placed& k = placed_[c];
  if (!k.moving || !(dt_ > 0)) return VecD::Zero();
  Eigen::Vector3f world = Eigen::Vector3f::Zero();
  world.template head<Dim>() = p;
  const Eigen::Vector3f local = k.rotation.transpose() * (world - k.translation);
  const Eigen::Vector3f before = k.previousRotation * local + k.previousTranslation;
  return ((world - before) / dt_).template head<Dim>();
}

template <int Dim>
void Colliders<Dim>::resetSlots(size_t particles) {
  const size_t chunks = (particles + kChunk - 1) / kChunk;
  slots_.assign(chunks * placed_.size(), Wrench{});
}

template <int Dim>
std::vector<Wrench> Colliders<Dim>::takeSlotSums() {
  const size_t n = placed_.size();
  std::vector<Wrench> total(n);
  for (size_t s = 0; s < slots_.size(); ++s) {
    total[s % n].force += slots_[s].force;
    total[s % n].torque += slots_[s].torque;
    slots_[s] = Wrench{};
  }
  return total;
}

template <int Dim>
void Colliders<Dim>::addWrenches(const std::vector<Wrench>& wrenches, double scale) {
  for (size_t c = 0; c < extra_.size(); ++c) {
    extra_[c].force += scale * wrenches[c].force;
    extra_[c].torque += scale * wrenches[c].torque;
  }
}

template <int Dim>
std::vector<Wrench> Colliders<Dim>::takeFrameWrenches(double duration) {
  addWrenches(takeSlotSums(), 1.0);
  std::vector<Wrench> total = extra_;
  for (Wrench& w : total) {
    w.force /= duration;
    w.torque /= duration;
  }
  extra_.assign(placed_.size(), Wrench{});
  return total;
}

template <int Dim>
void Colliders<Dim>::applyFriction(size_t i, const VecD& x, VecD& v, float mass) {
  forEachNear(x, [&](size_t c, float d, const VecD& n) {
    const float mu = placed_[c].friction;
    if (mu == 0 || d >= contactDistance()) return;
    const VecD relative = v - wallVelocity(c, x);
    const VecD tangential = relative - relative.dot(n) * n;
    const VecD change = -mu * tangential;
    v += change;
    addImpulse(i, c, mass * change, x);
  });
}

template <int Dim>
size_t Colliders<Dim>::memoryBytes() const {
  size_t bytes = slots_.capacity() * sizeof(Wrench);
  if (shapes_)
    for (const ColliderShape& s : *shapes_) bytes += s.memoryBytes();
  return bytes;
}

template class Colliders<2>;
template class Colliders<3>;

}  // namespace surge
