#include "sim/pbf_solver.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/parallel.h"
#include "sim/solver_defaults.h"
#include "sim/tank.h"

namespace surge {
namespace {

// x^n for an integer 1 <= n <= 16 by squaring (std::pow costs more than the rest of the pair), with no branch
// on x, so that it vectorises.
inline float integerPower(float x, int n) {
  const float x2 = x * x, x4 = x2 * x2, x8 = x4 * x4, x16 = x8 * x8;
  return (n & 1 ? x : 1.0f) * (n & 2 ? x2 : 1.0f) * (n & 4 ? x4 : 1.0f) * (n & 8 ? x8 : 1.0f) * (n & 16 ? x16 : 1.0f);
}

// The neighbour loops of the two passes are written for the compiler's vectoriser (#pragma omp simd, built
// with -fopenmp-simd): plain floats, no branch that depends on the pair, sums kept in lanes and added at the
// end. The order of those sums depends on the vector width the build targets (so a build for another -march
// may differ in the last bits), never on the thread count. A pair closer than coincidentLength_ (see
// coincidentOffset) is rare; its particle is done again by the scalar loop beside.

// The rest lattice through the density's kernel (eq. 2) and its gradient's (eq. 8).
template <int Dim>
RestLattice<Dim> pbfRestLattice(const Scene& scene) {
  const float h = static_cast<float>(scene.solver.kernel_radius);
  const auto latticeOf = [&](const auto& kernels) {
    return RestLattice<Dim>(
        scene, h, [&](const Vec<Dim>& r) { return kernels.weight(r.squaredNorm()); },
        [&](const Vec<Dim>& r) { return kernels.gradient(r, r.norm()); });
  };
  return pbfUsesWendland(scene) ? latticeOf(PbfWendlandC2<Dim>(h)) : latticeOf(Kernels<Dim>(h));
}

}  // namespace

bool pbfUsesWendland(const Scene& scene) {
  return scene.dimensions == 2 && sceneSurfaceTension(scene) > 0;
}

// The mass makes an interior particle of the rest lattice have exactly rho_0 (eq. 2 summed over the lattice),
// so a block at rest starts unstressed and keeps its volume N x spacing^d.
template <int Dim>
PbfSolver<Dim>::PbfSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes)
    : PbfSolver(scene, std::move(shapes), pbfRestLattice<Dim>(scene)) {}

template <int Dim>
PbfSolver<Dim>::PbfSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, RestLattice<Dim> lattice)
    : Core(scene, std::move(shapes), lattice),
      kernels_(static_cast<float>(scene.solver.kernel_radius)),
      wendlandKernels_(static_cast<float>(scene.solver.kernel_radius)),
      wendland_(pbfUsesWendland(scene)) {
  substeps_ = scene.solver.substeps;
  const SolverSettings& s = scene.solver;
  const float spacing = static_cast<float>(scene.particle_spacing);
  massOverRho_ = mass_ / restDensity_;
  // sum_k |grad_k C_i|^2 at the rest lattice (eq. 8-9 with C_i = rho_i / rho_0 - 1): the scale of eq. 11's
  // denominator. epsilon is a fraction of it, s_corr is measured in lambda's units 1 / that sum.
  latticeGradientSum_ = static_cast<float>(massOverRho_ * massOverRho_ * lattice.gradientSquaredSum);
  epsilon_ = static_cast<float>(s.relaxation_epsilon) * latticeGradientSum_;
  coincidentLength_ = 1e-4f * kernels_.radius();
  // s_corr is for spray and sheets, and a fluid that fills a box periodic along every axis has neither: there it
  // would act on every uncompressed pair of the bulk (a Taylor-Green vortex kept 0.29 of its energy to 0.64 s).
  scorrK_ = this->periodic_.everyAxis() ? 0.0f : static_cast<float>(s.scorr_k);
  scorrN_ = s.scorr_n;
  const float dq = static_cast<float>(s.scorr_delta_q * s.kernel_radius);
  const auto scorrScales = [&](const auto& kernels) {  // each kernel's own expression (kernelWeight rounds r^2 first)
    scorrInvWdq_ = 1.0f / kernels.weight(dq * dq);
    scorrAtRest_ = integerPower(kernels.weight(spacing * spacing) * scorrInvWdq_, scorrN_);
  };
  if (wendland_)
    scorrScales(wendlandKernels_);
  else
    scorrScales(kernels_);
  vorticityEpsilon_ = static_cast<float>(s.vorticity_epsilon);
  xsphC_ = static_cast<float>(s.xsph_c);
  warmStart_ = static_cast<float>(s.warm_start);
  // The acceleration only when iterating to a tolerance with room for it (see solveDensityConstraints).
  chebyshevRho_ = s.max_density_error > 0 && s.iterations >= SolverSettings::kChebyshevLeastIterations
                      ? static_cast<float>(s.chebyshev_rho)
                      : 0.0f;
  iterations_ = s.iterations;
  maxDensityError_ = s.max_density_error;
  cfl_ = static_cast<float>(s.cfl);
  frameStep_ = static_cast<float>(1.0 / (scene.output.fps * std::max(1, substeps_)));
  backgroundPressure_ = static_cast<float>(s.background_pressure);
}

