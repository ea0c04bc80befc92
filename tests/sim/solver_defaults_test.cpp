// What the simulator decides from a scene's physics and its method's registration (sim/solver_defaults.h).
#include "sim/solver_defaults.h"

#include <gtest/gtest.h>

#include <cctype>

#include <cstdlib>

#include "core/errors.h"
#include "core/process.h"
#include "sim/fluid_solver.h"

namespace surge {
namespace {

const char* kValid = R"({
  "name": "tiny", "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [1, 1, 0.5]},
  "particle_spacing": 0.05,
  "fluids": [{"box": {"min": [0, 0, 0], "max": [0.4, 0.5, 0.5]}, "velocity": [1, 0, 0]}],
  "solver": {"substeps": 2},
  "output": {"fps": 24, "frames": 3}
})";

// Only the simulation refuses a scene by the memory its particles need (surface and render read any folder),
// and by the least of the machine's memory, its cgroup's limit and a Slurm job's.
TEST(SolverDefaults, MemoryCheckIsTheSimulationsAndHonoursTheJobsLimit) {
  // A lattice of 1e-5 m in a 0.4 x 0.5 x 0.5 box: 1e13 particles, far beyond any memory; the scene still loads.
  const Scene huge = parseScene(kValid, "scene.json", {"particle_spacing=1e-5"});
  try {
    checkSimulationMemory(huge);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("scene.json: particle_spacing: ", 0), 0u) << e.what();
  }
  const Scene scene = parseScene(kValid, "scene.json", {"particle_spacing=0.01"});
  const double need = double(scene.particleCount()) * bytesPerParticleEstimate(3, "pbf");
  ASSERT_LT(need, 0.8 * memoryLimit().bytes);
  EXPECT_NO_THROW(checkSimulationMemory(scene));
  // A Slurm job that asked for less than 1.25 times the need: refused, naming the job's limit.
  const std::string megabytes = std::to_string(int(need / 0.8 / 1048576.0 * 0.9));
  ::setenv("SLURM_MEM_PER_NODE", megabytes.c_str(), 1);
  EXPECT_EQ(memoryLimit().source, "this Slurm job's");
  EXPECT_NEAR(memoryLimit().bytes, std::stod(megabytes) * 1048576.0, 1.0);
  try {
    checkSimulationMemory(scene);
    ADD_FAILURE() << "a job limit of " << megabytes << " MB was not enough for " << need << " bytes";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more than this Slurm job's"), std::string::npos) << e.what();
  }
  ::unsetenv("SLURM_MEM_PER_NODE");
  EXPECT_NO_THROW(checkSimulationMemory(scene));
}

