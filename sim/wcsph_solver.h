// Weakly compressible SPH (Monaghan 1994, "Simulating free surface flows with SPH"; Becker & Teschner 2007,
// "Weakly compressible SPH for free surface flows"), in 2D and 3D, sharing the neighbour grid, the tank walls
// and the frame loop with PBF. Per evaluation:
//   density by summation     rho_i = sum_j m W_ij, plus the tank walls' mirror images of the fluid (and with
//                            surface tension the rest lattice beyond them, sim/tank.h) and the colliders' lattice
//   equation of state        Tait p = rho_0 c^2 / 7 ((rho / rho_0)^7 - 1), or the gas law p = k (rho - rho_0);
//                            negative pressures are clamped to 0 so the free surface does not pull together
//   symmetric pressure force a_i = -sum_j m (p_i / rho_i^2 + p_j / rho_j^2) grad W_ij, over the fluid and the
//                            walls' images, an image's pressure its particle's continued by the hydrostatic
//                            gradient to the image (so a side wall carries none of the water's weight); the
//                            colliders' pressure continued from p_i by it (Adami et al. 2012, eq. 27;
//                            Colliders::hydrostaticSum)
//   viscosity                artificial (Monaghan 1992): Pi_ij = -alpha c h mu_ij / rho_ij for approaching pairs,
//                            mu_ij = v_ij . x_ij / (|x_ij|^2 + 0.01 h^2); laminar (Morris et al. 1997), from
//                            solver.kinematic_viscosity when no fluid gives its own: a_i += 2 (d + 2) nu
//                            sum_j (m / rho_j) mu_ij grad W_ij between fluid pairs (no wall term); from
//                            fluids[i].viscosity: the shared solver at the end of each step (sim/viscosity.h),
//                            explicit unless solver.viscosity_solver is implicit, no-slip at the walls
//   near pressure (opt-in)   Clavet et al. 2005's near density sum_j (1 - q)^3 and near pressure k_near times it,
//                            as a force pushing close pairs apart
//   gravity and the attractor (sim/attractor.h)
//   transport velocity       (opt-in, solver.background_pressure p_b; Adami, Hu and Adams 2013, eq. 13-14) the
//                            particles move with v + (dt/2) a_b, a_b = -sum_j m p_b (1 / rho_i^2 + 1 / rho_j^2)
//                            grad W_ij (and the walls' and colliders' share), while v does not feel p_b: the push
//                            keeps the particles evenly spaced in a flow that stretches the lattice (the extra
//                            stress term A of the paper is left out: it changed Taylor-Green's energy by < 1%)
// Time integration: velocity Verlet (kick-drift-kick), or semi-implicit Euler; the step from the CFL condition
// on c + |v|max, the viscous limit and the force limit (or fixed). The integrator restarts at every output frame
// from (x, v), so a run resumed from a frame file continues exactly as an uninterrupted one.
#pragma once

#include <vector>

#include "core/scene.h"
#include "sim/kernels.h"
#include "sim/particle_solver.h"

namespace surge {

template <int Dim>
class WcsphSolver final : public ParticleSolver<Dim> {
 public:
  using VecD = Vec<Dim>;
  using ParticleSolver<Dim>::size;

  // `shapes`: the scene's collider shapes, built once by the caller; null builds them from the scene.
  explicit WcsphSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes = nullptr);

  // Steps are chosen by the solver (stableTimeStep), not a fixed count per frame.
  int fixedSubsteps() const override { return 0; }
  // Start of an output frame at `time`: forget the stored accelerations (see the header comment).
  void beginFrame(double time) override;
  // The largest stable step for the current state (or the scene's fixed time_step).
  float stableTimeStep() override;
  // One step of dt from `time`. Returns the index of the first particle that is not finite or left the tank, or -1.
  long step(float dt, double time) override;

  FluidMeasures measure() override;
  float maxPressure() const override { return framePressureMax_; }
  int lastIterations() const override { return 0; }
  float speedOfSound() const { return speedOfSound_; }
  // sum_i m_i e(rho_i), e the equation of state's internal energy, int p / rho^2 d rho from rest (zero below it,
  // where the pressure is clamped).
  double compressionEnergy() override;
  // Pressures of the last evaluation, in the particles' current order (for tests).
  const std::vector<float>& pressures() const { return pressure_; }
  // With the pair viscosity's force (Monaghan's, Morris's): it pushes approaching pairs apart only, so that a drop
  // that is not quite still holds a share of its pressure through it.
  double virialPressureWithin(const Vec<Dim>& centre, float radius) override;

 private:
  using Core = ParticleSolver<Dim>;
  using Core::x_, Core::v_, Core::neighbors_, Core::walls_, Core::colliders_, Core::mass_, Core::times_;
  using Core::restDensity_, Core::gravity_, Core::attractor_, Core::massRatio_, Core::inverseMassRatio_;

  void resizeChannels(size_t n) override;
  void computeAccelerations(double time);
  // Adami et al. 2013's a_b into transportAcceleration_ (only with background_pressure > 0).
  template <typename Kernel>
  void computeTransportAccelerations(const Kernel& kernel);
  // The drift of a step dt: with the transport velocity, the particles move with v + kick a_b.
  void drift(float dt, float kick);
  template <typename Kernel>
  void computeAccelerationsWith(const Kernel& kernel, double time);

  // Parameters.
  bool verlet_, tait_;
  // Without surface tension the tank's walls mirror the fluid (its images) and the colliders' pressure is Adami's
  // (the particle's mirrored and continued hydrostatically); with it both take Akinci 2012's (the particle's own
  // once, the gradient of its compression energy).
  bool mirroredWalls_;
  SphKernel<Dim> kernel_;
  float support_, smoothingLength_, speedOfSound_, gasConstant_, taitB_;
  float alpha_, nu_, nearStiffness_, cfl_, fixedStep_, backgroundPressure_;

  // WCSPH's channels beside the core's.
  std::vector<VecD> a_;
  std::vector<float> density_, pressure_;
  std::vector<float> nearPressure_;  // only with near_pressure > 0
  std::vector<VecD> transportAcceleration_;  // a_b at the last evaluation; only with background_pressure > 0
  std::vector<Wrench> colliderForces_;   // each collider's force at the last evaluation (for the impulses)

  bool accelerationsValid_ = false;
  bool frameStart_ = true;      // beginFrame: the next accelerations place the moving solids first
  float frameDuration_ = 0;     // 1 / fps: a keyframed solid's velocity at a frame's start is over the frame before
  double time_ = 0;  // the simulated time of the current state (moves the attractor)
  float framePressureMax_ = 0;
};

// Its registration (sim/wcsph_method.cpp), which the registry lists (sim/fluid_solver.cpp).
extern const FluidMethod kWcsphMethod;

extern template class WcsphSolver<2>;
extern template class WcsphSolver<3>;

}  // namespace surge
