#include "sim/particle_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/parallel.h"
#include "sim/solver_defaults.h"

namespace surge {

template <int Dim>
RestLattice<Dim> sphRestLattice(const Scene& scene) {
  return sphKernel<Dim>(scene).visit([&](const auto& kernel) {
    return RestLattice<Dim>(
        scene, kernel.radius(), [&](const Vec<Dim>& r) { return kernel.value(r.norm()); },
        [&](const Vec<Dim>& r) -> Vec<Dim> { return kernel.gradientFactor(r.norm()) * r; });
  });
}

template <int Dim>
ParticleSolver<Dim>::ParticleSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes,
                                    RestLattice<Dim> lattice)
    : restDensity_(static_cast<float>(scene.referenceDensity())),
      mass_(static_cast<float>(scene.referenceDensity() / lattice.weightSum)),
      gravity_(toVec<Dim>(scene.gravity)),
      attractor_(scene.attractor),
      tension_(scene, mass_),
      viscosity_(scene, static_cast<float>(scene.solver.kernel_radius)),
      periodic_(scene),
      grid_(lattice.walls.domainMin(), lattice.walls.domainMax(),
            NeighborGrid<Dim>::cellSizeFor(static_cast<float>(scene.solver.kernel_radius))),
      walls_(std::move(lattice.walls)),
      sceneSpeedLimit_(static_cast<float>(runawaySpeed(scene))) {
  grid_.setPeriodic(periodic_);
  latticeSpacing_ = static_cast<float>(scene.particle_spacing);
  gravity_.cwiseAbs().maxCoeff(&down_);
  floorMin_ = toVec<Dim>(scene.domain.min);
  columns_.setOnes();
  columnWidth_ = toVec<Dim>(scene.domain.max - scene.domain.min);
  for (int k = 0; k < Dim; ++k) {
    if (k == down_) continue;
    columns_[k] = std::max(1, int(std::lround(columnWidth_[k] / (kColumnSpacings * latticeSpacing_))));
    columnWidth_[k] /= float(columns_[k]);
    columnArea_ *= columnWidth_[k];
  }
  if (hasSolids(scene)) colliders_ = Colliders<Dim>(scene, std::move(shapes), walls_);
  if (scene.severalFluids()) {
    fluidMassRatio_.assign(scene.fluids.size(), 1.0f);
    for (size_t f = 0; f < scene.fluids.size(); ++f)
      fluidMassRatio_[f] = static_cast<float>(scene.fluids[f].rest_density / scene.referenceDensity());
  }
}

// fluid_ from a frame's (fluid 0 where it has none), and massRatio_ from it.
template <int Dim>
void ParticleSolver<Dim>::setFluids(const std::vector<uint8_t>& fluids, size_t n) {
  if (fluidMassRatio_.empty()) return;
  fluid_ = fluids;
  fluid_.resize(n, 0);
  massRatio_.resize(n);
  inverseMassRatio_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (fluid_[i] >= fluidMassRatio_.size()) throw std::invalid_argument("a particle of a fluid the scene has not");
    massRatio_[i] = fluidMassRatio_[fluid_[i]];
    inverseMassRatio_[i] = 1.0f / massRatio_[i];
  }
}

// Frame files hold 3 components; the channels hold Dim.
template <int Dim>
void ParticleSolver<Dim>::setParticles(const ParticleFrame& frame) {
  const size_t n = frame.size();
  x_.resize(n);
  v_.resize(n);
  id_ = frame.id;
  for (size_t i = 0; i < n; ++i) {
    x_[i] = frame.position[i].head<Dim>();
    v_[i] = frame.velocity[i].head<Dim>();
  }
  setFluids(frame.fluid, n);
  colliders_.resetSlots(n);
  speedLimit_ = runawaySpeedFor(sceneSpeedLimit_, v_);
  resizeChannels(n);
  viscosity_.resize(n);
}

template <int Dim>
void ParticleSolver<Dim>::getParticles(ParticleFrame& frame) const {
  const size_t n = x_.size();
  frame.dimensions = Dim;
  frame.resize(n);
  for (size_t i = 0; i < n; ++i) {
    frame.position[i].setZero();
    frame.velocity[i].setZero();
    frame.position[i].head<Dim>() = x_[i];
    frame.velocity[i].head<Dim>() = v_[i];
  }
  frame.id = id_;
  frame.fluid = fluid_;
}

