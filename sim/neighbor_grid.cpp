#include "sim/neighbor_grid.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#if defined(__AVX2__) || defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "core/parallel.h"

namespace surge {
namespace {

// A dense cell array is used while the box holds at most this many cells per particle, or at most
// kDenseCellsAlways cells (16 MB of starts): a dam break of 64,000 particles splashed over its 4 x 3 x 1.5 m tank
// has 18 cells a particle, and searching its occupied cells cost 40% of a DFSPH step.
constexpr uint64_t kDenseCellsPerParticle = 8;
constexpr uint64_t kDenseCellsMinimum = 1 << 16;
constexpr uint64_t kDenseCellsAlways = 1 << 22;

}  // namespace

// kNeighborPadding and the filters are declared in the header. The squared distance is summed in one fixed
// order with fused multiply-adds on every path, so the lists are the same whichever a build uses.
template <int Dim>
uint32_t* keepInRangeScalar(const float* coordinates, size_t n, const Vec<Dim>& xi, float r2, uint32_t i,
                            uint32_t begin, uint32_t end, uint32_t* out) {
  for (uint32_t j = begin; j < end; ++j) {
    const float d0 = xi[0] - coordinates[j], d1 = xi[1] - coordinates[n + j];
    float length2 = std::fma(d1, d1, d0 * d0);
    if constexpr (Dim == 3) {
      const float d2 = xi[2] - coordinates[2 * n + j];
      length2 = std::fma(d2, d2, length2);
    }
    *out = j;
    out += (length2 < r2) & (j != i);
  }
  return out;
}

// A stencil row holds a few dozen particles at most; a scalar loop over them mispredicts the end of almost every
// row, where vector lanes take a row in a block or two.
#if defined(__AVX512F__)
template <int Dim>
uint32_t* keepInRangeAvx512(const float* coordinates, size_t n, const Vec<Dim>& xi, float r2, uint32_t i,
                            uint32_t begin, uint32_t end, uint32_t* out) {
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const __m512 radius2 = _mm512_set1_ps(r2);
  for (uint32_t j = begin; j < end; j += 16) {
    const uint32_t count = std::min<uint32_t>(16, end - j);
    const __mmask16 valid = static_cast<__mmask16>((1u << count) - 1u);
    const __m512 d0 = _mm512_sub_ps(_mm512_set1_ps(xi[0]), _mm512_maskz_loadu_ps(valid, coordinates + j));
    const __m512 d1 = _mm512_sub_ps(_mm512_set1_ps(xi[1]), _mm512_maskz_loadu_ps(valid, coordinates + n + j));
    __m512 length2 = _mm512_fmadd_ps(d1, d1, _mm512_mul_ps(d0, d0));
    if constexpr (Dim == 3) {
      const __m512 d2 = _mm512_sub_ps(_mm512_set1_ps(xi[2]), _mm512_maskz_loadu_ps(valid, coordinates + 2 * n + j));
      length2 = _mm512_fmadd_ps(d2, d2, length2);
    }
    const uint32_t self = i - j < 16 ? 1u << (i - j) : 0u;
    const __mmask16 keep =
        static_cast<__mmask16>(_mm512_mask_cmp_ps_mask(valid, length2, radius2, _CMP_LT_OQ) & ~self);
    // Compressed in a register and stored whole: a compressing store to memory is slow on some CPUs.
    const __m512i slots = _mm512_add_epi32(_mm512_set1_epi32(static_cast<int>(j)), lane);
    _mm512_storeu_si512(out, _mm512_maskz_compress_epi32(keep, slots));
    out += __builtin_popcount(keep);
  }
  return out;
}
#endif

#if defined(__AVX2__) && defined(__FMA__)
namespace {
// For each 8-bit mask of kept lanes, the lanes in order, packed to the front (AVX2 has no compress).
struct CompressTable {
  uint8_t lanes[256][8] = {};
  constexpr CompressTable() {
    for (int mask = 0; mask < 256; ++mask) {
      int k = 0;
      for (int lane = 0; lane < 8; ++lane)
        if (mask & (1 << lane)) lanes[mask][k++] = static_cast<uint8_t>(lane);
    }
  }
};
constexpr CompressTable kCompressTable;
}  // namespace

template <int Dim>
uint32_t* keepInRangeAvx2(const float* coordinates, size_t n, const Vec<Dim>& xi, float r2, uint32_t i,
                          uint32_t begin, uint32_t end, uint32_t* out) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 radius2 = _mm256_set1_ps(r2);
  for (uint32_t j = begin; j < end; j += 8) {
    const int count = static_cast<int>(std::min<uint32_t>(8, end - j));
    const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(count), lane);  // masked loads do not fault
    const __m256 d0 = _mm256_sub_ps(_mm256_set1_ps(xi[0]), _mm256_maskload_ps(coordinates + j, valid));
    const __m256 d1 = _mm256_sub_ps(_mm256_set1_ps(xi[1]), _mm256_maskload_ps(coordinates + n + j, valid));
    __m256 length2 = _mm256_fmadd_ps(d1, d1, _mm256_mul_ps(d0, d0));
    if constexpr (Dim == 3) {
      const __m256 d2 = _mm256_sub_ps(_mm256_set1_ps(xi[2]), _mm256_maskload_ps(coordinates + 2 * n + j, valid));
      length2 = _mm256_fmadd_ps(d2, d2, length2);
    }
    const uint32_t self = i - j < 8 ? 1u << (i - j) : 0u;
    const uint32_t keep = static_cast<uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(length2, radius2, _CMP_LT_OQ))) &
                          ((1u << count) - 1u) & ~self;
    const __m256i order = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(kCompressTable.lanes[keep])));
    const __m256i slots = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(j)), lane);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm256_permutevar8x32_epi32(slots, order));
    out += __builtin_popcount(keep);
  }
  return out;
}
#endif

