// Moving particles between a frame file's ParticleFrame (always 3 components) and a solver's channels of
// Dim components, and scene vectors into Vec<Dim>: shared by both solvers.
#pragma once

#include <vector>

#include "core/ply.h"
#include "sim/kernels.h"

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

}  // namespace surge
