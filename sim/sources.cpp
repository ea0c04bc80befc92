#include "sim/sources.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "sim/colliders.h"

namespace surge {
namespace {

constexpr double kNozzleLayers = 2;     // the nozzle's depth, in layers (docs/sources.md)
constexpr float kIntruderStep = 0.5f;  // the farthest a step moves water out of a nozzle, in spacings
constexpr double kGoldenAngle = 2.399963229728653;  // pi (3 - sqrt 5): the sunflower's turn between sites

// The keyframes' value at `time`, linear between them and held outside.
template <typename Value, typename Read>
Value interpolate(const std::vector<EmitterKeyframe>& keys, double time, Read read) {
  if (time <= keys.front().time || keys.size() == 1) return read(keys.front());
  if (time >= keys.back().time) return read(keys.back());
  size_t k = 1;
  while (keys[k].time < time) ++k;
  const double span = keys[k].time - keys[k - 1].time;
  const double f = span > 0 ? (time - keys[k - 1].time) / span : 1.0;
  return (1 - f) * read(keys[k - 1]) + f * read(keys[k]);
}

}  // namespace

EmitterSchedule::EmitterSchedule(const EmitterSettings& settings, double spacing, int dimensions)
    : settings_(settings), dimensions_(dimensions) {
  const double s = spacing, r = settings.radius;
  double area = 0;  // of the face (m^2, or m in 2D)
  if (dimensions == 2) {
    const size_t n = std::max<long>(1, std::lround(2 * r / s));
    for (size_t j = 0; j < n; ++j) sites_.emplace_back((j + 0.5) * 2 * r / double(n) - r, 0.0);
    area = 2 * r;
    reach_ = r;
  } else if (settings.shape == "rectangle") {
    const double w = settings.size[0], h = settings.size[1];
    const size_t nw = std::max<long>(1, std::lround(w / s)), nh = std::max<long>(1, std::lround(h / s));
    for (size_t j = 0; j < nh; ++j)
      for (size_t i = 0; i < nw; ++i)
        sites_.emplace_back((i + 0.5) * w / double(nw) - w / 2, (j + 0.5) * h / double(nh) - h / 2);
    area = w * h;
    reach_ = 0.5 * std::hypot(w, h);
  } else {
    area = M_PI * r * r;
    const size_t n = std::max<long>(1, std::lround(area / (s * s)));
    for (size_t j = 0; j < n; ++j) {
      const double radius = r * std::sqrt((j + 0.5) / double(n)), angle = double(j) * kGoldenAngle;
      sites_.emplace_back(radius * std::cos(angle), radius * std::sin(angle));
    }
    reach_ = r;
  }
  // A layer's volume is sites x s^d; over the face's area that is the distance between layers.
  pitch_ = double(sites_.size()) * std::pow(s, dimensions) / area;
}

double EmitterSchedule::keyedSpeed(double time) const {
  if (settings_.motion.empty()) return settings_.speed;
  return interpolate<double>(settings_.motion, time,
                             [&](const EmitterKeyframe& k) { return k.speed < 0 ? settings_.speed : k.speed; });
}

// The speed is linear between keyframes: the trapezoid rule over each piece is exact.
double EmitterSchedule::speedIntegral(double from, double to) const {
  if (!(to > from)) return 0;
  if (settings_.motion.empty()) return settings_.speed * (to - from);
  double total = 0, at = from;
  for (const EmitterKeyframe& k : settings_.motion)
    if (k.time > at && k.time < to) {
      total += 0.5 * (keyedSpeed(at) + keyedSpeed(k.time)) * (k.time - at);
      at = k.time;
    }
  return total + 0.5 * (keyedSpeed(at) + keyedSpeed(to)) * (to - at);
}

double EmitterSchedule::pushed(double time) const {
  const double end = settings_.stop > 0 ? std::min(time, settings_.stop) : time;
  return speedIntegral(settings_.start, end);
}

size_t EmitterSchedule::layersBy(double time) const {
  const double d = pushed(time);
  return d > 0 ? size_t(std::ceil(d / pitch_)) : 0;
}

Eigen::Vector3d EmitterSchedule::position(double time) const {
  if (settings_.motion.empty()) return settings_.position;
  return interpolate<Eigen::Vector3d>(settings_.motion, time, [](const EmitterKeyframe& k) { return k.position; });
}

Eigen::Vector3d EmitterSchedule::velocity(double time) const {
  const auto& keys = settings_.motion;
  if (keys.size() < 2 || time <= keys.front().time || time >= keys.back().time) return Eigen::Vector3d::Zero();
  size_t k = 1;
  while (keys[k].time < time) ++k;
  const double span = keys[k].time - keys[k - 1].time;
  return span > 0 ? Eigen::Vector3d((keys[k].position - keys[k - 1].position) / span) : Eigen::Vector3d::Zero();
}

Eigen::Vector3d EmitterSchedule::direction(double time) const {
  auto unit = [&](const Eigen::Vector3d& d) {
    Eigen::Vector3d u = d;
    if (dimensions_ == 2) u.z() = 0;
    return u.norm() > 0 ? Eigen::Vector3d(u.normalized()) : Eigen::Vector3d::Zero();
  };
  const Eigen::Vector3d own = unit(settings_.direction);
  if (settings_.motion.empty()) return own;
  const Eigen::Vector3d d = unit(interpolate<Eigen::Vector3d>(
      settings_.motion, time, [&](const EmitterKeyframe& k) { return k.direction.norm() > 0 ? unit(k.direction) : own; }));
  return d.norm() > 0 ? d : own;
}

double EmitterSchedule::speed(double time) const {
  if (time < settings_.start || (settings_.stop > 0 && time >= settings_.stop)) return 0;
  return keyedSpeed(time);
}

Eigen::Vector3d EmitterSchedule::site(size_t j, const Eigen::Vector3d& centre, const Eigen::Vector3d& d) const {
  if (dimensions_ == 2) return centre + sites_[j].x() * Eigen::Vector3d(-d.y(), d.x(), 0);
  // Width along d x up (x when d is vertical), height along width x d.
  Eigen::Vector3d u = d.cross(Eigen::Vector3d::UnitY());
  u = u.norm() > 1e-9 ? Eigen::Vector3d(u.normalized()) : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d w = u.cross(d);
  return centre + sites_[j].x() * u + sites_[j].y() * w;
}

template <int Dim>
struct FluidSources<Dim>::Sink {
  const ColliderSettings* settings;
  ColliderShape shape;
  Pose pose;
  Eigen::AlignedBox<float, Dim> bounds;  // in the world; everything for a plane