template <int Dim>
uint32_t* keepInRange(const float* coordinates, size_t n, const Vec<Dim>& xi, float r2, uint32_t i, uint32_t begin,
                      uint32_t end, uint32_t* out) {
#if defined(__AVX512F__)
  return keepInRangeAvx512<Dim>(coordinates, n, xi, r2, i, begin, end, out);
#elif defined(__AVX2__) && defined(__FMA__)
  return keepInRangeAvx2<Dim>(coordinates, n, xi, r2, i, begin, end, out);
#else
  return keepInRangeScalar<Dim>(coordinates, n, xi, r2, i, begin, end, out);
#endif
}

template <int Dim>
float NeighborGrid<Dim>::cellSizeFor(float radius) {
#if defined(__AVX512F__) || (defined(__AVX2__) && defined(__FMA__))
  return radius;
#else
  return 0.5f * radius;
#endif
}

template <int Dim>
NeighborGrid<Dim>::NeighborGrid(const Vec<Dim>& domainMin, const Vec<Dim>& domainMax, float cellSize)
    : domainMin_(domainMin), domainMax_(domainMax), cellSize_(cellSize), inverseCellSize_(1.0f / cellSize) {}

template <int Dim>
typename NeighborGrid<Dim>::Cell NeighborGrid<Dim>::cellCoordinates(const Vec<Dim>& p) const {
  Cell c;
  for (int k = 0; k < Dim; ++k) {
    const float x = (p[k] - origin_[k]) * inverseCellSize_;
    // NaN and far-away positions land in the border cells; the solver reports them separately.
    c[k] = x >= 0.0f ? std::min(static_cast<int64_t>(std::min(x, 4e18f)), resolution_[k] - 1) : 0;
  }
  return c;
}

template <int Dim>
uint64_t NeighborGrid<Dim>::linearIndex(const Cell& c) const {
  uint64_t index = 0;
  for (int k = Dim - 1; k >= 0; --k) index = index * static_cast<uint64_t>(resolution_[k]) + c[k];
  return index;
}

