#include "sim/particle_solver.h"

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
    : restDensity_(static_cast<float>(scene.solver.rest_density)),
      mass_(static_cast<float>(scene.solver.rest_density / lattice.weightSum)),
      gravity_(toVec<Dim>(scene.gravity)),
      attractor_(scene.attractor),
      grid_(toVec<Dim>(scene.domain.min), toVec<Dim>(scene.domain.max),
            NeighborGrid<Dim>::cellSizeFor(static_cast<float>(scene.solver.kernel_radius))),
      walls_(std::move(lattice.walls)),
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

template RestLattice<2> sphRestLattice<2>(const Scene&);
template RestLattice<3> sphRestLattice<3>(const Scene&);
template class ParticleSolver<2>;
template class ParticleSolver<3>;

}  // namespace surge
