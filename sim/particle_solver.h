// The particle core every fluid method is built on. It holds what the methods share: the particles (positions,
// velocities, ids), the neighbour grid and lists and the reorder of every channel by cell, the tank's walls, the
// colliders and bodies the fluid meets, gravity and the attractor, the runaway-speed check, the measures of
// stats.csv and the phase timers; and it implements the part of FluidSolver (sim/fluid_solver.h) that is the
// same for all of them. A method derives from ParticleSolver and keeps only its own phases and channels, so its
// .cpp reads as its paper's algorithm.
//
// It is a base class rather than a state object each method holds: the loops of a method read x_, v_ and the
// neighbour lists directly (no accessor per particle), and FluidSolver's bookkeeping is written once.
#pragma once

#include <algorithm>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "core/ply.h"
#include "core/scene.h"
#include "sim/attractor.h"
#include "sim/colliders.h"
#include "sim/fluid_solver.h"
#include "sim/kernels.h"
#include "sim/measures.h"
#include "sim/neighbor_grid.h"
#include "sim/periodic.h"
#include "sim/surface_tension.h"
#include "sim/tank.h"
#include "sim/viscosity.h"

namespace surge {

// Sizes a channel to n values, growing its capacity by half at least, so that a count that keeps growing (an
// emitter's) reallocates rarely.
template <typename T>
void sizeChannel(std::vector<T>& channel, size_t n, const T& value) {
  if (n > channel.capacity()) channel.reserve(std::max(n, channel.capacity() + channel.capacity() / 2));
  channel.assign(n, value);
}

// The box the tank's walls stand on: the domain, with each open face (domain.open) and each face of a periodic
// axis (domain.periodic) moved out by two kernel radii, where it reaches no particle inside the domain; a particle
// that crosses an open face is removed at the end of its step (sim/sources.h), one that crosses a periodic face
// is moved back in by a period (sim/periodic.h).
template <int Dim>
void tankWallBox(const Scene& scene, Vec<Dim>& lower, Vec<Dim>& upper) {
  lower = toVec<Dim>(scene.domain.min);
  upper = toVec<Dim>(scene.domain.max);
  const float margin = 2 * static_cast<float>(scene.solver.kernel_radius);
  for (int axis = 0; axis < Dim; ++axis) {
    if (!scene.hasWall(axis, false)) lower[axis] -= margin;
    if (!scene.hasWall(axis, true)) upper[axis] += margin;
  }
}

// The scene's SPH kernel (WCSPH, DFSPH).
template <int Dim>
SphKernel<Dim> sphKernel(const Scene& scene) {
  return SphKernel<Dim>(scene.solver.kernel, static_cast<float>(scene.solver.kernel_radius));
}

// The rest lattice of the scene's spacing seen through a method's kernel, given by W and grad W as functions of
// the offset r with support `radius`: the tank's walls (the lattice continued beyond them) and the lattice sums
// of W and |grad W|^2 around an interior particle, which set the particle mass (the rest lattice has exactly
// rest_density) and PBF's constraint scale.
template <int Dim>
struct RestLattice {
  TankWalls<Dim> walls;
  double weightSum = 0, gradientSquaredSum = 0;

  template <typename Weight, typename Gradient>
  RestLattice(const Scene& scene, float radius, Weight weight, Gradient gradient)
      : walls(wallBox(scene, 0), wallBox(scene, 1), static_cast<float>(scene.particle_spacing), radius, weight,
              gradient) {
    latticeSums<Dim>(static_cast<float>(scene.particle_spacing), radius, weight, gradient, &weightSum,
                     &gradientSquaredSum);
  }

 private:
  static Vec<Dim> wallBox(const Scene& scene, int corner) {
    Vec<Dim> lower, upper;
    tankWallBox<Dim>(scene, lower, upper);
    return corner == 0 ? lower : upper;
  }
};

// The rest lattice through the scene's SPH kernel (WCSPH, DFSPH).
template <int Dim>
RestLattice<Dim> sphRestLattice(const Scene& scene);

template <int Dim>
class ParticleSolver : public FluidSolver<Dim> {
 public:
  using VecD = Vec<Dim>;