template <int Dim>
void NeighborGrid<Dim>::sort(const std::vector<Vec<Dim>>& positions) {
  const size_t n = positions.size();
  // The box of the particles, clipped to the domain (NaN compares false and is skipped).
  struct Bounds {
    Vec<Dim> lo = Vec<Dim>::Constant(INFINITY), hi = Vec<Dim>::Constant(-INFINITY);
    Bounds& operator+=(const Bounds& o) {
      lo = lo.cwiseMin(o.lo);
      hi = hi.cwiseMax(o.hi);
      return *this;
    }
  };
  Bounds box = parallelSum<Bounds>(0, n, [&](size_t b, size_t e) {
    Bounds local;
    for (size_t i = b; i < e; ++i)
      for (int k = 0; k < Dim; ++k) {
        if (positions[i][k] < local.lo[k]) local.lo[k] = positions[i][k];
        if (positions[i][k] > local.hi[k]) local.hi[k] = positions[i][k];
      }
    return local;
  });
  uint64_t cells = 1;
  for (int k = 0; k < Dim; ++k) {
    if (periodic_.periodic(k)) {  // the whole period, whatever the particles' box; the last cell takes the rest
      origin_[k] = periodic_.min(k);
      resolution_[k] = std::max<int64_t>(1, static_cast<int64_t>(std::floor(periodic_.period(k) * inverseCellSize_)));
      cells *= static_cast<uint64_t>(resolution_[k]);
      continue;
    }
    const float lo = std::clamp(box.lo[k], domainMin_[k], domainMax_[k]);
    const float hi = std::clamp(box.hi[k], lo, domainMax_[k]);
    origin_[k] = n ? lo : domainMin_[k];
    resolution_[k] = std::max<int64_t>(1, static_cast<int64_t>(std::floor((hi - lo) * inverseCellSize_)) + 1);
    cells *= static_cast<uint64_t>(resolution_[k]);
  }
  cellCount_ = cells;
  sparse_ = cells > std::max({kDenseCellsMinimum, kDenseCellsAlways, kDenseCellsPerParticle * n}) ||
            cells >= (uint64_t(1) << 32);

  order_.resize(n);
  if (!sparse_) {
    // Counting sort: cell of each particle, histogram, exclusive prefix sum, stable placement.
    keyOfParticle_.clear();
    keyOfParticle_.shrink_to_fit();
    cellOfParticle_.resize(n);
    parallelFor(0, n, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) cellOfParticle_[i] = static_cast<uint32_t>(linearIndex(cellCoordinates(positions[i])));
    });
    // Counts go two places up, so that after the prefix sum cellStart_[c + 1] is where cell c starts; placing
    // the particles advances it to where cell c ends, which is where cell c + 1 starts: the array ends up as
    // the cells' starts with no second cursor array.
    cellStart_.assign(cells + 2, 0);
    for (size_t i = 0; i < n; ++i) ++cellStart_[cellOfParticle_[i] + 2];
    for (size_t c = 2; c < cellStart_.size(); ++c) cellStart_[c] += cellStart_[c - 1];
    for (size_t i = 0; i < n; ++i) order_[cellStart_[cellOfParticle_[i] + 1]++] = static_cast<uint32_t>(i);
    return;
  }
  cellOfParticle_.clear();
  cellOfParticle_.shrink_to_fit();
  keyOfParticle_.resize(n);
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) keyOfParticle_[i] = linearIndex(cellCoordinates(positions[i]));
  });
  // Sparse: sort (key, index) pairs, which are unique, so the result does not depend on the threads.
  for (size_t i = 0; i < n; ++i) order_[i] = static_cast<uint32_t>(i);
  tbb::parallel_sort(order_.begin(), order_.end(), [&](uint32_t a, uint32_t b) {
    return keyOfParticle_[a] != keyOfParticle_[b] ? keyOfParticle_[a] < keyOfParticle_[b] : a < b;
  });
  cellKeys_.clear();
  sparseStart_.clear();
  for (size_t k = 0; k < n; ++k) {
    const uint64_t key = keyOfParticle_[order_[k]];
    if (cellKeys_.empty() || cellKeys_.back() != key) {
      cellKeys_.push_back(key);
      sparseStart_.push_back(static_cast<uint32_t>(k));
    }
  }
  sparseStart_.push_back(static_cast<uint32_t>(n));
  // The row index: where each row of cells along x starts among the occupied cells, so that a query searches
  // the few occupied cells of its row instead of all of them (a dam break spread over its tank spent 55 ms a
  // step of 64,000 particles in those searches). Kept within the dense path's budget of entries.
  const uint64_t rows = cells / static_cast<uint64_t>(resolution_[0]);
  rowIndexed_ = rows <= std::max<uint64_t>(kDenseCellsMinimum, kDenseCellsPerParticle * n);
  if (!rowIndexed_) {
    rowStart_.clear();
    return;
  }
  rowStart_.resize(rows + 1);
  size_t k = 0;
  for (uint64_t row = 0; row <= rows; ++row) {
    while (k < cellKeys_.size() && cellKeys_[k] / static_cast<uint64_t>(resolution_[0]) < row) ++k;
    rowStart_[row] = static_cast<uint32_t>(k);
  }
}

