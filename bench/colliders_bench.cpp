// Colliders' costs (issue: colliders), printed as a markdown table for docs/performance.md:
//  - baking a mesh of 100,000 triangles (a torus) into its distance field, as `surge sim` does when it reads
//    the scene (read the OBJ, check it is closed, OpenVDB's mesh to volume, copy to the dense grid), wall time;
//  - the colliders' share of a PBF step: 100,000 particles in a pool with that torus lying in the water, stepped
//    with the collider and, from the very same particle state, without it; the share is 1 - t_without /
//    t_with, both timed in this process, four steps each in turn, the median over the rounds; at rest after a
//    second, and while the water settles at the start;
//  - the memory the collider holds.
// Run: build/bench/surge_bench_colliders [threads]   (default: all cores)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

#include "bench/bench_timing.h"
#include "core/parallel.h"
#include "sim/pbf_solver.h"
#include "sim/simulation.h"

namespace surge {
namespace {

// A torus about the y axis (major radius R, minor r), u x v quads as 2 u v triangles, written as OBJ.
void writeTorusObj(const fs::path& path, double major, double minor, int u, int v) {
  std::ofstream out(path);
  for (int i = 0; i < u; ++i)
    for (int j = 0; j < v; ++j) {
      const double a = 2 * M_PI * i / u, b = 2 * M_PI * j / v;
      const double ring = major + minor * std::cos(b);
      out << "v " << ring * std::cos(a) << " " << minor * std::sin(b) << " " << ring * std::sin(a) << "\n";
    }
  auto index = [&](int i, int j) { return (i % u) * v + (j % v) + 1; };
  for (int i = 0; i < u; ++i)
    for (int j = 0; j < v; ++j) {
      out << "f " << index(i, j) << " " << index(i, j + 1) << " " << index(i + 1, j + 1) << "\n";
      out << "f " << index(i, j) << " " << index(i + 1, j + 1) << " " << index(i + 1, j) << "\n";
    }
}

Scene pool(const std::string& colliders) {
  return parseScene(R"({"name": "bench", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [0.6, 0.5, 0.6]},
    "particle_spacing": 0.01, "fluids": [{"box": {"min": [0, 0, 0], "max": [0.6, 0.32, 0.6]}}],
    "colliders": )" + colliders + "}",
                    "bench");
}

// Steps of the scene's own length (the frame over its resolved substeps), as `surge sim` takes them.
template <typename Solver>
double timeSteps(Solver& solver, const Scene& scene, int steps, double& time) {
  const float dt = float(1.0 / (scene.output.fps * scene.solver.substeps));
  const auto start = BenchClock::now();
  for (int s = 0; s < steps; ++s) {
    solver.step(dt, time);
    time += dt;
  }
  return secondsSince(start) / steps;
}

}  // namespace
}  // namespace surge

int main(int argc, char** argv) {
  using namespace surge;
  const int threads = argc > 1 ? std::atoi(argv[1]) : 0;
  ThreadLimit limit(threads);
  const fs::path obj = fs::temp_directory_path() / "surge_bench_torus.obj";
  writeTorusObj(obj, 0.15, 0.06, 250, 200);  // 100,000 triangles
  const std::string collider =
      R"([{"name": "torus", "shape": "mesh", "file": ")" + obj.string() + R"(", "position": [0.3, 0.1, 0.3]}])";
  const Scene withMesh = pool(collider);

  auto start = BenchClock::now();
  const std::shared_ptr<const ColliderShapes> shapes = buildColliderShapes(withMesh);
  const double bake = secondsSince(start);
  const ColliderShape& torus = shapes->front();

  PbfSolver<3> with(withMesh, shapes);
  {
    ParticleFrame initial = initialParticles(withMesh);
    removeParticlesInside(with.colliders(), initial);
    with.setParticles(initial);
  }
  double time = 0;
  const Scene withoutMesh = pool("[]");
  PbfSolver<3> without(withoutMesh);
  // Four steps without the collider from the pool's state, then four with it, twelve times in turn.
  constexpr int kRounds = 12;
  auto measureShare = [&] {
    std::vector<double> withTimes, withoutTimes;
    for (int round = 0; round < kRounds; ++round) {
      ParticleFrame state;
      with.getParticles(state);
      without.setParticles(state);
      double t0 = time, t1 = time;
      withoutTimes.push_back(timeSteps(without, withoutMesh, 4, t0));
      withTimes.push_back(timeSteps(with, withMesh, 4, t1));
      time = t1;
    }
    return stepShare(withTimes, withoutTimes);
  };
  // From the start, while the water settles onto the torus (its first 48 steps, 0.23 s: the column compresses
  // under its weight and flows round the torus); then at rest, after a second in all. (Until 2026-11-30 the
  // steps were 1/120 s, longer than this scene's stable 1/210 s: the pool boiled, its mean speed 1.5 m/s and
  // rising, and that was what the share measured.)
  const StepShare settling = measureShare();
  const int secondOfSteps = int(withMesh.output.fps) * withMesh.solver.substeps;
  timeSteps(with, withMesh, secondOfSteps - 4 * kRounds, time);
  const StepShare measured = measureShare();
  std::printf("| measure | value |\n|---|---|\n");
  std::printf("| threads | %d |\n", threads > 0 ? threads : ThreadLimit::available());
  std::printf("| mesh triangles | %zu |\n", torus.mesh.triangles.size());
  std::printf("| bake: read OBJ, check closed, mesh to distance grid | %.2f s |\n", bake);
  std::printf("| distance grid | %d x %d x %d voxels of %.4f m, %.1f MB |\n", torus.grid.counts()[0],
              torus.grid.counts()[1], torus.grid.counts()[2], torus.grid.voxel(), torus.memoryBytes() / 1e6);
  std::printf("| particles | %zu |\n", with.size());
  std::printf("| step | 1/%d s (%d substeps a frame) |\n", int(withMesh.output.fps) * withMesh.solver.substeps,
              withMesh.solver.substeps);
  std::printf("| PBF step with the torus (median) | %.1f ms |\n", 1e3 * measured.with);
  std::printf("| PBF step, same particles, no collider (median) | %.1f ms |\n", 1e3 * measured.without);
  std::printf("| colliders' share of a step (median of %d rounds; quartiles) | %.1f%% (%.1f%% - %.1f%%) |\n",
              kRounds, 100 * measured.share, 100 * measured.lowQuartile, 100 * measured.highQuartile);
  std::printf("| the same while the water settles (its first %d steps) | %.1f%% (%.1f%% - %.1f%%), %.1f ms |\n",
              4 * kRounds, 100 * settling.share, 100 * settling.lowQuartile, 100 * settling.highQuartile,
              1e3 * settling.with);
  fs::remove(obj);
  return 0;
}
