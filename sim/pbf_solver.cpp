#include "sim/pbf_solver.h"

#include <Eigen/Geometry>
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

// The rest lattice's sums of poly6 and of the squared spiky gradient (eq. 2 and 8-9 over the lattice).
template <int Dim>
struct LatticeSums {
  double weight = 0, gradientSquared = 0;
  LatticeSums(const Scene& scene, const Kernels<Dim>& kernels) {
    latticeSums<Dim>(static_cast<float>(scene.particle_spacing), kernels.radius(),
                     [&](const Vec<Dim>& r) { return kernels.poly6(r.squaredNorm()); },
                     [&](const Vec<Dim>& r) { return kernels.spikyGradient(r, r.norm()); }, &weight, &gradientSquared);
  }
};

template <int Dim>
TankWalls<Dim> pbfTankWalls(const Scene& scene, const Kernels<Dim>& kernels) {
  return TankWalls<Dim>(toVec<Dim>(scene.domain.min), toVec<Dim>(scene.domain.max),
                        static_cast<float>(scene.particle_spacing), kernels.radius(),
                        [&](const Vec<Dim>& r) { return kernels.poly6(r.squaredNorm()); },
                        [&](const Vec<Dim>& r) { return kernels.spikyGradient(r, r.norm()); });
}

}  // namespace

// The mass makes an interior particle of the rest lattice have exactly rho_0 (eq. 2 summed over the lattice),
// so a block at rest starts unstressed and keeps its volume N x spacing^d.
template <int Dim>
PbfSolver<Dim>::PbfSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes)
    : Core(scene, std::move(shapes), pbfTankWalls<Dim>(scene, Kernels<Dim>(float(scene.solver.kernel_radius))),
           static_cast<float>(scene.solver.rest_density /
                              LatticeSums<Dim>(scene, Kernels<Dim>(float(scene.solver.kernel_radius))).weight)),
      kernels_(static_cast<float>(scene.solver.kernel_radius)) {
  substeps_ = scene.solver.substeps;
  const SolverSettings& s = scene.solver;
  const float spacing = static_cast<float>(scene.particle_spacing);
  massOverRho_ = mass_ / restDensity_;
  // sum_k |grad_k C_i|^2 at the rest lattice (eq. 8-9 with C_i = rho_i / rho_0 - 1): the scale of eq. 11's
  // denominator. epsilon is a fraction of it, s_corr is measured in lambda's units 1 / that sum.
  latticeGradientSum_ = static_cast<float>(massOverRho_ * massOverRho_ * LatticeSums<Dim>(scene, kernels_).gradientSquared);
  epsilon_ = static_cast<float>(s.relaxation_epsilon) * latticeGradientSum_;
  coincidentLength_ = 1e-4f * kernels_.radius();
  scorrK_ = static_cast<float>(s.scorr_k);
  scorrN_ = s.scorr_n;
  const float dq = static_cast<float>(s.scorr_delta_q * s.kernel_radius);
  scorrInvWdq_ = 1.0f / kernels_.poly6(dq * dq);
  scorrAtRest_ = integerPower(kernels_.poly6(spacing * spacing) * scorrInvWdq_, scorrN_);
  vorticityEpsilon_ = static_cast<float>(s.vorticity_epsilon);
  xsphC_ = static_cast<float>(s.xsph_c);
  warmStart_ = static_cast<float>(s.warm_start);
  // The acceleration only when iterating to a tolerance with room for it (see solveDensityConstraints).
  chebyshevRho_ = s.max_density_error > 0 && s.iterations >= SolverSettings::kChebyshevLeastIterations
                      ? static_cast<float>(s.chebyshev_rho)
                      : 0.0f;
  iterations_ = s.iterations;
  maxDensityError_ = s.max_density_error;
}

