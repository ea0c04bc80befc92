#include "sim/wcsph_solver.h"

#include <chrono>
#include <cmath>
#include <optional>

#include "core/parallel.h"

namespace surge {
namespace {

// Calls f(j, offset, shift) for the mirror images of particle i and of its neighbours across the tank's walls
// within the support of i (each wall, and each pair and triple of them on different axes where they meet):
// offset = x_i - x_j', shift = x_j' - x_j, for the images closer to i than the support. An image is never closer
// to i than its particle, so i's neighbours hold every image within reach.
template <int Dim, typename Wrap, typename F>
void forEachWallImage(const TankWalls<Dim>& walls, const std::vector<Vec<Dim>>& x, const NeighborLists& neighbors,
                      size_t i, float support, const Wrap& wrap, F&& f) {
  int axes[2 * Dim];
  float planes[2 * Dim];
  const int count = walls.nearPlanes(x[i], support, axes, planes);
  if (count == 0) return;
  // Bit b set where walls b and b + 1 face each other across one axis (a tank thinner than twice the support):
  // a set holding both has no single image.
  int facing = 0;
  for (int b = 0; b + 1 < count; ++b)
    if (axes[b] == axes[b + 1]) facing |= 1 << b;
  const float reach2 = support * support;
  const auto images = [&](size_t j, const Vec<Dim>& offset) {
    // Across wall b the image lies `across[b]` from i along the wall's axis; beyond the support, no image
    // across b reaches i.
    float across[2 * Dim];
    int reaching = 0;
    for (int b = 0; b < count; ++b) {
      across[b] = x[i][axes[b]] + x[j][axes[b]] - 2 * planes[b];
      if (across[b] * across[b] < reach2) reaching |= 1 << b;
    }
    for (int set = 1; set < (1 << count); ++set) {
      if ((set & ~reaching) || (set & (set >> 1) & facing)) continue;
      Vec<Dim> o = offset, shift = Vec<Dim>::Zero();
      for (int b = 0; b < count; ++b)
        if (set >> b & 1) {
          o[axes[b]] = across[b];
          shift[axes[b]] = 2 * (planes[b] - x[j][axes[b]]);
        }
      if (o.squaredNorm() < reach2) f(j, o, shift);
    }
  };
  images(i, Vec<Dim>::Zero());
  for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j) {
    Vec<Dim> offset = x[i] - x[*j];
    wrap(offset);
    images(*j, offset);
  }
}

}  // namespace

// The mass gives the rest lattice exactly rho_0 (the same choice as PBF's, with this kernel).
template <int Dim>
WcsphSolver<Dim>::WcsphSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes)
    : Core(scene, std::move(shapes), sphRestLattice<Dim>(scene)),
      verlet_(scene.solver.integrator == "velocity_verlet"),
      tait_(scene.solver.equation_of_state == "tait"),
      mirroredWalls_(!this->tension_.active()),
      kernel_(sphKernel<Dim>(scene)) {
  const SolverSettings& s = scene.solver;
  support_ = static_cast<float>(s.kernel_radius);
  smoothingLength_ = 0.5f * support_;
  frameDuration_ = static_cast<float>(1.0 / scene.output.fps);
  speedOfSound_ = static_cast<float>(s.speed_of_sound);
  gasConstant_ = static_cast<float>(s.gas_constant);
  taitB_ = restDensity_ * speedOfSound_ * speedOfSound_ / 7.0f;
  alpha_ = static_cast<float>(s.artificial_viscosity);
  // solver.kinematic_viscosity, every fluid's when none gives its own: Morris's pair term inside the integrator,
  // as it always was (no wall term); fluids[i].viscosity goes to the shared solver instead.
  nu_ = sceneHasViscosity(scene) ? 0.0f : static_cast<float>(s.kinematic_viscosity);
  nearStiffness_ = static_cast<float>(s.near_pressure);
  cfl_ = static_cast<float>(s.cfl);
  fixedStep_ = static_cast<float>(s.time_step);
  backgroundPressure_ = static_cast<float>(s.background_pressure);
}

template <int Dim>
void WcsphSolver<Dim>::resizeChannels(size_t n) {
  sizeChannel(a_, n, VecD(VecD::Zero()));
  sizeChannel(density_, n, restDensity_);
  sizeChannel(pressure_, n, 0.0f);
  if (nearStiffness_ > 0) sizeChannel(nearPressure_, n, 0.0f);
  if (backgroundPressure_ > 0) sizeChannel(transportAcceleration_, n, VecD(VecD::Zero()));
  colliderForces_.assign(colliders_.size(), Wrench{});
  accelerationsValid_ = false;
}