  // Not copyable: the colliders point at the tank's walls of this object.
  ParticleSolver(const ParticleSolver&) = delete;
  ParticleSolver& operator=(const ParticleSolver&) = delete;

  void setParticles(const ParticleFrame& frame) final;
  void getParticles(ParticleFrame& frame) const final;
  void editParticles(const ParticleEdit<Dim>& edit) final;
  std::vector<float> carriedState() const final;
  void restoreCarriedState(const std::vector<float>& state) final;
  size_t size() const final { return x_.size(); }
  const std::vector<VecD>& positions() const final { return x_; }
  const std::vector<VecD>& velocities() const final { return v_; }
  const std::vector<uint32_t>& ids() const final { return id_; }
  float particleMass() const final { return mass_; }
  const std::vector<float>& massRatios() const final { return massRatio_; }
  uint32_t particleId(size_t i) const { return id_[i]; }
  PhaseTimes& phaseTimes() final { return times_; }
  int lastViscosityIterations() const final { return viscosity_.active() ? viscosity_.lastIterations() : -1; }
  double takeForceWork() final { return tension_.active() ? tension_.takeWork() : 0.0; }
  Colliders<Dim>& colliders() final { return colliders_; }
  const Colliders<Dim>& colliders() const { return colliders_; }

 protected:
  // `lattice`: the rest lattice through the method's kernel, whose walls become the tank and whose weight sum the
  // particle mass. `shapes`: the scene's collider shapes, null builds them.
  ParticleSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, RestLattice<Dim> lattice);

  // The method's own channels, sized for the n particles setParticles or editParticles left (sizeChannel).
  virtual void resizeChannels(size_t n) = 0;
  // Visits the channels the method carries from step to step and frame to frame (FluidSolver::carriedState),
  // one float a particle each, in a fixed order; none by default. editParticles keeps them with their particles.
  virtual void forEachCarriedChannel(const std::function<void(std::vector<float>&)>& visit) { (void)visit; }

  // Sorts the particles into the grid at `key` (x_, or a method's predicted positions) and reorders x_, v_, id_,
  // `key` and every channel given by cell, so that neighbours are close in memory; an empty channel is skipped.
  // cellOrder() is then the order, for a channel of another type.
  template <typename... Channels>
  void reorderByCell(std::vector<VecD>& key, Channels&... channels);
  const std::vector<uint32_t>& cellOrder() const { return grid_.sortedOrder(); }
  // The neighbour lists of the positions `at`, as the last reorderByCell sorted them.
  void findNeighborsOf(const std::vector<VecD>& at, float radius) { grid_.findNeighbors(at, radius, neighbors_); }

  // Gravity and the attractor (at `time`) as velocity changes of a step dt: kick(i, v) adds them to v.
  struct ExternalForces {
    const ParticleSolver& core;
    float dt;
    bool attract;
    VecD attractorAt;
    void kick(const VecD& x, VecD& v) const {
      v += dt * core.gravity_;
      if (attract) v += dt * core.attractor_.acceleration(x, attractorAt);
    }
  };
  ExternalForces externalForces(float dt, double time) const {
    const bool attract = attractor_.active();
    return {*this, dt, attract, attract ? attractor_.position(time) : VecD::Zero()};
  }

