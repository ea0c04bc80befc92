#include "sim/dfsph_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/parallel.h"

namespace surge {
namespace {

// A particle with less than this fraction of the rest density around it (walls included) is at the free
// surface: about 0.7 at a flat surface of the rest lattice, 0.95 one layer below it.
constexpr float kSurfaceDensity = 0.8f;
// The share of the last step's total lambda that starts each solve: the density solver's total is mostly the
// pool's hydrostatic pressure, which changes little from step to step; the divergence solver starts from half,
// as SPlisHSPlasH's does (docs/speed-accuracy.md has the measurements).
constexpr float kDensityWarmStart = 0.8f, kDivergenceWarmStart = 0.5f;
// The Jacobi relaxation omega: d_i = omega s_i / S_i, at most 0.5 (omega = 1 diverges, docs/speed-accuracy.md),
// and less for a kernel with many neighbours (jacobiRelaxation).
constexpr float kRelaxation = 0.5f;

// On the rest lattice a lambda wave exp(i k . x) changes the residual by mu(k) = |sum_j g_j sin(k . r_j)|^2 /
// sum_j |g_j|^2 times itself (g_j = grad W at the neighbour offset r_j, the bulk's S_i the denominator), so the
// relaxed Jacobi iteration converges where omega mu(k) < 2 for every k of the lattice's Brillouin zone. The
// largest mu is 2.15 (2D) and 2.81 (3D) for the cubic spline at 2 spacings, 5.1 at 3.5 spacings in 2D (where 0.5
// diverged). omega mu is kept at 1.5, what the 3D default runs at rounded up; the defaults keep 0.5.
template <int Dim, typename Kernel>
float jacobiRelaxation(const Kernel& kernel, float spacing) {
  const float support = kernel.radius();
  const int reach = static_cast<int>(std::ceil(support / spacing));
  std::vector<Eigen::Matrix<double, Dim, 1>> offsets, gradients;
  Eigen::Matrix<int, Dim, 1> o = Eigen::Matrix<int, Dim, 1>::Constant(-reach);
  while (true) {
    const Eigen::Matrix<double, Dim, 1> r = o.template cast<double>() * double(spacing);
    if (r.norm() > 0 && r.norm() < support) {
      offsets.push_back(o.template cast<double>());
      gradients.push_back(double(kernel.gradientFactor(static_cast<float>(r.norm()))) * r);
    }
    int k = 0;
    while (k < Dim && ++o[k] > reach) o[k++] = -reach;
    if (k == Dim) break;
  }
  double squares = 0;
  for (const auto& g : gradients) squares += g.squaredNorm();
  if (squares == 0) return kRelaxation;
  // k over a grid of the zone [-pi, pi)^Dim (in units of 1 / spacing), 24 points an axis.
  constexpr int kSamples = 24;
  double largest = 0;
  Eigen::Matrix<int, Dim, 1> index = Eigen::Matrix<int, Dim, 1>::Zero();
  while (true) {
    const Eigen::Matrix<double, Dim, 1> wave = (index.template cast<double>() * (2 * M_PI / kSamples)).array() - M_PI;
    Eigen::Matrix<double, Dim, 1> sum = Eigen::Matrix<double, Dim, 1>::Zero();
    for (size_t j = 0; j < offsets.size(); ++j) sum += std::sin(wave.dot(offsets[j])) * gradients[j];
    largest = std::max(largest, sum.squaredNorm() / squares);
    int k = 0;
    while (k < Dim && ++index[k] == kSamples) index[k++] = 0;
    if (k == Dim) break;
  }
  return std::min(kRelaxation, static_cast<float>(1.5 / largest));
}

}  // namespace

template <int Dim>
DfsphSolver<Dim>::DfsphSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes)
    : Core(scene, std::move(shapes), sphRestLattice<Dim>(scene)),
      kernel_(sphKernel<Dim>(scene)) {
  const SolverSettings& s = scene.solver;
  support_ = static_cast<float>(s.kernel_radius);
  volume_ = mass_ / restDensity_;
  spacing_ = static_cast<float>(scene.particle_spacing);
  maxDensityError_ = s.max_density_error;
  maxDivergenceError_ = s.max_divergence_error;
  maxIterations_ = s.max_iterations;
  cfl_ = static_cast<float>(s.cfl);
  maxStep_ = s.time_step > 0 ? static_cast<float>(s.time_step)
                             : static_cast<float>(1.0 / (scene.output.fps * std::max(1, s.substeps)));
  xsphC_ = static_cast<float>(s.xsph_c);
  backgroundPressure_ = static_cast<float>(s.background_pressure);
  pressureBeforeViscosity_ = this->viscosity_.active();
  relaxation_ = kernel_.visit([&](const auto& kernel) { return jacobiRelaxation<Dim>(kernel, spacing_); });
}

