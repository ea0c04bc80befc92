// What the solvers share about particles: moving them between a frame file's ParticleFrame (always 3
// components) and a solver's channels of Dim components, scene vectors into Vec<Dim>, and the SPH kernel
// (`solver.kernel`) and tank walls of the SPH methods (WCSPH).
#pragma once

#include <vector>

#include "core/ply.h"
#include "core/scene.h"
#include "sim/kernels.h"
#include "sim/tank.h"

namespace surge {

template <int Dim>
Vec<Dim> toVec(const Eigen::Vector3d& v) {
  return v.head<Dim>().template cast<float>();
}

template <int Dim>
void readChannels(const ParticleFrame& frame, std::vector<Vec<Dim>>& x, std::vector<Vec<Dim>>& v,
                  std::vector<uint32_t>& id) {
  const size_t n = frame.size();
  x.resize(n);
  v.resize(n);
  id = frame.id;
  for (size_t i = 0; i < n; ++i) {
    x[i] = frame.position[i].head<Dim>();
    v[i] = frame.velocity[i].head<Dim>();
  }
}

template <int Dim>
void writeChannels(const std::vector<Vec<Dim>>& x, const std::vector<Vec<Dim>>& v, const std::vector<uint32_t>& id,
                   ParticleFrame& frame) {
  const size_t n = x.size();
  frame.dimensions = Dim;
  frame.resize(n);
  for (size_t i = 0; i < n; ++i) {
    frame.position[i].setZero();
    frame.velocity[i].setZero();
    frame.position[i].head<Dim>() = x[i];
    frame.velocity[i].head<Dim>() = v[i];
  }
  frame.id = id;
}

// Calls use(kernel) with the scene's SPH kernel (solver.kernel: cubic spline or Wendland C2, support
// kernel_radius) and returns what it returns.
template <int Dim, typename Use>
auto withSphKernel(const Scene& scene, Use&& use) {
  const float support = static_cast<float>(scene.solver.kernel_radius);
  if (scene.solver.kernel == "wendland_c2") return use(WendlandC2Kernel<Dim>(support));
  return use(CubicSplineKernel<Dim>(support));
}

// The tank's walls seen through the scene's SPH kernel.
template <int Dim>
TankWalls<Dim> makeSphTankWalls(const Scene& scene) {
  const float spacing = static_cast<float>(scene.particle_spacing);
  const Vec<Dim> lo = toVec<Dim>(scene.domain.min), hi = toVec<Dim>(scene.domain.max);
  return withSphKernel<Dim>(scene, [&](const auto& kernel) {
    return TankWalls<Dim>(
        lo, hi, spacing, kernel.radius(), [&](const Vec<Dim>& r) { return kernel.value(r.norm()); },
        [&](const Vec<Dim>& r) -> Vec<Dim> { return kernel.gradientFactor(r.norm()) * r; });
  });
}

// The particle mass that gives the rest lattice of `spacing` exactly rest_density with the scene's SPH kernel.
template <int Dim>
float sphParticleMass(const Scene& scene) {
  double weightSum = 0, unused = 0;
  withSphKernel<Dim>(scene, [&](const auto& kernel) {
    latticeSums<Dim>(static_cast<float>(scene.particle_spacing), kernel.radius(),
                     [&](const Vec<Dim>& r) { return kernel.value(r.norm()); },
                     [&](const Vec<Dim>& r) -> Vec<Dim> { return kernel.gradientFactor(r.norm()) * r; },
                     &weightSum, &unused);
    return 0;
  });
  return static_cast<float>(scene.solver.rest_density / weightSum);
}

}  // namespace surge