// Each method's registration, not a comparison of names, decides its defaults and its memory: DFSPH's density
// limit of 0 is 0.0005 and PBF's stays 0 (run exactly `iterations`); DFSPH's pairs hold a gradient vector each.
TEST(SolverDefaults, EachMethodsRegistrationResolvesItsOwnDefaults) {
  EXPECT_DOUBLE_EQ(parseScene(kValid, "s", {"solver.method=dfsph"}).solver.max_density_error, 0.0005);
  EXPECT_DOUBLE_EQ(parseScene(kValid, "s", {"solver.method=pbf"}).solver.max_density_error, 0.0);
  EXPECT_DOUBLE_EQ(parseScene(kValid, "s", {"solver.method=dfsph", "solver.max_density_error=0.01"})
                       .solver.max_density_error, 0.01);
  EXPECT_GT(bytesPerParticleEstimate(3, "dfsph"), bytesPerParticleEstimate(3, "pbf"));
  // WCSPH's push is a spacing a frame, PBF's a spacing a step: PBF's runaway speed is the larger by 10 x spacing x
  // fps x (substeps - 1), everything else being the scene's.
  const Scene pbf = parseScene(kValid, "s", {"solver.method=pbf", "solver.substeps=5"});
  const Scene wcsph = parseScene(kValid, "s", {"solver.method=wcsph", "solver.substeps=5"});
  EXPECT_NEAR(runawaySpeed(pbf) - runawaySpeed(wcsph), 10 * 0.05 * 24 * 4, 1e-9);
  // PBF's note about substeps below the stable number, and none when they meet it.
  EXPECT_EQ(solverNotes(parseScene(kValid, "s", {"solver.substeps=1", "particle_spacing=0.005"})).size(), 1u);
  EXPECT_TRUE(solverNotes(parseScene(kValid, "s")).empty());
  EXPECT_TRUE(solverNotes(parseScene(kValid, "s", {"solver.method=wcsph", "solver.substeps=1"})).empty());
  // PBF's kernels wider than 2.5 spacings: a note that they stir a fluid at rest; none at 2.5.
  const std::vector<std::string> wide =
      solverNotes(parseScene(kValid, "s", {"solver.method=pbf", "solver.substeps=5", "solver.kernel_radius=0.15"}));
  ASSERT_EQ(wide.size(), 1u);
  EXPECT_NE(wide[0].find("solver.kernel_radius is 3 spacings"), std::string::npos) << wide[0];
  EXPECT_TRUE(
      solverNotes(parseScene(kValid, "s", {"solver.method=pbf", "solver.substeps=5", "solver.kernel_radius=0.125"}))
          .empty());
  EXPECT_TRUE(solverNotes(parseScene(kValid, "s", {"solver.method=dfsph", "solver.kernel_radius=0.15"})).empty());
  // solver.background_pressure, in every method: a note that this fluid, 20% of its tank, has a free surface the
  // push pulls apart, none where the fluid fills the tank; in PBF also one that the push stirs a fluid at rest.
  for (const char* method : {"wcsph", "dfsph", "pbf"}) {
    const std::string choice = std::string("solver.method=") + method;
    const size_t own = std::string(method) == "pbf" ? 1 : 0;
    const std::vector<std::string> notes =
        solverNotes(parseScene(kValid, "s", {choice, "solver.substeps=5", "solver.background_pressure=1e4"}));
    ASSERT_EQ(notes.size(), 1u + own) << method;
    EXPECT_NE(notes[own].find("this fluid fills 20% of the tank"), std::string::npos) << notes[own];
    const std::vector<std::string> full = solverNotes(parseScene(
        kValid, "s", {choice, "solver.substeps=5", "solver.background_pressure=1e4", "domain.max=[0.4,0.5,0.5]"}));
    ASSERT_EQ(full.size(), own) << method;
    if (own) EXPECT_NE(full[0].find("stirs a fluid at rest"), std::string::npos) << full[0];
  }
  // A body in a viscous fluid: DFSPH's note when nu dt / a^2 is over 0.15 at the largest step (a ball of radius
  // 0.05 in nu = 0.37: 3.08 at 1 / 24 s over 2 substeps; a 1 ms step, 0.148, none), naming the solid; PBF's and
  // WCSPH's that their drag falls short; none without viscosity, without a body, or for a collider that stands.
  const std::vector<std::string> honey = {"fluids[0].viscosity=0.37",
      R"(bodies=[{"name": "ball", "shape": "sphere", "radius": 0.05, "position": [0.7, 0.3, 0.25], "density": 7800}])"};
  auto with = [&](std::vector<std::string> sets, const std::vector<std::string>& more) {
    sets.insert(sets.end(), more.begin(), more.end());
    return solverNotes(parseScene(kValid, "s", sets));
  };
  const std::vector<std::string> coarse = with(honey, {"solver.method=dfsph"});
  ASSERT_EQ(coarse.size(), 1u);
  EXPECT_NE(coarse[0].find("here it is 3.08 for ball (a = 0.05 m)"), std::string::npos) << coarse[0];
  EXPECT_NE(coarse[0].find("solver.time_step 0.00101"), std::string::npos) << coarse[0];
  EXPECT_TRUE(with(honey, {"solver.method=dfsph", "solver.time_step=0.001"}).empty());
  EXPECT_TRUE(with({honey[1]}, {"solver.method=dfsph"}).empty());
  EXPECT_TRUE(with({honey[0]}, {"solver.method=dfsph"}).empty());
  EXPECT_TRUE(with({honey[0], R"(colliders=[{"shape": "sphere", "radius": 0.05, "position": [0.7, 0.3, 0.25]}])"},
                   {"solver.method=dfsph"}).empty());
  for (const char* method : {"PBF", "WCSPH"}) {
    std::string name = method;
    for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
    const std::vector<std::string> notes = with(honey, {"solver.method=" + name, "solver.viscosity_solver=implicit"});
    ASSERT_EQ(notes.size(), 1u) << method;
    EXPECT_NE(notes[0].find(std::string(method) + "'s drag on a solid moving through a viscous fluid"),
              std::string::npos);
  }
  // WCSPH's explicit viscosity: a note when its step limit 0.125 (h/2)^2 / nu is under a quarter of the sound's,
  // cfl (h/2) / c. Here h/2 = 0.05 and c = 10 sqrt(2 g 1 m) = 44.3 m/s (resolved as the scene is read), so the
  // sound's step is 4.52e-4 s; nu = 5 gives 6.25e-5 s, 7 times shorter (none with the implicit solve, above, nor
  // for nu = 0.37, whose 8.45e-4 s is the longer).
  const std::vector<std::string> explicitHoney = with({"fluids[0].viscosity=5"}, {"solver.method=wcsph"});
  ASSERT_EQ(explicitHoney.size(), 1u);
  EXPECT_NE(explicitHoney[0].find("WCSPH's explicit viscosity limits its step to 6.25e-05 s here, 7 times shorter"),
            std::string::npos)
      << explicitHoney[0];
  EXPECT_TRUE(with({"fluids[0].viscosity=5", "solver.viscosity_solver=implicit"}, {"solver.method=wcsph"}).empty());
  EXPECT_TRUE(with({honey[0]}, {"solver.method=wcsph"}).empty());
  // A name the registry does not hold is refused as the scene is read.
  try {
    parseScene(kValid, "s", {"solver.method=sph"});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("solver.method: 'sph' is not one of: pbf, wcsph, dfsph"), std::string::npos)
        << e.what();
  }
}

