#include "whitewater/whitewater.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "core/hash.h"
#include "core/parallel.h"

namespace surge {
namespace {

// A particle counts as on the surface where its colour gradient, sum of (x_i - x_j) / h w_ij, is above this
// share of S: about zero inside a block at rest, about 0.6 on a flat surface of the 3D lattice at h = 2 s.
constexpr float kSurfaceGradient = 0.15f;

// Ihmsen's weight (eq. 3): 1 - r / h within h.
inline float weight(float r, float h) { return r < h ? 1 - r / h : 0.0f; }

// A potential clamped to [0, 1] between its thresholds (eq. 1).
inline float clampPotential(double value, double lo, double hi) {
  return float((std::min(value, hi) - std::min(value, lo)) / (hi - lo));
}

// Uniform in [0, 1), from what it is drawn for: the frame, the parent fluid particle's id, the draw.
inline float uniform(uint32_t frame, uint32_t id, uint32_t draw) {
  return unitFromBits(hashBits(hashBits(hashBits(frame) ^ id) + draw));
}

// dv/dt = a + rate (u - v), exact over dt for constant a and u: spray under gravity and air drag (u = 0), a
// bubble under buoyancy and drag toward the fluid's velocity. In double, so that a step of 1e-4 s loses nothing.
void drift(Eigen::Vector3f& x, Eigen::Vector3f& v, const Eigen::Vector3f& a, const Eigen::Vector3f& u, double rate,
           double dt) {
  const Eigen::Vector3d x0 = x.cast<double>(), v0 = v.cast<double>(), ad = a.cast<double>();
  if (rate > 0) {
    const Eigen::Vector3d terminal = u.cast<double>() + ad / rate;
    x = (x0 + terminal * dt - (v0 - terminal) * (std::expm1(-rate * dt) / rate)).cast<float>();
    v = (terminal + (v0 - terminal) * std::exp(-rate * dt)).cast<float>();
  } else {
    x = (x0 + v0 * dt + 0.5 * ad * dt * dt).cast<float>();
    v = (v0 + ad * dt).cast<float>();
  }
}

Eigen::Vector3f lerp(const Eigen::Vector3f& p, const Eigen::Vector3f& q, float t) { return p + t * (q - p); }

}  // namespace

WhitewaterStepper::WhitewaterStepper(const Scene& scene)
    : scene_(scene),
      settings_(scene.whitewater),
      h_(float(scene.solver.kernel_radius)),
      grid_((scene.domain.min.cast<float>().array() - 2 * float(scene.solver.kernel_radius)).matrix(),
            (scene.domain.max.cast<float>().array() + 2 * float(scene.solver.kernel_radius)).matrix(),
            NeighborGrid<3>::cellSizeFor(float(scene.solver.kernel_radius))) {
  double sum = 0;
  for (double r : restNeighborDistances(scene)) sum += 1 - r / scene.solver.kernel_radius;
  restSum_ = float(sum);
  const WhitewaterScale scale = whitewaterScale(scene);
  speed_ = float(scale.speed);
  timeScale_ = float(scale.time);
  frameTime_ = float(1 / scene.output.fps);
  gravity_ = scene.gravity.cast<float>();
  tankMin_ = scene.domain.min.cast<float>();
  tankMax_ = scene.domain.max.cast<float>();
  if (scene.dimensions == 2) gravity_.z() = tankMin_.z() = tankMax_.z() = 0;
  for (size_t c = 0; c < scene.colliders.size(); ++c) colliders_.push_back(buildColliderShape(scene, c));
  periodic_ = PeriodicDomain<3>(scene);
}

void WhitewaterStepper::sortFluidAndImages(const ParticleFrame& fluid) {
  if (!periodic_.active()) {
    sortFluid(fluid.position, fluid.velocity);
    return;
  }
  const ParticleFrame all = withPeriodicImages(fluid, scene_, 2 * h_);
  sortFluid(all.position, all.velocity);
}

bool WhitewaterStepper::meetColliders(Eigen::Vector3f& p, Eigen::Vector3f& v, bool spray,
                                      const std::vector<Pose>& poses) const {
  for (size_t c = 0; c < colliders_.size(); ++c) {
    const Pose& pose = poses[c];
    Eigen::Vector3f normal;
    const float d = float(pose.scale) *
                    colliders_[c].distance(pose.toLocal(p.cast<double>()).cast<float>(), normal);
    if (!(d < 0)) continue;
    if (spray) return false;
    const Eigen::Vector3f n = (pose.rotation * normal.cast<double>()).cast<float>();
    p -= d * n;
    v -= std::min(0.0f, v.dot(n)) * n;
  }
  return true;
}

void WhitewaterStepper::sortFluid(const std::vector<Eigen::Vector3f>& x, const std::vector<Eigen::Vector3f>& v) {
  grid_.sort(x);
  const std::vector<uint32_t>& order = grid_.sortedOrder();
  const size_t n = x.size();
  sortedX_.resize(n);
  sortedV_.resize(n);
  coordinates_.resize(3 * n);
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      sortedX_[k] = x[order[k]], sortedV_[k] = v[order[k]];
      for (int c = 0; c < 3; ++c) coordinates_[c * n + k] = sortedX_[k][c];
    }
  });
}

