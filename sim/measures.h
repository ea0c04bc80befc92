// What the frame loop reports of any solver: time per phase, the density error of DESIGN.md and the kinetic
// energy, and the first particle that went bad. Shared by every method (sim/particle_solver.h).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/parallel.h"
#include "sim/neighbor_grid.h"
#include "sim/periodic.h"
#include "sim/tank.h"

namespace surge {

// Milliseconds spent per phase, accumulated until reset, as stats.csv's columns: `neighbors` the sort, reorder
// and lists (ms_neighbors); `pressure` the density or pressure solve (ms_constraint: PBF's constraint
// iterations, WCSPH's density and equation of state, DFSPH's two solvers); `vorticity` (ms_vorticity); `forces`
// the other forces (ms_viscosity: XSPH, and WCSPH's force pass).
struct PhaseTimes {
  double neighbors = 0, pressure = 0, vorticity = 0, forces = 0;
};

using PhaseClock = std::chrono::steady_clock;
inline double millisecondsSince(PhaseClock::time_point start) {
  return std::chrono::duration<double, std::milli>(PhaseClock::now() - start).count();
}

// Adds the milliseconds of its own life to one of PhaseTimes' phases. A timer of the same phase inside it (DFSPH's
// forces around the viscosity's) is counted once: the outer one sets the phase to its start's value plus its life.
class PhaseTimer {
 public:
  explicit PhaseTimer(double& phase) : phase_(phase), before_(phase), start_(PhaseClock::now()) {}
  ~PhaseTimer() { phase_ = before_ + millisecondsSince(start_); }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  double& phase_;
  const double before_;
  PhaseClock::time_point start_;
};

// Density error as DESIGN.md defines it (compression only, max(rho_i / rho_0 - 1, 0)) averaged and maximised
// over the particles, and the kinetic energy.
struct FluidMeasures {
  double densityErrorAvg = 0, densityErrorMax = 0, kineticEnergy = 0;
};

// The measures at positions x with neighbour lists of (nearly) those positions; weight(r2) is the density
// kernel W as a function of the squared distance; walls.add(p, weight, gradient) adds the boundary's share.
// `sharedWrap` takes a pair's offset to its nearest image (sim/periodic.h) in a domain that wraps.
template <int Dim, typename Walls, typename Weight, typename Wrap = NoWrap>
FluidMeasures measureDensityAndEnergy(const std::vector<Vec<Dim>>& x, const std::vector<Vec<Dim>>& v,
                                      const NeighborLists& neighbors, const Walls& walls, float mass,
                                      float restDensity, Weight weight, const std::vector<float>& massRatio = {},
                                      const Wrap& sharedWrap = {}) {
  struct Sums {
    double errorSum = 0, errorMax = 0, energy = 0;
    Sums& operator+=(const Sums& o) {
      errorSum += o.errorSum;
      errorMax = std::max(errorMax, o.errorMax);
      energy += o.energy;
      return *this;
    }
  };
  const float selfWeight = weight(0.0f);
  const Sums sums = parallelSum<Sums>(0, x.size(), [&](size_t b, size_t e) {
    const Wrap wrap = sharedWrap;  // the thread's own copy (sim/periodic.h)
    Sums s;
    for (size_t i = b; i < e; ++i) {
      float w = selfWeight;
      for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j) {
        Vec<Dim> r = x[i] - x[*j];
        wrap(r);
        w += weight(r.squaredNorm());
      }
      Vec<Dim> unusedGradient = Vec<Dim>::Zero();
      walls.add(x[i], w, unusedGradient);
      const double error = std::max(double(mass * w / restDensity) - 1.0, 0.0);
      s.errorSum += error;
      s.errorMax = std::max(s.errorMax, error);
      s.energy += 0.5 * mass * (massRatio.empty() ? 1.0f : massRatio[i]) * v[i].squaredNorm();
    }
    return s;
  });
  FluidMeasures m;
  m.densityErrorAvg = x.empty() ? 0 : sums.errorSum / double(x.size());
  m.densityErrorMax = sums.errorMax;
  m.kineticEnergy = sums.energy;
  return m;
}

// The runaway speed of particles set with velocities of their own (a test's swirl, a resumed frame): the
// scene's, plus ten times the fastest of them, as runawaySpeed counts the scene's initial speeds.
template <int Dim>
float runawaySpeedFor(float sceneLimit, const std::vector<Vec<Dim>>& v) {
  float fastest = 0;
  for (const Vec<Dim>& velocity : v) fastest = std::max(fastest, velocity.norm());
  return sceneLimit + 10 * fastest;
}

// The index of the first particle whose position or velocity is not finite, whose position left the tank, or
// whose speed passed `speedLimit` (runawaySpeed, core/scene.h: a blow-up that the tank's clamp would otherwise
// hide inside the tank), or -1.
template <int Dim>
long firstParticleOutside(const std::vector<Vec<Dim>>& x, const std::vector<Vec<Dim>>& v,
                          const TankWalls<Dim>& walls, float speedLimit) {
  struct First {
    long index = -1;
    First& operator+=(const First& o) {
      if (index < 0 || (o.index >= 0 && o.index < index)) index = o.index;
      return *this;
    }
  };
  const float limitSquared = speedLimit * speedLimit;
  return parallelSum<First>(0, x.size(), [&](size_t b, size_t e) {
           First first;
           for (size_t i = b; i < e && first.index < 0; ++i)
             if (!x[i].allFinite() || !v[i].allFinite() || !walls.contains(x[i]) ||
                 !(v[i].squaredNorm() <= limitSquared))
               first.index = static_cast<long>(i);
           return first;
         }).index;
}

// A ball (a disc in 2D) over which Irving and Kirkwood's mechanical pressure is averaged
// (FluidSolver::virialPressureWithin): a pair's virial counts by the share of the segment between its particles
// inside the ball. `halfInside(x, r)` is that share of the pair's half at x, the segment from x to x - r / 2 (r =
// x_i - x_j, so that the two halves' shares sum to the pair's).
template <int Dim>
struct VirialBall {
  Vec<Dim> centre;
  float radius;

  float halfInside(const Vec<Dim>& x, const Vec<Dim>& r) const {
    const Vec<Dim> a = x - centre, d = -0.5f * r;  // the half is a + t d, t in [0, 1]
    const float dd = d.squaredNorm(), ad = a.dot(d), c = a.squaredNorm() - radius * radius;
    if (dd == 0) return c < 0 ? 1.0f : 0.0f;
    const float discriminant = ad * ad - dd * c;
    if (discriminant <= 0) return 0;
    const float root = std::sqrt(discriminant);
    return std::max(0.0f, std::min(1.0f, (-ad + root) / dd) - std::max(0.0f, (-ad - root) / dd));
  }
  double volume() const {
    return Dim == 2 ? M_PI * double(radius) * radius : 4.0 / 3.0 * M_PI * std::pow(double(radius), 3);
  }
};

// The largest value of `values`, in parallel.
inline float parallelMax(const std::vector<float>& values) {
  struct Max {
    float value = 0;
    Max& operator+=(const Max& o) {
      value = std::max(value, o.value);
      return *this;
    }
  };
  return parallelSum<Max>(0, values.size(), [&](size_t b, size_t e) {
           Max m;
           for (size_t i = b; i < e; ++i) m.value = std::max(m.value, values[i]);
           return m;
         }).value;
}

}  // namespace surge
