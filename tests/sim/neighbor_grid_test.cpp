#include "sim/neighbor_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

#include "core/scene.h"
#include "sim/periodic.h"

namespace surge {
namespace {

// The brute-force twin: every pair closer than the radius, O(n^2).
template <int Dim>
std::vector<std::vector<uint32_t>> bruteForce(const std::vector<Vec<Dim>>& x, float radius) {
  std::vector<std::vector<uint32_t>> lists(x.size());
  for (size_t i = 0; i < x.size(); ++i)
    for (size_t j = 0; j < x.size(); ++j)
      if (i != j && (x[i] - x[j]).squaredNorm() < radius * radius) lists[i].push_back(uint32_t(j));
  return lists;
}

template <int Dim>
void expectSameAsBruteForceWithCells(std::vector<Vec<Dim>> x, const Vec<Dim>& lo, const Vec<Dim>& hi, float h,
                                     float cell) {
  NeighborGrid<Dim> grid(lo, hi, cell);
  grid.sort(x);
  std::vector<Vec<Dim>> sorted, scratch;
  sorted = x;
  gatherByOrder(grid.sortedOrder(), sorted, scratch);
  // The order is a permutation that groups cells.
  std::vector<uint32_t> order = grid.sortedOrder();
  std::sort(order.begin(), order.end());
  for (size_t i = 0; i < order.size(); ++i) ASSERT_EQ(order[i], i);

  NeighborLists lists;
  grid.findNeighbors(sorted, h, lists);
  const auto expected = bruteForce<Dim>(sorted, h);
  size_t pairs = 0;
  for (size_t i = 0; i < sorted.size(); ++i) {
    std::vector<uint32_t> got(lists.begin(i), lists.end(i));
    ASSERT_EQ(got, expected[i]) << "particle " << i;
    pairs += got.size();
  }
  EXPECT_GT(pairs, 0u);
}

// Checked with cells as wide as the radius (3 cells a side searched) and half as wide (5 a side, as both solvers
// use).
template <int Dim>
void expectSameAsBruteForce(const std::vector<Vec<Dim>>& x, const Vec<Dim>& lo, const Vec<Dim>& hi, float h) {
  for (float cell : {h, 0.5f * h}) {
    SCOPED_TRACE("cells of " + std::to_string(cell));
    expectSameAsBruteForceWithCells<Dim>(x, lo, hi, h, cell);
  }
}

TEST(NeighborGrid, MatchesBruteForceOnRandomPoints) {
  std::mt19937 random(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Vec<3>> x(3000);
  for (auto& p : x) p = Vec<3>(u(random), u(random) * 0.5f, u(random) * 0.7f);
  expectSameAsBruteForce<3>(x, Vec<3>(0, 0, 0), Vec<3>(1, 0.5f, 0.7f), 0.07f);
  std::vector<Vec<2>> y(2000);
  for (auto& p : y) p = Vec<2>(u(random) * 2, u(random));
  expectSameAsBruteForce<2>(y, Vec<2>(0, 0), Vec<2>(2, 1), 0.05f);
}

TEST(NeighborGrid, MatchesBruteForceWhenClusteredOrInOneCell) {
  std::mt19937 random(2);
  std::normal_distribution<float> n(0.0f, 0.02f);
  std::vector<Vec<3>> clustered(2000);
  for (size_t i = 0; i < clustered.size(); ++i) {
    const Vec<3> centre = i % 2 ? Vec<3>(0.1f, 0.1f, 0.1f) : Vec<3>(0.8f, 0.05f, 0.5f);
    clustered[i] = (centre + Vec<3>(n(random), n(random), n(random))).cwiseMax(0.0f).cwiseMin(1.0f);
  }
  expectSameAsBruteForce<3>(clustered, Vec<3>(0, 0, 0), Vec<3>(1, 1, 1), 0.05f);

  std::uniform_real_distribution<float> u(0.0f, 0.04f);
  std::vector<Vec<3>> oneCell(500);
  for (auto& p : oneCell) p = Vec<3>(0.5f + u(random), 0.5f + u(random), 0.5f + u(random));
  expectSameAsBruteForce<3>(oneCell, Vec<3>(0, 0, 0), Vec<3>(1, 1, 1), 0.05f);
}

TEST(NeighborGrid, PointsOnAndBeyondTheBorderAreClampedIntoCells) {
  std::vector<Vec<2>> x = {{0, 0}, {1, 1}, {1.02f, 1.0f}, {-0.01f, 0.0f}, {0.5f, 0.5f}};
  expectSameAsBruteForce<2>(x, Vec<2>(0, 0), Vec<2>(1, 1), 0.1f);
}

}  // namespace
}  // namespace surge

namespace surge {
namespace {

TEST(NeighborGrid, SparsePathInALargeDomainMatchesBruteForce) {
  // 2000 particles in two small clumps at opposite corners of a 100 m tank with 5 cm cells: the box of the
  // particles spans 8e9 cells, so the grid keeps only the occupied ones.
  std::mt19937 random(4);
  std::uniform_real_distribution<float> u(0.0f, 0.3f);
  std::vector<Vec<3>> x(2000);
  for (size_t i = 0; i < x.size(); ++i) {
    const Vec<3> corner = i % 2 ? Vec<3>(1, 1, 1) : Vec<3>(98, 97, 96);
    x[i] = corner + Vec<3>(u(random), u(random), u(random));
  }
  NeighborGrid<3> grid(Vec<3>(0, 0, 0), Vec<3>(100, 100, 100), 0.05f);
  grid.sort(x);
  EXPECT_TRUE(grid.sparse());
  expectSameAsBruteForce<3>(x, Vec<3>(0, 0, 0), Vec<3>(100, 100, 100), 0.05f);
}

TEST(NeighborGrid, SparsePathWithARowIndexMatchesBruteForce) {
  // 3000 particles in clumps strung along a tank 40 m long, 1 m wide and deep, with 1 cm cells: 40 million cells
  // in the particles' box (sparse), in 10,000 rows along x (indexed).
  std::mt19937 random(6);
  std::uniform_real_distribution<float> u(0.0f, 0.05f);
  std::vector<Vec<3>> x(3000);
  for (size_t i = 0; i < x.size(); ++i) {
    const float along = float(i % 30) * 1.33f, across = float(i % 7) * 0.14f;
    x[i] = Vec<3>(along, across, 0.95f - across) + Vec<3>(u(random), u(random), u(random));
  }
  x[0] = Vec<3>(0, 0, 0);
  x[1] = Vec<3>(40, 1, 1);
  NeighborGrid<3> grid(Vec<3>(0, 0, 0), Vec<3>(40, 1, 1), 0.01f);
  grid.sort(x);
  EXPECT_TRUE(grid.rowIndexed());
  expectSameAsBruteForce<3>(x, Vec<3>(0, 0, 0), Vec<3>(40, 1, 1), 0.01f);
}

// Every vector filter the build has (keepInRange is the widest of them) keeps exactly what the scalar one keeps, over runs
// of every length from 0 to 40 (partial, whole and several blocks of 16), with the particle itself inside,
// first, last or outside the run, on a lattice whose spacing is half the radius, so that many pairs sit at the
// radius to within rounding.
template <int Dim>
void expectFiltersAgree() {
  const float h = 0.04f;
  std::mt19937 random(9);
  std::uniform_real_distribution<float> jitter(-1e-6f, 1e-6f);
  const size_t n = 400;
  std::vector<float> coordinates(Dim * n);
  for (size_t j = 0; j < n; ++j)
    for (int k = 0; k < Dim; ++k) coordinates[k * n + j] = 0.5f * h * float((j >> (3 * k)) % 8) + jitter(random);
  size_t kept = 0;
  for (uint32_t begin = 0; begin < 120; begin += 7)
    for (uint32_t length = 0; length <= 40; ++length)
      for (uint32_t i : {begin, begin + length / 2, begin + length - 1, begin + length + 3}) {
        if (i >= n) continue;  // begin + length - 1 with begin = length = 0
        Vec<Dim> xi;
        for (int k = 0; k < Dim; ++k) xi[k] = coordinates[k * n + i];
        auto keep = [&](auto filter) {
          std::vector<uint32_t> slots(length + kNeighborPadding);
          slots.resize(filter(coordinates.data(), n, xi, h * h, i, begin, begin + length, slots.data()) - slots.data());
          return slots;
        };
        const std::vector<uint32_t> scalar = keep(keepInRangeScalar<Dim>);
        ASSERT_EQ(keep(keepInRange<Dim>), scalar) << "run " << begin << " + " << length << ", particle " << i;
#if defined(__AVX512F__)
        ASSERT_EQ(keep(keepInRangeAvx512<Dim>), scalar) << "AVX-512, run " << begin << " + " << length << ", particle " << i;
#endif
#if defined(__AVX2__) && defined(__FMA__)
        ASSERT_EQ(keep(keepInRangeAvx2<Dim>), scalar) << "AVX2, run " << begin << " + " << length << ", particle " << i;
#endif
        kept += scalar.size();
      }
  EXPECT_GT(kept, 1000u);
}

TEST(NeighborGrid, VectorFilterKeepsWhatTheScalarOneKeeps) {
  expectFiltersAgree<2>();
  expectFiltersAgree<3>();
}

TEST(NeighborGrid, DenseGridCoversOnlyTheParticlesBox) {
  // A clump in the corner of a large tank costs cells for the clump only.
  std::mt19937 random(5);
  std::uniform_real_distribution<float> u(0.0f, 0.5f);
  std::vector<Vec<3>> x(5000);
  for (auto& p : x) p = Vec<3>(u(random), u(random), u(random));
  NeighborGrid<3> grid(Vec<3>(0, 0, 0), Vec<3>(50, 50, 50), 0.05f);
  grid.sort(x);
  EXPECT_FALSE(grid.sparse());
  EXPECT_LE(grid.cellCount(), 11u * 11u * 11u);
}

// A domain that wraps: every pair closer than the radius through the nearest image, found across the seams, for
// radii that leave the last cell of a period wider than the others (the period is not a whole number of cells).
template <int Dim>
void expectPeriodicSameAsBruteForce(const std::string& domain, float radius, size_t count) {
  const std::string corner = Dim == 2 ? "[0.1, 0.1]" : "[0.1, 0.1, 0.1]", origin = Dim == 2 ? "[0, 0]" : "[0, 0, 0]";
  const Scene scene = parseScene(R"({"name": "p", "dimensions": )" + std::to_string(Dim) + R"(, "domain": )" + domain +
                                     R"(, "particle_spacing": 0.01, "fluids": [{"box": {"min": )" + origin +
                                     R"(, "max": )" + corner + "}}]}",
                                 "test");
  const PeriodicDomain<Dim> periodic(scene);
  const Vec<Dim> lo = toVec<Dim>(scene.domain.min), hi = toVec<Dim>(scene.domain.max);
  std::mt19937 random(7);
  std::vector<Vec<Dim>> x(count);
  for (auto& p : x)
    for (int k = 0; k < Dim; ++k) p[k] = std::uniform_real_distribution<float>(lo[k], hi[k])(random);
  for (float cell : {radius, 0.5f * radius}) {
    SCOPED_TRACE("radius " + std::to_string(radius) + ", cells of " + std::to_string(cell));
    NeighborGrid<Dim> grid(lo, hi, cell);
    grid.setPeriodic(periodic);
    grid.sort(x);
    std::vector<Vec<Dim>> sorted = x, scratch;
    gatherByOrder(grid.sortedOrder(), sorted, scratch);
    NeighborLists lists;
    grid.findNeighbors(sorted, radius, lists);
    for (size_t i = 0; i < sorted.size(); ++i) {
      std::vector<uint32_t> expected;
      for (size_t j = 0; j < sorted.size(); ++j) {
        Vec<Dim> r = sorted[i] - sorted[j];
        for (int k = 0; k < Dim; ++k) r[k] = periodic.component(k, r[k]);
        if (i != j && r.squaredNorm() < radius * radius) expected.push_back(uint32_t(j));
      }
      std::vector<uint32_t> got(lists.begin(i), lists.end(i));
      std::sort(got.begin(), got.end());
      ASSERT_EQ(got, expected) << "particle " << i << " at " << sorted[i].transpose();
    }
  }
}

TEST(NeighborGrid, PeriodicAxesMatchBruteForceAcrossTheSeams) {
  for (float radius : {0.0583333f, 0.0675f, 0.1075f})
    expectPeriodicSameAsBruteForce<2>(R"({"min": [0, 0], "max": [1, 1], "periodic": ["x", "y"]})", radius, 3000);
  expectPeriodicSameAsBruteForce<3>(R"({"min": [0, 0, 0], "max": [0.5, 0.4, 0.3], "periodic": ["x", "z"]})", 0.07f,
                                    3000);
}

}  // namespace
}  // namespace surge