template <int Dim>
void DfsphSolver<Dim>::resizeChannels(size_t n) {
  sizeChannel(densityWarm_, n, 0.0f);
  sizeChannel(divergenceWarm_, n, 0.0f);
  prepared_ = false;
}

template <int Dim>
void DfsphSolver<Dim>::beginFrame(double) {
  framePressureMax_ = 0;
}

// The CFL condition on the fastest particle after a step's worth of gravity at most, and the depth criterion on
// the deepest column as the fluid stands: from rest, a longer step loads a deep column faster than the density
// solve meets within its iterations (lava's 0.5 m column at 5 steps a frame: 35 to 69% compressed, docs/viscosity.md).
template <int Dim>
float DfsphSolver<Dim>::stableTimeStep() {
  const float fastest = this->fastestAfterFall(maxStep_);
  const float step = fastest > 0 ? std::min(maxStep_, cfl_ * spacing_ / fastest) : maxStep_;
  return std::min({step, this->depthStableStepNow(), this->tension_.stableStep(), this->viscosity_.stableStep(),
                   this->transportStableStep(backgroundPressure_, support_)});
}

template <int Dim>
long DfsphSolver<Dim>::step(float dt, double time) {
  // The moving solids are placed where they stand now (Colliders::placeAtStepStart), from (time, dt) and the
  // bodies' poses alone: the uninterrupted run and one resumed from a frame (whose colliders knew no step
  // before) read the same walls in this step's forces and density solve.
  const bool moving = colliders_.anyMoving();
  if (moving) colliders_.placeAtStepStart(time, dt);
  if (!prepared_) prepareStep();
  else if (moving) updateWallFlux();
  applyNonPressureForces(dt, time);

  // Algorithm 3: the density solver on v*, then the move.
  {
    const PhaseTimer timer(times_.pressure);
    densityIterations_ = solve(true, dt, maxDensityError_, 2, densityWarm_, pressureBeforeViscosity_);
    lastStep_ = dt;
    framePressureMax_ = std::max(framePressureMax_, restDensity_ / (dt * dt) * parallelMax(densityWarm_));
    if (!colliders_.empty()) recordColliderImpulses(densityWarm_, dt);
  }
  if (!colliders_.empty()) colliders_.beginStep(time, dt);
  if (backgroundPressure_ > 0) computeTransportAccelerations();
  driftAgainstSolids(x_, v_, dt, mass_, this->massRatio_, colliders_, walls_,
                     backgroundPressure_ > 0 ? &transportAcceleration_ : nullptr, dt);

  // The new positions' neighbours and factors, and Algorithm 2: the divergence solver on v.
  prepareStep();
  {
    const PhaseTimer timer(times_.pressure);
    divergenceIterations_ = solve(false, dt, maxDivergenceError_, 1, divergenceWarm_);
    if (!colliders_.empty()) recordColliderImpulses(divergenceWarm_, dt);
  }
  return this->endStep();
}

template <int Dim>
float DfsphSolver<Dim>::colliderTerms(const VecD& xi, float& weight, VecD& gradient) const {
  float flux = 0;
  colliders_.forEachNear(xi, [&](size_t c, float d, const VecD& normal) {
    float w;
    VecD g;
    colliders_.wallTerms(c, xi, d, normal, w, g);
    weight += w;
    gradient += g;
    flux += colliders_.wallVelocity(c, xi).dot(g);
  });
  return flux;
}

