// The solvers' one interface and its registry (sim/fluid_solver.h).
#include "sim/fluid_solver.h"

#include <gtest/gtest.h>

#include <cmath>

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

// fluids[i].jitter: each particle off its lattice site by up to jitter x half the spacing along each axis, by a
// pattern fixed by its id (the same in every run), spread over that range (not all in one corner); a block
// without jitter stays on the lattice.
TEST(FluidSolver, AJitteredBlockStartsOffItsLatticeWithinItsCellsTheSameEveryRun) {
  const Scene plain = blockScene("pbf");
  const Scene jittered = parseScene(
      R"({"name": "f", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [0.4, 0.4, 0.4]}, "particle_spacing": 0.02,
          "fluids": [{"box": {"min": [0, 0, 0], "max": [0.2, 0.2, 0.2]}, "jitter": 0.4}]})",
      "test");
  const ParticleFrame lattice = initialParticles(plain);
  for (const auto& p : lattice.position) EXPECT_NEAR(std::fmod(p.x() / 0.02, 1.0), 0.5, 1e-4);
  const ParticleFrame frame = initialParticles(jittered), again = initialParticles(jittered);
  ASSERT_EQ(frame.size(), 1000u);
  EXPECT_EQ(frame.position, again.position);
  double lowest = 1, highest = -1, sum = 0;
  for (const auto& p : frame.position)
    for (int k = 0; k < 3; ++k) {
      const double off = std::fmod(p[k] / 0.02, 1.0) - 0.5;  // the offset from the site, in spacings
      lowest = std::min(lowest, off);
      highest = std::max(highest, off);
      sum += off;
    }
  // Up to 0.4 x half a spacing: within +-0.2, reaching near both ends, centred (the mean of 3000 uniform
  // offsets of variance 0.4^2 / 12 is within 0.002 of 0 at 1 sigma).
  EXPECT_GE(lowest, -0.2);
  EXPECT_LE(highest, 0.2);
  EXPECT_LT(lowest, -0.19);
  EXPECT_GT(highest, 0.19);
  EXPECT_NEAR(sum / 3000, 0.0, 0.008);
}

// fluids[i].velocity_field: each particle starts with velocity plus the formulas at its own (jittered) place, in
// its own block only; a formula that is not finite somewhere in the block is one line naming the component's key.
TEST(FluidSolver, AVelocityFieldStartsEachParticleWithTheFormulaAtItsPlace) {
  const std::string json = R"({"name": "f", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1]},
      "particle_spacing": 0.05,
      "fluids": [{"box": {"min": [0, 0], "max": [0.5, 0.5]}, "jitter": 0.3, "velocity": [1, 0],
                  "velocity_field": ["y", "-x*x"]},
                 {"box": {"min": [0.5, 0], "max": [1, 0.5]}, "velocity": [0, 2]}]})";
  const ParticleFrame frame = initialParticles(parseScene(json, "test"));
  ASSERT_EQ(frame.size(), 200u);
  for (size_t i = 0; i < frame.size(); ++i) {
    const Eigen::Vector3f p = frame.position[i], v = frame.velocity[i];
    if (p.x() < 0.5) {
      EXPECT_FLOAT_EQ(v.x(), 1 + p.y());
      EXPECT_FLOAT_EQ(v.y(), -p.x() * p.x());
      EXPECT_NE(std::fmod(p.y() / 0.05, 1.0), 0.5);  // at the jittered place, not the site
    } else {
      EXPECT_EQ(v, Eigen::Vector3f(0, 2, 0));
    }
  }
  try {
    initialParticles(parseScene(json, "test", {R"X(fluids[0].velocity_field=["1", "sqrt(x - 0.3)"])X"}));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("test: fluids[0].velocity_field[1]: 'sqrt(x - 0.3)' is not finite at (", 0), 0u)
        << e.what();
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