  // The measures of stats.csv at x_ with the current neighbour lists; weight(r2) is the method's density kernel
  // as a function of the squared distance.
  template <typename Weight>
  FluidMeasures measureWith(Weight weight) const {
    return periodic_.withNearestImage([&](const auto& wrap) {
      return measureDensityAndEnergy<Dim>(x_, v_, neighbors_, Boundary<Dim>{walls_, colliders_}, mass_, restDensity_,
                                          weight, massRatio_, wrap);
    });
  }
  // The fastest particle's speed after `dt` of gravity: the CFL conditions' |v|max.
  float fastestAfterFall(float dt);
  // stableSubsteps's depth criterion on the deepest column as the fluid stands now, dt <= 0.9 spacing /
  // sqrt(|g| depth) (infinity without gravity or particles): a dam break's column is deeper at the start than
  // the pool it settles into. With several fluids a column's depth is at least its weight over its bottom
  // particle's density (a light layer under a heavy one).
  float depthStableStepNow();
  // The fluid-filled box's shared parts (DFSPH's and PBF's): the density target of a domain periodic along every
  // axis, the mean of `densityRatio` (rho_i / rho_0) when above 1; and the step the transport velocity's push
  // allows, dt <= 0.45 (support / 2) / sqrt(p_b / rho_0) (infinity without it).
  float meanDensityTarget(const std::vector<float>& densityRatio) const;
  float transportStableStep(float backgroundPressure, float support) const;
  // The end of a method's step: positions that crossed a periodic face move back in by a period; then the
  // first particle that is not finite, left the tank or ran away (firstParticleOutside), or -1.
  long endStep() {
    periodic_.wrap(x_);
    return firstParticleOutside(x_, v_, walls_, speedLimit_);
  }
  // virialPressureWithin for a method whose pressure force is -m_i m_j (p_i / rho_i^2 + p_j / rho_j^2) grad W_ij
  // (`density` empty: rho_0 for every particle), over neighbour lists of its own at x_; adhesion left out. With
  // several fluids DFSPH weights its pressure force by its density contrast, so there the figure is approximate.
  // `other(i, j, r)`: the method's other pair force on i from j (its viscosity's) over m_0^2 grad W_ij, if any.
  using OtherPairForce = std::function<float(size_t, size_t, const VecD&)>;
  double pairVirialPressureWithin(const SphKernel<Dim>& kernel, const std::vector<float>& pressure,
                                  const std::vector<float>& density, const VirialBall<Dim>& ball,
                                  const OtherPairForce& other = {});
  // Each particle's half of sum_j x_ij . F_ij, each pair's half counted by its share inside `ball`.
  std::vector<double> pairVirials(const SphKernel<Dim>& kernel, const std::vector<float>& pressure,
                                  const std::vector<float>& density, const VirialBall<Dim>& ball,
                                  const OtherPairForce& other);
  float densityOf(const std::vector<float>& density, size_t i) const {
    return density.empty() ? restDensity_ : density[i];
  }
  // Particle i's mass, m_0 times its fluid's mass ratio.
  float massOf(size_t i) const { return massRatio_.empty() ? mass_ : mass_ * massRatio_[i]; }
  // Bytes held by the shared channels, the grid, the lists and the colliders (capacities).
  size_t coreMemoryBytes() const;

  // Surface tension and adhesion at `at` with the current neighbour lists, as a velocity change over dt
  // (counted in the forces phase); nothing without them.
  void kickSurfaceTension(const std::vector<VecD>& at, float dt) {
    if (!tension_.active()) return;
    const PhaseTimer timer(times_.forces);
    tension_.computeAccelerations(at, neighbors_, colliders_, dt, fluid_);
    tension_.kick(v_, dt, massRatio_);
  }

  // The fluid's viscosity (sim/viscosity.h) on v_ at `at` with the current neighbour lists, over a step dt
  // (counted in the forces phase); nothing without it.
  void applyViscosity(const std::vector<VecD>& at, float dt) {
    if (!viscosity_.active()) return;
    const PhaseTimer timer(times_.forces);
    viscosity_.apply(at, v_, neighbors_, walls_, colliders_, fluid_, mass_, massRatio_, dt);
  }

  // Parameters, fixed at construction. restDensity_ and mass_ are fluid 0's (Scene::referenceDensity).
  const float restDensity_, mass_;
  // Several fluids (Scene::severalFluids): each particle's fluid and its mass over mass_ (rho_f / rho_0, its
  // volume being the lattice's) and its inverse; all empty in a scene of one fluid. fluidMassRatio_ is by fluid.
  std::vector<uint8_t> fluid_;
  std::vector<float> massRatio_, inverseMassRatio_, fluidMassRatio_;
  const VecD gravity_;
  const Attractor<Dim> attractor_;
  SurfaceTension<Dim> tension_;  // inactive without surface tension
  Viscosity<Dim> viscosity_;     // inactive without viscosity

