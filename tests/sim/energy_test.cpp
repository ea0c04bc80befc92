// The fluid's potential energy in stats.csv (issue 32), against what it must be: a pool's at rest, and in a
// free fall the exact energy account of the frame loop's steps.
#include <gtest/gtest.h>

#include <cmath>

#include "core/files.h"
#include "core/progress.h"
#include "sim/pbf_solver.h"
#include "sim/simulation.h"
#include "tests/sim/stats_columns.h"

namespace surge {
namespace {

std::map<std::string, std::vector<double>> run(const Scene& scene, const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::remove_all(dir);
  Progress quiet;
  simulate(scene, dir, false, quiet);
  return readStats(dir);
}

// A 2D pool W wide and H deep at rest holds m g W H^2 / (2 s^2) against the floor: its particles sit at
// (j + 1/2) s, whose heights sum to exactly n^2 s / 2 over a column of n, m the method's particle mass (PBF's
// is rho s^2 less 1.4%, its rest lattice's share of the walls). Gravity along -x measures against the -x wall.
TEST(Energy, APoolHoldsItsWeightTimesHalfItsDepth) {
  for (const char* gravity : {"[0, -9.81]", "[-9.81, 0]"}) {
    const Scene scene = parseScene(std::string(R"({"name": "pool", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.5, 0.5]},
        "particle_spacing": 0.01, "gravity": )") + gravity + R"(,
        "fluids": [{"box": {"min": [0, 0], "max": [0.2, 0.2]}}], "output": {"fps": 30, "frames": 1}})",
                                   "pool.json");
    const auto stats = run(scene, "energy_pool");
    const double mass = PbfSolver<2>(scene).particleMass(), columns = 20, n = 20;
    const double expected = mass * 9.81 * columns * n * n * 0.01 / 2;
    std::printf("pool (gravity %s): potential energy %.4f J/m against m g W H^2 / (2 s^2) = %.4f (rho g W H^2 / 2 "
                "= %.4f)\n", gravity, stats.at("potential_energy")[0], expected, 1000 * 9.81 * 0.2 * 0.2 * 0.2 / 2);
    EXPECT_NEAR(stats.at("potential_energy")[0], expected, 1e-5 * expected) << gravity;
  }
}

// A block in free fall: the frame loop's step (v += g dt, then x += v dt) after n equal steps has given the block
// n g dt of speed and dropped it g dt^2 n (n + 1) / 2, so the potential energy it lost exceeds the kinetic it
// gained by exactly KE / n: the account must read that, to float rounding (1e-4 of the energies). 12 steps a
// frame meet the CFL step of its fastest (2.6 m/s) and the depth step of its 0.2 m column, so none is shortened.
TEST(Energy, AFreeFallAccountsForEveryStep) {
  const Scene scene = parseScene(
      R"({"name": "fall", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1]}, "particle_spacing": 0.01,
          "fluids": [{"box": {"min": [0.4, 0.5], "max": [0.6, 0.7]}}], "solver": {"substeps": 12},
          "output": {"fps": 30, "frames": 8}})",
      "fall.json");
  const auto stats = run(scene, "energy_fall");
  const std::vector<double>&pe = stats.at("potential_energy"), &ke = stats.at("kinetic_energy");
  double steps = 0;
  for (size_t f = 1; f < pe.size(); ++f) {
    EXPECT_EQ(stats.at("substeps")[f], 12) << "frame " << f;
    steps += stats.at("substeps")[f];
  }
  const double lost = pe.front() - pe.back(), gained = ke.back();
  std::printf("free fall over %.0f steps: potential energy lost %.4f J/m, kinetic gained %.4f, their difference "
              "%.5f against KE / n = %.5f\n", steps, lost, gained, lost - gained, gained / steps);
  ASSERT_GT(gained, 1.0);
  EXPECT_NEAR(lost - gained, gained / steps, 1e-4 * lost);
}

}  // namespace
}  // namespace surge
