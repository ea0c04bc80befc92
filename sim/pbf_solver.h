// Position Based Fluids, Macklin & Mueller, SIGGRAPH 2013 ("the paper"), in 2D and 3D.
// One step is the paper's Algorithm 1, split into named phases:
//   predictPositions        lines 1-4   apply external forces, predict x*
//   findNeighbors           lines 5-7   sort into the grid, reorder particles, build neighbour lists
//   prepareFilledDomain                 (not in the paper) in a box periodic along every axis, the constraints
//                                       aim at the mean density; with solver.background_pressure p_b,
//                                       x* += dt^2 a_b, Adami et al. 2013's transport velocity (as DFSPH's)
//   solveDensityConstraints lines 8-19  a warm start (below), then Jacobi iterations: lambda (eq. 11), delta p
//                                       with s_corr (eq. 12-14), collision response, x* += delta p; the
//                                       iterations are Chebyshev-accelerated when they run to a density
//                                       error under a cap of 8 or more (Wang 2015, see the .cpp)
//   updateVelocities        line 21     v = (x* - x) / dt (less the push's dt a_b)
//   vorticity + XSPH        line 22     vorticity confinement (eq. 15-16), XSPH viscosity (eq. 17)
//   commit                  line 23     x = x*
// The warm start (solver.warm_start, not in the paper; off by default, experimental): each particle's lambdas of
// a step are summed, and the next step begins with one correction of eq. 12 by that share of the sums, as DFSPH
// warm-starts its pressure (Bender & Koschier 2017, sec. 4.3). A particle found uncompressed at any iteration
// forgets its sum. It halves the iterations of a 3D dam break at the same density error, but the constraint is
// one-sided: a push beyond what the compression needed is never taken back and stays as velocity, and a deep 2D
// dam break ends with three times the kinetic energy the other methods give it (docs/speed-accuracy.md). The
// sums are carried between frames (FluidSolver::carriedState), so a resumed run continues exactly.
// Every loop gathers over neighbours and writes only its own particle, so results do not depend on the thread
// count. A feature the scene turns off (s_corr k = 0, vorticity epsilon = 0, XSPH c = 0) runs no pass and holds
// no memory.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/scene.h"
#include "sim/colliders.h"
#include "sim/kernels.h"
#include "sim/particle_solver.h"

namespace surge {

// Wendland C2 for eq. 2 and 8 in a 2D scene with surface tension (PbfWendlandC2); poly6 and spiky elsewhere.
bool pbfUsesWendland(const Scene& scene);

template <int Dim>
class PbfSolver final : public ParticleSolver<Dim> {
 public:
  using VecD = Vec<Dim>;
  using ParticleSolver<Dim>::size;

  // `shapes`: the scene's collider shapes, built once by the caller; null builds them from the scene.
  explicit PbfSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes = nullptr);

  // The frame loop's interface (see sim/simulation.cpp): PBF takes the scene's substeps a frame, each shortened
  // when the state needs it (stableTimeStep).
  int fixedSubsteps() const override { return substeps_; }
  void beginFrame(double) override {}
  float stableTimeStep() override;

  // One time step of Algorithm 1 from `time` (which moves the attractor). Returns the index of the first
  // particle whose state is not finite or lies outside the domain afterwards, or -1 if all are well.
  long step(float dt, double time = 0) override;

  FluidMeasures measure() override;
  int lastIterations() const override { return lastIterations_; }
  int densityIterationCap() const override { return maxDensityError_ > 0 ? iterations_ : 0; }
  // Bytes held by every particle channel, the grid, the neighbour lists and the pair factors (capacities).
  size_t memoryBytes() const;