  const PeriodicDomain<Dim> periodic_;  // inactive without domain.periodic
  // The particles (structure of arrays), the grid, the walls and the colliders.
  std::vector<VecD> x_, v_;
  std::vector<uint32_t> id_;
  NeighborGrid<Dim> grid_;
  NeighborLists neighbors_;
  TankWalls<Dim> walls_;
  Colliders<Dim> colliders_;  // empty without colliders and bodies
  // Scratch a method may use between its own passes; reorderByCell uses them too.
  std::vector<VecD> vectorScratch_;
  std::vector<float> floatScratch_;
  std::vector<uint32_t> idScratch_;
  std::vector<uint8_t> byteScratch_;
  PhaseTimes times_;

 private:
  std::vector<VecD>& scratchFor(std::vector<VecD>&) { return vectorScratch_; }
  std::vector<float>& scratchFor(std::vector<float>&) { return floatScratch_; }
  std::vector<uint32_t>& scratchFor(std::vector<uint32_t>&) { return idScratch_; }

  void setFluids(const std::vector<uint8_t>& fluids, size_t n);
  // The method's carried channels (forEachCarriedChannel), then the viscosity's warm start.
  void forEachCarried(const std::function<void(std::vector<float>&)>& visit) {
    forEachCarriedChannel(visit);
    viscosity_.forEachCarriedChannel(visit);
  }

  // The deepest column (depthStableStepNow): the particles counted on a grid over the tank's floor, its cells
  // kColumnSpacings spacings across; a column's depth is its particles' volume over its cell's area (a pool's
  // depth in a pool, a thin jet's little). With several fluids, a column also weighs its particles' mass ratios and
  // keeps its bottom particle's (its depth along gravity, its ratio).
  static constexpr float kColumnSpacings = 4;
  float latticeSpacing_ = 0;
  int down_ = 1;                      // the axis gravity is mostly along
  Vec<Dim> floorMin_, columnWidth_;   // the grid's corner and cell size (the down axis's unused)
  float columnArea_ = 1;              // a cell's area across the down axis (its length in 2D)
  Eigen::Matrix<int, Dim, 1> columns_;
  std::vector<uint32_t> columnCounts_;
  std::vector<float> columnMass_;
  std::vector<std::pair<float, float>> columnBottom_;

  std::vector<std::vector<float>> carriedHold_;  // editParticles: the carried channels while the rest resize
  float sceneSpeedLimit_;  // runawaySpeed(scene)
  float speedLimit_ = 0;   // and ten times the fastest particle given (runawaySpeedFor): faster is a blow-up
};

template <int Dim>
template <typename... Channels>
void ParticleSolver<Dim>::reorderByCell(std::vector<VecD>& key, Channels&... channels) {
  periodic_.wrap(key, &key != &x_ ? &x_ : nullptr);  // the grid takes positions inside the period
  grid_.sort(key);
  const std::vector<uint32_t>& order = grid_.sortedOrder();
  gatherByOrder(order, x_, vectorScratch_);
  gatherByOrder(order, v_, vectorScratch_);
  if (&key != &x_) gatherByOrder(order, key, vectorScratch_);
  gatherByOrder(order, id_, idScratch_);
  if (!fluid_.empty()) {
    gatherByOrder(order, fluid_, byteScratch_);
    gatherByOrder(order, massRatio_, floatScratch_);
    gatherByOrder(order, inverseMassRatio_, floatScratch_);
  }
  [[maybe_unused]] auto gather = [&](auto& channel) {
    if (!channel.empty()) gatherByOrder(order, channel, scratchFor(channel));
  };
  (gather(channels), ...);
  if (viscosity_.implicit()) viscosity_.forEachCarriedChannel([&](std::vector<float>& channel) { gather(channel); });
}

extern template class ParticleSolver<2>;
extern template class ParticleSolver<3>;

}  // namespace surge
