// Surface tension under gravity (issue 34): a pool with surface tension stands at rest in PBF at its defaults,
// which give a fluid surface tension holds under gravity 8 iterations, and leave Chebyshev's acceleration off in 3D
// at its wider support (resolvePbfDefaults, sim/pbf_method.cpp; docs/surface-tension.md, "A pool under gravity").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "core/scene.h"
#include "sim/solver_defaults.h"
#include "tests/sim/run_scene.h"

namespace surge {
namespace {

// Water 40 particles deep (2D, 0.1 m wide) or 20 deep (3D, 20 x 20 across) at 1 mm, with sigma 0.0728, in PBF at
// its defaults (or those `sets` overrides); in 3D with `oil` a layer of oil (900 kg/m^3, sigma 0.03) 6 particles deep
// on 14 of water.
Scene poolScene(int dim, bool oil, const std::vector<std::string>& sets = {}) {
  // A point as the scene's dimensions write it: x, y and, in 3D, z.
  const auto at = [dim](const std::string& x, const std::string& y, const std::string& z) {
    return "[" + x + ", " + y + (dim == 3 ? ", " + z : "") + "]";
  };
  const std::string width = dim == 3 ? "0.02" : "0.1", depth = dim == 3 ? "0.02" : "0.04";
  std::string fluids = R"({"surface_tension": 0.0728, "box": {"min": )" + at("0", "0", "0") +
                       ", \"max\": " + at(width, oil ? "0.014" : depth, width) + "}}";
  if (oil)
    fluids += R"(, {"name": "oil", "rest_density": 900, "surface_tension": 0.03, "box": {"min": )" +
              at("0", "0.014", "0") + ", \"max\": " + at(width, depth, width) + "}}";
  return parseScene("{\"name\": \"pool\", \"dimensions\": " + std::to_string(dim) +
                        ", \"particle_spacing\": 0.001, \"domain\": {\"min\": " + at("0", "0", "0") +
                        ", \"max\": " + at(width, "0.06", width) + "}, \"gravity\": " + at("0", "-9.81", "0") +
                        R"(, "solver": {"method": "pbf"}, "output": {"fps": 30, "frames": )" +
                        (dim == 3 ? "10" : "30") + "}, \"fluids\": [" + fluids + "]}",
                    "pool.json", sets);
}

// The pool runs to its last frame (the energy check stops a run that gains energy), holds its density within 2% (a
// pool compressed by e stands lower by about e of its potential energy, and the energy account allows 2% of the
// most energy the fluid held), and gains no energy after its first frame: its kinetic and potential energy, less
// the work surface tension did, is at the end no more than at frame 1. In 3D it also settles: its motion at the end
// is below its first frame's (the lattice settling under its weight, and its meniscus), where a pool that boils
// gains it. The 2D pool at PBF's 3.5 spacings passes its settling's energy into a slosh (its kinetic energy peaks at
// 1.8 times frame 1's at 1.3 s and is back at 1.0 by 4 s), so there the energy, not the motion, is held. Measured:
// 2D 0.90%, energy 0.754591 J/m against 0.761903 at frame 1 (at 2.5 spacings with s_corr, before session 71: 1.34%,
// motion 0.46 of frame 1's); 3D 0.20%, 0.58 at 0.33 s; 3D with oil (iterated to 0.1%) 0.09%, 0.32. At 4 iterations
// the 2D and 3D pools blew up in their first frame (2D at 2.5 spacings under Wendland's kernels), and with oil,
// under Chebyshev's 0.85, the 3D pool gained energy within it: the energy check stopped each. Without surface
// tension PBF's 4 iterations at 2 spacings hold the 2D pool to 4.6%.
TEST(SurfaceTensionUnderGravity, APoolStandsAtRestInPbfAtItsDefaults) {
  for (const auto& [dim, oil] : {std::pair{2, false}, std::pair{3, false}, std::pair{3, true}}) {
    SCOPED_TRACE(std::to_string(dim) + "D" + (oil ? " with oil" : ""));
    const Scene scene = poolScene(dim, oil);
    fs::path dir;
    try {
      dir = runScene(scene, "pool_" + std::to_string(dim) + (oil ? "d_oil" : "d"));
    } catch (const std::exception& stop) {
      ADD_FAILURE() << stop.what();
      continue;
    }
    const auto stats = readStats(dir);
    const auto& kinetic = stats.at("kinetic_energy");
    ASSERT_EQ(kinetic.size(), size_t(scene.output.frames + 1));
    const auto energy = [&](size_t frame) {
      return kinetic.at(frame) + stats.at("potential_energy").at(frame) - stats.at("source_work").at(frame);
    };
    const double error = stats.at("density_error_avg").back(), settled = kinetic.back() / kinetic.at(1);
    std::printf(
        "%dD pool%s: density error %.4f, kinetic energy at the end %.3g of frame 1's, energy %.6g at "
        "frame 1, %.6g at the end\n",
        dim, oil ? " with oil" : "", error, settled, energy(1), energy(kinetic.size() - 1));
    EXPECT_LT(error, 0.02);
    EXPECT_LE(energy(kinetic.size() - 1), energy(1));
    if (dim == 3) EXPECT_LT(settled, 1.0);
  }
}

// A shallow pool, 10 particles deep and 50 across, in WCSPH: at rest (RMS speed 1.3 mm/s at the end, held under 1
// cm/s), its surface tension's work drifts below none (-6e-5 J/m a frame from frame 5; its cause is not found),
// which the energy account once took as surface energy stored and stopped the run at frame 16.
// The account credits it from none (sim/simulation.cpp), so the run reaches its end with source_work at none.
TEST(SurfaceTensionUnderGravity, AShallowPoolStandsAtRestInWcsphAndItsAccountHoldsIt) {
  Scene scene = parseScene(R"({"name": "shallow", "dimensions": 2, "particle_spacing": 0.001,
      "domain": {"min": [0, 0], "max": [0.05, 0.03]}, "gravity": [0, -9.81], "solver": {"method": "wcsph"},
      "output": {"fps": 30, "frames": 20},
      "fluids": [{"surface_tension": 0.0728, "box": {"min": [0, 0], "max": [0.05, 0.01]}}]})",
                           "shallow.json");
  fs::path dir;
  try {
    dir = runScene(scene, "shallow_wcsph");
  } catch (const std::exception& stop) {
    FAIL() << stop.what();
  }
  const auto stats = readStats(dir);
  ASSERT_EQ(stats.at("kinetic_energy").size(), 21u);
  const double mass = 0.05 * 0.01 * 1000, speed = std::sqrt(2 * stats.at("kinetic_energy").back() / mass);
  std::printf("WCSPH shallow pool: RMS speed %.2g m/s, source_work %.3g J/m at the end\n", speed,
              stats.at("source_work").back());
  EXPECT_LT(speed, 0.01);
  for (double work : stats.at("source_work")) EXPECT_GT(work, -1e-9);
}