// The CFL condition on the fastest particle after a step's gravity, dt <= cfl kernel_radius / |v|max, and the
// depth criterion of stableSubsteps on the deepest column as the fluid stands now (the frame loop shortens the
// scene's substeps to it).
template <int Dim>
float PbfSolver<Dim>::stableTimeStep() {
  const float fastest = this->fastestAfterFall(frameStep_);
  const float dt = std::min(fastest > 0 ? cfl_ * kernels_.radius() / fastest : INFINITY, this->depthStableStepNow());
  return std::min({dt, this->tension_.stableStep(), this->viscosity_.stableStep(),
                   this->transportStableStep(backgroundPressure_, kernels_.radius())});
}

template <int Dim>
void PbfSolver<Dim>::resizeChannels(size_t n) {
  p_.resize(n);
  sizeChannel(lambda_, n, 0.0f);
  if (warmStart_ > 0) sizeChannel(lambdaTotal_, n, 0.0f);
  foundHolds_ = false;
  if (!colliders_.empty()) {
    found_.resize(n);
    onlyGradient_.resize(n);
  }
  if (vorticityEpsilon_ > 0) (Dim == 3 ? omega3_.resize(n) : omega2_.resize(n));
}

template <int Dim>
long PbfSolver<Dim>::step(float dt, double time) {
  stepDt_ = dt;
  foundHolds_ = foundHolds_ && !colliders_.anyMoving();
  if (!colliders_.empty()) colliders_.beginStep(time, dt);
  predictPositions(dt, time);
  findNeighbors();
  if (this->periodic_.everyAxis() || backgroundPressure_ > 0) prepareFilledDomain(dt);
  pullBySurfaceTension(dt);
  solveDensityConstraints();
  updateVelocities(dt);
  if (backgroundPressure_ > 0) removePushFromVelocities(dt);
  this->applyViscosity(p_, dt);
  if (colliders_.hasFriction()) applyFriction();
  if (vorticityEpsilon_ > 0) applyVorticityConfinement(dt);
  if (xsphC_ > 0) applyXsphViscosity();
  x_.swap(p_);  // line 23: x_i = x*_i
  return this->endStep();
}

// Algorithm 1, lines 1-4: v_i += dt f_ext(x_i); x*_i = x_i + dt v_i. The walls act on x* at once. External
// forces: gravity, and the attractor when the scene has one.
template <int Dim>
void PbfSolver<Dim>::predictPositions(float dt, double time) {
  const auto external = this->externalForces(dt, time);
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      external.kick(x_[i], v_[i]);
      p_[i] = x_[i] + dt * v_[i];
      if (colliders_.empty()) {
        walls_.clamp(p_[i]);
        continue;
      }
      const bool found = foundHolds_;
      if (colliders_.moveFarFrom(x_[i], p_[i]) || (found && colliders_.nothingStops(found_[i], x_[i], p_[i])))
        walls_.clamp(p_[i]);
      else
        collide(i, x_[i], true);
      if (found) colliders_.carry(found_[i], x_[i], p_[i]);
    }
  });
}

// Lines 5-7: neighbours of x*. Particles are reordered by cell first, every step, for memory locality.
template <int Dim>
void PbfSolver<Dim>::findNeighbors() {
  const PhaseTimer timer(times_.neighbors);
  this->reorderByCell(p_, lambdaTotal_);
  if (foundHolds_) gatherByOrder(this->cellOrder(), found_, scratchFound_);
  this->findNeighborsOf(p_, kernels_.radius());
  sizeForPairs(neighbors_, pairGradientFactors_);
}

