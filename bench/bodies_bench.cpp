// The rigid bodies' share of a step (issue: rigid bodies), printed as a markdown table for docs/performance.md:
// 10 bodies (boxes and balls at half the water's density) floating in a pool of about 100,000 particles,
// stepped coupled (Bullet's step, the bodies' colliders, their forces; Bullet's world rebuilt every frame as the
// frame loop does) and, from the very same particle state, without bodies. The share is 1 - t_without / t_with,
// both timed in this process, a frame each in turn, the median over the rounds (bench/bench_timing.h).
// Run: build/bench/surge_bench_bodies [threads]   (default: all cores)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench/bench_timing.h"
#include "core/parallel.h"
#include "sim/pbf_solver.h"
#include "sim/rigid_bodies.h"
#include "sim/simulation.h"

namespace surge {
namespace {

Scene pool(const std::string& bodies) {
  return parseScene(R"({"name": "bench", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [0.6, 0.5, 0.6]},
    "particle_spacing": 0.01, "fluids": [{"box": {"min": [0, 0, 0], "max": [0.6, 0.32, 0.6]}}],
    "bodies": )" + bodies + "}",
                    "bench");
}

// Ten bodies on a 4 x 3 grid over the pool (two places left empty), boxes and balls in turn.
std::string tenBodies() {
  std::string list = "[";
  int count = 0;
  for (int i = 0; i < 4 && count < 10; ++i)
    for (int j = 0; j < 3 && count < 10; ++j, ++count) {
      const double x = 0.09 + 0.14 * i, z = 0.12 + 0.18 * j;
      char body[256];
      if (count % 2 == 0)
        std::snprintf(body, sizeof body,
                      R"({"shape": "box", "size": [0.08, 0.05, 0.08], "position": [%.3f, 0.33, %.3f], "density": 500})",
                      x, z);
      else
        std::snprintf(body, sizeof body,
                      R"({"shape": "sphere", "radius": 0.04, "position": [%.3f, 0.33, %.3f], "density": 500})", x, z);
      list += (count ? ", " : "") + std::string(body);
    }
  return list + "]";
}

}  // namespace
}  // namespace surge

int main(int argc, char** argv) {
  using namespace surge;
  const int threads = argc > 1 ? std::atoi(argv[1]) : 0;
  ThreadLimit limit(threads);
  const Scene withBodies = pool(tenBodies());
  const std::shared_ptr<const ColliderShapes> shapes = buildColliderShapes(withBodies);
  PbfSolver<3> with(withBodies, shapes);
  RigidBodies bodies(withBodies, shapes);
  {
    ParticleFrame initial = initialParticles(withBodies);
    removeParticlesInside(with.colliders(), initial);
    with.setParticles(initial);
  }
  const int substeps = withBodies.solver.substeps;
  const float dt = float(1.0 / (withBodies.output.fps * substeps));
  double time = 0;
  // Steps of the coupled pool, a frame (substeps steps) at a time, as the frame loop takes them.
  auto coupledFrames = [&](int frames) {
    const auto start = BenchClock::now();
    for (int f = 0; f < frames; ++f) {
      bodies.beginFrame(time);
      placeBodies(bodies, with.colliders());
      for (int s = 0; s < substeps; ++s) {
        long badBody = -1;
        coupledStep<3>(with, &bodies, dt, time, badBody);
        time += dt;
      }
      with.takeColliderWrenches(1.0 / withBodies.output.fps);
    }
    return secondsSince(start) / (frames * substeps);
  };
  coupledFrames(6);  // the bodies settle onto the water
  const Scene withoutBodies = pool("[]");
  PbfSolver<3> without(withoutBodies);
  // A frame without the bodies, from the coupled pool's state, then a frame with them, twelve times in turn.
  constexpr int kRounds = 12;
  std::vector<double> withTimes, withoutTimes;
  for (int round = 0; round < kRounds; ++round) {
    ParticleFrame state;
    with.getParticles(state);
    without.setParticles(state);
    double t0 = time;
    const auto start = BenchClock::now();
    for (int s = 0; s < substeps; ++s, t0 += dt) without.step(dt, t0);
    withoutTimes.push_back(secondsSince(start) / substeps);
    withTimes.push_back(coupledFrames(1));
  }
  const StepShare measured = stepShare(withTimes, withoutTimes);
  std::printf("| measure | value |\n|---|---|\n");
  std::printf("| threads | %d |\n", threads > 0 ? threads : ThreadLimit::available());
  std::printf("| particles | %zu |\n", with.size());
  std::printf("| bodies | %zu |\n", bodies.size());
  std::printf("| PBF step with the bodies (coupled, Bullet, world rebuilt each frame; median) | %.1f ms |\n",
              1e3 * measured.with);
  std::printf("| PBF step, same particles, no bodies (median) | %.1f ms |\n", 1e3 * measured.without);
  std::printf("| bodies' share of a step (median of %d rounds; quartiles) | %.1f%% (%.1f%% - %.1f%%) |\n", kRounds,
              100 * measured.share, 100 * measured.lowQuartile, 100 * measured.highQuartile);
  return 0;
}
