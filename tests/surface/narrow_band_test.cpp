// Tests of surface/narrow_band.h on analytic fields: planes and spheres sampled into blocks as the rasteriser
// lays them out (only the blocks that hold part of the band), so every stencil also reads across blocks and
// from missing ones.
#include "surface/narrow_band.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "core/parallel.h"

namespace surge {
namespace {

constexpr double kVoxel = 0.01;
constexpr float kBand = 3 * kVoxel, kInside = 5 * kVoxel;

Eigen::Vector3d voxelPoint(const Eigen::Vector3i& origin, int a) {
  return kVoxel * Eigen::Vector3d(origin.x() + a / 64, origin.y() + (a / 8) % 8, origin.z() + a % 8);
}

// The blocks of [-4, 4)^3 blocks of 8^3 voxels holding a voxel with -kInside < phi < kBand, phi clamped to
// that range (the rasteriser keeps every block that deep: its raw inside is never below -radius, and only
// blocks far inside are left out).
BlockField sample(const std::function<double(const Eigen::Vector3d&)>& phi) {
  BlockField field;
  for (int bx = -4; bx < 4; ++bx)
    for (int by = -4; by < 4; ++by)
      for (int bz = -4; bz < 4; ++bz) {
        const Eigen::Vector3i origin = kBlockDim * Eigen::Vector3i(bx, by, bz);
        std::vector<float> values(kBlockVoxels);
        bool inBand = false;
        for (int a = 0; a < kBlockVoxels; ++a) {
          const double v = phi(voxelPoint(origin, a));
          inBand |= v > -kInside && v < kBand;
          values[size_t(a)] = float(std::clamp(v, -double(kInside), double(kBand)));
        }
        if (!inBand) continue;
        field.origins.push_back(origin);
        field.values.insert(field.values.end(), values.begin(), values.end());
      }
  return field;
}

// Calls check(point, value) for every voxel of the field at least 8 voxels in from the sampled domain's faces
// (beyond them the field is missing, and reads as the clamp value; no test here iterates 8 times).
void forEachVoxel(const BlockField& field, const std::function<void(const Eigen::Vector3d&, float)>& check) {
  for (size_t b = 0; b < field.origins.size(); ++b)
    for (int a = 0; a < kBlockVoxels; ++a) {
      const Eigen::Vector3d x = voxelPoint(field.origins[b], a);
      if (x.cwiseAbs().maxCoeff() > (32 - 9) * kVoxel) continue;
      check(x, field.values[b * kBlockVoxels + size_t(a)]);
    }
}

const Eigen::Vector3d kNormal = Eigen::Vector3d(1, 2, 2) / 3;  // an oblique plane through (0.013, 0, 0)
double planeDistance(const Eigen::Vector3d& x) {
  return kNormal.dot(x - Eigen::Vector3d(0.013, 0, 0));
}

TEST(NarrowBand, RedistanceKeepsAPlanesDistanceAndRestoresItFromTheVoxelsBesideIt) {
  // A plane's distance is a fixed point of the first-order upwind update at any orientation: unchanged to
  // float rounding (1e-6 of a voxel a layer) after 3 iterations, everywhere off the clamps.
  NarrowBand exact(sample(planeDistance), kVoxel, kBand, kInside);
  exact.redistance(3);
  size_t checked = 0;
  forEachVoxel(exact.blocks(), [&](const Eigen::Vector3d& x, float value) {
    const double d = planeDistance(x);
    if (d > kBand - kVoxel || d < -kInside + kVoxel) return;  // within a voxel of a clamp
    ASSERT_NEAR(value, d, 1e-5 * kVoxel) << x.transpose();
    ++checked;
  });
  EXPECT_GT(checked, 10000u);
  // The voxels within a voxel of the plane hold its distance, the others twice it (clamped). A voxel's update
  // needs its upwind neighbour on every axis to be right, and the x neighbour is only a third of a voxel
  // nearer the plane (the normal's smallest component), so each iteration restores a third of a voxel more:
  // after 6, every voxel within 1 + 6 / 3 = 3 voxels (checked to 2.5) is exact again.
  NarrowBand wrong(sample([](const Eigen::Vector3d& x) {
                     const double d = planeDistance(x);
                     return std::abs(d) < kVoxel ? d : 2 * d;
                   }),
                   kVoxel, kBand, kInside);
  wrong.redistance(6);
  checked = 0;
  forEachVoxel(wrong.blocks(), [&](const Eigen::Vector3d& x, float value) {
    const double d = planeDistance(x);
    if (std::abs(d) > 2.5 * kVoxel) return;
    ASSERT_NEAR(value, d, 1e-5 * kVoxel) << x.transpose();
    ++checked;
  });
  EXPECT_GT(checked, 10000u);
}

TEST(NarrowBand, MeanCurvatureStepMovesASphereInwardByItsCurvature) {
  // A sphere of radius R = 12 voxels: mean curvature H = 1 / R, so one step of dt = voxel^2 / 3 moves the
  // surface in by dt H and raises phi near it by voxel^2 / (3 R) = voxel / 36. Second-order central
  // differences of a distance field of radius 12 voxels get H within 1% (O(voxel^2 / R^2)); the bound is 5%.
  const double R = 12 * kVoxel;
  BlockField field = sample([&](const Eigen::Vector3d& x) { return x.norm() - R; });
  NarrowBand band(field, kVoxel, kBand, kInside);
  band.meanCurvatureStep();
  const double expected = kVoxel * kVoxel / (3 * R);
  size_t checked = 0;
  forEachVoxel(band.blocks(), [&](const Eigen::Vector3d& x, float value) {
    const double d = x.norm() - R;
    if (std::abs(d) > kVoxel) return;
    // At distance d the level set through the voxel has radius R + d, curvature 1 / (R + d).
    ASSERT_NEAR(value - d, kVoxel * kVoxel / (3 * (R + d)), 0.05 * expected) << x.transpose();
    ++checked;
  });
  EXPECT_GT(checked, 1000u);
}

TEST(NarrowBand, SameBytesAtOneAndTwoThreads) {
  const double R = 12 * kVoxel;
  BlockField field =
      sample([&](const Eigen::Vector3d& x) { return x.norm() - R + 0.3 * kVoxel * std::sin(40 * x.x()); });
  std::vector<float> values[2];
  for (int threads : {1, 2}) {
    ThreadLimit limit(threads);
    NarrowBand band(field, kVoxel, kBand, kInside);
    band.meanCurvatureStep();
    band.offset(0.5f * float(kVoxel));
    band.redistance(3);
    values[threads - 1] = band.blocks().values;
  }
  EXPECT_TRUE(values[0] == values[1]);
}

}  // namespace
}  // namespace surge
