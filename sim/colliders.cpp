#include "sim/colliders.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "core/parallel.h"
#include "geometry/pose.h"

namespace surge {

std::shared_ptr<const ColliderShapes> buildColliderShapes(const Scene& scene) {
  auto shapes = std::make_shared<ColliderShapes>();
  for (size_t i = 0; i < scene.colliders.size(); ++i) shapes->push_back(buildColliderShape(scene, i));
  for (size_t i = 0; i < scene.bodies.size(); ++i) shapes->push_back(buildBodyShape(scene, i));
  return shapes;
}

template <int Dim>
Colliders<Dim>::Colliders(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes,
                          const TankWalls<Dim>& tank)
    : shapes_(std::move(shapes)), settings_(scene.colliders), tank_(&tank) {
  if (!shapes_ && hasSolids(scene)) shapes_ = buildColliderShapes(scene);
  firstBody_ = settings_.size();
  for (const BodySettings& b : scene.bodies) {
    settings_.push_back(b.solid);
    settings_.back().friction = 0;  // a body's friction is its contacts'; the fluid slides along it
    bodyStart_.push_back(colliderPose(b.solid, 0.0));
  }
  bodyEnd_ = bodyStart_;
  bodyCentre_.assign(scene.bodies.size(), Eigen::Vector3d::Zero());
  support_ = static_cast<float>(scene.solver.kernel_radius);
  radius_ = static_cast<float>(0.5 * scene.particle_spacing);
  placed_.resize(settings_.size());
  if (placed_.size() > 65535) throw InputError(scene.source, "colliders", "more than 65535 colliders and bodies");
  for (size_t c = 0; c < placed_.size(); ++c) all_.push_back(static_cast<uint16_t>(c));
  extra_.assign(settings_.size(), Wrench{});
  stepMark_ = extra_;
  // The candidates' grid over the tank.
  for (int k = 0; k < Dim; ++k) {
    const float extent = static_cast<float>(scene.domain.max[k] - scene.domain.min[k]);
    const float cell = std::max(support_, extent / 64);
    gridCounts_[k] = std::max(1, static_cast<int>(std::ceil(extent / cell)));
    gridMin_[k] = static_cast<float>(scene.domain.min[k]);
    cellInverse_[k] = gridCounts_[k] / extent;
  }
  for (size_t c = 0; c < placed_.size(); ++c) {
    placed_[c].shape = &(*shapes_)[c];
    placed_[c].friction = static_cast<float>(settings_[c].friction);
    placed_[c].moving = isMoving(settings_[c]) || c >= firstBody_;
    hasFriction_ = hasFriction_ || settings_[c].friction > 0;
  }
  beginStep(0.0, 0.0f);
}

template <int Dim>
void Colliders<Dim>::setBodyPose(size_t body, const Pose& pose, const Eigen::Vector3d& centreOfMass) {
  bodyStart_[body] = bodyEnd_[body];
  bodyEnd_[body] = pose;
  bodyCentre_[body] = centreOfMass;
}

template <int Dim>
void Colliders<Dim>::placeAtStepStart(double time, float dt) {
  // A body's start pose S and end pose E: placed at S, its step-start pose taken as S E^-1 S (the coming step's
  // motion run backwards from S), so that its walls move at the coming step's velocity.
  const std::vector<Pose> start = bodyStart_, end = bodyEnd_;
  for (size_t b = 0; b < start.size(); ++b) {
    const Pose& s = start[b];
    const Eigen::Quaterniond back = s.rotation * end[b].rotation.conjugate();
    bodyEnd_[b] = s;
    bodyStart_[b].rotation = (back * s.rotation).normalized();
    bodyStart_[b].translation = back * (s.translation - end[b].translation) + s.translation;
    bodyStart_[b].scale = s.scale;
  }
  beginStep(time - dt, dt);
  bodyStart_ = start;
  bodyEnd_ = end;
}

template <int Dim>
std::vector<Wrench> Colliders<Dim>::takeStepWrenches(double dt) {
  addWrenches(takeSlotSums(), 1.0);
  std::vector<Wrench> step(extra_.size());
  for (size_t c = 0; c < extra_.size(); ++c) {
    step[c].force = (extra_[c].force - stepMark_[c].force) / dt;
    step[c].torque = (extra_[c].torque - stepMark_[c].torque) / dt;
  }
  stepMark_ = extra_;
  return step;
}

template <int Dim>
void Colliders<Dim>::beginStep(double time, float dt) {
  dt_ = dt;
  for (size_t c = 0; c < placed_.size(); ++c) {
    Placed& k = placed_[c];
    const ColliderShape& shape = *k.shape;
    const bool body = c >= firstBody_;
    const Pose end = body ? bodyEnd_[c - firstBody_] : colliderPose(settings_[c], time + dt);
    const Pose start = body ? bodyStart_[c - firstBody_] : k.moving ? colliderPose(settings_[c], time) : end;
    k.rotation = end.rotation.toRotationMatrix().cast<float>();
    k.translation = end.translation.cast<float>();
    k.previousRotation = start.rotation.toRotationMatrix().cast<float>();
    k.previousTranslation = start.translation.cast<float>();
    k.scale = static_cast<float>(end.scale);
    // friction is the fraction of the sliding velocity taken away over kFrictionTime of contact, so that it
    // means the same at any number of substeps: over a step dt, 1 - (1 - friction)^(dt / kFrictionTime).
    k.frictionThisStep =
        k.friction >= 1 ? 1.0f : static_cast<float>(1 - std::pow(1.0 - k.friction, double(dt) / kFrictionTime));
    // Torques are about a collider's position, a body's centre of mass.
    k.centre = body ? Vec<Dim>(bodyCentre_[c - firstBody_].cast<float>().template head<Dim>())
                    : Vec<Dim>(k.translation.template head<Dim>());
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
    // A box, collider or body, is counted exactly (a body kept the flat wall while a heavy box rested on a
    // trapped layer of water, which no longer forms: docs/bodies.md).
    if (shape.kind == ShapeKind::Box && !shape.container) placeBox(k);
  }
  buildGrid();
}

template <int Dim>
void Colliders<Dim>::placeBox(Placed& k) const {
  k.boxMax = k.shape->halfExtents * k.scale;
  k.boxMin = -k.boxMax;
  k.exactBox = false;
  // In 2D the box is cut by the plane z = 0: its own z axis must be the world's.
  if (Dim == 2 && std::abs(k.rotation(2, 2)) < 1 - 1e-6f) return;
  // A box inside the tank (within a quarter spacing, as a body resting on the floor may sink) shares no
  // lattice with the tank's walls.
  const float tolerance = 0.5f * radius_;
  bool inside = true;
  for (int corner = 0; corner < (1 << Dim); ++corner) {
    Eigen::Vector3f local;
    for (int a = 0; a < 3; ++a) local[a] = (corner >> a & 1) ? k.boxMax[a] : k.boxMin[a];
    const VecD at = (k.rotation * local + k.translation).template head<Dim>();
    inside = inside && (at.array() >= tank_->domainMin().array() - tolerance).all() &&
             (at.array() <= tank_->domainMax().array() + tolerance).all();
  }
  if (inside) {
    k.exactBox = true;
    return;
  }
  // A box square to the tank that reaches through its walls (a plate across the tank) is cut back to them.
  for (int a = 0; a < Dim; ++a) {
    int axis = 0;
    for (int w = 1; w < 3; ++w)
      if (std::abs(k.rotation(w, a)) > std::abs(k.rotation(axis, a))) axis = w;
    if (axis >= Dim || std::abs(k.rotation(axis, a)) < 1 - 1e-6f) return;
    const float sign = k.rotation(axis, a) > 0 ? 1.0f : -1.0f;
    // The tank along `axis`, in the box's frame along a.
    float lo = (tank_->domainMin()[axis] - k.translation[axis]) * sign;
    float hi = (tank_->domainMax()[axis] - k.translation[axis]) * sign;
    if (lo > hi) std::swap(lo, hi);
    k.boxMin[a] = std::max(k.boxMin[a], lo);
    k.boxMax[a] = std::min(k.boxMax[a], hi);
  }
  k.exactBox = true;
}

// Calls visit(sign, walls, axes, distances, towards) for every term of a box's lattice at q (in its frame):
// the intersection of the half-spaces beyond `walls` faces on the distinct axes axes[0..walls-1], at distances
// distances[m] from q, lying towards towards[m] (+1 or -1 along the axis), counted with `sign`. Along each axis
// the fluid's side is one or two half-spaces beyond faces, or everything between them less the two beyond; the
// solid is the product over the axes, expanded.
template <int Dim, typename Visit>
void forEachBoxTerm(const Eigen::Vector3f& q, const Eigen::Vector3f& boxMin, const Eigen::Vector3f& boxMax,
                    float support, Visit&& visit) {
  struct Factor {
    float distance;  // < 0: everything along this axis
    float towards, sign;
  };
  Factor factors[Dim][3];
  int count[Dim];
  for (int a = 0; a < Dim; ++a) {
    const float x = q[a], lo = boxMin[a], hi = boxMax[a];
    int n = 0;
    if (x > hi) {
      factors[a][n++] = {x - hi, -1, 1};
      if (x - lo < support) factors[a][n++] = {x - lo, -1, -1};
    } else if (x < lo) {
      factors[a][n++] = {lo - x, 1, 1};
      if (hi - x < support) factors[a][n++] = {hi - x, 1, -1};
    } else {
      factors[a][n++] = {-1, 0, 1};
      if (hi - x < support) factors[a][n++] = {hi - x, 1, -1};
      if (x - lo < support) factors[a][n++] = {x - lo, -1, -1};
    }
    count[a] = n;
  }
  const int combinations = Dim == 3 ? count[0] * count[1] * count[Dim - 1] : count[0] * count[1];
  for (int combination = 0; combination < combinations; ++combination) {
    int rest = combination, axes[3], walls = 0;
    float distances[3], towards[3], sign = 1;
    for (int a = Dim - 1; a >= 0; --a) {
      const Factor& f = factors[a][rest % count[a]];
      rest /= count[a];
      sign *= f.sign;
      if (f.distance < 0) continue;
      axes[walls] = a;
      distances[walls] = f.distance;
      towards[walls++] = f.towards;
    }
    if (walls > 0) visit(sign, walls, axes, distances, towards);
  }
}

template <int Dim>
void Colliders<Dim>::boxTerms(const Placed& k, const VecD& p, float& weight, VecD& gradient) const {
  Eigen::Vector3f world = Eigen::Vector3f::Zero();
  world.template head<Dim>() = p;
  const Eigen::Vector3f q = k.rotation.transpose() * (world - k.translation);
  float w = 0;
  Eigen::Vector3f g = Eigen::Vector3f::Zero();
  forEachBoxTerm<Dim>(q, k.boxMin, k.boxMax, support_,
                      [&](float sign, int walls, const int* axes, const float* distances, const float* towards) {
                        float termWeight = 0, magnitudes[3] = {0, 0, 0};
                        if (walls == 1) {
                          tank_->flatWall().lookup(distances[0], termWeight, magnitudes[0]);
                        } else if (walls == 2) {
                          if (!tank_->edgeTerms(distances[0], distances[1], termWeight, magnitudes[0], magnitudes[1]))
                            return;
                        } else if constexpr (Dim == 3) {
                          if (!tank_->cornerTerms(distances, termWeight, magnitudes)) return;
                        }
                        w += sign * termWeight;
                        for (int m = 0; m < walls; ++m) g[axes[m]] += sign * magnitudes[m] * towards[m];
                      });
  weight = w;
  gradient = (k.rotation * g).template head<Dim>();
}

template <int Dim>
typename Colliders<Dim>::VecD Colliders<Dim>::boxHydrostaticSum(const Placed& k, const VecD& p,
                                                                const VecD& gravity) const {
  Eigen::Vector3f world = Eigen::Vector3f::Zero(), g = Eigen::Vector3f::Zero();
  world.template head<Dim>() = p;
  g.template head<Dim>() = gravity;
  const Eigen::Vector3f q = k.rotation.transpose() * (world - k.translation), gl = k.rotation.transpose() * g;
  // sum_b (g . (x_b - x_i)) grad W = -M g, M = sum_b (W'(r) / r) r r^T over the term's lattice (r = x_i - x_b).
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  forEachBoxTerm<Dim>(q, k.boxMin, k.boxMax, support_,
                      [&](float sign, int walls, const int* axes, const float* distances, const float* towards) {
                        if (walls == 1) {  // a face: the flat wall's own sum, along its axis
                          const Eigen::Vector3f axis = Eigen::Vector3f::Unit(axes[0]);
                          sum += sign * tank_->flatWall().hydrostaticSum(distances[0], axis, gl);
                          return;
                        }
                        // An edge's quarter; a corner's eighth has no tabulated moments (docs/colliders.md).
                        if (walls == 2)
                          sum += sign * tank_->edgeHydrostaticSum(distances[0], distances[1], axes, towards, gl);
                      });
  return (k.rotation * sum).template head<Dim>();
}

template <int Dim>
void Colliders<Dim>::buildGrid() {
  // Each collider is listed in the cells its near box reaches, grown by a margin that covers a short move and
  // the pushes it may take (project).
  size_t cells = 1;
  for (int k = 0; k < Dim; ++k) cells *= size_t(gridCounts_[k]);
  std::vector<uint32_t> count(cells + 1, 0);
  auto forCells = [&](const Eigen::AlignedBox<float, Dim>& box, float margin, auto&& f) {
    Eigen::Array<int, Dim, 1> lo, hi;
    for (int k = 0; k < Dim; ++k) {
      const float a = (box.min()[k] - margin - gridMin_[k]) * cellInverse_[k];
      const float b = (box.max()[k] + margin - gridMin_[k]) * cellInverse_[k];
      lo[k] = static_cast<int>(std::clamp(std::floor(a), 0.0f, float(gridCounts_[k] - 1)));
      hi[k] = static_cast<int>(std::clamp(std::floor(b), 0.0f, float(gridCounts_[k] - 1)));
      if (!(b >= 0) || !(a < gridCounts_[k])) return;  // off the grid (or NaN)
    }
    const int zLo = Dim == 3 ? lo[Dim - 1] : 0, zHi = Dim == 3 ? hi[Dim - 1] : 0;
    for (int z = zLo; z <= zHi; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) {
          size_t index = Dim == 3 ? (size_t(z) * gridCounts_[1] + y) * gridCounts_[0] + x
                                  : size_t(y) * gridCounts_[0] + x;
          f(index);
        }
  };
  const float margin = kGridMargin * radius_;
  for (size_t c = 0; c < placed_.size(); ++c) forCells(placed_[c].near, margin, [&](size_t i) { ++count[i + 1]; });
  for (size_t i = 0; i < cells; ++i) count[i + 1] += count[i];
  cellStart_ = count;
  cellSolids_.resize(count[cells]);
  for (size_t c = 0; c < placed_.size(); ++c)
    forCells(placed_[c].near, margin, [&](size_t i) { cellSolids_[count[i]++] = static_cast<uint16_t>(c); });
  // And the cells that no collider reaches (farFrom).
  cellReached_.assign(cells, 0);
  for (size_t c = 0; c < placed_.size(); ++c)
    forCells(placed_[c].near, kFarMargin * radius_, [&](size_t i) { cellReached_[i] = 1; });
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
bool Colliders<Dim>::sweep(size_t c, const VecD& from, const VecD& p, bool fromStepStart, VecD& delta) const {
  const Placed& k = placed_[c];
  const Eigen::AlignedBox<float, Dim> segment(from.cwiseMin(p), from.cwiseMax(p));
  if (!k.near.intersects(segment)) return false;
  // The move in the shape's frame (unscaled): a straight line from where `from` was relative to the shape to
  // where p is relative to it.
  Eigen::Vector3f a = Eigen::Vector3f::Zero(), b = Eigen::Vector3f::Zero();
  a.head<Dim>() = from;
  b.head<Dim>() = p;
  const bool atStart = fromStepStart && k.moving;
  const Eigen::Vector3f q0 = (atStart ? k.previousRotation : k.rotation).transpose() *
                             (a - (atStart ? k.previousTranslation : k.translation)) / k.scale;
  const Eigen::Vector3f q1 = k.rotation.transpose() * (b - k.translation) / k.scale;
  const Eigen::Vector3f move = q1 - q0;
  const float length = move.norm();
  if (!std::isfinite(length)) return false;  // a diverged particle is reported, not moved
  const float radius = radius_ / k.scale;
  const ColliderShape& shape = *k.shape;
  Eigen::Vector3f normal, endNormal;
  // Every point of the move is at least atEnd - length from the solid (a distance is 1-Lipschitz).
  const float atEnd = shape.distance(q1, endNormal);
  if (atEnd >= radius + length) return false;
  // Sphere tracing from q0: steps as long as the distance allows, and at least half a radius. A wall one
  // spacing (two radii) thick has a band four radii deep closer than a radius, which no step can cross. The
  // move stops where it comes closer than a radius while approaching the wall: a particle already that close
  // and moving away (the density pushing it off) goes on.
  const float shortest = 0.5f * radius;
  float t = 0, d = 0, previous = INFINITY;
  Eigen::Vector3f at = q0;
  bool hit = false;
  while (true) {
    at = length > 0 ? Eigen::Vector3f(q0 + (t / length) * move) : q0;
    d = shape.distance(at, normal);
    if (d < radius && (t > 0 ? d < previous : move.dot(normal) < 0)) {
      hit = true;
      break;
    }
    if (t >= length) break;
    previous = d;
    t = std::min(length, t + std::max(d - radius, shortest));
  }
  Eigen::Vector3f target;
  float landed;  // the distance at target
  if (hit) {
    // Stop on the surface at a radius and keep the rest of the move along it.
    target = at + (radius - d) * normal;
    Eigen::Vector3f rest = q1 - at;
    rest -= rest.dot(normal) * normal;
    target += rest;
    landed = shape.distance(target, normal);
  } else if (atEnd < radius) {
    target = q1;  // moved off the wall, not yet a radius away: lifted below
    landed = atEnd;
    normal = endNormal;
  } else {
    return false;
  }
  if (landed < radius) target += (radius - landed) * normal;
  const Eigen::Vector3f world = k.translation + k.rotation * (k.scale * target);
  delta = world.head<Dim>() - p;
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
typename Colliders<Dim>::VecD Colliders<Dim>::spinAcross(size_t c, const VecD& n) const {
  const Placed& k = placed_[c];
  Eigen::Vector3f across = Eigen::Vector3f::Zero();
  across.template head<Dim>() = n;
  // wallVelocity is affine in p, its gradient (I - R_previous R^T) / dt.
  const Eigen::Vector3f change = (across - k.previousRotation * (k.rotation.transpose() * across)) / dt_;
  return change.template head<Dim>();
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
    total[s % n].work += slots_[s].work;
    slots_[s] = Wrench{};
  }
  return total;
}

template <int Dim>
void Colliders<Dim>::addWrenches(const std::vector<Wrench>& wrenches, double scale) {
  for (size_t c = 0; c < extra_.size(); ++c) {
    extra_[c].force += scale * wrenches[c].force;
    extra_[c].torque += scale * wrenches[c].torque;
    extra_[c].work += scale * wrenches[c].work;
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
  stepMark_ = extra_;
  return total;
}

template <int Dim>
void Colliders<Dim>::applyFriction(size_t i, const VecD& x, VecD& v, float mass) {
  forEachNear(x, [&](size_t c, float d, const VecD& n) {
    const float mu = placed_[c].frictionThisStep;
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

template <int Dim>
size_t removeParticlesInside(const Colliders<Dim>& colliders, ParticleFrame& frame) {
  size_t kept = 0;
  const float radius = 0.99f * colliders.particleRadius();  // a fluid box drawn against a wall keeps its layer
  for (size_t i = 0; i < frame.size(); ++i) {
    const Vec<Dim> p = frame.position[i].head<Dim>();
    bool inside = false;
    for (size_t c = 0; c < colliders.size() && !inside; ++c) {
      Vec<Dim> normal;
      inside = colliders.distance(c, p, normal) < radius;
    }
    if (inside) continue;
    frame.position[kept] = frame.position[i];
    frame.velocity[kept] = frame.velocity[i];
    frame.id[kept] = static_cast<uint32_t>(kept);
    if (!frame.fluid.empty()) frame.fluid[kept] = frame.fluid[i];
    ++kept;
  }
  const size_t removed = frame.size() - kept;
  frame.resize(kept);
  return removed;
}

template <int Dim>
void driftAgainstSolids(std::vector<Vec<Dim>>& x, std::vector<Vec<Dim>>& v, float dt, float referenceMass,
                        const std::vector<float>& massRatio, Colliders<Dim>& colliders, const TankWalls<Dim>& walls,
                        const std::vector<Vec<Dim>>* push, float pushScale) {
  parallelFor(0, x.size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (push) v[i] += pushScale * (*push)[i];
      const Vec<Dim> from = x[i];
      const float mass = massRatio.empty() ? referenceMass : referenceMass * massRatio[i];
      x[i] += dt * v[i];
      if (!colliders.empty()) {
        colliders.project(from, x[i], true, [&](size_t c, const Vec<Dim>& delta) {
          const float length = delta.norm();
          if (!(length > 0)) return;
          const Vec<Dim> n = delta / length;
          const float approach = (v[i] - colliders.wallVelocity(c, x[i])).dot(n);
          if (approach >= 0) return;
          const Vec<Dim> change = -approach * n;
          v[i] += change;
          colliders.addImpulse(i, c, mass * change, x[i]);
        });
        if (colliders.hasFriction()) colliders.applyFriction(i, x[i], v[i], mass);
      }
      const int moved = walls.clamp(x[i]);
      for (int k = 0; k < Dim; ++k)
        if (moved & (1 << k)) v[i][k] = 0;
      if (push) v[i] -= pushScale * (*push)[i];
    }
  });
}

template class Colliders<2>;
template class Colliders<3>;
template size_t removeParticlesInside(const Colliders<2>&, ParticleFrame&);
template size_t removeParticlesInside(const Colliders<3>&, ParticleFrame&);
template void driftAgainstSolids(std::vector<Vec<2>>&, std::vector<Vec<2>>&, float, float, const std::vector<float>&,
                                 Colliders<2>&, const TankWalls<2>&, const std::vector<Vec<2>>*, float);
template void driftAgainstSolids(std::vector<Vec<3>>&, std::vector<Vec<3>>&, float, float, const std::vector<float>&,
                                 Colliders<3>&, const TankWalls<3>&, const std::vector<Vec<3>>*, float);

}  // namespace surge