template <int Dim>
void ParticleSolver<Dim>::editParticles(const ParticleEdit<Dim>& edit) {
  for (size_t k = 0; k < edit.steer.size(); ++k) {
    x_[edit.steer[k]] = edit.steerPosition[k];
    v_[edit.steer[k]] = edit.steerVelocity[k];
  }
  // Even with no particle added or removed, a moved one makes what the method derived from x_ stale.
  if (edit.remove.empty() && edit.addPosition.empty() && edit.steer.empty()) return;
  const size_t before = x_.size();
  // The survivors move down over the removed, in order, with their carried channels.
  auto compact = [&](auto& channel) {
    size_t kept = 0, r = 0;
    for (size_t i = 0; i < before; ++i) {
      if (r < edit.remove.size() && edit.remove[r] == i) {
        ++r;
        continue;
      }
      channel[kept++] = channel[i];
    }
    channel.resize(kept);
  };
  if (!edit.remove.empty()) {
    compact(x_);
    compact(v_);
    compact(id_);
    if (!fluid_.empty()) compact(fluid_);
  }
  x_.insert(x_.end(), edit.addPosition.begin(), edit.addPosition.end());
  v_.insert(v_.end(), edit.addVelocity.begin(), edit.addVelocity.end());
  id_.insert(id_.end(), edit.addId.begin(), edit.addId.end());
  const size_t n = x_.size();
  if (!fluidMassRatio_.empty()) {
    fluid_.insert(fluid_.end(), edit.addFluid.begin(), edit.addFluid.end());
    setFluids(std::vector<uint8_t>(fluid_), n);
  }
  // The carried channels step aside while the method sizes its others, then come back, new particles at 0.
  size_t channels = 0;
  forEachCarried([&](std::vector<float>& channel) {
    if (!edit.remove.empty()) compact(channel);
    channel.resize(n, 0.0f);
    if (carriedHold_.size() <= channels) carriedHold_.emplace_back();
    carriedHold_[channels++].swap(channel);
  });
  resizeChannels(n);
  channels = 0;
  forEachCarried([&](std::vector<float>& channel) { carriedHold_[channels++].swap(channel); });
  colliders_.resizeSlots(n);
}

template <int Dim>
float ParticleSolver<Dim>::fastestAfterFall(float dt) {
  const VecD fall = dt * gravity_;
  std::vector<float>& speeds = floatScratch_;
  speeds.resize(size());
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) speeds[i] = (v_[i] + fall).norm();
  });
  return parallelMax(speeds);
}

// Counting is a pass over the particles in order, the same at any thread count.
// A fluid that fills a box periodic along every axis cannot be compressed as a whole, and a disordered set's
// summation density averages above the lattice's (0.8% at jitter 0.2): aimed at 1, DFSPH's solve ran into its
// iteration cap every step and PBF's constraints acted on every particle (docs/viscosity.md). The sum runs in chunk
// order, so the target is the same at any thread count.
template <int Dim>
float ParticleSolver<Dim>::meanDensityTarget(const std::vector<float>& densityRatio) const {
  const double sum = parallelSum<double>(0, densityRatio.size(), [&](size_t b, size_t e) {
    double local = 0;
    for (size_t i = b; i < e; ++i) local += densityRatio[i];
    return local;
  });
  return densityRatio.empty() ? 1.0f : std::max(1.0f, static_cast<float>(sum / densityRatio.size()));
}

// The push moves a particle by dt^2 a_b a step, a_b of order p_b / (rho_0 h) where the particles are uneven (h half
// the support): DFSPH's vortex held at dt^2 p_b / rho_0 = 0.18 h^2 and blew up at 0.2 to 0.36, so dt <= 0.45 h /
// sqrt(p_b / rho_0), the step of a sound speed sqrt(p_b / rho_0) at Courant number 0.45. A shorter step
// (solver.time_step, substeps) weakens the push as dt^2 (docs/viscosity.md).
template <int Dim>
float ParticleSolver<Dim>::transportStableStep(float backgroundPressure, float support) const {
  if (!(backgroundPressure > 0)) return std::numeric_limits<float>::infinity();
  return 0.45f * (0.5f * support) / std::sqrt(backgroundPressure / restDensity_);
}

template <int Dim>
float ParticleSolver<Dim>::depthStableStepNow() {
  const float g = gravity_.norm();
  if (!(g > 0) || size() == 0) return INFINITY;
  const size_t cells = size_t(columns_.prod());
  columnCounts_.assign(cells, 0);
  const bool several = !massRatio_.empty();
  if (several) {
    columnMass_.assign(cells, 0.0f);
    columnBottom_.assign(cells, {-INFINITY, 1.0f});
  }
  const float downward = gravity_[down_] < 0 ? -1.0f : 1.0f;  // a particle's depth along gravity is downward p
  for (size_t i = 0; i < size(); ++i) {
    const VecD& p = x_[i];
    size_t cell = 0;
    for (int k = Dim - 1; k >= 0; --k) {
      if (k == down_) continue;
      const int c = std::clamp(int((p[k] - floorMin_[k]) / columnWidth_[k]), 0, columns_[k] - 1);
      cell = cell * size_t(columns_[k]) + size_t(c);
    }
    ++columnCounts_[cell];
    if (several) {
      columnMass_[cell] += massRatio_[i];
      const float depth = downward * p[down_];
      if (depth > columnBottom_[cell].first) columnBottom_[cell] = {depth, massRatio_[i]};
    }
  }
  // With several fluids, the column's weight held by the fluid at its bottom, in that fluid's own depth: a light
  // layer under a heavy one is pressed as a pool of the light fluid as deep as the column's weight.
  float most = 0;
  for (size_t c = 0; c < cells; ++c)
    most = std::max(most, several ? std::max(float(columnCounts_[c]), columnMass_[c] / columnBottom_[c].second)
                                  : float(columnCounts_[c]));
  const float deepest = most * std::pow(latticeSpacing_, float(Dim)) / columnArea_;
  return static_cast<float>(depthStableStep(latticeSpacing_, g, deepest));
}