 private:
  using Core = ParticleSolver<Dim>;
  // Delegated to by the one above, with the rest lattice through PBF's kernels.
  PbfSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, RestLattice<Dim> lattice);
  using Core::x_, Core::v_, Core::neighbors_, Core::walls_, Core::colliders_, Core::mass_, Core::times_;
  using Core::massRatio_, Core::inverseMassRatio_;
  using Core::vectorScratch_, Core::restDensity_;

  void resizeChannels(size_t n) override;
  void forEachCarriedChannel(const std::function<void(std::vector<float>&)>& visit) override {
    if (warmStart_ > 0) visit(lambdaTotal_);
  }
  void predictPositions(float dt, double time);
  void findNeighbors();
  void solveDensityConstraints();
  // Eq. 11 (with the Chebyshev weight omega of this iteration, 1 for plain Jacobi); returns the average density
  // error before this iteration's correction.
  double computeLambdas(float omega);
  template <bool kWendland>
  double computeLambdasWith(float omega);
  template <bool kSeveral, bool kPeriodic, bool kWendland>
  double computeLambdasOf(float omega);
  void applyWarmStart();
  // Eq. 12 from lambda_: an iteration's correction, or with kWarmStart the warm start's (kernel gradients
  // evaluated here rather than read from the lambda pass, no s_corr, nothing added to the lambda totals).
  template <bool kWarmStart>
  void applyPositionCorrections() {
    if (wendland_)
      applyPositionCorrectionsWith<kWarmStart, true>();
    else
      applyPositionCorrectionsWith<kWarmStart, false>();
  }
  template <bool kWarmStart, bool kWendland>
  void applyPositionCorrectionsWith() {
    if (this->periodic_.active())
      applyPositionCorrectionsOf<kWarmStart, true, kWendland>();
    else
      applyPositionCorrectionsOf<kWarmStart, false, kWendland>();
  }
  // kPeriodic: pairs take their nearest image (sim/periodic.h); without it the loops are what they were.
  template <bool kWarmStart, bool kPeriodic, bool kWendland>
  void applyPositionCorrectionsOf();
  // The kernels of eq. 2 and 8: poly6 and spiky, or with kWendland Wendland C2 for both (wendland_). The hot
  // loops are compiled for each and pick one per pass; the passes that run seldom pick per pair (kernelWeight...).
  template <bool kWendland>
  const auto& kernelsOf() const {
    if constexpr (kWendland)
      return wendlandKernels_;
    else
      return kernels_;
  }
  float kernelWeight(float r2) const { return wendland_ ? wendlandKernels_.weight(r2) : kernels_.weight(r2); }
  typename Kernels<Dim>::Pair kernelPair(float r2) const {
    return wendland_ ? wendlandKernels_.pair(r2) : kernels_.pair(r2);
  }
  VecD kernelGradient(const VecD& r, float length) const {
    return wendland_ ? wendlandKernels_.gradient(r, length) : kernels_.gradient(r, length);
  }
  void pullBySurfaceTension(float dt);
  void updateVelocities(float dt);
  // p*_i += delta_i, stopped at the colliders and the tank (the position corrections, the push).
  void moveBy(const std::vector<VecD>& delta);
  // sim/pbf_transport.cpp: before the constraints, the mean target of a box periodic along every axis
  // (densityTarget_) and the transport velocity's push (solver.background_pressure), a move of x* the velocity
  // does not keep (removePushFromVelocities).
  void prepareFilledDomain(float dt);
  void removePushFromVelocities(float dt);
  void collide(size_t i, const VecD& from, bool fromStepStart);
  VecD colliderCorrection(size_t i, const VecD& p, float lambda);
  void applyFriction();
  void applyVorticityConfinement(float dt);
  void applyXsphViscosity();
  template <bool kWendland>
  void applyXsphViscosityWith();
  // The offset p_i - p_j used for a pair closer than coincidentLength_ (see the .cpp).
  VecD coincidentOffset(size_t i, size_t j) const;
  VecD pairOffset(size_t i, size_t j, const VecD& pi) const;  // p_i - p_j, or the offset above

  // Parameters, fixed at construction.
  Kernels<Dim> kernels_;                // poly6 and spiky (eq. 2 and 8)
  PbfWendlandC2<Dim> wendlandKernels_;  // in their place in a 2D scene with surface tension (pbfUsesWendland)
  bool wendland_;
  float massOverRho_, epsilon_, latticeGradientSum_;
  float scorrK_, scorrInvWdq_, scorrAtRest_;
  int scorrN_;
  float coincidentLength_;
  float vorticityEpsilon_, xsphC_;
  float warmStart_;
  float chebyshevRho_;  // 0: plain Jacobi
  int iterations_;
  double maxDensityError_;
  int substeps_;
  float cfl_, frameStep_;  // the Courant number; a frame over the substeps
  float backgroundPressure_;  // p_b of the transport velocity; 0 none

  // PBF's channels beside the core's: the predicted positions x* and the multipliers.
  std::vector<VecD> p_;
  std::vector<float> lambda_;
  float densityTarget_ = 1;           // C_i = rho_i / rho_0 - densityTarget_ (prepareFilledDomain)
  std::vector<float> densityRatio_;  // rho_i / rho_0 at x*; only in prepareFilledDomain
  std::vector<VecD> transportPush_;  // dt^2 a_b; only with solver.background_pressure
  std::vector<float> lambdaTotal_;  // the sums of each particle's lambdas this step; only with the warm start
  std::vector<VecD> omega3_;    // vorticity (3D); allocated only when vorticity confinement is on
  std::vector<float> omega2_;   // vorticity (2D, a scalar)
  // What the colliders gave each particle at p_ in the lambda pass (or the warm start's), reused by the
  // correction that follows at the same positions; sized only with colliders.
  std::vector<typename Colliders<Dim>::Found> found_;
  std::vector<VecD> onlyGradient_;
  std::vector<typename Colliders<Dim>::Found> scratchFound_;
  // found_ holds for the particles where they stand: taken at this step's positions and carried since, or at the
  // last step's end when no collider moves.
  bool foundHolds_ = false;
  float stepDt_ = 0;          // the current step (turns collider displacements into impulses)
  // Per neighbour pair, parallel to neighbors_: the spiky gradient factor g of Kernels::pair, computed by the
  // lambda pass and reused by the position-correction pass of the same iteration (same positions).
  std::vector<std::vector<float>> pairGradientFactors_;

  int lastIterations_ = 0;
};

// Its registration (sim/pbf_method.cpp), which the registry lists (sim/fluid_solver.cpp).
extern const FluidMethod kPbfMethod;

extern template class PbfSolver<2>;
extern template class PbfSolver<3>;

}  // namespace surge
