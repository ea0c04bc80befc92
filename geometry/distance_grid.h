// A signed distance sampled on a dense grid (a mesh's, baked by geometry/mesh_sdf.cpp), read back by trilinear
// interpolation with the interpolant's own gradient. Outside the grid the distance grows with the distance to the
// grid's box, so a far point is far; the grid is made to cover its shape plus the band the simulator reads.
// (Stored in bricks of 4^3 samples, so that a cell's corners share two cache lines, the torus benchmark of
// docs/performance.md was no faster: its reads wait on the first line, not on the other three.)
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace surge {

class DistanceGrid {
 public:
  DistanceGrid() = default;
  // `samples` at origin + voxel * (i, j, k), i < counts[0] ..., x fastest (counts.prod() of them, each count >= 2).
  DistanceGrid(const Eigen::Vector3f& origin, float voxel, const Eigen::Array3i& counts, std::vector<float> samples)
      : origin_(origin), voxel_(voxel), counts_(counts), values_(std::move(samples)) {}

  const Eigen::Array3i& counts() const { return counts_; }
  const Eigen::Vector3f& origin() const { return origin_; }
  float voxel() const { return voxel_; }
  size_t memoryBytes() const { return values_.capacity() * sizeof(float); }

  // The interpolated distance at p, and its gradient (not normalised) in `gradient`.
  float sample(const Eigen::Vector3f& p, Eigen::Vector3f& gradient) const {
    Eigen::Vector3f u = (p - origin_) / voxel_;
    float outside = 0;
    Eigen::Vector3f outsideDirection = Eigen::Vector3f::Zero();
    for (int a = 0; a < 3; ++a) {
      const float hi = float(counts_[a] - 1);
      const float clamped = std::min(std::max(u[a], 0.0f), hi);
      outsideDirection[a] = u[a] - clamped;
      u[a] = std::min(clamped, hi - 1e-4f);
    }
    const int i = int(u[0]), j = int(u[1]), k = int(u[2]);
    const float fx = u[0] - i, fy = u[1] - j, fz = u[2] - k;
    const size_t base = index(i, j, k), sx = 1, sy = size_t(counts_[0]), sz = sy * size_t(counts_[1]);
    const float c000 = values_[base], c100 = values_[base + sx], c010 = values_[base + sy],
                c110 = values_[base + sx + sy], c001 = values_[base + sz], c101 = values_[base + sx + sz],
                c011 = values_[base + sy + sz], c111 = values_[base + sx + sy + sz];
    const float c00 = c000 + fx * (c100 - c000), c10 = c010 + fx * (c110 - c010);
    const float c01 = c001 + fx * (c101 - c001), c11 = c011 + fx * (c111 - c011);
    const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
    const float value = c0 + fz * (c1 - c0);
    const float dx = (1 - fz) * ((1 - fy) * (c100 - c000) + fy * (c110 - c010)) +
                     fz * ((1 - fy) * (c101 - c001) + fy * (c111 - c011));
    const float dy = (1 - fz) * (c10 - c00) + fz * (c11 - c01);
    const float dz = c1 - c0;
    gradient = Eigen::Vector3f(dx, dy, dz) / voxel_;
    outside = outsideDirection.norm();
    if (outside > 0) {
      gradient = outsideDirection / outside;
      return value + outside * voxel_;
    }
    return value;
  }

 private:
  size_t index(int i, int j, int k) const { return (size_t(k) * counts_[1] + j) * counts_[0] + i; }

  Eigen::Vector3f origin_ = Eigen::Vector3f::Zero();
  float voxel_ = 1;
  Eigen::Array3i counts_ = Eigen::Array3i::Zero();
  std::vector<float> values_;
};

}  // namespace surge
