// Divergence-Free SPH (Bender & Koschier, "Divergence-Free Smoothed Particle Hydrodynamics", SCA 2015, and
// "Divergence-Free SPH for Incompressible and Viscous Fluids", TVCG 2017; "the paper" is the 2015 one, whose
// algorithm numbers are used), in 2D and 3D, sharing the grid, the tank walls and the colliders with PBF and
// WCSPH. One step is the paper's Algorithm 1:
//   non-pressure forces       gravity, the attractor, XSPH viscosity (as PBF's eq. 17): v* = v + dt a
//   correctDensityError       Algorithm 3: the constant-density solver on v*, until the average predicted
//                             compression is under solver.max_density_error (at least 2 iterations)
//   drift                     x += dt v*, stopped at the colliders and the tank (with solver.background_pressure,
//                             x += dt (v* + dt a_b): Adami et al. 2013's transport velocity, as WCSPH's)
//   neighbours, rho, alpha    the grid sort, rho_i = sum_j m W_ij and the factor alpha_i of the new positions
//   correctDivergenceError    Algorithm 2: the divergence-free solver on v, until the average density change a
//                             step of compression would cause is under solver.max_divergence_error (at least 1)
// Both solvers are the paper's, written in the units of PBF's lambda (dimensionless, so warm starts carry over
// steps of any length): with V = m / rho_0 and g_ij = V grad W_ij,
//   S_i = |sum_j g_ij + G_i|^2 + sum_j |g_ij|^2          (rho_i / alpha_i over rho_0^2; G_i the walls')
//   lambda_i = s_i / S_i                                  (kappa_i dt^2 / rho_i)
//   v_i -= (1 / dt) (sum_j (lambda_i + lambda_j) g_ij + lambda_i G_i)   (the pressure force; walls as Akinci's)
// where s_i is the predicted compression rho*_i / rho_0 - 1, rho*_i = rho_i + dt D rho_i / Dt, for the density
// solver, and dt times the velocity divergence D rho_i / Dt / rho_0 = sum_j (v_i - v_j) . g_ij + v_i . G_i
// (less the walls' own motion) for the divergence solver; in a box periodic along every axis, which cannot be
// compressed as a whole, the density solver's 1 is the mean of rho_i / rho_0 when above 1. The solvers are Jacobi
// iterations, relaxed by 0.5 (as SPlisHSPlasH's) or less where the kernel's many neighbours need it, on the
// accumulated lambda, projected to lambda >= 0 (no tension). Part of each one's
// total starts it in the next step (the 2017 paper's warm start); the totals are carried state, written beside
// each frame (FluidSolver::carriedState), so a run resumed from a frame continues exactly.
// The tank's clamp (a particle radius inside its walls) bounds every velocity the solvers compute, so they
// predict the move the clamp will allow: the walls, continued as the rest lattice (sim/tank.h), leave a
// particle at rest against them with a density that does not change to first order as it slides into them,
// and unbounded, the density solver let the first layer sink into the clamp and compressed the second by 25%.
// Particles at the free surface (less than 80% of the rest density around them) take no divergence correction
// of their own, as in the paper's implementation: it would hold splashes together.
//
// The step is from the CFL condition, dt = cfl particle_spacing / |v + g dt_max|max (the paper's dt <= 0.4 d / |v|
// at cfl 0.4, d the particle diameter), at most dt_max = solver.time_step if set, else one frame / solver.substeps
// (and the depth, surface tension, viscosity and transport velocity bounds).
// (Not a fixed step, as time_step is for WCSPH: beyond its CFL step the linear prediction of both solvers fails,
// and a whole frame a step left a dam break 30% compressed after 100 iterations, and gaining energy.)
#pragma once

#include <vector>

#include "core/scene.h"
#include "sim/kernels.h"
#include "sim/particle_solver.h"

namespace surge {

template <int Dim>
class DfsphSolver final : public ParticleSolver<Dim> {
 public:
  using VecD = Vec<Dim>;
  using ParticleSolver<Dim>::size;

  explicit DfsphSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes = nullptr);

  int fixedSubsteps() const override { return 0; }
  float stableTimeStep() override;
  void beginFrame(double time) override;
  long step(float dt, double time) override;

  FluidMeasures measure() override;
  int lastIterations() const override { return densityIterations_; }
  int densityIterationCap() const override { return maxIterations_; }
  int lastDivergenceIterations() const override { return divergenceIterations_; }
  // The largest pressure of the frame's density solves, p_i = rho_0 lambda_i / dt^2.
  float maxPressure() const override { return framePressureMax_; }
  // Each particle's pressure in the last step's density solve, rho_0 lambda_i / dt^2, in the current order; with
  // `withDivergence`, plus the divergence solve's (the same form): the whole pressure force of the step.
  std::vector<float> pressures(bool withDivergence = false) const;
  // Both solves' pressures: without the divergence solve's, a drop at rest summed to -0.27 Pa, not zero
  // (docs/surface-tension.md, "Laplace's pressure").
  double virialPressureWithin(const Vec<Dim>& centre, float radius) override {
    return this->pairVirialPressureWithin(kernel_, pressures(true), {}, VirialBall<Dim>{centre, radius});
  }