template <int Dim>
void PbfSolver<Dim>::resizeChannels(size_t n) {
  p_.resize(n);
  lambda_.assign(n, 0.0f);
  if (warmStart_ > 0) lambdaTotal_.assign(n, 0.0f);
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
  solveDensityConstraints();
  updateVelocities(dt);
  if (colliders_.hasFriction()) applyFriction();
  if (vorticityEpsilon_ > 0) applyVorticityConfinement(dt);
  if (xsphC_ > 0) applyXsphViscosity();
  x_.swap(p_);  // line 23: x_i = x*_i
  return this->firstBadParticle();
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

// The collision response for the move of p*_i from `from`, against the colliders and the tank; each collider's
// push is an impulse m delta / dt given to the particle (v = (x* - x) / dt at the end of the step). Where a
// collider meets a wall (a ball on the floor), the wall's clamp can put the particle back into the collider:
// then both act again, from there, up to kCornerRounds times, so the particle ends in the corner rather than
// inside (alternating, the two close in on a narrow corner geometrically: one round left a particle 5.01% of
// its radius inside a ball on the floor, past the 5% the rest test allows; four rounds kicked the corner's
// particles harder, and a ball of density 2000 resting on the floor then moved at 2.03 cm/s, past its 2).
// The clamp acts last: the tank always holds.
// A corner round's push records no impulse: it is the tank's push passed on through a particle caught between
// the tank and the collider. Recorded, it came back in every round of every iteration as m delta / dt for the
// same overlap delta, a stiff spring with nothing to damp it, and a heavy box rested on a layer of caught
// particles one spacing above the floor, rocking (docs/bodies.md). The particle's pressure still reaches the
// collider through the density terms, and a body's contact with the tank is Bullet's.
template <int Dim>
void PbfSolver<Dim>::collide(size_t i, const VecD& from, bool fromStepStart) {
  constexpr int kCornerRounds = 2;
  auto pushed = [&](size_t c, const VecD& delta) { colliders_.addImpulse(i, c, (mass_ / stepDt_) * delta, p_[i]); };
  colliders_.project(from, p_[i], fromStepStart, pushed);
  for (int round = 0; round < kCornerRounds; ++round) {
    if (walls_.clamp(p_[i]) == 0) return;
    const VecD clamped = p_[i];
    if (!colliders_.project(clamped, p_[i], false, [](size_t, const VecD&) {})) return;
  }
  walls_.clamp(p_[i]);
}

// Friction at the colliders, on the velocities of line 21.
template <int Dim>
void PbfSolver<Dim>::applyFriction() {
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) colliders_.applyFriction(i, p_[i], v_[i], mass_);
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

// Lines 8-19: Jacobi iterations on the density constraints. With solver.max_density_error > 0 the loop stops
// early once the average density error is under it; solver.iterations caps it either way.
// The Chebyshev semi-iterative acceleration (Wang 2015, "A Chebyshev Semi-Iterative Approach for Accelerating
// Projective and Position-based Dynamics", eq. 12) weights iteration k by
//   omega_1 = 1, omega_2 = 2 / (2 - rho^2), omega_k+1 = 4 / (4 - rho^2 omega_k),
// rho being solver.chebyshev_rho, the spectral radius it assumes for the Jacobi iterations. The paper
// extrapolates positions; here the extrapolation is of the step's summed multipliers Lambda (Lambda_k+1 =
// omega (Lambda_k + lambda_k - Lambda_k-1) + Lambda_k-1), so the multiplier an iteration applies in eq. 12 is
//   mu_k = omega_k lambda_k + (omega_k - 1) mu_k-1,
// and it is kept only while the particle's constraint is active: a particle no longer compressed gets no push
// from the momentum of earlier ones (computeLambdas). Extrapolating positions, as the paper does, kept moving
// such particles, and a 2D dam break gained energy (docs/speed-accuracy.md).
// It runs only when the loop iterates to solver.max_density_error. After a fixed handful of iterations its
// polynomial leaves up to 1 / T_k(1 / rho) of the most local errors (19% at 4 iterations, rho = 0.85), which one
// plain Jacobi iteration clears: a deep pool at the default 4 iterations stirred itself to 0.14 m/s RMS, against
// 0.03 m/s without it. A tolerance that solver.iterations cuts short is the same case: a resting 3D pool
// (0.6 x 0.3 x 0.6 m, spacing 0.02) iterated to 0.3% moved at 0.28 m/s RMS where the cap of 4 stopped every
// step, 0.09 m/s at a cap of 6 and 0.05 m/s at 8, as plain Jacobi's 0.054 m/s; so it needs a cap of
// SolverSettings::kChebyshevLeastIterations.
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

template <int Dim>
void PbfSolver<Dim>::restoreCarriedState(const std::vector<float>& state) {
  if (state.size() != lambdaTotal_.size()) throw std::invalid_argument("PBF: carried state of the wrong size");
  lambdaTotal_ = state;
}

// Eq. 2: rho_i = sum_j m W_poly6(p_i - p_j, h). Eq. 1: C_i = rho_i / rho_0 - 1, used one-sided (only
// compression is corrected, so particles at the free surface do not pull together; s_corr handles clumping).
// Eq. 8: grad_{p_k} C_i = (m / rho_0) sum_j grad W(p_i - p_j) for k = i, and -(m / rho_0) grad W(p_i - p_k)
// for k = j. Eq. 11: lambda_i = -C_i / (sum_k |grad_{p_k} C_i|^2 + epsilon).
template <int Dim>
double PbfSolver<Dim>::computeLambdas(float omega) {
  const float selfWeight = kernels_.poly6(0.0f);
  const double averageError = parallelSum<double>(0, size(), [&](size_t b, size_t e) {
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
        const float r0 = pi[0] - p[Dim * j], r1 = pi[1] - p[Dim * j + 1];
        const float r2 = Dim == 3 ? pi[Dim - 1] - p[Dim * j + Dim - 1] : 0.0f;
        const float length2 = r0 * r0 + r1 * r1 + r2 * r2;
        coincident |= length2 <= coincidentLength_ * coincidentLength_;
        const auto pair = kernels_.pair(length2);
        factors[k] = pair.gradientFactor;
        w += pair.weight;
        g0 += pair.gradientFactor * r0;
        g1 += pair.gradientFactor * r1;
        g2 += pair.gradientFactor * r2;
        squares += pair.gradientFactor * pair.gradientFactor * length2;
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
          const auto pair = kernels_.pair(r2);
          factors[k] = pair.gradientFactor;
          weight += pair.weight;
          gradientSum += pair.gradientFactor * r;
          gradientSquaredSum += pair.gradientFactor * pair.gradientFactor * r2;
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
      const float constraint = std::max(mass_ * weight / restDensity_ - 1.0f, 0.0f);
      const float lambda = -constraint / (gradientSquaredSum + gradientI.squaredNorm() + epsilon_);
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
//   s_corr = -k (W_poly6(p_i - p_j) / W_poly6(delta q))^n, in lambda's units (divided by the rest lattice's
//   sum of squared gradients) so that k means the same at every resolution.
// Two changes to eq. 13, both because our density constraint is one-sided where the paper's is two-sided (the
// paper's s_corr counters the tension of its two-sided constraint; ours has none):
//  - the value s_corr has at the rest spacing is subtracted (and s_corr kept <= 0), so it pushes only pairs
//    closer than the rest lattice: unshifted, it swells a resting column by several percent;
//  - it acts only on pairs whose density constraints are both inactive (lambda_i = lambda_j = 0), that is in
//    spray and thin sheets where nothing else keeps particles apart; in compressed fluid the constraint already
//    does, and s_corr there adds pressure that the position update turns into kinetic energy.
template <int Dim>
template <bool kWarmStart>
void PbfSolver<Dim>::applyPositionCorrections() {
  const bool scorr = scorrK_ > 0 && !kWarmStart;
  const bool sumLambdas = !kWarmStart && !lambdaTotal_.empty();
  std::vector<VecD>& corrections = vectorScratch_;  // applied after all are computed (Jacobi)
  corrections.resize(size());
  const float scorrScale = scorrK_ / latticeGradientSum_;
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const VecD pi = p_[i];
      const float lambdaI = lambda_[i];
      if (sumLambdas) lambdaTotal_[i] += lambdaI;
      VecD delta = VecD::Zero();
      const float* factors = pairGradientFactors_[i / NeighborLists::kChunk].data() + neighbors_.start(i);
      const uint32_t* neighbor = neighbors_.begin(i);
      const int count = static_cast<int>(neighbors_.end(i) - neighbor);
      // s_corr's coefficient for a pair at squared distance r2 (used where lambda_i + lambda_j = 0).
      auto artificialPressure = [kernels = kernels_, scorrScale, inverse = scorrInvWdq_, n = scorrN_,
                                 atRest = scorrAtRest_](float r2) {
        const float excess = integerPower(kernels.poly6(r2) * inverse, n) - atRest;
        return excess > 0.0f ? -scorrScale * excess : 0.0f;
      };
      // The pair's gradient factor: the lambda pass's, or evaluated here for the warm start.
      auto gradientFactor = [&](int k, float r2) {
        if constexpr (kWarmStart) return kernels_.pair(r2).gradientFactor;
        else return factors[k];
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
        const float r0 = pi[0] - p[Dim * j], r1 = pi[1] - p[Dim * j + 1];
        const float r2 = Dim == 3 ? pi[Dim - 1] - p[Dim * j + Dim - 1] : 0.0f;
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
    }
  });
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const VecD before = p_[i];
      p_[i] += corrections[i];
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

// The colliders' share of eq. 12 for particle i at p with lambda_i: (m / rho_0) lambda_i sum_c grad W_c, each
// collider's part an impulse it gives the particle. The lambda pass found the colliders at p (found_); the
// gradient of a single one, as most particles near any have, is kept from there. Kept out of the loop above,
// which stays as it was for a scene without colliders (same instructions, same bytes).
template <int Dim>
typename PbfSolver<Dim>::VecD PbfSolver<Dim>::colliderCorrection(size_t i, const VecD& p, float lambda) {
  auto share = [&](size_t c, const VecD& gradient) {
    const VecD move = (massOverRho_ * lambda) * gradient;
    colliders_.addImpulse(i, c, (mass_ / stepDt_) * move, p);
    return move;
  };
  if (found_[i].count == 1) return share(found_[i].only, onlyGradient_[i]);
  VecD delta = VecD::Zero();
  colliders_.forEachNear(p, [&](size_t c, float d, const VecD& n) {
    float unused;
    VecD gradient;
    colliders_.wallTerms(c, p, d, n, unused, gradient);
    delta += share(c, gradient);
  });
  return delta;
}

// Line 21: v_i = (x*_i - x_i) / dt.
template <int Dim>
void PbfSolver<Dim>::updateVelocities(float dt) {
  const float inverseDt = 1.0f / dt;
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) v_[i] = (p_[i] - x_[i]) * inverseDt;
  });
}

