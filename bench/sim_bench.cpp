// Simulator benchmarks (issue: PBF solver). Counters:
//   particle_iterations/s  particles x substeps x iterations per CPU-second of all threads (per core),
//                          over whole steps (all phases); the Time column is process CPU time
//   bytes_per_particle     the process's peak resident memory, less what it held before the scene was made,
//                          over the particle count (includes the initial particle frame and every channel;
//                          only meaningful for the first run of a size: the peak is the process's)
//   solver_bytes_per_particle  what the solver holds after the run (capacities of all its arrays), exact
// Run: build/bench/surge_bench_sim [--benchmark_filter=...]
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <random>

#include "core/parallel.h"
#include "sim/neighbor_grid.h"
#include "sim/pbf_solver.h"
#include "sim/simulation.h"

namespace surge {
namespace {

// A 3D dam break of about `particles` particles: a block of 1 x 2 x 1 aspect in a tank 4 x 2.5 x 1 times its
// width, 4 substeps, 4 iterations (the issue's configuration). Without the warm start, whose one correction a
// step is not a Jacobi iteration: the rate is that of the iterations alone (the warm start's worth is fewer of
// them, measured by scripts/bench_peers.sh).
Scene damBreak(double particles) {
  const double spacing = std::cbrt(2.0 / particles) * 0.5;  // block 0.5 x 1 x 0.5 m
  const std::string json = R"({"name": "bench", "dimensions": 3,
    "domain": {"min": [0, 0, 0], "max": [2, 1.25, 0.5]}, "particle_spacing": )" +
                           std::to_string(spacing) + R"(,
    "fluids": [{"box": {"min": [0, 0, 0], "max": [0.5, 1, 0.5]}}],
    "solver": {"substeps": 4, "iterations": 4, "warm_start": 0}})";
  return parseScene(json, "bench");
}

size_t peakResidentBytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<size_t>(usage.ru_maxrss) * 1024;
}

size_t currentResidentBytes() {
  long pages = 0, resident = 0;
  if (FILE* statm = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(statm, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(statm);
  }
  return static_cast<size_t>(resident) * static_cast<size_t>(sysconf(_SC_PAGESIZE));
}

void BM_PbfDamBreak(benchmark::State& state) {
  ThreadLimit threads(static_cast<int>(state.range(1)));
  // Memory is measured from here: the process's own baseline (runtime, thread pool) is not the particles'.
  // Runs go from small to large, so the peak seen at the end belongs to this run.
  const size_t baseline = currentResidentBytes();
  const Scene scene = damBreak(static_cast<double>(state.range(0)));
  PbfSolver<3> solver(scene);
  solver.setParticles(initialParticles(scene));
  const float dt = static_cast<float>(1.0 / (scene.output.fps * scene.solver.substeps));
  // Let the dam collapse for a few frames first, so the measured steps see a moving, splashing fluid.
  for (int s = 0; s < 8; ++s) solver.step(dt);
  size_t iterations = 0;
  for (auto _ : state) {
    for (int s = 0; s < scene.solver.substeps; ++s) {
      solver.step(dt);
      iterations += static_cast<size_t>(solver.lastIterations());
    }
  }
  state.counters["particles"] = static_cast<double>(solver.size());
  state.counters["particle_iterations/s"] =
      benchmark::Counter(static_cast<double>(iterations * solver.size()), benchmark::Counter::kIsRate);
  state.counters["bytes_per_particle"] = static_cast<double>(peakResidentBytes() - baseline) / solver.size();
  state.counters["solver_bytes_per_particle"] = static_cast<double>(solver.memoryBytes()) / solver.size();
}
BENCHMARK(BM_PbfDamBreak)
    ->Args({100000, 1})
    ->Args({100000, 2})
    ->Args({1000000, 2})
    ->ArgNames({"particles", "threads"})->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// PBF's choice of step (PbfSolver::stableTimeStep: the fastest particle and the deepest column), which the frame
// loop asks before every step, beside the step itself, on the dam break above at 100k particles: the counter
// `share` is its time over the step's.
void BM_PbfStableTimeStep(benchmark::State& state) {
  ThreadLimit threads(static_cast<int>(state.range(0)));
  const Scene scene = damBreak(100000);
  PbfSolver<3> solver(scene);
  solver.setParticles(initialParticles(scene));
  const float dt = static_cast<float>(1.0 / (scene.output.fps * scene.solver.substeps));
  for (int s = 0; s < 8; ++s) solver.step(dt);
  double choosing = 0, stepping = 0;
  float stable = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    stable += solver.stableTimeStep();
    const auto chosen = std::chrono::steady_clock::now();
    solver.step(dt);
    choosing += std::chrono::duration<double>(chosen - start).count();
    stepping += std::chrono::duration<double>(std::chrono::steady_clock::now() - chosen).count();
  }
  benchmark::DoNotOptimize(stable);
  state.counters["share"] = choosing / stepping;
}
BENCHMARK(BM_PbfStableTimeStep)->Arg(1)->Arg(2)->ArgNames({"threads"})->Unit(benchmark::kMillisecond)->Iterations(40);