 private:
  using Core = ParticleSolver<Dim>;
  using Core::x_, Core::v_, Core::neighbors_, Core::walls_, Core::colliders_, Core::mass_, Core::times_;
  using Core::restDensity_, Core::vectorScratch_, Core::floatScratch_, Core::inverseMassRatio_;

  void resizeChannels(size_t n) override;
  // The two solvers' lambda totals, particle by particle.
  void forEachCarriedChannel(const std::function<void(std::vector<float>&)>& visit) override {
    visit(densityWarm_);
    visit(divergenceWarm_);
  }
  // Sorts the particles into the grid (reordering every channel) and computes, at the current positions, the
  // neighbour lists, each pair's g_ij, each particle's wall gradient G_i, density ratio and S_i.
  void prepareStep();
  // The colliders near xi: adds their weight and gradient sums (wallTerms) and returns sum_c v_c . grad W, the
  // flux a moving wall drives into the particle (wallFlux_ over the volume).
  float colliderTerms(const VecD& xi, float& weight, VecD& gradient) const;
  // Each particle's wall flux (wallFlux_) at the current positions with the colliders as placed now.
  void updateWallFlux();
  template <bool kSeveral, typename Kernel>
  void computeFactors(const Kernel& kernel);
  void applyNonPressureForces(float dt, double time);
  // a_b of solver.background_pressure at the step's start.
  void computeTransportAccelerations();
  // A share of last step's total (kDensityWarmStart, kDivergenceWarmStart) applied to v, the solve's start.
  void warmStart(bool density, float dt, std::vector<float>& total);
  // One of the two solvers (Algorithms 2 and 3): iterates on v_ until the average residual is at most `limit`
  // (and at least `minimum` times, at most solver.max_iterations), from the warm start (applied here unless
  // `warmed`); `total` ends as this solve's total. Returns the corrections applied.
  int solve(bool density, float dt, double limit, int minimum, std::vector<float>& total, bool warmed = false);
  // s_i of the solver at the current velocities (the compression if density, else dt D rho / Dt / rho_0).
  float residual(size_t i, bool density, float dt) const;
  // v_i -= (1 / dt) (sum_j (d_i + d_j) g_ij + d_i G_i) for the lambda increments d, and total_i += d_i.
  void applyIncrements(const std::vector<float>& increments, float dt, std::vector<float>& total);
  // The impulses the colliders gave the particles through their share of G_i over this step's solves.
  void recordColliderImpulses(const std::vector<float>& lambda, float dt);

  // Parameters.
  SphKernel<Dim> kernel_;
  float support_, volume_, spacing_;
  double maxDensityError_, maxDivergenceError_;
  int maxIterations_;
  float cfl_, maxStep_, xsphC_;
  bool pressureBeforeViscosity_ = false;  // with viscosity: the density warm start goes before its solve
  float relaxation_;  // the Jacobi relaxation omega for this kernel and spacing (jacobiRelaxation)
  float backgroundPressure_;  // p_b of the transport velocity; 0 none

  // DFSPH's channels beside the core's.
  std::vector<float> densityRatio_;  // rho_i / rho_0 at the current positions
  std::vector<float> diagonal_;      // S_i
  std::vector<VecD> wallGradient_;   // G_i, the tank's and the colliders'
  std::vector<float> wallFlux_;      // sum_c V v_c . grad W over the colliders (moving walls); only with colliders
  std::vector<float> densityWarm_, divergenceWarm_, increments_;
  std::vector<VecD> transportAcceleration_;  // a_b, with solver.background_pressure only
  std::vector<std::vector<VecD>> pairGradients_;  // g_ij, parallel to neighbors_
  std::vector<std::vector<float>> pairWeights_;   // W_ij for XSPH; only with xsph_c > 0
  bool prepared_ = false;  // the factors are those of the current positions
  float densityTarget_ = 1;  // what the density solve aims rho_i / rho_0 at (ParticleSolver::meanDensityTarget)

  int densityIterations_ = 0, divergenceIterations_ = 0;
  float framePressureMax_ = 0, lastStep_ = 0;
};

// Its registration (sim/dfsph_method.cpp), which the registry lists (sim/fluid_solver.cpp).
extern const FluidMethod kDfsphMethod;

extern template class DfsphSolver<2>;
extern template class DfsphSolver<3>;

}  // namespace surge