template <int Dim>
void WcsphSolver<Dim>::beginFrame(double time) {
  time_ = time;
  accelerationsValid_ = false;
  frameStart_ = true;
  framePressureMax_ = 0;
}

// dt = min(cfl h / (c + |v|max), 0.125 h^2 / nu, 0.25 sqrt(h / |a|max)), h the smoothing length (half the
// support): the CFL condition on the speed of sound and the fastest particle, and the viscous and force limits
// of Monaghan 1992 / Morris et al. 1997.
template <int Dim>
float WcsphSolver<Dim>::stableTimeStep() {
  if (fixedStep_ > 0) return fixedStep_;
  if (!accelerationsValid_) {
    // At a frame's start the solids are placed where they stand (a resumed run's colliders knew no step before).
    if (frameStart_ && colliders_.anyMoving()) colliders_.placeAtStepStart(time_, frameDuration_);
    computeAccelerations(time_);  // the state's time: step() then uses these accelerations as a(x_n)
  }
  frameStart_ = false;
  struct Maxima {
    float speed = 0, acceleration = 0;
    Maxima& operator+=(const Maxima& o) {
      speed = std::max(speed, o.speed);
      acceleration = std::max(acceleration, o.acceleration);
      return *this;
    }
  };
  const Maxima m = parallelSum<Maxima>(0, size(), [&](size_t b, size_t e) {
    Maxima local;
    for (size_t i = b; i < e; ++i) {
      local.speed = std::max(local.speed, v_[i].norm());
      local.acceleration = std::max(local.acceleration, a_[i].norm());
    }
    return local;
  });
  const float h = smoothingLength_;
  float dt = cfl_ * h / (speedOfSound_ + m.speed);
  if (nu_ > 0) dt = std::min(dt, 0.125f * h * h / nu_);
  if (m.acceleration > 0) dt = std::min(dt, 0.25f * std::sqrt(h / m.acceleration));
  return std::min({dt, this->tension_.stableStep(), this->viscosity_.stableStep()});
}

template <int Dim>
long WcsphSolver<Dim>::step(float dt, double time) {
  if (!colliders_.empty()) colliders_.beginStep(time, dt);
  if (!accelerationsValid_) computeAccelerations(time);
  // The colliders' impulses: each kick's share of their pressure forces, and the drift's stops.
  const bool colliding = !colliders_.empty();
  if (verlet_) {
    // Kick-drift-kick: v += dt/2 a(x_n); x += dt v; v += dt/2 a(x_n+1).
    parallelFor(0, size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) v_[i] += (0.5f * dt) * a_[i];
    });
    if (this->tension_.active()) this->tension_.addWork(v_, dt, this->massRatio_);  // at the half step's velocities
    if (colliding) colliders_.addWrenches(colliderForces_, 0.5 * dt);
    drift(dt, 0.5f * dt);
    if (colliding) colliders_.addWrenches(colliders_.takeSlotSums(), 1.0);
    computeAccelerations(time + dt);
    parallelFor(0, size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) v_[i] += (0.5f * dt) * a_[i];
    });
    if (colliding) colliders_.addWrenches(colliderForces_, 0.5 * dt);
    accelerationsValid_ = true;  // a(x_n+1), with the half-step velocity in its viscous terms
  } else {
    // Semi-implicit Euler: v += dt a(x_n, v_n); x += dt v.
    parallelFor(0, size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) v_[i] += dt * a_[i];
    });
    if (this->tension_.active()) this->tension_.addWork(v_, dt, this->massRatio_);
    if (colliding) colliders_.addWrenches(colliderForces_, dt);
    drift(dt, dt);
    if (colliding) colliders_.addWrenches(colliders_.takeSlotSums(), 1.0);
    accelerationsValid_ = false;
  }
  // The fluids' own viscosity (sim/viscosity.h), explicit or implicit, on the step's end velocities.
  this->applyViscosity(x_, dt);
  if (colliding && this->viscosity_.active()) colliders_.addWrenches(colliders_.takeSlotSums(), 1.0);  // its drag
  time_ = time + dt;
  return this->endStep();
}