template <int Dim>
void DfsphSolver<Dim>::updateWallFlux() {
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      float unusedWeight = 0;
      VecD unusedGradient = VecD::Zero();
      wallFlux_[i] = volume_ * colliderTerms(x_[i], unusedWeight, unusedGradient);
    }
  });
}

template <int Dim>
void DfsphSolver<Dim>::prepareStep() {
  {
    const PhaseTimer timer(times_.neighbors);
    this->reorderByCell(x_, densityWarm_, divergenceWarm_);
    this->findNeighborsOf(x_, support_);
    sizeForPairs(neighbors_, pairGradients_);
    if (xsphC_ > 0) sizeForPairs(neighbors_, pairWeights_);
  }
  kernel_.visit([&](const auto& kernel) {
    if (inverseMassRatio_.empty()) computeFactors<false>(kernel);
    else computeFactors<true>(kernel);
    return 0;
  });
  if (this->periodic_.everyAxis() && size() > 0) densityTarget_ = this->meanDensityTarget(densityRatio_);
  prepared_ = true;
}

// rho_i / rho_0 = V (W(0) + sum_j W_ij + the walls' sum), g_ij = V grad W_ij, G_i = V (the walls' gradient sum),
// S_i, and the moving walls' share of the divergence. With several fluids (kSeveral) each particle's move is
// weighted by its inverse mass w = m_0 / m, as PBF's (Solenthaler and Pajarola 2008's number density, as
// position-based dynamics with masses): S_i = w_i |sum_j g_ij + G_i|^2 + sum_j w_j |g_ij|^2, and applyIncrements
// moves v_i by w_i times the pressure's change. The density ratio stays the number density's.
template <int Dim>
template <bool kSeveral, typename Kernel>
void DfsphSolver<Dim>::computeFactors(const Kernel& kernel) {
  const PhaseTimer timer(times_.pressure);
  const size_t n = size();
  densityRatio_.resize(n);
  diagonal_.resize(n);
  wallGradient_.resize(n);
  const bool colliding = !colliders_.empty();
  if (colliding) wallFlux_.resize(n);
  const float selfWeight = kernel.value(0.0f);
  [[maybe_unused]] const float* inverse = inverseMassRatio_.data();  // w
  this->periodic_.withNearestImage([&](const auto& sharedWrap) {
  parallelFor(0, n, [&](size_t b, size_t e) {
    const auto wrap = sharedWrap;  // the thread's own copy (sim/periodic.h)
    for (size_t i = b; i < e; ++i) {
      const VecD xi = x_[i];
      float weight = selfWeight, squares = 0;
      VecD sum = VecD::Zero();
      VecD* g = pairGradients_[i / NeighborLists::kChunk].data() + neighbors_.start(i);
      float* w = xsphC_ > 0 ? pairWeights_[i / NeighborLists::kChunk].data() + neighbors_.start(i) : nullptr;
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j, ++g) {
        VecD r = xi - x_[*j];
        wrap(r);
        const auto k = kernel.pair(r.norm());
        weight += k.value;
        if (w) *w++ = k.value;
        *g = (volume_ * k.gradientFactor) * r;
        sum += *g;
        if constexpr (kSeveral) squares += inverse[*j] * g->squaredNorm();
        else squares += g->squaredNorm();
      }
      float wallWeight = 0;
      VecD wall = VecD::Zero();
      walls_.add(xi, wallWeight, wall);
      if (colliding) wallFlux_[i] = volume_ * colliderTerms(xi, wallWeight, wall);

      wallGradient_[i] = volume_ * wall;
      densityRatio_[i] = volume_ * (weight + wallWeight);
      float own = (sum + wallGradient_[i]).squaredNorm();
      if constexpr (kSeveral) own *= inverse[i];
      diagonal_[i] = own + squares;
    }
  });
  });
}