  void place(double time) {
    pose = colliderPose(*settings, time);
    bounds.setEmpty();
    if (shape.kind == ShapeKind::Plane) {
      bounds.extend(Vec<Dim>::Constant(-INFINITY)).extend(Vec<Dim>::Constant(INFINITY));
      return;
    }
    const Eigen::AlignedBox3d world = worldBounds(shape, pose);
    bounds.extend(world.min().template head<Dim>().template cast<float>());
    bounds.extend(world.max().template head<Dim>().template cast<float>());
  }
};

template <int Dim>
FluidSources<Dim>::FluidSources(const Scene& scene, uint32_t firstId, double time)
    : scene_(scene),
      spacing_(static_cast<float>(scene.particle_spacing)),
      domainMin_(toVec<Dim>(scene.domain.min)),
      domainMax_(toVec<Dim>(scene.domain.max)),
      nextId_(firstId),
      lastTime_(time),
      potential_(scene) {
  for (int axis = 0; axis < Dim; ++axis)
    for (int upper = 0; upper < 2; ++upper)
      if (scene.isOpen(axis, upper)) openFaces_ |= 1 << (2 * axis + upper);
  for (const FluidBlock& fluid : scene.fluids) fluidMassRatio_.push_back(fluid.rest_density / scene.referenceDensity());
  for (size_t e = 0; e < scene.emitters.size(); ++e) {
    emitters_.emplace_back(scene.emitters[e], scene.particle_spacing, Dim);
    layers_.push_back(emitters_.back().layersBy(time));
    nextId_ += static_cast<uint32_t>(layers_.back() * emitters_.back().sitesPerLayer());
    emittedFluid_.push_back(scene.severalFluids() ? static_cast<uint8_t>(scene.emittedFluid(e)) : 0);
  }
  for (size_t i = 0; i < scene.sinks.size(); ++i) {
    auto sink = std::make_unique<Sink>();
    sink->shape = buildSolidShape(scene, scene.sinks[i], "sinks[" + std::to_string(i) + "]", false);
    sink->settings = &scene.sinks[i];
    sink->place(time);
    sinks_.push_back(std::move(sink));
  }
}

template <int Dim>
FluidSources<Dim>::~FluidSources() = default;

template <int Dim>
bool FluidSources<Dim>::inSink(const VecD& p) const {
  for (const std::unique_ptr<Sink>& sink : sinks_) {
    if (!sink->bounds.contains(p)) continue;
    Eigen::Vector3d world = Eigen::Vector3d::Zero();
    world.template head<Dim>() = p.template cast<double>();
    const Eigen::Vector3f local = sink->pose.toLocal(world).template cast<float>();
    if (sink->shape.distance(local) < 0) return true;
  }
  return false;
}

template <int Dim>
void FluidSources<Dim>::placeSinks(double time) {
  for (const std::unique_ptr<Sink>& sink : sinks_)
    if (isMoving(*sink->settings)) sink->place(time);
}

template <int Dim>
bool FluidSources<Dim>::pastOpenFace(const VecD& p) const {
  for (int k = 0; k < Dim; ++k) {
    if ((openFaces_ >> (2 * k) & 1) && p[k] < domainMin_[k]) return true;
    if ((openFaces_ >> (2 * k + 1) & 1) && p[k] > domainMax_[k]) return true;
  }
  return false;
}

template <int Dim>
void FluidSources<Dim>::checkStart(const std::vector<VecD>& particles, const Colliders<Dim>& colliders) const {
  for (size_t e = 0; e < emitters_.size(); ++e) {
    const VecD centre = emitters_[e].position(0.0).template head<Dim>().template cast<float>();
    for (size_t c = 0; c < colliders.size(); ++c) {
      VecD normal;
      if (colliders.distance(c, centre, normal) < 0) {
        const size_t n = scene_.colliders.size();
        const std::string& name = c < n ? scene_.colliders[c].name : scene_.bodies[c - n].solid.name;
        throw InputError(scene_.source, "emitters[" + std::to_string(e) + "].position",
                         "lies inside " + std::string(c < n ? "collider " : "body ") + name);
      }
    }
  }
  if (!sinks_.empty() && !particles.empty() &&
      std::all_of(particles.begin(), particles.end(), [&](const VecD& p) { return inSink(p); }))
    throw InputError(scene_.source, "sinks", "hold the whole initial fluid: nothing would be left to simulate");
}

// How far to move water found in a nozzle (at `r` from the face's centre, `along` its direction d and `across`
// it) toward the nearest way out: behind the face, past the sides or ahead of the held layers, at most
// kIntruderStep spacings a step, so that water standing where a nozzle opens (a submerged emitter's start)
// clears over a few steps without piling onto what is around it.
template <int Dim>
Vec<Dim> FluidSources<Dim>::outOfNozzle(const VecD& r, float along, float across, const VecD& d, float reach,
                                        float depth) const {
  const float radius = 0.5f * spacing_, most = kIntruderStep * spacing_;
  const float back = along + radius, side = reach + radius - across, ahead = depth + radius - along;
  if (back <= side && back <= ahead) return -std::min(back, most) * d;
  if (ahead <= side) return std::min(ahead, most) * d;
  const VecD outward = across > 0 ? VecD((r - along * d) / across) : VecD(VecD::Unit(Dim - 1));
  return std::min(side, most) * outward;
}

// Emitter e's part of the edit after the step that ended at `time`: its nozzle held, and the layers it owes.
template <int Dim>
void FluidSources<Dim>::emit(size_t e, FluidSolver<Dim>& solver, double time) {
  const EmitterSchedule& emitter = emitters_[e];
  const size_t due = emitter.layersBy(time);
  const double speed = emitter.speed(time);
  if (!(speed > 0) && due == layers_[e]) return;
  const std::vector<VecD>& x = solver.positions();
  const float s = spacing_, radius = 0.5f * s;
  const Eigen::Vector3d centre = emitter.position(time), direction = emitter.direction(time);
  const VecD c = toVec<Dim>(centre), d = toVec<Dim>(direction);
  // The jet's velocity, and the emitter's own when its keyframes move it (a hose swept across).
  const Eigen::Vector3d jet = speed * direction + emitter.velocity(time);
  const double pushed = emitter.pushed(time), pitch = emitter.pitch();
  // Where site j of the layer `offset` in front of the face is, and how fast it moves: in free flight since it
  // left the face, so that holding a jet into air in its nozzle changes nothing.
  const Eigen::Vector3d& g = scene_.gravity;
  auto nozzleSite = [&](double offset, size_t j, VecD& velocity) {
    const double flight = speed > 0 ? std::max(0.0, offset) / speed : 0.0;
    velocity = toVec<Dim>(jet + flight * g);
    return toVec<Dim>(emitter.site(j, centre + offset * direction, direction) + 0.5 * flight * flight * g);
  };

  // The nozzle, kNozzleLayers layers in front of the face, is a pipe while the emitter runs: each particle of a
  // layer in it rides its site whatever the solver did, and anything else in it (water drawn in from behind or
  // the sides) is moved out the nearest way. The water in front is then pushed as by a piston, and the next
  // layer's sites are free (docs/sources.md).
  const float reach = static_cast<float>(emitter.reach()), depth = static_cast<float>(kNozzleLayers * pitch);
  const size_t sites = emitter.sitesPerLayer();
  const size_t heldFrom =
      std::min(layers_[e], static_cast<size_t>(std::max(0.0, std::ceil((pushed - kNozzleLayers * pitch) / pitch))));
  // The held layers' sites, where their particles go and how fast, once for the scan below.
  heldAt_.resize((layers_[e] - heldFrom) * sites);
  heldVelocity_.resize(heldAt_.size());
  for (size_t k = heldFrom; k < layers_[e]; ++k)
    for (size_t j = 0; j < sites; ++j) {
      const size_t slot = (k - heldFrom) * sites + j;
      heldAt_[slot] = nozzleSite(pushed - double(k) * pitch, j, heldVelocity_[slot]);
    }
  held_.assign(heldAt_.size(), 0);
  const float farthest = std::max(static_cast<float>(pushed - double(layers_[e]) * pitch), depth) + s;
  nearby_.clear();
  for (size_t i = 0; i < x.size(); ++i) {
    const VecD r = x[i] - c;
    const float along = r.dot(d);
    if (along < -s || along > farthest) continue;
    const float across = (r - along * d).norm();
    if (across > reach + s) continue;
    VecD at = x[i];
    if (speed > 0 && along > -radius && along < depth + radius && across < reach + radius) {
      const long k = std::lround((pushed - double(along)) / pitch);
      // A layer that has left the nozzle goes its own way; one in it rides its nearest site, if near and free.
      long slot = -1;
      if (k >= long(heldFrom) && k < long(layers_[e])) {
        const size_t first = (size_t(k) - heldFrom) * sites;
        size_t nearest = first;
        float best = INFINITY;
        for (size_t j = first; j < first + sites; ++j) {
          const float d2 = (heldAt_[j] - x[i]).squaredNorm();
          if (d2 < best) best = d2, nearest = j;
        }
        if (best < radius * radius && !held_[nearest]) slot = long(nearest);
      }
      if (slot >= 0 || k >= long(heldFrom)) {  // held, or water to move out
        if (slot >= 0) held_[size_t(slot)] = 1;
        at = slot >= 0 ? heldAt_[size_t(slot)] : VecD(at + outOfNozzle(r, along, across, d, reach, depth));
        // Held back on its site against the water's push, m (v - U) / dt over the last step (U the velocity the
        // site gave it, as its site has now), the nozzle works on the water: that push times the way back.
        if (slot >= 0 && stepTime_ > 0)
          heldWork_ -= massOf(solver, i) / stepTime_ *
                       double((solver.velocities()[i] - heldVelocity_[size_t(slot)]).dot(at - x[i]));
        edit_.steer.push_back(static_cast<uint32_t>(i));
        edit_.steerPosition.push_back(at);
        edit_.steerVelocity.push_back(slot >= 0 ? heldVelocity_[size_t(slot)] : solver.velocities()[i]);
      }
    }
    nearby_.push_back(at);
  }

  // The layers due by now, each site unless it is blocked. Each new particle is pushed in against the water
  // standing above the face: its flow work, p V = m g (the depth there), goes to the ledger.
  Colliders<Dim>& colliders = solver.colliders();
  float above = NAN;
  const double fluidRatio = fluidMassRatio_.empty() ? 1.0 : fluidMassRatio_[emittedFluid_[e]];
  for (size_t k = layers_[e]; k < due; ++k)
    for (size_t j = 0; j < sites; ++j) {
      const uint32_t id = nextId_++;
      VecD velocity;
      const VecD p = nozzleSite(pushed - double(k) * pitch, j, velocity);
      bool blocked = ((p - domainMin_).array() < radius).any() || ((domainMax_ - p).array() < radius).any();
      for (size_t b = 0; b < colliders.size() && !blocked; ++b) {
        VecD normal;
        blocked = colliders.distance(b, p, normal) < radius;
      }
      for (size_t q = 0; q < nearby_.size() && !blocked; ++q)
        blocked = (nearby_[q] - p).squaredNorm() < radius * radius;
      if (blocked || inSink(p)) continue;
      if (!std::isfinite(above)) above = waterAbove(c, reach, x);
      flowWork_ += solver.particleMass() * fluidRatio * scene_.gravity.norm() * above;
      edit_.addPosition.push_back(p);
      edit_.addVelocity.push_back(velocity);
      edit_.addId.push_back(id);
      edit_.addFluid.push_back(emittedFluid_[e]);
    }
  layers_[e] = due;
}

template <int Dim>
void FluidSources<Dim>::apply(FluidSolver<Dim>& solver, double time) {
  edit_.clear();
  flowWork_ = heldWork_ = 0;
  stepTime_ = time - lastTime_;
  lastTime_ = time;
  placeSinks(time);
  const std::vector<VecD>& x = solver.positions();
  const size_t n = x.size();
  if (!sinks_.empty() || openFaces_ != 0)
    for (size_t i = 0; i < n; ++i)
      if (pastOpenFace(x[i]) || inSink(x[i])) edit_.remove.push_back(static_cast<uint32_t>(i));

  for (size_t e = 0; e < emitters_.size(); ++e) emit(e, solver, time);
  emitted += edit_.addPosition.size();
  removed += edit_.remove.size();
  if (edit_.empty()) return;
  work += editEnergy(solver);
  solver.editParticles(edit_);
}

template <int Dim>
float FluidSources<Dim>::waterAbove(const VecD& c, float reach, const std::vector<VecD>& x) const {
  const double g = scene_.gravity.norm();
  if (!(g > 0)) return 0;
  const VecD up = toVec<Dim>(-scene_.gravity / g);
  const float s = spacing_, gap = 2 * s;
  std::vector<float> heights;
  for (const VecD& p : x) {
    const float height = (p - c).dot(up);
    if (height > -s && (p - c - height * up).norm() < reach + s) heights.push_back(height);
  }
  std::sort(heights.begin(), heights.end());
  if (heights.empty() || heights.front() > gap) return 0;
  size_t i = 0;
  while (i + 1 < heights.size() && heights[i + 1] - heights[i] < gap) ++i;
  return std::max(0.0f, heights[i] + 0.5f * s);
}

template <int Dim>
double FluidSources<Dim>::massOf(const FluidSolver<Dim>& solver, size_t i) const {
  const std::vector<float>& ratio = solver.massRatios();
  return ratio.empty() ? solver.particleMass() : solver.particleMass() * ratio[i];
}

template <int Dim>
double FluidSources<Dim>::editEnergy(const FluidSolver<Dim>& solver) const {
  const std::vector<VecD>&x = solver.positions(), &v = solver.velocities();
  double energy = 0;
  for (const uint32_t i : edit_.remove) energy -= potential_.energy<Dim>(x[i], v[i], massOf(solver, i));
  for (size_t k = 0; k < edit_.steer.size(); ++k) {
    const uint32_t i = edit_.steer[k];
    const double m = massOf(solver, i);
    energy += potential_.energy<Dim>(edit_.steerPosition[k], edit_.steerVelocity[k], m) -
              potential_.energy<Dim>(x[i], v[i], m);
  }
  for (size_t k = 0; k < edit_.addPosition.size(); ++k) {
    const double ratio = fluidMassRatio_.empty() ? 1.0 : fluidMassRatio_[edit_.addFluid[k]];
    energy += potential_.energy<Dim>(edit_.addPosition[k], edit_.addVelocity[k], solver.particleMass() * ratio);
  }
  return energy + flowWork_ + heldWork_;
}

size_t mostEmittedParticles(const Scene& scene, double time) {
  size_t total = 0;
  for (const EmitterSettings& settings : scene.emitters) {
    const EmitterSchedule emitter(settings, scene.particle_spacing, scene.dimensions);
    total += emitter.layersBy(time) * emitter.sitesPerLayer();
  }
  return total;
}

template class FluidSources<2>;
template class FluidSources<3>;

}  // namespace surge