template <int Dim>
void NeighborGrid<Dim>::slotsOfCells(uint64_t first, uint64_t last, uint32_t& begin, uint32_t& end) const {
  if (!sparse_) {
    begin = cellStart_[first];
    end = cellStart_[last + 1];
    return;
  }
  // first and last lie in one row of cells along x.
  auto rowBegin = cellKeys_.begin(), rowEnd = cellKeys_.end();
  if (rowIndexed_) {
    const uint64_t row = first / static_cast<uint64_t>(resolution_[0]);
    rowBegin = cellKeys_.begin() + rowStart_[row];
    rowEnd = cellKeys_.begin() + rowStart_[row + 1];
  }
  const auto lo = std::lower_bound(rowBegin, rowEnd, first);
  const auto hi = std::upper_bound(lo, rowEnd, last);
  begin = sparseStart_[lo - cellKeys_.begin()];
  end = sparseStart_[hi - cellKeys_.begin()];
}

template <int Dim>
void NeighborGrid<Dim>::findNeighbors(const std::vector<Vec<Dim>>& x, float radius, NeighborLists& lists) {
  const size_t n = x.size();
  const float r2 = radius * radius;
  // Cells of the radius are searched one cell out, cells of half of it two (see cellSizeFor).
  const int64_t reach = static_cast<int64_t>(std::ceil(radius / cellSize_ - 1e-4f));
  if (reach < 1 || reach > 2) throw std::invalid_argument("NeighborGrid: radius must be 1 or 2 cells");
  constexpr size_t kChunk = NeighborLists::kChunk;
  const size_t chunks = (n + kChunk - 1) / kChunk;
  lists.ends.resize(n);
  lists.chunks.resize(chunks);
  // The positions as Dim arrays of floats (x of every particle, then y, ...) for the filter's vector loads.
  coordinates_.resize(Dim * n);
  float* coordinates = coordinates_.data();
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t j = b; j < e; ++j)
      for (int k = 0; k < Dim; ++k) coordinates[k * n + j] = x[j][k];
  });
  parallelFor(
      0, chunks,
      [&](size_t c0, size_t c1) {
        for (size_t c = c0; c < c1; ++c) {
          // The chunk's vector only grows (its size is its usable room); `used` counts what is filled.
          std::vector<uint32_t>& chunk = lists.chunks[c];
          size_t used = 0;
          // The stencil's rows of candidates, kept while the particles (sorted by cell) stay in one cell.
          constexpr int kRows = Dim == 3 ? 25 : 5;  // rows of a stencil of reach 2
          uint32_t rowBegin[2 * kRows], rowEnd[2 * kRows];  // a periodic row may split in two at the seam
          Vec<Dim> rowShift[2 * kRows];                      // periodic: the image of the row's cells
          int rows = 0;
          size_t candidates = 0;
          Cell rowsCell;
          rowsCell.fill(-1);
          for (size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
            const Vec<Dim> xi = x[i];
            const Cell cell = cellCoordinates(xi);
            if (cell != rowsCell && periodic_.active()) {
              rowsCell = cell;
              rows = periodicRuns(cell, reach, rowBegin, rowEnd, rowShift);
              candidates = 0;
              for (int row = 0; row < rows; ++row) candidates += rowEnd[row] - rowBegin[row];
            } else if (cell != rowsCell) {
              rowsCell = cell;
              Cell lo = cell, hi = cell;
              for (int k = 0; k < Dim; ++k) {
                lo[k] = std::max<int64_t>(cell[k] - reach, 0);
                hi[k] = std::min<int64_t>(cell[k] + reach, resolution_[k] - 1);
              }
              rows = 0;
              candidates = 0;
              const int64_t z0 = Dim == 3 ? lo[Dim - 1] : 0, z1 = Dim == 3 ? hi[Dim - 1] : 0;
              for (int64_t z = z0; z <= z1; ++z)
                for (int64_t y = lo[1]; y <= hi[1]; ++y, ++rows) {
                  Cell first = lo, last = hi;
                  first[1] = last[1] = y;
                  if constexpr (Dim == 3) first[2] = last[2] = z;
                  slotsOfCells(linearIndex(first), linearIndex(last), rowBegin[rows], rowEnd[rows]);
                  candidates += rowEnd[rows] - rowBegin[rows];
                }
            }
            // Room for every candidate, then keep those in range: no capacity check per neighbour.
            if (chunk.size() < used + candidates + kNeighborPadding) {
              // Grow to what the whole chunk will likely need (the mean so far times the chunk, plus a tenth),
              // exactly: resize() alone would double.
              const size_t done = i - c * kChunk;  // particles of this chunk already listed
              const size_t expected = done ? used * kChunk / done : 0;
              const size_t room = std::max(used, expected + expected / 10) + candidates + kNeighborPadding;
              chunk.reserve(room);
              chunk.resize(room);
            }
            uint32_t* out = chunk.data() + used;
            if (periodic_.active()) {
              for (int row = 0; row < rows; ++row)
                out = keepInRange<Dim>(coordinates, n, xi - rowShift[row], r2, static_cast<uint32_t>(i), rowBegin[row],
                                       rowEnd[row], out);
            } else {
              for (int row = 0; row < rows; ++row)
                out = keepInRange<Dim>(coordinates, n, xi, r2, static_cast<uint32_t>(i), rowBegin[row], rowEnd[row], out);
            }
            used = static_cast<size_t>(out - chunk.data());
            lists.ends[i] = static_cast<uint32_t>(used);
          }
        }
      },
      1);
}