// Adami, Hu and Adams 2013's transport velocity, as WCSPH's (sim/wcsph_solver.h): the drift moves particles with
// v + dt a_b, a_b = -(p_b / rho_0) (sum_j (1 / r_i^2 + 1 / r_j^2) g_ij + 2 / r_i^2 G_i), r = rho / rho_0 (m_j = V
// rho_0), from the factors of the step's start (w_i times it with several fluids, as the pressure's change).
template <int Dim>
void DfsphSolver<Dim>::computeTransportAccelerations() {
  const PhaseTimer timer(times_.forces);
  transportAcceleration_.resize(size());
  const float scale = -backgroundPressure_ / restDensity_;
  const float* inverse = inverseMassRatio_.empty() ? nullptr : inverseMassRatio_.data();
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const float inverseSquareI = 1.0f / (densityRatio_[i] * densityRatio_[i]);
      VecD sum = (2.0f * inverseSquareI) * wallGradient_[i];
      const VecD* g = pairGradients_[i / NeighborLists::kChunk].data() + neighbors_.start(i);
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j, ++g)
        sum += (inverseSquareI + 1.0f / (densityRatio_[*j] * densityRatio_[*j])) * *g;
      transportAcceleration_[i] = (inverse ? scale * inverse[i] : scale) * sum;
    }
  });
}

// v += dt (g + the attractor); then XSPH: v_i += c sum_j V (v_j - v_i) W_ij.
template <int Dim>
void DfsphSolver<Dim>::applyNonPressureForces(float dt, double time) {
  const PhaseTimer timer(times_.forces);
  // An incremental pressure correction (van Kan 1986): the viscosity solve sees last step's pressure, so it holds
  // the fluid to a solid against the pressure's gradient along it; the density solve then adds only the change.
  // Applied after it, a disc dragged through honey at the default step felt half of Faxen's drag, the fluid
  // slipping along it (docs/viscosity.md). That pressure is the warm start's share of last step's, so the
  // viscosity solve sees the same share of the external forces and the rest follows it: at rest the two cancel,
  // where a whole step of gravity against 0.8 of its pressure left the no-slip walls holding the other 0.2, and a
  // ball held still in honey felt -1.5 N of fluid force instead of its 5.1 N of buoyancy.
  const auto kickExternal = [&](float share) {
    const auto external = this->externalForces(share * dt, time);
    parallelFor(0, size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) external.kick(x_[i], v_[i]);
    });
  };
  const float before = pressureBeforeViscosity_ ? kDensityWarmStart : 1.0f;
  kickExternal(before);
  this->kickSurfaceTension(x_, dt);
  if (pressureBeforeViscosity_) warmStart(true, dt, densityWarm_);
  this->applyViscosity(x_, dt);
  if (pressureBeforeViscosity_) kickExternal(1.0f - before);
  if (xsphC_ > 0) {
    std::vector<VecD>& smoothed = vectorScratch_;
    smoothed.resize(size());
    const float scale = xsphC_ * volume_;
    parallelFor(0, size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        VecD sum = VecD::Zero();
        const float* w = pairWeights_[i / NeighborLists::kChunk].data() + neighbors_.start(i);
        for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j, ++w) sum += (v_[*j] - v_[i]) * *w;
        smoothed[i] = v_[i] + scale * sum;
      }
    });
    v_.swap(smoothed);
  }
}

template <int Dim>
float DfsphSolver<Dim>::residual(size_t i, bool density, float dt) const {
  const VecD vi = v_[i];
  float divergence = vi.dot(wallGradient_[i]);
  const VecD* g = pairGradients_[i / NeighborLists::kChunk].data() + neighbors_.start(i);
  for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j, ++g) divergence += (vi - v_[*j]).dot(*g);
  if (!colliders_.empty()) divergence -= wallFlux_[i];
  if (density) return densityRatio_[i] - densityTarget_ + dt * divergence;
  return densityRatio_[i] < kSurfaceDensity ? 0.0f : dt * divergence;
}

