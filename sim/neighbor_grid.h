// Neighbour search on a uniform grid of cells of the kernel radius or half of it (after Green's "Particle
// Simulation using CUDA" and SPlisHSPlasH's CompactNSearch). Each sort() lays the grid over the particles'
// bounding box (clipped to the domain), so a small body of fluid in a large tank costs no more than in a small
// one. Particles are sorted into cells in linear cell order (x fastest): with a counting sort over a dense array
// of cells when the box holds at most a few cells per particle, else (fluid spread thinly over a large domain)
// by sorting 64-bit cell keys and keeping only the occupied cells. The caller reorders its particle arrays by
// the sorted order so neighbours sit close in memory, and neighbour lists are built into flat arrays. A row of
// cells along x is one contiguous run of particles, so a query reads one run per row of its stencil (3 or 5
// cells a side, for cells of the radius or half of it); piling every particle into a few cells costs nothing
// beyond the neighbour pairs themselves.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/parallel.h"
#include "sim/kernels.h"
#include "sim/periodic.h"

namespace surge {

// Neighbour lists in flat arrays, one per fixed chunk of kChunk particles (so that chunks fill their arrays in
// parallel with no second pass and no copy): the neighbours of particle i are a run of chunk i / kChunk's array
// that ends at ends[i] and starts where particle i - 1's ends (or at 0 for the first particle of a chunk). The
// arrays keep their capacity from one rebuild to the next, so a step allocates nothing once warmed up.
struct NeighborLists {
  static constexpr size_t kChunk = 2048;
  std::vector<uint32_t> ends;
  std::vector<std::vector<uint32_t>> chunks;

  size_t size() const { return ends.size(); }
  // Where particle i's run starts in its chunk's array (also indexes arrays kept parallel to the lists).
  size_t start(size_t i) const { return i % kChunk ? ends[i - 1] : 0; }
  const uint32_t* begin(size_t i) const { return chunks[i / kChunk].data() + start(i); }
  const uint32_t* end(size_t i) const { return chunks[i / kChunk].data() + ends[i]; }
  size_t count(size_t i) const { return end(i) - begin(i); }
  size_t memoryBytes() const {
    size_t bytes = ends.capacity() * sizeof(uint32_t);
    for (const auto& chunk : chunks) bytes += chunk.capacity() * sizeof(uint32_t);
    return bytes;
  }
  size_t total() const {
    size_t sum = 0;
    for (size_t i = kChunk - 1; i < ends.size(); i += kChunk) sum += ends[i];
    return ends.empty() ? 0 : sum + (ends.size() % kChunk ? ends.back() : 0);
  }
};

// Sizes `perPair`, one array a chunk of `lists`, to hold a value for every neighbour pair (indexed as the lists
// are, by NeighborLists::start): the per-pair values a solver keeps beside its lists. Capacities are kept.
template <typename T>
void sizeForPairs(const NeighborLists& lists, std::vector<std::vector<T>>& perPair) {
  perPair.resize(lists.chunks.size());
  for (size_t c = 0; c < lists.chunks.size(); ++c) {
    const size_t last = std::min(lists.size(), (c + 1) * NeighborLists::kChunk) - 1;
    if (perPair[c].size() < lists.ends[last]) {
      perPair[c].reserve(lists.chunks[c].size());
      perPair[c].resize(lists.ends[last]);
    }
  }
}

template <int Dim>
class NeighborGrid {
 public:
  // The cell size the solvers use for neighbours within `radius`. With a vector filter (AVX-512 or AVX2, see
  // keepInRange) a stencil of 3 x 3 rows of cells of the radius (a block or few a row) is quicker than one of
  // 5 x 5 rows of cells of half of it (a row's set-up and its partial block cost as much as a full one).
  // Filtered one at a time, cells of half the radius read fewer candidates and win (docs/performance.md).
  static float cellSizeFor(float radius);

  // Cells of `cellSize`; positions outside [domainMin, domainMax] are clamped into the border cells.
  NeighborGrid(const Vec<Dim>& domainMin, const Vec<Dim>& domainMax, float cellSize);
  // A domain that wraps (sim/periodic.h): the grid spans each periodic axis's period and neighbours are found
  // across its seam, for positions inside the period (PeriodicDomain::wrap).
  void setPeriodic(const PeriodicDomain<Dim>& periodic) { periodic_ = periodic; }

  // Sorts the particles into cells. Afterwards sortedOrder()[k] is the input index of the k-th particle in cell
  // order; the sort is stable, so equal inputs give equal orders whatever the thread count.
  void sort(const std::vector<Vec<Dim>>& positions);
  const std::vector<uint32_t>& sortedOrder() const { return order_; }

  // For positions in the order of the last sort(): lists, for each particle, every other particle closer than
  // `radius` (one or two cell sizes), in increasing index order.
  void findNeighbors(const std::vector<Vec<Dim>>& sortedPositions, float radius, NeighborLists& lists);