// The stencil of `cell` in a domain that wraps: for each row of cells along x within `reach`, the runs of slots
// of its cells, a row split in two where it crosses the seam along x, each with the shift of its cells' image
// near the cell (a whole period where the stencil wrapped). The runs come in increasing slot order, so the lists
// stay in increasing index order. resolution_ >= 2 reach + 1 on a periodic axis, so no cell comes twice.
template <int Dim>
int NeighborGrid<Dim>::periodicRuns(const Cell& cell, int64_t reach, uint32_t* begin, uint32_t* end,
                                    Vec<Dim>* shift) const {
  // Along axis k, the stencil's cells as (first, last, image shift) segments of cells that do not wrap inside.
  struct Segment {
    int64_t first, last;
    float shift;
  };
  auto segments = [&](int k, Segment* out) {
    const int64_t lo = cell[k] - reach, hi = cell[k] + reach, res = resolution_[k];
    if (!periodic_.periodic(k)) {
      out[0] = {std::max<int64_t>(lo, 0), std::min<int64_t>(hi, res - 1), 0.0f};
      return 1;
    }
    int count = 0;
    const float period = periodic_.period(k);
    if (lo < 0) out[count++] = {lo + res, res - 1, -period};
    out[count++] = {std::max<int64_t>(lo, 0), std::min<int64_t>(hi, res - 1), 0.0f};
    if (hi >= res) out[count++] = {0, hi - res, period};
    return count;
  };
  Segment xs[3];
  const int xCount = segments(0, xs);
  int runs = 0;
  auto addRows = [&](int64_t y, float yShift, int64_t z, float zShift) {
    for (int a = 0; a < xCount; ++a) {
      Cell first = cell, last = cell;
      first[0] = xs[a].first;
      last[0] = xs[a].last;
      first[1] = last[1] = y;
      if constexpr (Dim == 3) first[2] = last[2] = z;
      slotsOfCells(linearIndex(first), linearIndex(last), begin[runs], end[runs]);
      if (end[runs] == begin[runs]) continue;
      shift[runs] = Vec<Dim>::Zero();
      shift[runs][0] = xs[a].shift;
      shift[runs][1] = yShift;
      if constexpr (Dim == 3) shift[runs][2] = zShift;
      ++runs;
    }
  };
  Segment ys[3];
  const int yCount = segments(1, ys);
  auto addPlane = [&](int64_t z, float zShift) {
    for (int b = 0; b < yCount; ++b)
      for (int64_t y = ys[b].first; y <= ys[b].last; ++y) addRows(y, ys[b].shift, z, zShift);
  };
  if constexpr (Dim == 3) {
    Segment zs[3];
    const int zCount = segments(2, zs);
    for (int c = 0; c < zCount; ++c)
      for (int64_t z = zs[c].first; z <= zs[c].last; ++z) addPlane(z, zs[c].shift);
  } else {
    addPlane(0, 0.0f);
  }
  // Increasing slot order (the runs are disjoint): a few dozen at most, sorted by insertion.
  for (int a = 1; a < runs; ++a)
    for (int b = a; b > 0 && begin[b] < begin[b - 1]; --b) {
      std::swap(begin[b], begin[b - 1]);
      std::swap(end[b], end[b - 1]);
      std::swap(shift[b], shift[b - 1]);
    }
  return runs;
}