// Lines 8-19: Jacobi iterations on the density constraints, stopped early once the average density error is
// under solver.max_density_error (> 0); solver.iterations caps them. Iterating to a tolerance with a cap of at
// least SolverSettings::kChebyshevLeastIterations, they are Chebyshev-accelerated (Wang 2015, eq. 12):
//   omega_1 = 1, omega_2 = 2 / (2 - rho^2), omega_k+1 = 4 / (4 - rho^2 omega_k),
// on the step's summed multipliers rather than the positions, so an iteration applies mu_k = omega_k lambda_k +
// (omega_k - 1) mu_k-1 while the particle's constraint is active (computeLambdas). docs/speed-accuracy.md has
// why the multipliers and why the cap.
template <int Dim>
void PbfSolver<Dim>::solveDensityConstraints() {
  const PhaseTimer timer(times_.pressure);
  lastIterations_ = 0;
  if (warmStart_ > 0) applyWarmStart();
  const float rho2 = chebyshevRho_ * chebyshevRho_;
  float omega = 1;  // 1 throughout with rho = 0: plain Jacobi
  for (int iteration = 0; iteration < iterations_; ++iteration) {
    omega = iteration == 0 ? 1.0f : iteration == 1 ? 2.0f / (2.0f - rho2) : 4.0f / (4.0f - rho2 * omega);
    const double averageError = computeLambdas(omega);
    if (maxDensityError_ > 0 && averageError <= maxDensityError_) break;
    applyPositionCorrections<false>();
    ++lastIterations_;
  }
}

// The warm start: lambda_i = warm_start x the sum of particle i's lambdas last step, applied as one correction
// (eq. 12) at this step's predicted positions; the sums start again from these lambdas.
template <int Dim>
void PbfSolver<Dim>::applyWarmStart() {
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      lambda_[i] = lambdaTotal_[i] = warmStart_ * lambdaTotal_[i];
      if (colliders_.empty()) continue;
      float unusedWeight = 0;  // what the colliders give p_, for the correction (found_)
      VecD unusedGradient = VecD::Zero();
      colliders_.add(p_[i], unusedWeight, unusedGradient, found_[i], onlyGradient_[i]);
    }
  });
  foundHolds_ = !colliders_.empty();
  applyPositionCorrections<true>();
}

// Eq. 2: rho_i = sum_j m W_poly6(p_i - p_j, h). Eq. 1: C_i = rho_i / rho_0 - 1, used one-sided (only
// compression is corrected, so particles at the free surface do not pull together; s_corr handles clumping).
// Eq. 8: grad_{p_k} C_i = (m / rho_0) sum_j grad W(p_i - p_j) for k = i, and -(m / rho_0) grad W(p_i - p_k)
// for k = j. Eq. 11: lambda_i = -C_i / (sum_k |grad_{p_k} C_i|^2 + epsilon).
// With several fluids (Solenthaler and Pajarola 2008's density contrast, as position-based dynamics with masses):
// the constraint stays the number density's, C_i = V sum_j W - 1, and each particle's move is weighted by its
// inverse mass w = m_0 / m: lambda_i = -C_i / (w_i |grad_i C_i|^2 + sum_j w_j |grad_j C_i|^2 + epsilon), and
// eq. 12's delta p_i is times w_i. A heavy particle moves less for the same lambda, so lambda holds up the weight
// above it (hydrostatic pressure) and a light fluid under a heavy one is pushed up.
template <int Dim>
double PbfSolver<Dim>::computeLambdas(float omega) {
  return wendland_ ? computeLambdasWith<true>(omega) : computeLambdasWith<false>(omega);
}

template <int Dim>
template <bool kWendland>
double PbfSolver<Dim>::computeLambdasWith(float omega) {
  if (this->periodic_.active())
    return massRatio_.empty() ? computeLambdasOf<false, true, kWendland>(omega)
                              : computeLambdasOf<true, true, kWendland>(omega);
  return massRatio_.empty() ? computeLambdasOf<false, false, kWendland>(omega)
                            : computeLambdasOf<true, false, kWendland>(omega);
}