// x += dt v against the solids; with the transport velocity, x += dt (v + kick a_b), the solids' stops applied to
// v alone (the kick is added for the drift and taken back after it).
template <int Dim>
void WcsphSolver<Dim>::drift(float dt, float kick) {
  driftAgainstSolids(x_, v_, dt, mass_, this->massRatio_, colliders_, walls_,
                     backgroundPressure_ > 0 ? &transportAcceleration_ : nullptr, kick);
}

template <int Dim>
void WcsphSolver<Dim>::computeAccelerations(double time) {
  // Neighbours of the current positions; every channel is reordered by cell first.
  {
    const PhaseTimer timer(times_.neighbors);
    this->reorderByCell(x_);
    this->findNeighborsOf(x_, support_);
  }
  kernel_.visit([&](const auto& kernel) {
    computeAccelerationsWith(kernel, time);
    if (backgroundPressure_ > 0) computeTransportAccelerations(kernel);
    return 0;
  });
  accelerationsValid_ = true;
}

template <int Dim>
template <typename Kernel>
void WcsphSolver<Dim>::computeAccelerationsWith(const Kernel& kernel, double time) {
  std::optional<PhaseTimer> timer(std::in_place, times_.pressure);
  const float selfWeight = kernel.value(0.0f);
  const bool near = nearStiffness_ > 0;
  // Several fluids (Solenthaler and Pajarola 2008): density_ is m_0 times the number density, the same for every
  // fluid at rest, and each fluid's pressure is its rest density's (rho_f / rho_0 = the mass ratio m_f / m_0).
  // Eq. 8's a_i = -(1 / m_i) sum_j (p_i / delta_i^2 + p_j / delta_j^2) grad W_ij is then m_0 / m_i times the
  // one fluid's sum; the viscous and near-pressure forces are weighted so that each pair's forces stay opposite.
  const bool several = !massRatio_.empty();
  const float* massRatio = massRatio_.data();
  const float* inverse = inverseMassRatio_.data();
  const float inverseSupport = 1.0f / support_;
  // Density by summation and the equation of state.
  this->periodic_.withNearestImage([&](const auto& sharedWrap) {
  parallelFor(0, size(), [&](size_t b, size_t e) {
    const auto wrap = sharedWrap;  // the thread's own copy (sim/periodic.h)
    for (size_t i = b; i < e; ++i) {
      float weight = selfWeight, nearDensity = 0;
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j) {
        VecD offset = x_[i] - x_[*j];
        wrap(offset);
        const float r = offset.norm();
        weight += kernel.value(r);
        if (near) {
          const float d = std::max(1.0f - r * inverseSupport, 0.0f);
          nearDensity += d * d * d;
        }
      }
      VecD unusedGradient = VecD::Zero();
      if (mirroredWalls_)
        forEachWallImage(walls_, x_, neighbors_, i, support_, wrap,
                         [&](size_t, const VecD& o, const VecD&) { weight += kernel.value(o.norm()); });
      else
        walls_.add(x_[i], weight, unusedGradient);
      if (!colliders_.empty()) colliders_.add(x_[i], weight, unusedGradient, !mirroredWalls_);
      density_[i] = mass_ * weight;
      const float ratio = density_[i] / restDensity_;
      float p = tait_ ? taitB_ * (std::pow(ratio, 7.0f) - 1.0f) : gasConstant_ * (density_[i] - restDensity_);
      if (several) p *= massRatio[i];  // the fluid's own rest density in the equation of state
      pressure_[i] = std::max(p, 0.0f);
      if (near) nearPressure_[i] = nearStiffness_ * nearDensity;
    }
  });
  });
  framePressureMax_ = std::max(framePressureMax_, parallelMax(pressure_));

  // Forces, gathered per particle.
  timer.emplace(times_.forces);
  const VecD attractorAt = attractor_.active() ? attractor_.position(time) : VecD::Zero();
  const float h = smoothingLength_;
  const float eta2 = 0.01f * h * h;
  const float laminar = 2.0f * (Dim + 2) * nu_;
  this->periodic_.withNearestImage([&](const auto& sharedWrap) {
  parallelFor(0, size(), [&](size_t b, size_t e) {
    const auto wrap = sharedWrap;  // the thread's own copy (sim/periodic.h)
    for (size_t i = b; i < e; ++i) {
      const float pressureTermI = pressure_[i] / (density_[i] * density_[i]);
      VecD pressureForce = VecD::Zero(), viscousForce = VecD::Zero(), nearForce = VecD::Zero();
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j) {
        VecD r = x_[i] - x_[*j];
        wrap(r);
        const float length = r.norm();
        const VecD gradient = kernel.gradientFactor(length) * r;
        pressureForce -= (pressureTermI + pressure_[*j] / (density_[*j] * density_[*j])) * gradient;
        const VecD vij = v_[i] - v_[*j];
        const float mu = vij.dot(r) / (length * length + eta2);
        // With several fluids m_j / m_i times a pair's mean mass over m_0 (2 m_j / (m_i + m_j)), so that
        // m_i a_ij = -m_j a_ji; computed only for a pair that has such a force.
        const auto pairMass = [&] { return several ? 2.0f * massRatio[*j] / (massRatio[i] + massRatio[*j]) : 1.0f; };
        if (alpha_ > 0 && mu < 0) {
          const float meanDensity = 0.5f * (density_[i] + density_[*j]);
          viscousForce += (pairMass() * alpha_ * speedOfSound_ * h * mu / meanDensity) * gradient;
        }
        if (nu_ > 0) viscousForce += (pairMass() * laminar * mu / density_[*j]) * gradient;
        if (near && length > 1e-12f) {
          const float d = std::max(1.0f - length * inverseSupport, 0.0f);
          nearForce += (pairMass() * (nearPressure_[i] + nearPressure_[*j]) * d * d * inverseSupport / length) * r;
        }
      }
      // The tank's walls. Without surface tension, the mirror images of the fluid beside them (forEachWallImage),
      // each with its particle's pressure continued by the hydrostatic gradient to where the image stands (its
      // height's, beyond a floor; the same beside a side wall, which then holds none of the water's weight).
      // With surface tension the particle's own pressure once (Akinci 2012): the cohesion holds particles at a
      // wall with its own pressure, where a mirrored wall's second share stands them off it and feeds their
      // motion (docs/surface-tension.md, "WCSPH's walls with surface tension").
      if (mirroredWalls_) {
        forEachWallImage(walls_, x_, neighbors_, i, support_, wrap, [&](size_t j, const VecD& o, const VecD& shift) {
          const float trueDensity = several ? density_[j] * massRatio[j] : density_[j];
          const float image = std::max(pressure_[j] + trueDensity * gravity_.dot(shift), 0.0f);
          pressureForce -=
              (pressureTermI + image / (density_[j] * density_[j])) * (kernel.gradientFactor(o.norm()) * o);
        });
      } else {
        float unusedWeight = 0;
        VecD wallGradient = VecD::Zero();
        walls_.add(x_[i], unusedWeight, wallGradient);
        pressureForce -= pressureTermI * wallGradient;
      }
      // The colliders as the rest lattice beyond them, its pressure the particle's mirrored and continued
      // hydrostatically (Adami's wall, Colliders::hydrostaticSum; with surface tension the particle's once); each
      // one's share is a force on the particle, recorded for colliders.csv. Where one meets a tank wall, the
      // lattice beyond both is the collider's alone: the images mirror the fluid only.
      if (!colliders_.empty()) {
        // The colliders' pressure continued at the particle's own density, m_i / m_0 times density_.
        const float hydrostaticScale = (several ? massRatio[i] : 1.0f) / density_[i];
        colliders_.forEachNear(x_[i], [&](size_t c, float d, const VecD& n) {
          float unused;
          VecD gradient;
          colliders_.wallTerms(c, x_[i], d, n, unused, gradient, !mirroredWalls_);
          const VecD force = mirroredWalls_
                                 ? VecD(-2.0f * pressureTermI * gradient -
                                        hydrostaticScale * colliders_.hydrostaticSum(c, x_[i], d, n, gravity_))
                                 : VecD(-pressureTermI * gradient);
          pressureForce += force;
          colliders_.addImpulse(i, c, (mass_ * mass_) * force, x_[i]);
        });
      }
      // m_0 (the pair sums) over m_i: the impulse on a collider, m_i times its share, is m_0^2 force either way.
      const float massScale = several ? mass_ * inverse[i] : mass_;
      VecD acceleration = gravity_ + massScale * (pressureForce + viscousForce) + (several ? inverse[i] : 1.0f) * nearForce;
      if (attractor_.active()) acceleration += attractor_.acceleration(x_[i], attractorAt);
      a_[i] = acceleration;
    }
  });
  });
  // Surface tension and adhesion (sim/surface_tension.h), their adhesion recorded as forces with the others.
  if (this->tension_.active()) {
    this->tension_.computeAccelerations(x_, neighbors_, colliders_, 1.0f, this->fluid_);
    this->tension_.addTo(a_);
  }
  if (!colliders_.empty()) colliderForces_ = colliders_.takeSlotSums();
}