// The defaults behind the pools above: 8 iterations where surface tension holds a fluid under gravity (4 in zero
// gravity or without surface tension; a file's own kept, and surge sim notes one under 8), and Chebyshev's
// acceleration off in 3D at a support wider than 2 spacings (0.85 at 2 and in 2D; a file's own kept).
TEST(SurfaceTensionUnderGravity, PbfGivesAStandingFluidEightIterationsAndNoChebyshevAtA3DWiderSupport) {
  const auto notesOn = [](const Scene& scene) {
    int count = 0;
    for (const std::string& note : solverNotes(scene))
      count += note.find("surface tension holds a fluid under gravity") != std::string::npos;
    return count;
  };
  for (int dim : {2, 3}) {
    SCOPED_TRACE(std::to_string(dim) + "D");
    EXPECT_EQ(poolScene(dim, false).solver.iterations, 8);
    EXPECT_EQ(poolScene(dim, false, {"gravity=" + std::string(dim == 3 ? "[0, 0, 0]" : "[0, 0]")}).solver.iterations,
              4);
    EXPECT_EQ(poolScene(dim, false, {"fluids[0].surface_tension=0"}).solver.iterations, 4);
    EXPECT_EQ(poolScene(dim, false, {"solver.iterations=5"}).solver.iterations, 5);
    EXPECT_EQ(notesOn(poolScene(dim, false)), 0);
    EXPECT_EQ(notesOn(poolScene(dim, false, {"solver.iterations=5"})), 1);
    EXPECT_EQ(poolScene(dim, true).solver.iterations, 30);  // where the densities differ, as before
  }
  EXPECT_EQ(poolScene(3, true).solver.chebyshev_rho, 0);
  EXPECT_EQ(poolScene(3, true, {"solver.kernel_radius=0.002"}).solver.chebyshev_rho, 0.85);
  EXPECT_EQ(poolScene(3, true, {"solver.chebyshev_rho=0.5"}).solver.chebyshev_rho, 0.5);
  EXPECT_EQ(poolScene(2, false).solver.chebyshev_rho, 0.85);
}

}  // namespace
}  // namespace surge