template <typename Visit>
void WhitewaterStepper::forEachFluidNear(const Eigen::Vector3f& p, Visit&& visit) const {
  thread_local std::vector<uint32_t> kept;
  const float h2 = h_ * h_;
  grid_.forEachCandidateRun(p, h_, [&](uint32_t begin, uint32_t end) {
    kept.resize(end - begin + kNeighborPadding);
    const uint32_t* last =
        keepInRange<3>(coordinates_.data(), sortedX_.size(), p, h2, UINT32_MAX, begin, end, kept.data());
    for (const uint32_t* slot = kept.data(); slot != last; ++slot) visit(*slot, (sortedX_[*slot] - p).squaredNorm());
  });
}

WhitewaterStepper::FluidSample WhitewaterStepper::sampleFluid(const Eigen::Vector3f& p) const {
  // The fluid's velocity at p fitted linearly by weighted least squares about the neighbours' weighted mean
  // (Shepard's average, eq. 13, corrected by the fitted gradient): exact for a rigid motion, where Shepard's
  // alone gives the velocity of the neighbours' centre, below a surface point, and foam drifts off its path.
  FluidSample sample;
  double weights = 0, vv = 0;
  Eigen::Vector3d d = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
  Eigen::Matrix3d dd = Eigen::Matrix3d::Zero(), vd = Eigen::Matrix3d::Zero();
  forEachFluidNear(p, [&](uint32_t slot, float r2) {
    const double w = weight(std::sqrt(r2), h_);
    const Eigen::Vector3d dj = (sortedX_[slot] - p).cast<double>(), vj = sortedV_[slot].cast<double>();
    ++sample.neighbors;
    weights += w;
    d += w * dj;
    v += w * vj;
    vv += w * vj.squaredNorm();
    dd += w * dj * dj.transpose();
    vd += w * vj * dj.transpose();
  });
  if (!(weights > 0)) return sample;
  d /= weights;
  v /= weights;
  // Covariances; a direction the neighbours do not span (one layer, or 2D's z) is left uncorrected.
  const double h2 = double(h_) * h_;
  const Eigen::Matrix3d cdd = dd / weights - d * d.transpose() + 1e-3 * h2 * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d cvd = vd / weights - v * d.transpose();
  Eigen::Vector3d correction = -(cvd * cdd.inverse()) * d;
  // Never beyond the spread of the neighbours' own velocities: noise in a splash fits a steep gradient.
  const double spread = std::sqrt(std::max(0.0, vv / weights - v.squaredNorm()));
  if (correction.norm() > spread) correction *= spread / correction.norm();
  sample.velocity = (v + correction).cast<float>();
  return sample;
}

