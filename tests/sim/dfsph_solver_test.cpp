// Divergence-Free SPH (sim/dfsph_solver.h): the hydrostatic column, the dam break, the stopping rules.
#include "sim/dfsph_solver.h"

#include <gtest/gtest.h>

#include <map>

#include "sim/pbf_solver.h"
#include "sim/simulation.h"
#include "tests/sim/hydrostatic_column.h"
#include "tests/sim/run_scene.h"
#include "tests/sim/stats_columns.h"

namespace surge {
namespace {

Scene scene2d(const std::string& fluids, const std::vector<std::string>& overrides,
              const std::string& domain = R"({"min": [0, 0], "max": [1, 1]})") {
  const std::string json = R"({"name": "d", "dimensions": 2, "domain": )" + domain +
                           R"(, "particle_spacing": 0.02, "fluids": )" + fluids + R"(, "solver": {"method": "dfsph"}})";
  return parseScene(json, "test", overrides);
}

// Steps any solver over `duration` as the frame loop does: its fixed substeps, or its own stable steps.
void simulateFor(FluidSolver<2>& solver, double& time, double duration, double fps = 30) {
  const int frames = static_cast<int>(std::round(duration * fps));
  for (int f = 0; f < frames; ++f) {
    solver.beginFrame(time);
    double remaining = 1.0 / fps;
    int steps = 0;
    while (remaining > 0) {
      float dt;
      if (solver.fixedSubsteps() > 0) {
        dt = static_cast<float>(1.0 / (fps * solver.fixedSubsteps()));
        remaining = ++steps == solver.fixedSubsteps() ? 0 : remaining - dt;
      } else {
        const double count = std::max(1.0, std::ceil(remaining / solver.stableTimeStep() - 1e-9));
        dt = static_cast<float>(remaining / count);
        remaining = count == 1 ? 0 : remaining - dt;
      }
      ASSERT_EQ(solver.step(dt, time), -1) << "frame " << f;
      time += dt;
    }
  }
}

// A column 0.4 m deep (20 particles) and 0.3 m wide, settled for 3 s, then sampled 20 times over 0.67 s. Also with
// kernels of 3.5 spacings (36 neighbours in 2D): there the Jacobi relaxation of 0.5 diverged in the first frame,
// as the rest lattice's spectrum says it must (omega mu = 2.5 and 2.2 against 2, sim/dfsph_solver.cpp).
void expectColumnAtRest(const std::vector<std::string>& kernel) {
  std::vector<std::string> overrides = kernel;
  overrides.push_back("domain.max=[0.3,1]");
  const Scene scene = scene2d(R"([{"box": {"min": [0, 0], "max": [0.3, 0.4]}}])", overrides);
  DfsphSolver<2> solver(scene);
  solver.setParticles(initialParticles(scene));
  double time = 0;
  simulateFor(solver, time, 3.0);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  ColumnSamples column;
  double errorSum = 0;
  for (int sample = 0; sample < 20; ++sample) {
    simulateFor(solver, time, 1.0 / 30);
    column.add(solver.positions(), solver.velocities(), solver.pressures());
    errorSum += solver.measure().densityErrorAvg;
  }
  // The pressure is rho_0 g d below the surface, as for WCSPH, and the column holds still (hydrostatic_column.h).
  expectHydrostaticColumn(column, scene.solver.kernel_radius);
  // The density error stays near the solver's limit (max_density_error 0.0005 by default; the frame's measure
  // is of the positions after the move, which the linear prediction misses by its second-order terms): under
  // twice the limit.
  EXPECT_LT(errorSum / 20, 2 * scene.solver.max_density_error);
}

TEST(DfsphSolver, HydrostaticColumnHasHydrostaticPressureAndHoldsStill) { expectColumnAtRest({}); }

TEST(DfsphSolver, AWideKernelHoldsTheColumnStillToo) {
  for (const char* kernel : {"cubic_spline", "wendland_c2"}) {
    SCOPED_TRACE(kernel);
    expectColumnAtRest({std::string("solver.kernel=") + kernel, "solver.kernel_radius=0.07"});
  }
}

}  // namespace
}  // namespace surge