template <int Dim>
template <bool kSeveral, bool kPeriodic, bool kWendland>
double PbfSolver<Dim>::computeLambdasOf(float omega) {
  const float selfWeight = kernelsOf<kWendland>().weight(0.0f);
  [[maybe_unused]] const float* inverse = inverseMassRatio_.data();  // w
  const double averageError = parallelSum<double>(0, size(), [&](size_t b, size_t e) {
    // A copy of the thread's own: its periods stay in registers through the vectorised loop (read through the
    // solver, the compiler must assume the loop's stores may change them, and gathers them lane by lane).
    [[maybe_unused]] const PeriodicDomain<Dim> periodic = this->periodic_;
    double errorSum = 0;
    for (size_t i = b; i < e; ++i) {
      const VecD pi = p_[i];
      float weight = selfWeight;
      VecD gradientSum = VecD::Zero();  // sum_j grad W, times m / rho_0 below
      float gradientSquaredSum = 0;     // sum_j |grad W|^2, times (m / rho_0)^2 below
      float* factors = pairGradientFactors_[i / NeighborLists::kChunk].data() + neighbors_.start(i);
      const uint32_t* neighbor = neighbors_.begin(i);
      const int count = static_cast<int>(neighbors_.end(i) - neighbor);
      // The vectorised loop (see the note at the top); a coincident pair sends the particle to the scalar loop after it.
      const float* p = p_.data()->data();
      float w = 0, g0 = 0, g1 = 0, g2 = 0, squares = 0;
      int coincident = 0;
#pragma omp simd simdlen(8) reduction(+ : w, g0, g1, g2, squares) reduction(| : coincident)
      for (int k = 0; k < count; ++k) {
        const size_t j = neighbor[k];
        float r0 = pi[0] - p[Dim * j], r1 = pi[1] - p[Dim * j + 1];
        float r2 = Dim == 3 ? pi[Dim - 1] - p[Dim * j + Dim - 1] : 0.0f;
        if constexpr (kPeriodic) periodic.nearest(r0, r1, r2);
        const float length2 = r0 * r0 + r1 * r1 + r2 * r2;
        coincident |= length2 <= coincidentLength_ * coincidentLength_;
        const auto pair = kernelsOf<kWendland>().pair(length2);
        factors[k] = pair.gradientFactor;
        w += pair.weight;
        g0 += pair.gradientFactor * r0;
        g1 += pair.gradientFactor * r1;
        g2 += pair.gradientFactor * r2;
        if constexpr (kSeveral) squares += pair.gradientFactor * pair.gradientFactor * length2 * inverse[j];
        else squares += pair.gradientFactor * pair.gradientFactor * length2;
      }
      if (!coincident) [[likely]] {
        weight += w;
        gradientSum[0] = g0;
        gradientSum[1] = g1;
        if constexpr (Dim == 3) gradientSum[2] = g2;
        gradientSquaredSum = squares;
      } else {
        for (int k = 0; k < count; ++k) {
          const VecD r = pairOffset(i, neighbor[k], pi);
          const float r2 = r.squaredNorm();
          const auto pair = kernelsOf<kWendland>().pair(r2);
          factors[k] = pair.gradientFactor;
          weight += pair.weight;
          gradientSum += pair.gradientFactor * r;
          gradientSquaredSum += pair.gradientFactor * pair.gradientFactor * r2 * (kSeveral ? inverse[neighbor[k]] : 1.0f);
        }
      }
      VecD gradientI = massOverRho_ * gradientSum;
      gradientSquaredSum *= massOverRho_ * massOverRho_;
      VecD wallGradient = VecD::Zero();
      walls_.add(p_[i], weight, wallGradient);
      gradientI += massOverRho_ * wallGradient;
      // A particle that stayed clear of the colliders' support since the last pass found it so gets nothing.
      if (!colliders_.empty() && !(foundHolds_ && colliders_.clearOfSupport(found_[i]))) {
        float colliderWeight = 0;
        VecD colliderGradient = VecD::Zero();
        colliders_.add(pi, colliderWeight, colliderGradient, found_[i], onlyGradient_[i]);
        weight += colliderWeight;
        gradientI += massOverRho_ * colliderGradient;
      }
      const float constraint = std::max(mass_ * weight / restDensity_ - densityTarget_, 0.0f);
      float ownSquared = gradientI.squaredNorm();
      if constexpr (kSeveral) ownSquared *= inverse[i];
      const float lambda = -constraint / (gradientSquaredSum + ownSquared + epsilon_);
      // The Chebyshev acceleration (see solveDensityConstraints): lambda_[i] still holds mu_k-1, the multiplier
      // the last iteration applied. != 0 rather than > 0: a NaN constraint passes its NaN on, so that a blow-up
      // still shows.
      if (omega != 1.0f) lambda_[i] = constraint != 0.0f ? omega * lambda + (omega - 1.0f) * lambda_[i] : 0.0f;
      else lambda_[i] = lambda;
      // The warm start's sums forget a particle that is not compressed (see the header).
      if (constraint == 0.0f && !lambdaTotal_.empty()) lambdaTotal_[i] = 0.0f;
      errorSum += constraint;
    }
    return errorSum;
  }) / std::max<double>(1, size());
  foundHolds_ = !colliders_.empty();
  return averageError;
}

