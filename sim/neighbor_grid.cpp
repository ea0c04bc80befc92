#include "sim/neighbor_grid.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"

namespace surge {

template <int Dim>
NeighborGrid<Dim>::NeighborGrid(const Vec<Dim>& domainMin, const Vec<Dim>& domainMax, float cellSize)
    : origin_(domainMin), inverseCellSize_(1.0f / cellSize), cellSize_(cellSize) {
  size_t cells = 1;
  for (int k = 0; k < Dim; ++k) {
    resolution_[k] = std::max(1, static_cast<int>(std::ceil((domainMax[k] - domainMin[k]) / cellSize)));
    cells *= static_cast<size_t>(resolution_[k]);
  }
  cellStart_.assign(cells + 1, 0);
}

template <int Dim>
Eigen::Matrix<int, Dim, 1> NeighborGrid<Dim>::cellCoordinates(const Vec<Dim>& p) const {
  Eigen::Matrix<int, Dim, 1> c;
  for (int k = 0; k < Dim; ++k) {
    const float x = (p[k] - origin_[k]) * inverseCellSize_;
    // NaN and far-away positions land in the border cells; the solver reports them separately.
    c[k] = x >= 0.0f ? std::min(static_cast<int>(x), resolution_[k] - 1) : 0;
  }
  return c;
}

template <int Dim>
uint32_t NeighborGrid<Dim>::cellOf(const Vec<Dim>& p) const {
  const auto c = cellCoordinates(p);
  uint32_t index = 0;
  for (int k = Dim - 1; k >= 0; --k) index = index * static_cast<uint32_t>(resolution_[k]) + c[k];
  return index;
}

template <int Dim>
void NeighborGrid<Dim>::sort(const std::vector<Vec<Dim>>& positions) {
  const size_t n = positions.size();
  cellOfParticle_.resize(n);
  order_.resize(n);
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) cellOfParticle_[i] = cellOf(positions[i]);
  });
  // Counting sort: histogram, exclusive prefix sum, stable placement.
  std::fill(cellStart_.begin(), cellStart_.end(), 0);
  for (size_t i = 0; i < n; ++i) ++cellStart_[cellOfParticle_[i] + 1];
  for (size_t c = 1; c < cellStart_.size(); ++c) cellStart_[c] += cellStart_[c - 1];
  cursor_.assign(cellStart_.begin(), cellStart_.end() - 1);
  for (size_t i = 0; i < n; ++i) order_[cursor_[cellOfParticle_[i]]++] = static_cast<uint32_t>(i);
}

template <int Dim>
void NeighborGrid<Dim>::findNeighbors(const std::vector<Vec<Dim>>& x, float radius, NeighborLists& lists) const {
  const size_t n = x.size();
  const float r2 = radius * radius;
  lists.offsets.resize(n + 1);
  // Visits, for particle i, each run of sorted slots that may hold its neighbours: rows of three cells along x.
  auto forEachCandidateRange = [&](size_t i, auto&& visit) {
    const auto c = cellCoordinates(x[i]);
    const int x0 = std::max(c[0] - 1, 0), x1 = std::min(c[0] + 1, resolution_[0] - 1);
    const int y0 = std::max(c[1] - 1, 0), y1 = std::min(c[1] + 1, resolution_[1] - 1);
    int z0 = 0, z1 = 0;
    if constexpr (Dim == 3) {
      z0 = std::max(c[2] - 1, 0);
      z1 = std::min(c[2] + 1, resolution_[2] - 1);
    }
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y) {
        const size_t row = (static_cast<size_t>(z) * resolution_[1] + y) * resolution_[0];
        visit(cellStart_[row + x0], cellStart_[row + x1 + 1]);
      }
  };
  // Pass 1: count. Pass 2 (after a prefix sum): fill. Each particle writes only its own entries.
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      uint32_t count = 0;
      forEachCandidateRange(i, [&](uint32_t s0, uint32_t s1) {
        for (uint32_t j = s0; j < s1; ++j) count += (j != i) & ((x[i] - x[j]).squaredNorm() < r2);
      });
      lists.offsets[i + 1] = count;
    }
  });
  lists.offsets[0] = 0;
  for (size_t i = 0; i < n; ++i) lists.offsets[i + 1] += lists.offsets[i];
  lists.indices.resize(lists.offsets[n]);
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      uint32_t* out = lists.indices.data() + lists.offsets[i];
      forEachCandidateRange(i, [&](uint32_t s0, uint32_t s1) {
        for (uint32_t j = s0; j < s1; ++j)
          if (j != i && (x[i] - x[j]).squaredNorm() < r2) *out++ = j;
      });
    }
  });
}

template <typename T>
void gatherByOrder(const std::vector<uint32_t>& order, std::vector<T>& values, std::vector<T>& scratch) {
  scratch.resize(values.size());
  parallelFor(0, values.size(), [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) scratch[k] = values[order[k]];
  });
  values.swap(scratch);
}

template class NeighborGrid<2>;
template class NeighborGrid<3>;
template void gatherByOrder(const std::vector<uint32_t>&, std::vector<Vec<2>>&, std::vector<Vec<2>>&);
template void gatherByOrder(const std::vector<uint32_t>&, std::vector<Vec<3>>&, std::vector<Vec<3>>&);
template void gatherByOrder(const std::vector<uint32_t>&, std::vector<uint32_t>&, std::vector<uint32_t>&);

}  // namespace surge