// a_b = -(m_0 / m_i) p_b [sum_j m_0 (1 / rho_i^2 + 1 / rho_j^2) grad W_ij + the walls' and colliders' 2 / rho_i^2
// gradients] (Adami, Hu and Adams 2013, eq. 14, with the pressure force's mirrored walls), a pass of its own so that
// a scene without it runs the pressure loop it always did.
template <int Dim>
template <typename Kernel>
void WcsphSolver<Dim>::computeTransportAccelerations(const Kernel& kernel) {
  const PhaseTimer timer(times_.forces);
  const float* inverse = inverseMassRatio_.data();
  this->periodic_.withNearestImage([&](const auto& sharedWrap) {
  parallelFor(0, size(), [&](size_t b, size_t e) {
    const auto wrap = sharedWrap;  // the thread's own copy (sim/periodic.h)
    for (size_t i = b; i < e; ++i) {
      const float inverseSquareI = 1.0f / (density_[i] * density_[i]);
      VecD sum = VecD::Zero();
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j) {
        VecD r = x_[i] - x_[*j];
        wrap(r);
        sum -= (inverseSquareI + 1.0f / (density_[*j] * density_[*j])) * (kernel.gradientFactor(r.norm()) * r);
      }
      float unusedWeight = 0;
      VecD wallGradient = VecD::Zero();
      walls_.add(x_[i], unusedWeight, wallGradient);
      if (!colliders_.empty()) colliders_.add(x_[i], unusedWeight, wallGradient);
      sum -= (2.0f * inverseSquareI) * wallGradient;
      const float massScale = inverseMassRatio_.empty() ? mass_ : mass_ * inverse[i];
      transportAcceleration_[i] = (massScale * backgroundPressure_) * sum;
    }
  });
  });
}