template <int Dim>
void DfsphSolver<Dim>::applyIncrements(const std::vector<float>& increments, float dt, std::vector<float>& total) {
  const float inverseDt = 1.0f / dt;
  const float* inverse = inverseMassRatio_.empty() ? nullptr : inverseMassRatio_.data();  // w (computeFactors)
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const float di = increments[i];
      VecD delta = di * wallGradient_[i];
      const VecD* g = pairGradients_[i / NeighborLists::kChunk].data() + neighbors_.start(i);
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j, ++g) delta += (di + increments[*j]) * *g;
      v_[i] -= (inverse ? inverseDt * inverse[i] : inverseDt) * delta;
      walls_.boundVelocity(x_[i], v_[i], dt);
      total[i] += di;
    }
  });
}

// The solve's start: a share of last step's total applied to v (and counted in `total` anew).
template <int Dim>
void DfsphSolver<Dim>::warmStart(bool density, float dt, std::vector<float>& total) {
  const size_t n = size();
  increments_.resize(n);
  bool warm = false;
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      increments_[i] = (density ? kDensityWarmStart : kDivergenceWarmStart) * total[i];
      total[i] = 0;  // applyIncrements adds the start
    }
  });
  for (size_t i = 0; i < n && !warm; ++i) warm = increments_[i] != 0;
  if (warm) applyIncrements(increments_, dt, total);
}

// Projected Jacobi on the total lambda of this solve, `total` (>= 0): each pass computes every particle's
// residual s_i at the current velocities and the increment d_i = max(total_i + s_i / S_i, 0) - total_i, then
// applies all increments at once. The error is the average of max(s_i, 0) before the pass's correction.
template <int Dim>
int DfsphSolver<Dim>::solve(bool density, float dt, double limit, int minimum, std::vector<float>& total,
                            bool warmed) {
  if (!warmed) warmStart(density, dt, total);
  const size_t n = size();
  increments_.resize(n);
  int corrections = 0;
  while (true) {
    const double error = parallelSum<double>(0, n, [&](size_t b, size_t e) {
                           double sum = 0;
                           for (size_t i = b; i < e; ++i) {
                             const float s = residual(i, density, dt);
                             const float next =
                                 diagonal_[i] > 0 ? std::max(total[i] + relaxation_ * s / diagonal_[i], 0.0f) : 0.0f;
                             increments_[i] = next - total[i];
                             sum += std::max(s, 0.0f);
                           }
                           return sum;
                         }) /
                         std::max<double>(1, n);
    if ((error <= limit && corrections >= minimum) || corrections >= maxIterations_) break;
    applyIncrements(increments_, dt, total);
    ++corrections;
  }
  return corrections;
}

// Each collider's share of lambda_i G_i moved particle i's velocity by -(w_i / dt) lambda_i V grad W_c: the
// impulse m_i times that, from the collider (m_i w_i = m_0, so the same with several fluids).
template <int Dim>
void DfsphSolver<Dim>::recordColliderImpulses(const std::vector<float>& lambda, float dt) {
  const float scale = -mass_ * volume_ / dt;
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (lambda[i] == 0) continue;
      colliders_.forEachNear(x_[i], [&](size_t c, float d, const VecD& normal) {
        float unused;
        VecD gradient;
        colliders_.wallTerms(c, x_[i], d, normal, unused, gradient);
        colliders_.addImpulse(i, c, (scale * lambda[i]) * gradient, x_[i]);
      });
    }
  });
}

template <int Dim>
std::vector<float> DfsphSolver<Dim>::pressures(bool withDivergence) const {
  std::vector<float> p(size(), 0.0f);
  if (lastStep_ > 0)
    for (size_t i = 0; i < size(); ++i)
      p[i] = restDensity_ * (densityWarm_[i] + (withDivergence ? divergenceWarm_[i] : 0.0f)) / (lastStep_ * lastStep_);
  return p;
}

template <int Dim>
FluidMeasures DfsphSolver<Dim>::measure() {
  if (!prepared_) prepareStep();
  return kernel_.visit([&](const auto& kernel) {
    return this->measureWith([&](float r2) { return kernel.value(std::sqrt(r2)); });
  });
}

template class DfsphSolver<2>;
template class DfsphSolver<3>;

}  // namespace surge
