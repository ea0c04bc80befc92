// Neighbour search on a uniform grid of cells the size of the kernel radius (after Green's "Particle
// Simulation using CUDA" and SPlisHSPlasH's CompactNSearch): particles are sorted into cells with a counting
// sort in linear cell order (x fastest), the caller reorders its particle arrays by that order so neighbours
// sit close in memory, and neighbour lists are built into flat arrays. A cell's particles are contiguous, and so
// are the particles of a row of three cells along x, so a query reads 3 ranges in 2D and 9 in 3D. Piling
// every particle into a few cells costs nothing extra beyond the neighbour pairs themselves.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/kernels.h"

namespace surge {

// Neighbour lists in flat arrays: the neighbours of particle i are indices[offsets[i] .. offsets[i + 1]).
struct NeighborLists {
  std::vector<uint32_t> offsets;
  std::vector<uint32_t> indices;

  size_t count(size_t i) const { return offsets[i + 1] - offsets[i]; }
  const uint32_t* begin(size_t i) const { return indices.data() + offsets[i]; }
  const uint32_t* end(size_t i) const { return indices.data() + offsets[i + 1]; }
};

template <int Dim>
class NeighborGrid {
 public:
  // Cells cover [domainMin, domainMax] (positions outside are clamped into the border cells).
  NeighborGrid(const Vec<Dim>& domainMin, const Vec<Dim>& domainMax, float cellSize);

  // Sorts the particles into cells. Afterwards sortedOrder()[k] is the input index of the k-th particle in cell
  // order; the sort is stable, so equal inputs give equal orders whatever the thread count.
  void sort(const std::vector<Vec<Dim>>& positions);
  const std::vector<uint32_t>& sortedOrder() const { return order_; }

  // For positions already in the order of the last sort(): lists, for each particle, every other particle
  // closer than `radius` (which must not exceed the cell size), in increasing index order.
  void findNeighbors(const std::vector<Vec<Dim>>& sortedPositions, float radius, NeighborLists& lists) const;

  size_t cellCount() const { return cellStart_.size() - 1; }

 private:
  uint32_t cellOf(const Vec<Dim>& p) const;
  Eigen::Matrix<int, Dim, 1> cellCoordinates(const Vec<Dim>& p) const;

  Vec<Dim> origin_;
  float inverseCellSize_;
  float cellSize_;
  Eigen::Matrix<int, Dim, 1> resolution_;
  std::vector<uint32_t> cellStart_;  // per cell, the first sorted slot; one extra entry at the end
  std::vector<uint32_t> cellOfParticle_;
  std::vector<uint32_t> order_;
  std::vector<uint32_t> cursor_;  // counting-sort scratch
};

// Applies a permutation: out[k] = in[order[k]], in parallel. Used to reorder every particle channel.
template <typename T>
void gatherByOrder(const std::vector<uint32_t>& order, std::vector<T>& values, std::vector<T>& scratch);

extern template class NeighborGrid<2>;
extern template class NeighborGrid<3>;

}  // namespace surge
