#include "sim/wcsph_solver.h"

#include <gtest/gtest.h>

#include <map>

#include "sim/simulation.h"
#include "tests/sim/hydrostatic_column.h"

namespace surge {
namespace {

Scene scene2d(const std::string& fluids, const std::vector<std::string>& overrides,
              const std::string& domain = R"({"min": [0, 0], "max": [1, 1]})") {
  const std::string json = R"({"name": "w", "dimensions": 2, "domain": )" + domain +
                           R"(, "particle_spacing": 0.02, "fluids": )" + fluids + R"(, "solver": {"method": "wcsph"}})";
  return parseScene(json, "test", overrides);
}

// Steps the solver over `duration` with its own stable steps (as the frame loop does), frame by frame.
void simulateFor(WcsphSolver<2>& solver, double duration, double fps = 30) {
  double time = 0;
  const int frames = static_cast<int>(std::round(duration * fps));
  for (int f = 0; f < frames; ++f) {
    solver.beginFrame(time);
    double remaining = 1.0 / fps;
    while (remaining > 0) {
      const double count = std::max(1.0, std::ceil(remaining / solver.stableTimeStep() - 1e-9));
      const float dt = static_cast<float>(remaining / count);
      ASSERT_EQ(solver.step(dt, time), -1) << "frame " << f;
      time += dt;
      remaining = count == 1 ? 0 : remaining - dt;
    }
  }
}

TEST(WcsphSolver, HydrostaticColumnHasHydrostaticPressureAndHoldsStill) {
  // A column 0.4 m deep (20 particles) and 0.3 m wide, settled for 3 s, then its pressures averaged over 20
  // evaluations in the next 0.67 s.
  const Scene scene = scene2d(R"([{"box": {"min": [0, 0], "max": [0.3, 0.4]}}])", {"domain.max=[0.3,1]"});
  WcsphSolver<2> solver(scene);
  solver.setParticles(initialParticles(scene));
  simulateFor(solver, 3.0);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  ColumnSamples column;
  for (int sample = 0; sample < 20; ++sample) {
    simulateFor(solver, 1.0 / 30);
    column.add(solver.positions(), solver.velocities(), solver.pressures());
  }
  expectHydrostaticColumn(column);
}

// The position of one particle orbiting the attractor (a smooth force field between its centre and radius:
// strength (1 - d / R) towards it; no neighbours, no gravity, no walls in reach) after 0.25 s of fixed steps.
Vec<2> orbitAfter(const std::string& integrator, float dt) {
  const Scene scene = scene2d(R"([{"box": {"min": [0.5, 0.6], "max": [0.52, 0.62]}}])",
                              {"gravity=[0,0]", "solver.integrator=" + integrator, "attractor.radius=0.3",
                               "attractor.strength=20", R"(attractor.keyframes=[{"time": 0, "position": [0.51, 0.51]}])"});
  ParticleFrame frame = initialParticles(scene);
  frame.velocity[0] = Eigen::Vector3f(0.8f, 0, 0);
  WcsphSolver<2> solver(scene);
  solver.setParticles(frame);
  solver.beginFrame(0);
  const int steps = static_cast<int>(std::lround(0.256 / dt));
  for (int s = 0; s < steps; ++s) EXPECT_EQ(solver.step(dt, s * dt), -1);
  return solver.positions()[0];
}

TEST(WcsphSolver, VelocityVerletIsSecondOrderAndEulerFirst) {
  // Against a reference of 1/32 the step, halving the step divides the error by about 4 for a second-order
  // method and 2 for a first-order one. Accepted: 3.4 to 4.6 for velocity Verlet, 1.7 to 2.3 for Euler (the
  // next terms of the error expansion shift the ratios by O(dt), several percent at these steps, which are
  // about a fortieth of the orbit's period). The steps are large enough that the errors (1e-4 m and more) dwarf
  // the single-precision rounding of positions near 0.5 m over the reference's 512 steps (~1e-6 m).
  for (const std::string integrator : {"velocity_verlet", "symplectic_euler"}) {
    const Vec<2> reference = orbitAfter(integrator, 1.6e-2f / 32);
    const double coarse = (orbitAfter(integrator, 1.6e-2f) - reference).norm();
    const double fine = (orbitAfter(integrator, 8e-3f) - reference).norm();
    const double ratio = coarse / fine;
    if (integrator == "velocity_verlet") {
      EXPECT_GT(ratio, 3.4) << integrator;
      EXPECT_LT(ratio, 4.6) << integrator;
    } else {
      EXPECT_GT(ratio, 1.7) << integrator;
      EXPECT_LT(ratio, 2.3) << integrator;
    }
    EXPECT_GT(coarse, 1e-6) << integrator;
  }
}

TEST(WcsphSolver, StableStepShrinksAsVelocityGrows) {
  const Scene scene = scene2d(R"([{"box": {"min": [0.4, 0.4], "max": [0.6, 0.6]}}])", {"gravity=[0,0]"});
  ParticleFrame frame = initialParticles(scene);
  WcsphSolver<2> solver(scene);
  solver.setParticles(frame);
  solver.beginFrame(0);
  const float atRest = solver.stableTimeStep();
  // dt = cfl h / (c + |v|max) with h half the support (0.02 m), cfl 0.4.
  EXPECT_NEAR(atRest, 0.4f * 0.02f / solver.speedOfSound(), 1e-3f * atRest);
  for (auto& v : frame.velocity) v = Eigen::Vector3f(solver.speedOfSound(), 0, 0);
  solver.setParticles(frame);
  solver.beginFrame(0);
  EXPECT_NEAR(solver.stableTimeStep(), atRest / 2, 1e-3f * atRest);
}

TEST(WcsphSolver, AttractorPullsTowardsItsPath) {
  // A block in free fall-less space, the attractor held just right of it: particles within its radius move
  // towards it, and away from it when the strength is negative.
  auto meanDistance = [](const WcsphSolver<2>& solver, const Vec<2>& point) {
    double sum = 0;
    for (const auto& p : solver.positions()) sum += (p - point).norm();
    return sum / solver.size();
  };
  const std::string block = R"([{"box": {"min": [0.3, 0.4], "max": [0.5, 0.6]}}])";
  const std::vector<std::string> common = {"gravity=[0,0]", "attractor.radius=0.3",
                                           R"(attractor.keyframes=[{"time": 0, "position": [0.6, 0.5]}])"};
  const Vec<2> point(0.6f, 0.5f);
  std::map<double, double> after;
  for (double strength : {0.0, 20.0, -20.0}) {
    std::vector<std::string> overrides = common;
    overrides.push_back("attractor.strength=" + std::to_string(strength));
    const Scene scene = scene2d(block, overrides);
    WcsphSolver<2> solver(scene);
    solver.setParticles(initialParticles(scene));
    simulateFor(solver, 0.2);
    after[strength] = meanDistance(solver, point);
  }
  EXPECT_LT(after[20.0], after[0.0] - 0.01);
  EXPECT_GT(after[-20.0], after[0.0] + 0.01);
}

TEST(WcsphSolver, FirstStepOfAFrameFeelsTheAttractorWhereItIsThen) {
  // The attractor is out of reach at t = 0 and arrives beside a resting particle at t = 1 s. The first step of
  // the frame that starts at t = 1 (its step size asked for first, as the frame loop does) must kick with the
  // force at t = 1 in both half-steps: v = dt a to within the particle's drift during the step (under 1e-6 of
  // the distance to the centre, so 1e-3 is generous). Evaluating the first half-kick at t = 0 would give dt a / 2.
  const Scene scene = scene2d(R"([{"box": {"min": [0.5, 0.6], "max": [0.52, 0.62]}}])",
                              {"gravity=[0,0]", "attractor.radius=0.3", "attractor.strength=20",
                               R"(attractor.keyframes=[{"time": 0, "position": [0.9, 0.9]},)"
                               R"( {"time": 1, "position": [0.51, 0.51]}])"});
  WcsphSolver<2> solver(scene);
  solver.setParticles(initialParticles(scene));
  const Vec<2> start = solver.positions()[0];
  solver.beginFrame(1.0);
  const float dt = solver.stableTimeStep();
  ASSERT_EQ(solver.step(dt, 1.0), -1);
  const Vec<2> centre(0.51f, 0.51f);
  const float distance = (centre - start).norm();
  const Vec<2> expected = dt * 20.0f * (1.0f - distance / 0.3f) / distance * (centre - start);
  EXPECT_NEAR(solver.velocities()[0].x(), expected.x(), 1e-3 * expected.norm());
  EXPECT_NEAR(solver.velocities()[0].y(), expected.y(), 1e-3 * expected.norm());
}

TEST(WcsphSolver, NoParticleEscapesAViolentDamBreak) {
  // A 2D dam thrown at 5 m/s into the far wall, one simulated second, both kernels, near pressure on:
  // every step keeps every particle finite and inside (step() returns -1, checked in simulateFor).
  for (const char* kernel : {"cubic_spline", "wendland_c2"}) {
    const Scene scene = scene2d(R"([{"box": {"min": [0, 0], "max": [0.4, 0.6]}, "velocity": [5, 0]}])",
                                {std::string("solver.kernel=") + kernel, "solver.near_pressure=0.05"},
                                R"({"min": [0, 0], "max": [1.2, 0.8]})");
    WcsphSolver<2> solver(scene);
    solver.setParticles(initialParticles(scene));
    simulateFor(solver, 1.0);
    SCOPED_TRACE(kernel);
  }
}

}  // namespace
}  // namespace surge