TEST(SolverDefaults, DocumentationListsEveryKey) {
  // docs/scene-format.md embeds the table that `surge keys` prints; a key added to scene_fields.cpp without
  // regenerating the document fails here. Here, where the simulator's registry names solver.method's choices.
  const std::string doc = readTextFile(fs::path(SURGE_SOURCE_DIR) / "docs" / "scene-format.md");
  const std::string table = sceneKeysMarkdown();
  EXPECT_NE(doc.find(table), std::string::npos) << "regenerate the table with `surge keys`";
}

// Every shipped scene loads with every method's keys declared (the methods' own keys are the simulator's).
TEST(SolverDefaults, ShippedScenesLoad) {
  for (const auto& entry : fs::directory_iterator(fs::path(SURGE_SOURCE_DIR) / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(loadScene(entry.path()));
  }
}

// A method's own key reads and writes through its registration: scene.json keeps it, and a key no method
// declares is refused.
TEST(SolverDefaults, AMethodsOwnKeysRoundTripThroughSceneJson) {
  const Scene scene =
      parseScene(kValid, "s", {"solver.iterations=3", "solver.near_pressure=2", "solver.max_iterations=9"});
  const Scene again = parseScene(sceneToJson(scene), "resolved.json");
  EXPECT_EQ(again.solver.iterations, 3);
  EXPECT_DOUBLE_EQ(again.solver.near_pressure, 2);
  EXPECT_EQ(again.solver.max_iterations, 9);
  EXPECT_EQ(sceneToJson(again), sceneToJson(scene));
  try {
    parseScene(kValid, "s", {"solver.iterations=-1"});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--set: solver.iterations: -1 is out of range (>= 0, <= 10000)");
  }
}

}  // namespace
}  // namespace surge