// Eq. 15: omega_i = sum_j (m / rho_0) v_ij x grad_{p_j} W(p_i - p_j), v_ij = v_j - v_i (a scalar in 2D): the
// curl of the velocity in 1/s. The paper leaves out the particle volume m / rho_0 (it assumes 1, as for XSPH),
// which made omega 1 / spacing^3 too large and a dam break at epsilon 0.001 throw a particle at 86 m/s.
// Eq. 16: f_i = epsilon (N x omega_i), N = eta / |eta|, eta = grad |omega|_i = sum_j |omega_j| grad_{p_i} W.
// The confinement force is applied as an acceleration: v_i += dt f_i.
template <int Dim>
void PbfSolver<Dim>::applyVorticityConfinement(float dt) {
  const PhaseTimer timer(times_.vorticity);
  auto omegaMagnitude = [&](size_t j) { return Dim == 3 ? omega3_[j].norm() : std::abs(omega2_[j]); };
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      Eigen::Vector3f omega = Eigen::Vector3f::Zero();
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j) {
        const VecD r = p_[i] - p_[*j];
        const VecD gradientJ = -kernels_.spikyGradient(r, r.norm());  // grad with respect to p_j
        Eigen::Vector3f vij = Eigen::Vector3f::Zero(), g = Eigen::Vector3f::Zero();
        vij.head<Dim>() = v_[*j] - v_[i];
        g.head<Dim>() = gradientJ;
        omega += vij.cross(g);
      }
      omega *= massOverRho_;  // the particle volume m / rho_0: the paper's eq. 15 assumes a unit volume
      if constexpr (Dim == 3) omega3_[i] = omega;
      else omega2_[i] = omega.z();
    }
  });
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      VecD eta = VecD::Zero();
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j) {
        const VecD r = p_[i] - p_[*j];
        eta += (omegaMagnitude(*j) - omegaMagnitude(i)) * kernels_.spikyGradient(r, r.norm());
      }
      const float etaLength = eta.norm();
      if (etaLength < 1e-12f) continue;
      Eigen::Vector3f n = Eigen::Vector3f::Zero(), omega;
      n.head<Dim>() = eta / etaLength;
      if constexpr (Dim == 3) omega = omega3_[i];
      else omega = Eigen::Vector3f(0, 0, omega2_[i]);
      const Eigen::Vector3f force = vorticityEpsilon_ * n.cross(omega);
      v_[i] += dt * force.head<Dim>();
    }
  });
}

