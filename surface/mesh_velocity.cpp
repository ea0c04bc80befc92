#include "surface/mesh_velocity.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/parallel.h"

namespace surge {
namespace {

// A cell of the particles' grid (cells of R, so that a vertex's support lies in the 27 around it) as one sortable
// key: 21 bits an axis, offset so that negative cells sort too.
uint64_t cellKey(const Eigen::Vector3i& c) {
  constexpr int64_t kOffset = 1 << 20;
  auto bits = [](int value) { return uint64_t(std::clamp<int64_t>(value + kOffset, 0, (1 << 21) - 1)); };
  return (bits(c.x()) << 42) | (bits(c.y()) << 21) | bits(c.z());
}

}  // namespace

void sampleVertexVelocities(TriangleMesh& mesh, const std::vector<Eigen::Vector3f>& x,
                            const std::vector<Eigen::Vector3f>& v, float support) {
  mesh.velocities.assign(mesh.positions.size(), Eigen::Vector3f::Zero());
  if (x.empty() || !(support > 0)) return;
  const float cell = support, r2 = support * support;
  auto cellOf = [&](const Eigen::Vector3f& p) {
    return Eigen::Vector3i(int(std::floor(p.x() / cell)), int(std::floor(p.y() / cell)), int(std::floor(p.z() / cell)));
  };
  // The particles sorted by cell (then index: the order, and so the sums, never depend on threads).
  std::vector<std::pair<uint64_t, uint32_t>> sorted(x.size());
  for (size_t i = 0; i < x.size(); ++i) sorted[i] = {cellKey(cellOf(x[i])), uint32_t(i)};
  std::sort(sorted.begin(), sorted.end());

  parallelFor(0, mesh.positions.size(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      const Eigen::Vector3f& p = mesh.positions[k];
      const Eigen::Vector3i c = cellOf(p);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      double weights = 0;
      float nearest = INFINITY;  // the fallback: the nearest in the 27 cells, within 2 R at least
      long nearestIndex = -1;
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const uint64_t key = cellKey(c + Eigen::Vector3i(dx, dy, dz));
            auto at = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(key, uint32_t(0)));
            for (; at != sorted.end() && at->first == key; ++at) {
              const float d2 = (x[at->second] - p).squaredNorm();
              if (d2 < nearest) nearest = d2, nearestIndex = long(at->second);
              if (d2 >= r2) continue;
              const double s = 1.0 - double(d2 / r2), w = s * s * s;
              sum += w * v[at->second].cast<double>();
              weights += w;
            }
          }
      if (weights > 0) mesh.velocities[k] = (sum / weights).cast<float>();
      else if (nearestIndex >= 0) mesh.velocities[k] = v[size_t(nearestIndex)];
    }
  });
}

}  // namespace surge