template class NeighborGrid<2>;
template class NeighborGrid<3>;
template uint32_t* keepInRange<2>(const float*, size_t, const Vec<2>&, float, uint32_t, uint32_t, uint32_t, uint32_t*);
template uint32_t* keepInRange<3>(const float*, size_t, const Vec<3>&, float, uint32_t, uint32_t, uint32_t, uint32_t*);
template uint32_t* keepInRangeScalar<2>(const float*, size_t, const Vec<2>&, float, uint32_t, uint32_t, uint32_t,
                                        uint32_t*);
template uint32_t* keepInRangeScalar<3>(const float*, size_t, const Vec<3>&, float, uint32_t, uint32_t, uint32_t,
                                        uint32_t*);
#if defined(__AVX512F__)
template uint32_t* keepInRangeAvx512<2>(const float*, size_t, const Vec<2>&, float, uint32_t, uint32_t, uint32_t,
                                        uint32_t*);
template uint32_t* keepInRangeAvx512<3>(const float*, size_t, const Vec<3>&, float, uint32_t, uint32_t, uint32_t,
                                        uint32_t*);
#endif
#if defined(__AVX2__) && defined(__FMA__)
template uint32_t* keepInRangeAvx2<2>(const float*, size_t, const Vec<2>&, float, uint32_t, uint32_t, uint32_t,
                                      uint32_t*);
template uint32_t* keepInRangeAvx2<3>(const float*, size_t, const Vec<3>&, float, uint32_t, uint32_t, uint32_t,
                                      uint32_t*);
#endif

}  // namespace surge
