// Tests of sim/tank.h: the walls stand in for the rest lattice continued beyond them, so a particle of the
// rest lattice anywhere in the tank, next to one wall, along an edge or in a corner, sees the sum of an
// interior one.
#include "sim/tank.h"

#include <gtest/gtest.h>

namespace surge {
namespace {

TEST(TankWalls, RestLatticeNearWallsEdgesAndCornersSeesTheInteriorSum) {
  const float h = 0.05f, support = 2 * h;
  const CubicSplineKernel<3> kernel(support);
  const auto weight = [&](const Vec<3>& r) { return kernel.value(r.norm()); };
  const auto gradient = [&](const Vec<3>& r) -> Vec<3> { return kernel.gradientFactor(r.norm()) * r; };
  const Vec<3> lo(0, 0, 0), hi(1, 1, 1);
  const TankWalls<3> walls(lo, hi, h, support, weight, gradient);
  double interior = 0, unused = 0;
  latticeSums<3>(h, support, weight, gradient, &interior, &unused);

  // Lattice points h/2 + h i from the walls; a particle at (a, b, c) of them, near the low corner and (by the
  // mirror image) near the high one. The fluid's own share is the lattice inside the tank within the support;
  // the walls add the rest. The particle's distances to the walls fall on nodes of the walls' tables, so the
  // sums agree to float rounding (1e-5 of the interior sum), and the gradient sums to zero by symmetry.
  const int offsets[][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 2}, {1, 1, 1}, {3, 0, 5}, {5, 5, 5}};
  for (const auto& o : offsets)
    for (int mirror = 0; mirror < 2; ++mirror) {
      Vec<3> p;
      for (int k = 0; k < 3; ++k) {
        const float fromWall = h / 2 + h * o[k];
        p[k] = mirror ? hi[k] - fromWall : lo[k] + fromWall;
      }
      float sum = 0;
      Vec<3> gradientSum = Vec<3>::Zero();
      for (int i = -4; i <= 4; ++i)
        for (int j = -4; j <= 4; ++j)
          for (int k = -4; k <= 4; ++k) {
            const Vec<3> q = p + h * Vec<3>(float(i), float(j), float(k));
            if (!walls.contains(q)) continue;
            sum += weight(p - q);
            gradientSum += gradient(p - q);
          }
      walls.add(p, sum, gradientSum);
      const std::string where = "particle " + std::to_string(o[0]) + "," + std::to_string(o[1]) + "," +
                                std::to_string(o[2]) +
                                (mirror ? " from the high corner" : " from the low corner");
      EXPECT_NEAR(sum, interior, 1e-5 * interior) << where;
      EXPECT_NEAR(gradientSum.norm(), 0.0, 1e-4 * interior / h) << where;
    }
}

}  // namespace
}  // namespace surge