// Eq. 17: v_i <- v_i + c sum_j (m / rho_0) v_ij W(p_i - p_j, h), with v_ij = v_j - v_i. The factor m / rho_0
// (the particle volume) makes c dimensionless, as the paper's c = 0.01 assumes unit particle volume.
template <int Dim>
void PbfSolver<Dim>::applyXsphViscosity() {
  const PhaseTimer timer(times_.forces);
  std::vector<VecD>& smoothed = vectorScratch_;
  smoothed.resize(size());
  const float scale = xsphC_ * massOverRho_;
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      VecD sum = VecD::Zero();
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j)
        sum += (v_[*j] - v_[i]) * kernels_.poly6((p_[i] - p_[*j]).squaredNorm());
      smoothed[i] = v_[i] + scale * sum;
    }
  });
  v_.swap(smoothed);
}

// p_i - p_j, or coincidentOffset for a pair closer than coincidentLength_.
template <int Dim>
typename PbfSolver<Dim>::VecD PbfSolver<Dim>::pairOffset(size_t i, size_t j, const VecD& pi) const {
  const VecD r = pi - p_[j];
  if (r.squaredNorm() <= coincidentLength_ * coincidentLength_) [[unlikely]] return coincidentOffset(i, j);
  return r;
}

// Two particles on the same point (the walls project every particle that overshoots a corner onto the same
// corner) have no kernel gradient between them, so no constraint could ever part them, and their summed density
// would push their neighbours ever harder. Such a pair is given a tiny offset along a direction that depends on
// the pair only and flips with its order (so momentum is still conserved).
template <int Dim>
typename PbfSolver<Dim>::VecD PbfSolver<Dim>::coincidentOffset(size_t i, size_t j) const {
  const uint32_t lo = static_cast<uint32_t>(std::min(i, j)), hi = static_cast<uint32_t>(std::max(i, j));
  uint32_t hash = lo * 0x9E3779B1u ^ (hi + 0x7F4A7C15u) * 0x85EBCA77u;
  VecD direction;
  for (int k = 0; k < Dim; ++k) {
    hash ^= hash >> 15;
    hash *= 0x2C1B3C6Du;
    direction[k] = static_cast<float>(hash & 0xFFFF) / 32768.0f - 1.0f;
  }
  direction[0] += 1e-3f;  // never the zero vector
  return (i < j ? coincidentLength_ : -coincidentLength_) * direction.normalized();
}

