// The fluid's energy account (issue 32). Its mechanical energy E is the kinetic energy and the potential energy
// against the tank's floor; its sources' work W (stats.csv's source_work, cumulative from frame 0) is what the
// moving colliders and bodies did on it (sim/colliders.h, Wrench::work), what the attractor did, and the energy
// the emitters bring in and steer, less what the sinks and open faces carry out (sim/sources.h), and the
// compression a jittered start holds in WCSPH (FluidSolver::compressionEnergy, in frame 1's). Every method
// dissipates (walls stop what hits them; viscosity, PBF's projection), so E - W never rises above frame 0's in
// a run that is right; the ledger stops a run whose E - E(0) - W passes tolerance().
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <string>

#include "core/files.h"
#include "core/scene.h"
#include "sim/kernels.h"

namespace surge {

// The potential energy of gravity against the tank's floor: m g . (c - x), c the tank's corner lowest along
// gravity, so 0 on the floor's plane and growing with height.
struct GravityPotential {
  explicit GravityPotential(const Scene& scene);
  double at(const Eigen::Vector3d& x) const { return gravity.dot(corner - x); }
  // A particle of mass m at x moving at v: kinetic plus potential energy (J; J/m in 2D).
  template <int Dim>
  double energy(const Vec<Dim>& x, const Vec<Dim>& v, double mass) const {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    p.head<Dim>() = x.template cast<double>();
    return mass * (0.5 * double(v.squaredNorm()) + at(p));
  }
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero(), corner = Eigen::Vector3d::Zero();
};

class EnergyLedger {
 public:
  static constexpr double kTolerance = 0.02;  // of the largest energy the fluid has held; see tolerance()

  // `speed`: the fastest the scene can give the fluid (sceneSpeed, sim/solver_defaults.h); `remedy`: what
  // the stop's line advises (FluidMethod::steadier); `stops` false keeps the account without stopping (a scene
  // with emitters under a method whose nozzle makes energy the account cannot see, FluidMethod::emittersAccounted).
  EnergyLedger(int dimensions, double speed, std::string remedy, bool stops)
      : dimensions_(dimensions), speed_(speed), remedy_(std::move(remedy)), stops_(stops) {}

  // A fresh run: frame 0's energies. A resumed one: stats.csv's rows up to `frame`, whose figures the ledger
  // then goes on from exactly as the uninterrupted run did (it keeps only what stats.csv prints).
  void start(double kinetic, double potential);
  void resume(const fs::path& stats, int frame);

  // Work done on the fluid since the last call (J).
  void add(double work) { work_ += work; }
  // source_work after the frame just stepped, as stats.csv prints it (the ledger keeps that rounding).
  double sourceWork();

  // After frame `frame` with these energies and the fluid's mass: RunError (exit 1) with one line, the frame, the
  // figures and the remedy, if E - E(0) - W passes tolerance().
  void check(int frame, double kinetic, double potential, double mass);
  // The gain allowed (J): 2% of the largest energy the fluid has held. The methods are set to hold the density
  // within about 1% of rest (WCSPH's speed of sound is chosen for it; DFSPH's and PBF's defaults hold it): a
  // fluid that far off its rest volume stands that far off its rest height, so its potential energy may differ
  // by 1% of E from the rest lattice it started as, one way at the start and the other way later: 2%.
  // At least the energy of the whole fluid moving at a hundredth of the scene's speed: a fluid at rest without
  // gravity holds nothing, and what float rounding stirs in it (1e-10 J) is no gain worth a stop.
  // docs/speed-accuracy.md measures the gain on every shipped scene and on pools at rest.
  double tolerance() const { return std::max(kTolerance * most_, 0.5 * mass_ * 1e-4 * speed_ * speed_); }

 private:
  int dimensions_;
  double speed_;
  std::string remedy_;
  bool stops_;
  double work_ = 0, start_ = 0, most_ = 0, mass_ = 0;
};

}  // namespace surge