  // For a point anywhere (a diffuse particle among the fluid's): visit(begin, end) for each run of slots, in the
  // last sort's order, of the cells within `radius` (one or two cell sizes) of p, a row of cells a run; the
  // caller filters the run by distance (keepInRange).
  template <typename Visit>
  void forEachCandidateRun(const Vec<Dim>& p, float radius, Visit&& visit) const {
    if (order_.empty()) return;
    const int64_t reach = static_cast<int64_t>(std::ceil(radius / cellSize_ - 1e-4f));
    const Cell cell = cellCoordinates(p);
    Cell lo = cell, hi = cell;
    for (int k = 0; k < Dim; ++k) {
      lo[k] = std::max<int64_t>(cell[k] - reach, 0);
      hi[k] = std::min<int64_t>(cell[k] + reach, resolution_[k] - 1);
    }
    const int64_t z0 = Dim == 3 ? lo[Dim - 1] : 0, z1 = Dim == 3 ? hi[Dim - 1] : 0;
    for (int64_t z = z0; z <= z1; ++z)
      for (int64_t y = lo[1]; y <= hi[1]; ++y) {
        Cell first = lo, last = hi;
        first[1] = last[1] = y;
        if constexpr (Dim == 3) first[2] = last[2] = z;
        uint32_t begin = 0, end = 0;
        slotsOfCells(linearIndex(first), linearIndex(last), begin, end);
        if (end > begin) visit(begin, end);
      }
  }

  // Cells of the last sort's box, and whether it used the sparse (sorted keys) path.
  uint64_t cellCount() const { return cellCount_; }
  size_t memoryBytes() const {
    return cellStart_.capacity() * 4 + cellKeys_.capacity() * 8 + sparseStart_.capacity() * 4 + rowStart_.capacity() * 4 +
           cellOfParticle_.capacity() * 4 + keyOfParticle_.capacity() * 8 + order_.capacity() * 4 +
           coordinates_.capacity() * 4;
  }
  bool sparse() const { return sparse_; }
  bool rowIndexed() const { return sparse_ && rowIndexed_; }

 private:
  using Cell = Eigen::Matrix<int64_t, Dim, 1>;
  Cell cellCoordinates(const Vec<Dim>& p) const;
  uint64_t linearIndex(const Cell& c) const;
  int periodicRuns(const Cell& cell, int64_t reach, uint32_t* begin, uint32_t* end, Vec<Dim>* shift) const;
  // The sorted slots [begin, end) of the cells with linear indices [first, last].
  void slotsOfCells(uint64_t first, uint64_t last, uint32_t& begin, uint32_t& end) const;

  Vec<Dim> domainMin_, domainMax_;
  PeriodicDomain<Dim> periodic_;
  float cellSize_, inverseCellSize_;
  Vec<Dim> origin_;
  Cell resolution_;
  uint64_t cellCount_ = 0;
  bool sparse_ = false;
  std::vector<uint32_t> cellStart_;    // dense: per cell, its first slot (and past the last cell, the end)
  std::vector<uint64_t> cellKeys_;     // sparse: the occupied cells' linear indices, ascending
  std::vector<uint32_t> sparseStart_;  // sparse: per occupied cell, its first slot (plus one at the end)
  std::vector<uint32_t> rowStart_;     // sparse: per row of cells along x, its first occupied cell (plus the end)
  bool rowIndexed_ = false;            // sparse: rowStart_ is built (rows within the dense budget)
  std::vector<uint32_t> cellOfParticle_;  // dense: each particle's cell
  std::vector<uint64_t> keyOfParticle_;   // sparse: each particle's 64-bit cell key
  std::vector<uint32_t> order_;
  std::vector<float> coordinates_;  // findNeighbors: the positions as Dim arrays of floats
};

// The filter of findNeighbors: writes to `out`, in increasing order, the slots j in [begin, end) other than i
// with |x_i - x_j|^2 < r2, reading positions stored as Dim arrays of n floats (all x, then all y, ...), and
// returns the new end. It may write up to kNeighborPadding entries past that end. keepInRange is the widest
// the build targets: AVX-512 (16 candidates at a time, compressed in a register), else AVX2 with FMA (8 at a
// time, packed by a table of lane orders), else keepInRangeScalar. All give the same lists, which a test checks.
constexpr size_t kNeighborPadding = 16;
template <int Dim>
uint32_t* keepInRange(const float* coordinates, size_t n, const Vec<Dim>& xi, float r2, uint32_t i, uint32_t begin,
                      uint32_t end, uint32_t* out);
template <int Dim>
uint32_t* keepInRangeScalar(const float* coordinates, size_t n, const Vec<Dim>& xi, float r2, uint32_t i,
                            uint32_t begin, uint32_t end, uint32_t* out);
#if defined(__AVX512F__)
template <int Dim>
uint32_t* keepInRangeAvx512(const float* coordinates, size_t n, const Vec<Dim>& xi, float r2, uint32_t i,
                            uint32_t begin, uint32_t end, uint32_t* out);
#endif
#if defined(__AVX2__) && defined(__FMA__)
template <int Dim>
uint32_t* keepInRangeAvx2(const float* coordinates, size_t n, const Vec<Dim>& xi, float r2, uint32_t i,
                          uint32_t begin, uint32_t end, uint32_t* out);
#endif

// Applies a permutation: values[k] = old values[order[k]], in parallel. Used to reorder every particle channel.
template <typename T>
void gatherByOrder(const std::vector<uint32_t>& order, std::vector<T>& values, std::vector<T>& scratch) {
  scratch.resize(values.size());
  parallelFor(0, values.size(), [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) scratch[k] = values[order[k]];
  });
  values.swap(scratch);
}

extern template class NeighborGrid<2>;
extern template class NeighborGrid<3>;

}  // namespace surge