WhitewaterStepper::Potentials WhitewaterStepper::potentials(const ParticleFrame& a) {
  const size_t n = a.size();
  sortFluidAndImages(a);
  const size_t all = sortedX_.size();  // the fluid and its images
  grid_.findNeighbors(sortedX_, h_, lists_);
  const std::vector<uint32_t>& order = grid_.sortedOrder();
  const float h = h_, S = restSum_;
  // Section 4.2: the surface normal from the colour gradient, where there is a surface (in the grid's order).
  std::vector<Eigen::Vector3f> normal(all, Eigen::Vector3f::Zero());
  parallelFor(0, all, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      const Eigen::Vector3f xk = sortedX_[k];
      Eigen::Vector3f gradient = Eigen::Vector3f::Zero();
      for (const uint32_t* j = lists_.begin(k); j != lists_.end(k); ++j) {
        const Eigen::Vector3f d = xk - sortedX_[*j];
        const float r = d.norm();
        if (r > 0) gradient += d * (weight(r, h) / h);
      }
      if (gradient.norm() > kSurfaceGradient * S) normal[k] = gradient.normalized();
    }
  });
  Potentials p;
  p.trappedAir.assign(n, 0);
  p.waveCrest.assign(n, 0);
  p.kinetic.assign(n, 0);
  p.generated.assign(n, 0);
  const WhitewaterSettings& w = settings_;
  const double U = speed_, perFrame = frameTime_ / timeScale_;
  parallelFor(0, all, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      const size_t i = order[k];  // the potentials are kept in a's order
      if (i >= n) continue;        // an image
      const Eigen::Vector3f xk = sortedX_[k], vk = sortedV_[k], nk = normal[k];
      // Section 4.3, eq. 8: the kinetic energy per unit mass, against U's.
      p.kinetic[i] = clampPotential(double(vk.squaredNorm()) / (U * U), w.kinetic_min, w.kinetic_max);
      if (p.kinetic[i] == 0) continue;
      double trapped = 0, curvature = 0;
      const bool surface = nk.squaredNorm() > 0;
      for (const uint32_t* j = lists_.begin(k); j != lists_.end(k); ++j) {
        const Eigen::Vector3f xkj = xk - sortedX_[*j];
        const float r = xkj.norm();
        if (!(r > 0)) continue;
        const float wkj = weight(r, h);
        // Section 4.1, eq. 2: trapped air where neighbours move against each other.
        const Eigen::Vector3f vkj = vk - sortedV_[*j];
        const float speed = vkj.norm();
        if (speed > 0) trapped += speed * (1 - vkj.dot(xkj) / (speed * r)) * wkj;
        // Section 4.2, eq. 4-5: curvature, from the convex neighbours (x_ji . n_i < 0) on the surface.
        const Eigen::Vector3f nj = normal[*j];
        if (surface && nj.squaredNorm() > 0 && -xkj.dot(nk) < 0) curvature += (1 - nk.dot(nj)) * wkj;
      }
      // Eq. 6-7: only where the surface moves outward.
      const bool outward = surface && vk.squaredNorm() > 0 && vk.normalized().dot(nk) >= 0.6f;
      p.trappedAir[i] = clampPotential(trapped / (U * S), w.trapped_air_min, w.trapped_air_max);
      p.waveCrest[i] = outward ? clampPotential(curvature / S, w.wave_crest_min, w.wave_crest_max) : 0.0f;
      // Eq. 9, its rates per T.
      p.generated[i] = float(p.kinetic[i] *
                             (w.trapped_air_rate * p.trappedAir[i] + w.wave_crest_rate * p.waveCrest[i]) * perFrame);
    }
  });
  return p;
}