// Eq. 12 with the artificial pressure of eq. 13-14:
//   delta p_i = (m / rho_0) sum_j (lambda_i + lambda_j + s_corr) grad W_spiky(p_i - p_j, h),
//   s_corr = -k (W_poly6(p_i - p_j) / W_poly6(delta q))^n, in lambda's units so that k means the same at every
//   resolution. Our constraint is one-sided where the paper's is two-sided, so s_corr is shifted to vanish at the
//   rest spacing (unshifted, it swells a resting column) and acts only where lambda_i = lambda_j = 0, in spray
//   and thin sheets (in compressed fluid it adds pressure that becomes kinetic energy).
template <int Dim>
template <bool kWarmStart, bool kPeriodic, bool kWendland>
void PbfSolver<Dim>::applyPositionCorrectionsOf() {
  const bool scorr = scorrK_ > 0 && !kWarmStart;
  const bool sumLambdas = !kWarmStart && !lambdaTotal_.empty();
  std::vector<VecD>& corrections = vectorScratch_;  // applied after all are computed (Jacobi)
  corrections.resize(size());
  const float scorrScale = scorrK_ / latticeGradientSum_;
  parallelFor(0, size(), [&](size_t b, size_t e) {
    [[maybe_unused]] const PeriodicDomain<Dim> periodic = this->periodic_;  // the thread's own (computeLambdasOf)
    for (size_t i = b; i < e; ++i) {
      const VecD pi = p_[i];
      const float lambdaI = lambda_[i];
      if (sumLambdas) lambdaTotal_[i] += lambdaI;
      VecD delta = VecD::Zero();
      const float* factors = pairGradientFactors_[i / NeighborLists::kChunk].data() + neighbors_.start(i);
      const uint32_t* neighbor = neighbors_.begin(i);
      const int count = static_cast<int>(neighbors_.end(i) - neighbor);
      // s_corr's coefficient for a pair at squared distance r2 (used where lambda_i + lambda_j = 0).
      auto artificialPressure = [kernels = kernelsOf<kWendland>(), scorrScale, inverse = scorrInvWdq_, n = scorrN_,
                                 atRest = scorrAtRest_](float r2) {
        const float excess = integerPower(kernels.weight(r2) * inverse, n) - atRest;
        return excess > 0.0f ? -scorrScale * excess : 0.0f;
      };
      // The pair's gradient factor: the lambda pass's, or evaluated here for the warm start.
      auto gradientFactor = [&](int k, float r2) {
        if constexpr (kWarmStart)
          return kernelsOf<kWendland>().pair(r2).gradientFactor;
        else
          return factors[k];
      };
      // The vectorised loop (see the note at the top); a coincident pair sends the particle to the scalar loop after it.
      const float* p = p_.data()->data();
      const float* lambda = lambda_.data();
      const float coincident2 = coincidentLength_ * coincidentLength_;
      float d0 = 0, d1 = 0, d2 = 0;
      int coincident = 0;
#pragma omp simd simdlen(8) reduction(+ : d0, d1, d2) reduction(| : coincident)
      for (int k = 0; k < count; ++k) {
        const size_t j = neighbor[k];
        float r0 = pi[0] - p[Dim * j], r1 = pi[1] - p[Dim * j + 1];
        float r2 = Dim == 3 ? pi[Dim - 1] - p[Dim * j + Dim - 1] : 0.0f;
        if constexpr (kPeriodic) periodic.nearest(r0, r1, r2);
        const float length2 = r0 * r0 + r1 * r1 + r2 * r2;
        coincident |= length2 <= coincident2;
        float coefficient = lambdaI + lambda[j];
        // Evaluated for every pair and kept where lambda_i + lambda_j = 0 (zero with s_corr off, as its k is):
        // a branch on `scorr` here stops the vectoriser.
        const float pressure = artificialPressure(length2);
        coefficient = coefficient == 0.0f ? pressure : coefficient;
        const float scale = coefficient * gradientFactor(k, length2);
        d0 += scale * r0;
        d1 += scale * r1;
        d2 += scale * r2;
      }
      if (!coincident) [[likely]] {
        delta[0] = d0;
        delta[1] = d1;
        if constexpr (Dim == 3) delta[2] = d2;
      } else {
        for (int k = 0; k < count; ++k) {
          const VecD r = pairOffset(i, neighbor[k], pi);
          float coefficient = lambdaI + lambda_[neighbor[k]];
          if (scorr && coefficient == 0.0f) coefficient = artificialPressure(r.squaredNorm());
          delta += (coefficient * gradientFactor(k, r.squaredNorm())) * r;
        }
      }
      // The walls do not move and carry no constraint of their own: only lambda_i acts along their gradient.
      float unusedWeight = 0;
      VecD wallGradient = VecD::Zero();
      walls_.add(p_[i], unusedWeight, wallGradient);
      delta += lambda_[i] * wallGradient;
      corrections[i] = massOverRho_ * delta;
      // The colliders likewise; each one's share is an impulse it gives the particle.
      if (!colliders_.empty() && lambdaI != 0.0f && found_[i].count > 0)
        corrections[i] += colliderCorrection(i, pi, lambdaI);
      if (!massRatio_.empty()) corrections[i] *= inverseMassRatio_[i];  // w_i (see computeLambdas)
    }
  });
  moveBy(corrections);
}