// The carried channels one after another.
template <int Dim>
std::vector<float> ParticleSolver<Dim>::carriedState() const {
  std::vector<float> state;
  const_cast<ParticleSolver*>(this)->forEachCarried(
      [&](std::vector<float>& channel) { state.insert(state.end(), channel.begin(), channel.end()); });
  return state;
}

template <int Dim>
void ParticleSolver<Dim>::restoreCarriedState(const std::vector<float>& state) {
  size_t channels = 0;
  forEachCarried([&](std::vector<float>&) { ++channels; });
  if (state.size() != channels * size()) throw std::invalid_argument("carried state of the wrong size");
  size_t at = 0;
  forEachCarried([&](std::vector<float>& channel) {
    channel.assign(state.begin() + std::ptrdiff_t(at), state.begin() + std::ptrdiff_t(at + size()));
    at += size();
  });
}

template <int Dim>
std::vector<double> ParticleSolver<Dim>::pairVirials(const SphKernel<Dim>& kernel, const std::vector<float>& pressure,
                                                     const std::vector<float>& density, const VirialBall<Dim>& ball,
                                                     const OtherPairForce& other) {
  const size_t n = x_.size();
  NeighborLists lists;
  grid_.findNeighbors(x_, kernel.radius(), lists);
  std::vector<double> virial(n, 0.0);
  kernel.visit([&](const auto& w) {
    periodic_.withNearestImage([&](const auto& sharedWrap) {
      parallelFor(0, n, [&](size_t b, size_t e) {
        const auto wrap = sharedWrap;  // the thread's own copy (sim/periodic.h)
        for (size_t i = b; i < e; ++i) {
          const float termI = pressure[i] / (densityOf(density, i) * densityOf(density, i));
          double sum = 0;
          for (const uint32_t* j = lists.begin(i); j != lists.end(i); ++j) {
            VecD r = x_[i] - x_[*j];
            wrap(r);
            float force =
                -massOf(i) * massOf(*j) * (termI + pressure[*j] / (densityOf(density, *j) * densityOf(density, *j)));
            if (other) force += mass_ * mass_ * other(i, *j, r);
            force *= w.gradientFactor(r.norm());  // F_ij / |x_ij| . x_ij / |x_ij| ...
            sum += double(ball.halfInside(x_[i], r)) * double(force) * double(r.squaredNorm());  // ... so x_ij . F_ij
          }
          virial[i] = 0.5 * sum;
        }
      });
    });
  });
  if (tension_.active()) tension_.addPairVirials(x_, lists, fluid_, ball, virial);
  return virial;
}

template <int Dim>
double ParticleSolver<Dim>::pairVirialPressureWithin(const SphKernel<Dim>& kernel, const std::vector<float>& pressure,
                                                     const std::vector<float>& density, const VirialBall<Dim>& ball,
                                                     const OtherPairForce& other) {
  const std::vector<double> virial = pairVirials(kernel, pressure, density, ball, other);
  // The momentum flux is the particles' motion relative to the ball's mean (its mass's), so that a fluid moving
  // as a whole reads the pressure it holds at rest. Sums in the particles' order: the same bytes at any thread count.
  const auto inside = [&](size_t i) { return (x_[i] - ball.centre).norm() < ball.radius; };
  Eigen::Matrix<double, Dim, 1> momentum = Eigen::Matrix<double, Dim, 1>::Zero();
  double mass = 0, sum = 0;
  for (size_t i = 0; i < x_.size(); ++i)
    if (inside(i)) {
      momentum += massOf(i) * v_[i].template cast<double>();
      mass += massOf(i);
    }
  const Eigen::Matrix<double, Dim, 1> mean = mass > 0 ? Eigen::Matrix<double, Dim, 1>(momentum / mass) : momentum;
  for (size_t i = 0; i < virial.size(); ++i) {
    sum += virial[i];
    if (inside(i)) sum += massOf(i) * (v_[i].template cast<double>() - mean).squaredNorm();
  }
  return sum / (Dim * ball.volume());
}

template <int Dim>
size_t ParticleSolver<Dim>::coreMemoryBytes() const {
  size_t bytes = (x_.capacity() + v_.capacity() + vectorScratch_.capacity()) * sizeof(VecD);
  bytes += (id_.capacity() + idScratch_.capacity()) * sizeof(uint32_t) + floatScratch_.capacity() * sizeof(float);
  bytes += fluid_.capacity() + byteScratch_.capacity() + (massRatio_.capacity() + inverseMassRatio_.capacity() + fluidMassRatio_.capacity()) * sizeof(float);
  return bytes + grid_.memoryBytes() + neighbors_.memoryBytes() + colliders_.memoryBytes() + tension_.memoryBytes() + viscosity_.memoryBytes();
}

template RestLattice<2> sphRestLattice<2>(const Scene&);
template RestLattice<3> sphRestLattice<3>(const Scene&);
template class ParticleSolver<2>;
template class ParticleSolver<3>;

}  // namespace surge
