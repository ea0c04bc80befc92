// A method added from outside the library (tests/sim/ballistic_method.h) runs a scene like the built-in ones.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/errors.h"
#include "core/files.h"
#include "core/ply.h"
#include "core/progress.h"
#include "sim/simulation.h"
#include "tests/sim/ballistic_method.h"

namespace surge {
namespace {

// Registered, a fourth method is a choice of solver.method and `surge sim`'s frame loop runs it: a 2D block high
// in its tank falls as symplectic Euler says, every particle by g dt^2 n (n + 1) / 2 after n steps of dt.
// It leaves the registry as it found it: other tests in the same process compare the built-in methods' key table
// with docs/scene-format.md (SolverDefaults.DocumentationListsEveryKey).
TEST(BallisticMethod, ANewMethodIsAPairOfFilesAndOneRegistration) {
  registerFluidMethod(kBallisticMethod);
  struct Unregister {
    ~Unregister() { unregisterFluidMethod(kBallisticMethod.name); }
  } unregister;
  const Scene scene = parseScene(
      R"({"name": "fall", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 2]}, "particle_spacing": 0.05,
          "fluids": [{"box": {"min": [0.2, 1.5], "max": [0.5, 1.8]}}],
          "solver": {"method": "ballistic", "substeps": 4}, "output": {"fps": 20, "frames": 6}})",
      "fall.json");
  const fs::path dir = fs::path(::testing::TempDir()) / "ballistic";
  fs::remove_all(dir);
  Progress quiet;
  simulate(scene, dir, false, quiet);
  const ParticleFrame first = readParticlePly(framePath(dir, "particles", 0, "ply"));
  const ParticleFrame last = readParticlePly(framePath(dir, "particles", 6, "ply"));
  ASSERT_EQ(first.size(), 36u);
  ASSERT_EQ(last.size(), first.size());
  const double dt = 1.0 / (20 * 4), n = 6 * 4;
  const double fall = 9.81 * dt * dt * n * (n + 1) / 2;  // 0.46 m: the block stays clear of the floor
  std::vector<double> startY(first.size());
  for (size_t i = 0; i < first.size(); ++i) startY[first.id[i]] = first.position[i].y();
  for (size_t i = 0; i < last.size(); ++i) EXPECT_NEAR(startY[last.id[i]] - last.position[i].y(), fall, 2e-5);
  const std::string stats = readTextFile(dir / "stats.csv");
  EXPECT_EQ(std::count(stats.begin(), stats.end(), '\n'), 8);  // the header and frames 0 to 6
}

// Unregistered, the method is gone again: solver.method no longer offers it and the key table is the built-in
// methods' (which docs/scene-format.md embeds).
TEST(BallisticMethod, UnregisteringLeavesTheBuiltInMethods) {
  const std::string builtIn = sceneKeysMarkdown();
  registerFluidMethod(kBallisticMethod);
  EXPECT_NE(sceneKeysMarkdown(), builtIn);
  unregisterFluidMethod(kBallisticMethod.name);
  EXPECT_EQ(sceneKeysMarkdown(), builtIn);
  EXPECT_THROW(fluidMethod("ballistic"), InputError);
}

}  // namespace
}  // namespace surge