// p*_i += delta_i, stopped at the colliders and the tank.
template <int Dim>
void PbfSolver<Dim>::moveBy(const std::vector<VecD>& delta) {
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const VecD before = p_[i];
      p_[i] += delta[i];
      if (colliders_.empty()) {
        walls_.clamp(p_[i]);
        continue;
      }
      if (colliders_.nothingStops(found_[i], before, p_[i])) walls_.clamp(p_[i]);
      else collide(i, before, false);
      colliders_.carry(found_[i], before, p_[i]);
    }
  });
}

// Surface tension and adhesion at the predicted positions, before the constraints: x*_i += dt^2 a_i, stopped at
// the colliders and the tank, so that the line 21 velocity keeps dt a_i. Taken at the step's projected positions
// instead (as an external force of lines 1-4), even a plain central cohesion fed the drops energy until they flew
// apart: an 8 mm cube of water within 10 frames with or without s_corr, XSPH or 50 iterations; a force at x* damps
// its own stiff modes by its stiffness times dt (docs/surface-tension.md, "PBF's order").
template <int Dim>
void PbfSolver<Dim>::pullBySurfaceTension(float dt) {
  if (!this->tension_.active()) return;
  this->kickSurfaceTension(p_, dt);  // its work counted; v_ itself is replaced at line 21
  const PhaseTimer timer(times_.forces);
  const auto& a = this->tension_.accelerations();
  const float dt2 = dt * dt;
  // Stopped as predictPositions stops x*, not as moveBy: found_ (the colliders at x*) may still be last step's,
  // which the first lambda pass finds again.
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const VecD before = p_[i];
      p_[i] += dt2 * a[i];
      if (colliders_.empty() || colliders_.moveFarFrom(before, p_[i])) walls_.clamp(p_[i]);
      else collide(i, before, false);
    }
  });
}

// Line 21: v_i = (x*_i - x_i) / dt.
template <int Dim>
void PbfSolver<Dim>::updateVelocities(float dt) {
  const float inverseDt = 1.0f / dt;
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) v_[i] = (p_[i] - x_[i]) * inverseDt;
  });
}

// Density error of DESIGN.md at the current positions, with the neighbour lists of the last step.
template <int Dim>
FluidMeasures PbfSolver<Dim>::measure() {
  if (neighbors_.size() != size()) {
    p_ = x_;  // before the first step: neighbours of the current positions
    findNeighbors();
  }
  return this->measureWith([&](float r2) { return kernelWeight(r2); });
}

template <int Dim>
size_t PbfSolver<Dim>::memoryBytes() const {
  size_t bytes = (p_.capacity() + omega3_.capacity() + onlyGradient_.capacity() + transportPush_.capacity()) *
                 sizeof(VecD);
  bytes += (lambda_.capacity() + lambdaTotal_.capacity() + omega2_.capacity() + densityRatio_.capacity()) *
           sizeof(float);
  for (const auto& factors : pairGradientFactors_) bytes += factors.capacity() * sizeof(float);
  bytes += (found_.capacity() + scratchFound_.capacity()) * sizeof(typename Colliders<Dim>::Found);
  return bytes + this->coreMemoryBytes();
}

template class PbfSolver<2>;
template class PbfSolver<3>;

}  // namespace surge