void WhitewaterStepper::advance(const ParticleFrame& a, const ParticleFrame& b, int frame, DiffuseFrame& diffuse) {
  counts_ = WhitewaterCounts{};
  const WhitewaterSettings& w = settings_;
  const int dims = scene_.dimensions;
  const size_t n = a.size();
  const Potentials potential = potentials(a);

  // The fluid of frame a at frame b, matched by id; a particle gone by b carries on with its velocity.
  uint32_t maxId = 0;
  for (uint32_t id : b.id) maxId = std::max(maxId, id);
  std::vector<int64_t> inB(b.size() ? size_t(maxId) + 1 : 0, -1);
  for (size_t k = 0; k < b.size(); ++k) inB[b.id[k]] = int64_t(k);
  std::vector<Eigen::Vector3f> xb(n), vb(n);
  float fastest = 0;
  for (size_t i = 0; i < n; ++i) {
    const int64_t k = a.id[i] < inB.size() ? inB[a.id[i]] : -1;
    xb[i] = k >= 0 ? b.position[size_t(k)] : Eigen::Vector3f(a.position[i] + frameTime_ * a.velocity[i]);
    if (periodic_.active()) {  // across the seam: the nearest image of its move, so it sweeps the short way
      Eigen::Vector3f move = xb[i] - a.position[i];
      periodic_(move);
      xb[i] = a.position[i] + move;
    }
    vb[i] = k >= 0 ? b.velocity[size_t(k)] : a.velocity[i];
    fastest = std::max({fastest, a.velocity[i].norm(), vb[i].norm()});
  }
  for (size_t k = 0; k < diffuse.size(); ++k) fastest = std::max(fastest, diffuse.velocity[k].norm());
  fastest += gravity_.norm() * frameTime_;
  const int substeps =
      w.substeps > 0 ? w.substeps : std::clamp(int(std::ceil(fastest * frameTime_ / h_)), 1, 1000);
  const float dt = frameTime_ / float(substeps);
  counts_.substeps = substeps;

  // Section 5: each fluid particle makes floor(n_d) diffuse particles, and one more with n_d's fraction as its
  // chance; in a's order, up to max_particles.
  std::vector<size_t> firstBorn(n + 1, 0);
  const size_t room = size_t(w.max_particles) > diffuse.size() ? size_t(w.max_particles) - diffuse.size() : 0;
  for (size_t i = 0; i < n; ++i) {
    const float due = potential.generated[i];
    size_t count = size_t(due) + (uniform(uint32_t(frame), a.id[i], 0) < due - std::floor(due) ? 1 : 0);
    count = std::min(count, room - std::min(room, firstBorn[i]));
    firstBorn[i + 1] = firstBorn[i] + count;
  }
  const size_t born = firstBorn[n], old = diffuse.size();
  diffuse.resize(old + born);
  std::vector<int> birthStep(old + born, 0);
  const float radius = float(scene_.particle_spacing / 2);
  parallelFor(0, n, [&](size_t b0, size_t e0) {
    for (size_t i = b0; i < e0; ++i)
      for (size_t k = firstBorn[i]; k < firstBorn[i + 1]; ++k) {
        const uint32_t draw = uint32_t(1 + 5 * (k - firstBorn[i]));
        auto u = [&](uint32_t d) { return uniform(uint32_t(frame), a.id[i], draw + d); };
        const int step = std::min(substeps - 1, int(u(0) * float(substeps)));
        const float t = float(step) / float(substeps);
        const Eigen::Vector3f xp = lerp(a.position[i], xb[i], t), vp = lerp(a.velocity[i], vb[i], t);
        const float speed = vp.norm();
        const Eigen::Vector3f along = speed > 0 ? Eigen::Vector3f(vp / speed) : Eigen::Vector3f::UnitY();
        // Eq. 10-12: a point of the cylinder the parent sweeps in a substep, of the particle radius.
        Eigen::Vector3f offset;
        if (dims == 2) {
          offset = radius * (2 * u(1) - 1) * Eigen::Vector3f(-along.y(), along.x(), 0);
        } else {
          const Eigen::Vector3f e1 = along.unitOrthogonal(), e2 = along.cross(e1);
          const float r = radius * std::sqrt(u(1)), theta = 6.2831853f * u(2);
          offset = r * (std::cos(theta) * e1 + std::sin(theta) * e2);
        }
        const size_t at = old + k;
        diffuse.position[at] = xp + offset + u(3) * speed * dt * along;
        periodic_.wrapPoint(diffuse.position[at]);
        diffuse.velocity[at] = vp;
        diffuse.id[at] = diffuse.nextId + uint32_t(k);
        diffuse.type[at] = kFoam;  // classified as it takes its first substep
        diffuse.lifetime[at] = float(w.lifetime_min + u(4) * (w.lifetime_max - w.lifetime_min));
        birthStep[at] = step;
      }
  });
  diffuse.nextId += uint32_t(born);
  diffuse.dimensions = dims;
  counts_.born = born;

  // Section 6: substeps through the fluid at each substep's middle time.
  std::vector<uint8_t> dead(diffuse.size(), 0);
  ParticleFrame middle;  // the fluid at a substep's middle time, matched to a by index
  middle.position.resize(n);
  middle.velocity.resize(n);
  if (periodic_.active()) middle.id = a.id;  // withPeriodicImages copies the ids with the images
  std::vector<Eigen::Vector3f>& xm = middle.position;
  std::vector<Eigen::Vector3f>& vm = middle.velocity;
  const float buoyancy = float(w.bubble_buoyancy);
  std::vector<Pose> poses(colliders_.size());
  for (int step = 0; step < substeps; ++step) {
    const float t = (float(step) + 0.5f) / float(substeps);
    for (size_t c = 0; c < colliders_.size(); ++c)
      poses[c] = colliderPose(scene_.colliders[c], (double(frame) + double(step + 1) / substeps) * frameTime_);
    parallelFor(0, n, [&](size_t b0, size_t e0) {
      for (size_t i = b0; i < e0; ++i) xm[i] = lerp(a.position[i], xb[i], t), vm[i] = lerp(a.velocity[i], vb[i], t);
    });
    periodic_.wrap(xm);
    sortFluidAndImages(middle);
    parallelFor(0, diffuse.size(), [&](size_t b0, size_t e0) {
      for (size_t k = b0; k < e0; ++k) {
        if (dead[k] || birthStep[k] > step) continue;
        Eigen::Vector3f& x = diffuse.position[k];
        Eigen::Vector3f& v = diffuse.velocity[k];
        const FluidSample here = sampleFluid(x);
        // Section 6: classified by the fluid neighbours.
        const uint8_t type = here.neighbors < w.spray_neighbors    ? kSpray
                             : here.neighbors > w.bubble_neighbors ? kBubble
                                                                   : kFoam;
        diffuse.type[k] = type;
        if (type == kSpray) {
          drift(x, v, gravity_, Eigen::Vector3f::Zero(), w.spray_drag, dt);  // ballistic, with air drag
        } else if (type == kBubble) {
          drift(x, v, -buoyancy * gravity_, here.velocity, w.bubble_drag, dt);  // buoyancy, drag to the fluid
          diffuse.lifetime[k] -= dt;
          if (diffuse.lifetime[k] <= 0) dead[k] = 1;
        } else {
          // Foam rides the fluid's velocity (eq. 15), by the midpoint rule: it keeps to a vortex's circles.
          const Eigen::Vector3f middle = x + 0.5f * dt * here.velocity;
          const FluidSample there = sampleFluid(middle);
          v = there.neighbors ? there.velocity : here.velocity;
          x += dt * v;
          diffuse.lifetime[k] -= dt;
          if (diffuse.lifetime[k] <= 0) dead[k] = 1;
        }
        // The tank: spray breaks on a wall; foam and bubbles stay in; an open face lets anything out; a periodic
        // axis brings anything round to the other side.
        periodic_.wrapPoint(x);
        for (int axis = 0; axis < dims; ++axis)
          for (int upper = 0; upper < 2 && !periodic_.periodic(axis); ++upper) {
            const bool outside = upper ? x[axis] > tankMax_[axis] : x[axis] < tankMin_[axis];
            if (!outside) continue;
            if (scene_.isOpen(axis, upper) || type == kSpray) {
              dead[k] = 1;
            } else {
              x[axis] = upper ? tankMax_[axis] : tankMin_[axis];
              v[axis] = upper ? std::min(v[axis], 0.0f) : std::max(v[axis], 0.0f);
            }
          }
        // The colliders: spray breaks on them, foam and bubbles are moved out.
        if (!colliders_.empty() && !meetColliders(x, v, type == kSpray, poses)) dead[k] = 1;
        if (!x.allFinite() || !v.allFinite()) dead[k] = 1;
      }
    });
  }

  // The survivors, in order.
  size_t kept = 0;
  for (size_t k = 0; k < diffuse.size(); ++k) {
    if (dead[k]) continue;
    if (kept != k) {
      diffuse.position[kept] = diffuse.position[k];
      diffuse.velocity[kept] = diffuse.velocity[k];
      diffuse.id[kept] = diffuse.id[k];
      diffuse.type[kept] = diffuse.type[k];
      diffuse.lifetime[kept] = diffuse.lifetime[k];
    }
    ++kept;
  }
  counts_.died = diffuse.size() - kept;
  diffuse.resize(kept);
  for (uint8_t type : diffuse.type) {
    if (type == kSpray) ++counts_.spray;
    else if (type == kFoam) ++counts_.foam;
    else ++counts_.bubbles;
  }
}

}  // namespace surge