// With x = rho / rho_0: Tait's e = (B / rho_0) ((x^6 - 1) / 6 + 1 / x - 1), the gas law's e = k (ln x + 1 / x - 1).
// A fluid's pressure is m_f / m_0 times the one fluid's and its particles as much heavier (computeAccelerationsWith),
// so it moves as water would and holds m_i e.
template <int Dim>
double WcsphSolver<Dim>::compressionEnergy() {
  if (neighbors_.size() != size()) computeAccelerations(time_);
  double energy = 0;
  for (size_t i = 0; i < size(); ++i) {
    const double x = double(density_[i]) / restDensity_;
    if (x <= 1) continue;
    const double e = tait_ ? double(taitB_) / restDensity_ * ((std::pow(x, 6) - 1) / 6 + 1 / x - 1)
                           : double(gasConstant_) * (std::log(x) + 1 / x - 1);
    const double ratio = massRatio_.empty() ? 1.0 : double(massRatio_[i]);
    energy += double(mass_) * ratio * e;
  }
  return energy;
}

template <int Dim>
FluidMeasures WcsphSolver<Dim>::measure() {
  if (neighbors_.size() != size()) computeAccelerations(time_);
  return kernel_.visit([&](const auto& kernel) {
    return this->measureWith([&](float r2) { return kernel.value(std::sqrt(r2)); });
  });
}

template <int Dim>
double WcsphSolver<Dim>::virialPressureWithin(const Vec<Dim>& centre, float radius) {
  const float h = smoothingLength_, eta2 = 0.01f * h * h, laminar = 2.0f * (Dim + 2) * nu_;
  const std::vector<float>& massRatio = this->massRatio_;
  // The force pass's viscous terms for the pair (i, j), over m_0^2 grad W_ij.
  const auto viscous = [&](size_t i, size_t j, const VecD& r) {
    const float mu = (v_[i] - v_[j]).dot(r) / (r.squaredNorm() + eta2);
    const float pairMass = massRatio.empty() ? 1.0f : 2.0f * massRatio[j] / (massRatio[i] + massRatio[j]);
    float term = 0;
    if (alpha_ > 0 && mu < 0) term += pairMass * alpha_ * speedOfSound_ * h * mu / (0.5f * (density_[i] + density_[j]));
    if (nu_ > 0) term += pairMass * laminar * mu / density_[j];
    return term;
  };
  return this->pairVirialPressureWithin(kernel_, pressure_, density_, VirialBall<Dim>{centre, radius}, viscous);
}

template class WcsphSolver<2>;
template class WcsphSolver<3>;

}  // namespace surge
