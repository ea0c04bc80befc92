// The solvers' one interface and its registry (sim/fluid_solver.h).
#include "sim/fluid_solver.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "sim/simulation.h"
#include "tests/core/scene_choices.h"

namespace surge {
namespace {

Scene blockScene(const std::string& method) {
  const std::string json =
      R"({"name": "f", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.4, 0.4]}, "particle_spacing": 0.02,
          "fluids": [{"box": {"min": [0, 0], "max": [0.2, 0.2]}}], "solver": {"method": ")" +
      method + R"("}, "output": {"fps": 30, "frames": 1}})";
  return parseScene(json, "test", {});
}

TEST(FluidSolver, EveryMethodASceneMayNameIsRegisteredAndNoOther) {
  const std::vector<std::string> registered = fluidSolverMethods();
  EXPECT_EQ(sceneChoices("solver.method"), registered);
  EXPECT_GE(registered.size(), 2u);
}

TEST(FluidSolver, EachRegisteredMethodStepsABlockThroughTheInterface) {
  for (const std::string& method : fluidSolverMethods()) {
    SCOPED_TRACE(method);
    const Scene scene = blockScene(method);
    const std::unique_ptr<FluidSolver<2>> solver = makeFluidSolver<2>(scene);
    ParticleFrame frame = initialParticles(scene);
    const size_t count = frame.size();
    solver->setParticles(frame);
    ASSERT_EQ(solver->size(), count);
    solver->beginFrame(0.0);
    const float dt = solver->fixedSubsteps() > 0 ? static_cast<float>(1.0 / (30.0 * solver->fixedSubsteps()))
                                                 : std::min(solver->stableTimeStep(), 1.0f / 30);
    ASSERT_GT(dt, 0.0f);
    for (int s = 0; s < 4; ++s) ASSERT_EQ(solver->step(dt, s * dt), -1);
    // Under gravity the block has started to fall: the mean vertical velocity is downwards, and no particle
    // was lost or left the tank.
    double vy = 0;
    for (const Vec<2>& v : solver->velocities()) vy += v.y();
    EXPECT_LT(vy / count, 0.0);
    solver->getParticles(frame);
    EXPECT_EQ(frame.size(), count);
    EXPECT_GT(solver->particleMass(), 0.0f);
  }
}

TEST(FluidSolver, AnUnregisteredMethodIsOneLineNamingTheKey) {
  Scene scene = blockScene("pbf");
  scene.solver.method = "sticky";
  try {
    makeFluidSolver<3>(scene);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("solver.method"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace surge
