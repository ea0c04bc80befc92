// Tests of sim/tank.h: the walls stand in for the rest lattice continued beyond them, so a particle of the
// rest lattice anywhere in the tank, next to one wall, along an edge or in a corner, sees the sum of an
// interior one.
#include "sim/tank.h"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

namespace surge {
namespace {

// Lattice points h/2 + h i from the walls; a particle at offsets o of them, near the low corner and (by the
// mirror image) near the high one. The fluid's own share is the lattice inside the tank within the support;
// the walls add the rest. The particle's distances to the walls fall on nodes of the walls' tables, so the
// sums agree to float rounding (1e-5 of the interior sum), and the gradient sums to zero by symmetry.
// WCSPH's pressure continued into the walls, sum_b (g . (x_b - x_i)) grad W, must equal an interior particle's
// (-g times the lattice's second moment) too, with gravity tilted so that every moment shows; but where three
// walls reach (3D), as a corner's eighth has no moments in the tables (as at a box collider).
template <int Dim>
void checkRestLattice(const std::vector<std::array<int, Dim>>& offsets) {
  const float h = 0.05f, support = 2 * h;
  const CubicSplineKernel<Dim> kernel(support);
  const auto weight = [&](const Vec<Dim>& r) { return kernel.value(r.norm()); };
  const auto gradient = [&](const Vec<Dim>& r) -> Vec<Dim> { return kernel.gradientFactor(r.norm()) * r; };
  const Vec<Dim> lo = Vec<Dim>::Zero(), hi = Vec<Dim>::Ones();
  Vec<Dim> gravity = Vec<Dim>::Zero();
  gravity[0] = 0.3f;
  gravity[1] = -9.81f;
  if constexpr (Dim == 3) gravity[2] = 0.2f;
  const TankWalls<Dim> walls(lo, hi, h, support, weight, gradient);
  double interior = 0, unused = 0;
  latticeSums<Dim>(h, support, weight, gradient, &interior, &unused);

  for (const auto& o : offsets)
    for (int mirror = 0; mirror < 2; ++mirror) {
      Vec<Dim> p;
      std::string where = "particle";
      bool cornerReaches = Dim == 3;
      for (int k = 0; k < Dim; ++k) {
        const float fromWall = h / 2 + h * o[k];
        p[k] = mirror ? hi[k] - fromWall : lo[k] + fromWall;
        where += (k ? "," : " ") + std::to_string(o[k]);
        cornerReaches = cornerReaches && o[k] < 2;
      }
      where += mirror ? " from the high corner" : " from the low corner";
      float sum = 0;
      Vec<Dim> gradientSum = Vec<Dim>::Zero(), hydrostatic = Vec<Dim>::Zero();
      Vec<Dim> interiorHydrostatic = Vec<Dim>::Zero();
      const int cells = Dim == 3 ? 9 * 9 * 9 : 9 * 9;
      for (int cell = 0; cell < cells; ++cell) {  // offsets -4..4 on every axis
        Vec<Dim> step;
        for (int k = 0, rest = cell; k < Dim; ++k, rest /= 9) step[k] = float(rest % 9 - 4);
        const Vec<Dim> q = p + h * step;
        const Vec<Dim> continued = gravity.dot(q - p) * gradient(p - q);
        interiorHydrostatic += continued;
        if (!walls.contains(q)) continue;
        sum += weight(p - q);
        gradientSum += gradient(p - q);
        hydrostatic += continued;
      }
      walls.add(p, sum, gradientSum);
      hydrostatic += walls.hydrostaticSum(p, gravity);
      EXPECT_NEAR(sum, interior, 1e-5 * interior) << where;
      EXPECT_NEAR(gradientSum.norm(), 0.0, 1e-4 * interior / h) << where;
      if (!cornerReaches)
        EXPECT_NEAR((hydrostatic - interiorHydrostatic).norm(), 0.0, 1e-4 * interior * 9.81) << where;
    }
}

TEST(TankWalls, RestLatticeNearWallsEdgesAndCornersSeesTheInteriorSum) {
  checkRestLattice<3>({{0, 0, 0}, {1, 0, 0}, {0, 1, 2}, {1, 1, 1}, {3, 0, 5}, {5, 5, 5}, {0, 0, 4}});
}

// In 2D two walls meet at a corner and the edge table is the whole of it: every sum agrees there too.
TEST(TankWalls, RestLatticeNearWallsAndCornersSeesTheInteriorSum2d) {
  checkRestLattice<2>({{0, 0}, {1, 0}, {0, 1}, {1, 1}, {3, 0}, {5, 5}});
}

}  // namespace
}  // namespace surge
