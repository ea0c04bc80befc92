// The hydrostatic-column check that WCSPH's and DFSPH's tests share: a 2D column 0.4 m deep at spacing 0.02,
// sampled in layers one spacing thick, whose pressure must be rho_0 g d below the surface.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>
#include <vector>

#include "sim/kernels.h"

namespace surge {

struct ColumnSamples {
  std::map<int, std::pair<double, int>> layers;  // per layer one spacing thick: pressure sum, samples
  float top = 0;
  double speedSquaredSum = 0;
  size_t speedSamples = 0;

  void add(const std::vector<Vec<2>>& positions, const std::vector<Vec<2>>& velocities,
           const std::vector<float>& pressures) {
    for (size_t i = 0; i < positions.size(); ++i) {
      auto& layer = layers[static_cast<int>(positions[i].y() / 0.02f)];
      layer.first += pressures[i];
      layer.second += 1;
      top = std::max(top, positions[i].y());
      speedSquaredSum += velocities[i].squaredNorm();
      ++speedSamples;
    }
  }
};

// Expected deviations from rho_0 g d (d below the surface, half a spacing above the top particle):
// (1) the surface is diffuse over one kernel support H (0.04 m by default: particles there miss neighbours above
// and their pressure is clamped at 0), shifting pressures by up to rho_0 g H / 2 (200 Pa); (2) compressibility:
// WCSPH's column is compressed by g d / c^2 (0.01% at c = 44 m/s), negligible, and DFSPH's by its solver's
// limit; (3) pressure noise, averaged over 15 particles and 20 samples a layer. So each layer from 2 H below the
// surface down to the rows the floor's wall table reaches (H less a spacing: the floor row at the default) must
// be within 10% + rho_0 g H / 2.
// Holding still: the root-mean-square speed is under 3% of the speed of a fall through the column (0.084 m/s).
// (Single particles at the free surface keep hopping: a surface particle has no pressure, its neighbours
// below push it up, and it falls back; so the bound is on the bulk, not on the fastest particle.)
inline void expectHydrostaticColumn(const ColumnSamples& column, double support = 0.04) {
  for (const auto& [index, sum] : column.layers)
    std::printf("layer %2d: %5.0f Pa (rho g d %5.0f)\n", index, sum.first / std::max(1, sum.second),
                1000 * 9.81 * (column.top + 0.01 - (index + 0.5) * 0.02));
  const int floorRows = static_cast<int>(std::ceil(support / 0.02 - 1 - 1e-9));
  int checked = 0;
  for (const auto& [index, sum] : column.layers) {
    const double y = (index + 0.5) * 0.02, depth = column.top + 0.01 - y;
    if (depth < 2 * support || index < floorRows || sum.second < 100) continue;
    const double expected = 1000 * 9.81 * depth, measured = sum.first / sum.second;
    EXPECT_NEAR(measured, expected, 0.1 * expected + 1000 * 9.81 * support / 2) << "layer at y = " << y;
    ++checked;
  }
  EXPECT_GE(checked, static_cast<int>((0.4 - 2 * support) / 0.02 + 1e-9) - floorRows - 3);  // 12 at the default
  EXPECT_LT(std::sqrt(column.speedSquaredSum / column.speedSamples), 0.03 * std::sqrt(2 * 9.81 * 0.4));
}

}  // namespace surge
