#include "sim/particle_solver.h"

#include "sim/solver_defaults.h"

namespace surge {

template <int Dim>
TankWalls<Dim> makeSphTankWalls(const Scene& scene) {
  const float spacing = static_cast<float>(scene.particle_spacing);
  const Vec<Dim> lo = toVec<Dim>(scene.domain.min), hi = toVec<Dim>(scene.domain.max);
  return sphKernel<Dim>(scene).visit([&](const auto& kernel) {
    return TankWalls<Dim>(
        lo, hi, spacing, kernel.radius(), [&](const Vec<Dim>& r) { return kernel.value(r.norm()); },
        [&](const Vec<Dim>& r) -> Vec<Dim> { return kernel.gradientFactor(r.norm()) * r; });
  });
}

template <int Dim>
float sphParticleMass(const Scene& scene) {
  double weightSum = 0, unused = 0;
  sphKernel<Dim>(scene).visit([&](const auto& kernel) {
    latticeSums<Dim>(static_cast<float>(scene.particle_spacing), kernel.radius(),
                     [&](const Vec<Dim>& r) { return kernel.value(r.norm()); },
                     [&](const Vec<Dim>& r) -> Vec<Dim> { return kernel.gradientFactor(r.norm()) * r; },
                     &weightSum, &unused);
    return 0;
  });
  return static_cast<float>(scene.solver.rest_density / weightSum);
}

template <int Dim>
ParticleSolver<Dim>::ParticleSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes,
                                    TankWalls<Dim> walls, float mass)
    : restDensity_(static_cast<float>(scene.solver.rest_density)),
      mass_(mass),
      gravity_(toVec<Dim>(scene.gravity)),
      attractor_(scene.attractor),
      grid_(toVec<Dim>(scene.domain.min), toVec<Dim>(scene.domain.max),
            NeighborGrid<Dim>::cellSizeFor(static_cast<float>(scene.solver.kernel_radius))),
      walls_(std::move(walls)),
      sceneSpeedLimit_(static_cast<float>(runawaySpeed(scene))) {
  if (hasSolids(scene)) colliders_ = Colliders<Dim>(scene, std::move(shapes), walls_);
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
  colliders_.resetSlots(n);
  speedLimit_ = runawaySpeedFor(sceneSpeedLimit_, v_);
  resizeChannels(n);
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
}

template <int Dim>
size_t ParticleSolver<Dim>::coreMemoryBytes() const {
  size_t bytes = (x_.capacity() + v_.capacity() + vectorScratch_.capacity()) * sizeof(VecD);
  bytes += (id_.capacity() + idScratch_.capacity()) * sizeof(uint32_t) + floatScratch_.capacity() * sizeof(float);
  return bytes + grid_.memoryBytes() + neighbors_.memoryBytes() + colliders_.memoryBytes();
}

template TankWalls<2> makeSphTankWalls<2>(const Scene&);
template TankWalls<3> makeSphTankWalls<3>(const Scene&);
template float sphParticleMass<2>(const Scene&);
template float sphParticleMass<3>(const Scene&);
template class ParticleSolver<2>;
template class ParticleSolver<3>;

}  // namespace surge