// Rebuilding the grid for 1M particles (sort into cells + reorder the positions), and, separately, building
// their neighbour lists. Spread: a jittered lattice at fluid density (spacing h / 2, about 30 neighbours)
// filling a 1 m tank. Piled: the same particles settled into one corner of a tank 8 times as wide (512 times
// the volume), the assignment's worst case for a spatial hash.
std::vector<Vec<3>> latticeParticles(size_t n, float spacing, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> jitter(-0.05f * spacing, 0.05f * spacing);
  const int perSide = static_cast<int>(std::ceil(std::cbrt(double(n))));
  std::vector<Vec<3>> x(n);
  for (size_t i = 0; i < n; ++i) {
    const int a = i % perSide, b = (i / perSide) % perSide, c = static_cast<int>(i / (perSide * perSide));
    x[i] = (Vec<3>(a, b, c) + Vec<3>::Constant(0.5f)) * spacing + Vec<3>(jitter(random), jitter(random), jitter(random));
  }
  std::shuffle(x.begin(), x.end(), random);
  return x;
}

void BM_GridRebuild(benchmark::State& state) {
  const bool piled = state.range(0) == 1;
  const std::vector<Vec<3>> x = latticeParticles(1000000, 0.01f, 7);
  NeighborGrid<3> grid(Vec<3>(0, 0, 0), Vec<3>::Constant(piled ? 8.0f : 1.0f), 0.02f);
  std::vector<Vec<3>> sorted, scratch;
  for (auto _ : state) {
    grid.sort(x);
    sorted = x;
    gatherByOrder(grid.sortedOrder(), sorted, scratch);
    benchmark::DoNotOptimize(sorted.data());
  }
  state.counters["cells"] = double(grid.cellCount());
}
BENCHMARK(BM_GridRebuild)->Arg(0)->Arg(1)->ArgNames({"piled"})->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

void BM_NeighborLists(benchmark::State& state) {
  const bool piled = state.range(0) == 1;
  std::vector<Vec<3>> x = latticeParticles(1000000, 0.01f, 7), scratch;
  const float cellSize = state.range(1) == 2 ? 0.01f : 0.02f;
  NeighborGrid<3> grid(Vec<3>(0, 0, 0), Vec<3>::Constant(piled ? 8.0f : 1.0f), cellSize);
  grid.sort(x);
  gatherByOrder(grid.sortedOrder(), x, scratch);
  NeighborLists lists;
  grid.findNeighbors(x, 0.02f, lists);  // warm-up: the lists keep their capacity, as in a run
  for (auto _ : state) {
    grid.findNeighbors(x, 0.02f, lists);
    benchmark::DoNotOptimize(lists.ends.data());
  }
  state.counters["neighbors/particle"] = double(lists.total()) / double(x.size());
}
BENCHMARK(BM_NeighborLists)->Args({0, 1})->Args({0, 2})->Args({1, 1})->ArgNames({"piled", "cells_per_radius"})->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

}  // namespace
}  // namespace surge

BENCHMARK_MAIN();