namespace surge {
namespace {

// The front of a 2D dam break (a 0.4 m square column against the left wall) for the first 0.3 s, before it
// reaches the far wall, with DFSPH and with PBF on the same scene.
std::vector<double> damBreakFront(const std::string& method) {
  const Scene scene = parseScene(
      R"({"name": "dam", "dimensions": 2, "domain": {"min": [0, 0], "max": [1.6, 0.8]}, "particle_spacing": 0.01,
          "fluids": [{"box": {"min": [0, 0], "max": [0.4, 0.4]}}], "output": {"fps": 60, "frames": 18}})",
      "test", {"solver.method=" + method});
  const std::unique_ptr<FluidSolver<2>> solver = makeFluidSolver<2>(scene);
  solver->setParticles(initialParticles(scene));
  std::vector<double> front;
  double time = 0;
  ParticleFrame frame;
  for (int f = 0; f < scene.output.frames; ++f) {
    simulateFor(*solver, time, 1.0 / 60, 60);
    solver->getParticles(frame);
    front.push_back(measureDamBreak(scene, frame).frontX);
  }
  return front;
}

TEST(DfsphSolver, DamBreakFrontIsNoSlowerThanPbfAndNoFasterThanRitter) {
  const std::vector<double> dfsph = damBreakFront("dfsph"), pbf = damBreakFront("pbf");
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  for (size_t f = 0; f < dfsph.size(); ++f) {
    const double t = (f + 1) / 60.0;
    // Ritter's inviscid shallow-water front, x = a + 2 sqrt(g H) t, is the fastest a collapsing column's front
    // can run (all its potential energy into the tongue). PBF's Jacobi iterations and XSPH take energy out of
    // the flow, DFSPH's solvers less: its front must not lag PBF's by more than two spacings.
    const double ritter = 0.4 + 2 * std::sqrt(9.81 * 0.4) * t;
    std::printf("t %.3f: dfsph %.3f pbf %.3f ritter %.3f\n", t, dfsph[f], pbf[f], ritter);
    EXPECT_LT(dfsph[f], ritter) << "t = " << t;
    EXPECT_GT(dfsph[f], pbf[f] - 0.02) << "t = " << t;
  }
  // And it has run: by 0.3 s (T = t sqrt(2 g / a) = 2.1) the front has moved by more than the column's width.
  EXPECT_GT(dfsph.back(), 0.8);
}

// A column 50 particles deep released from rest at the scene's defaults: DFSPH's step takes the deepest column's
// limit (0.9 spacing / sqrt(g H), 9 steps a frame here), so its density solve meets its tolerance from the first
// step. Bounded by the frame and its CFL step only (6 steps a frame, the fluid at rest), the solve ran into its
// 100 iterations in frame 1 with one particle 69% compressed, and the energy stop ended the run at frame 2. The
// largest compression of frames 1 to 4 is held under 5%: measured 0.3 to 1.3%, a particle's share of a
// converged solve's 0.1% average; an unconverged start reaches tens of percent.
TEST(DfsphSolver, ADeepColumnStartsFromRestWithinItsIterations) {
  const Scene scene = parseScene(
      R"({"name": "column", "dimensions": 2, "domain": {"min": [0, 0], "max": [2.0, 0.8]}, "particle_spacing": 0.01,
          "fluids": [{"box": {"min": [0, 0], "max": [0.5, 0.5]}}], "gravity": [0, -9.81],
          "solver": {"method": "dfsph"}, "output": {"fps": 30, "frames": 4}})",
      "column.json");
  const fs::path dir = runScene(scene, "dfsph_deep_column");
  const auto stats = readStats(dir);
  for (size_t f = 1; f < stats.at("frame").size(); ++f) {
    std::printf("frame %zu: %g steps, %.1f iterations a step, largest compression %.3f%%\n", f,
                stats.at("substeps")[f], stats.at("iterations")[f], 100 * stats.at("density_error_max")[f]);
    EXPECT_LT(stats.at("iterations")[f], scene.solver.max_iterations) << "frame " << f;
    EXPECT_LT(stats.at("density_error_max")[f], 0.05) << "frame " << f;
  }
}

}  // namespace
}  // namespace surge