// Density error of DESIGN.md at the current positions, with the neighbour lists of the last step.
template <int Dim>
FluidMeasures PbfSolver<Dim>::measure() {
  if (neighbors_.size() != size()) {
    p_ = x_;  // before the first step: neighbours of the current positions
    findNeighbors();
  }
  return this->measureWith([&](float r2) { return kernels_.poly6(r2); });
}

template <int Dim>
size_t PbfSolver<Dim>::memoryBytes() const {
  size_t bytes = (p_.capacity() + omega3_.capacity() + onlyGradient_.capacity()) * sizeof(VecD);
  bytes += (lambda_.capacity() + lambdaTotal_.capacity() + omega2_.capacity()) * sizeof(float);
  for (const auto& factors : pairGradientFactors_) bytes += factors.capacity() * sizeof(float);
  bytes += (found_.capacity() + scratchFound_.capacity()) * sizeof(typename Colliders<Dim>::Found);
  return bytes + this->coreMemoryBytes();
}

namespace {

// The projection moves a particle up to about a spacing a step (the velocity is that move over the step).
int pbfPushesPerFrame(const Scene& scene) { return std::max(1, scene.solver.substeps); }

std::vector<std::string> pbfNotes(const Scene& scene) {
  const int stable = stableSubsteps(scene);
  if (stable <= scene.solver.substeps) return {};
  return {"solver.substeps " + std::to_string(scene.solver.substeps) + " is below the " + std::to_string(stable) +
          " a PBF pool this deep needs to stay at rest (dt <= 0.9 particle_spacing / sqrt(g depth)); leave it out "
          "to get them"};
}

}  // namespace

// 400 bytes a particle in 3D: about 340 of channels (x, v, x* and a scratch copy, ids, lambdas, the grid's) and
// 30 neighbours with their gradient factors, the frame being written, and the allocator's slack; 250 in 2D
// (docs/performance.md).
const FluidMethod kPbfMethod = {"pbf", "Position Based Fluids (Macklin & Mueller 2013)",
    &makeMethod<PbfSolver, 2>, &makeMethod<PbfSolver, 3>, 250, 400,
    &pbfPushesPerFrame, nullptr, &pbfNotes};

template class PbfSolver<2>;
template class PbfSolver<3>;

}  // namespace surge
