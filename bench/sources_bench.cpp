// The emitters' and sinks' share of a step (issue 31), printed as a markdown table for docs/sources.md: a pour of
// about 100,000 particles (a 3D pool at spacing 0.01 under a tap, with a drain in the floor and the tank's top
// open), PBF at the scene's own step. Each step is the solver's step, then FluidSources::apply (the scan of the
// sinks and the open face, the nozzle, the new layer and FluidSolver::editParticles); both are timed, and the
// share is apply's part of their sum, the median over rounds of 10 steps. Also counted: how often the particle
// positions were reallocated over the timed steps.
// Run: build/bench/surge_bench_sources [threads]   (default: all cores)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench/bench_timing.h"
#include "core/parallel.h"
#include "sim/fluid_solver.h"
#include "sim/simulation.h"
#include "sim/sources.h"

int main(int argc, char** argv) {
  using namespace surge;
  const int threads = argc > 1 ? std::atoi(argv[1]) : 0;
  ThreadLimit limit(threads);
  const Scene scene = parseScene(
      R"({"name": "bench_pour", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [0.6, 0.6, 0.6], "open": ["+y"]},
          "particle_spacing": 0.01, "fluids": [{"box": {"min": [0, 0, 0], "max": [0.6, 0.28, 0.6]}}],
          "emitters": [{"position": [0.3, 0.55, 0.3], "direction": [0, -1, 0], "radius": 0.04, "speed": 1.5}],
          "sinks": [{"shape": "box", "position": [0.05, 0.01, 0.05], "size": [0.04, 0.02, 0.04]}],
          "output": {"fps": 30, "frames": 60}})",
      "bench_pour");
  const std::unique_ptr<FluidSolver<3>> solver = makeFluidSolver<3>(scene);
  solver->setParticles(initialParticles(scene));
  FluidSources<3> sources(scene, static_cast<uint32_t>(solver->size()), 0.0);
  const float dt = float(1.0 / (scene.output.fps * scene.solver.substeps));
  double time = 0;
  // A third of a second first: the jet reaches the pool and the drain runs.
  const int warm = int(scene.output.fps * scene.solver.substeps / 3);
  for (int s = 0; s < warm; ++s) {
    solver->step(dt, time);
    time += dt;
    sources.apply(*solver, time);
  }
  std::vector<double> shares;
  double stepSeconds = 0, applySeconds = 0;
  // A reallocation shows as a buffer not seen before (PBF swaps two position buffers every step).
  std::vector<const void*> buffers = {solver->positions().data()};
  size_t growths = 0;
  const size_t before = solver->size();
  sources.emitted = sources.removed = 0;
  constexpr int kRounds = 8, kSteps = 10;
  for (int round = 0; round < kRounds; ++round) {
    double step = 0, apply = 0;
    for (int s = 0; s < kSteps; ++s) {
      auto start = BenchClock::now();
      solver->step(dt, time);
      step += secondsSince(start);
      time += dt;
      start = BenchClock::now();
      sources.apply(*solver, time);
      apply += secondsSince(start);
      const void* buffer = solver->positions().data();
      if (std::find(buffers.begin(), buffers.end(), buffer) == buffers.end()) {
        buffers.push_back(buffer);
        growths += buffers.size() > 2;
      }
    }
    shares.push_back(apply / (step + apply));
    stepSeconds += step;
    applySeconds += apply;
  }
  std::sort(shares.begin(), shares.end());
  const int steps = kRounds * kSteps;
  std::printf("| particles | steps | solver step (ms) | sources (ms) | share (median of %d rounds) | emitted | removed | "
              "reallocations |\n|---|---|---|---|---|---|---|---|\n",
              kRounds);
  std::printf("| %zu to %zu | %d | %.2f | %.3f | %.2f%% | %zu | %zu | %zu |\n", before, solver->size(), steps,
              1e3 * stepSeconds / steps, 1e3 * applySeconds / steps, 100 * shares[kRounds / 2], sources.emitted,
              sources.removed, growths);
  return 0;
}
