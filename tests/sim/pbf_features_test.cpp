// The optional terms of PBF: artificial pressure s_corr (eq. 13-14), vorticity confinement (eq. 15-16) and
// XSPH viscosity (eq. 17), each against the same run without it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "sim/pbf_solver.h"
#include "sim/simulation.h"

namespace surge {
namespace {

// A 2D tank with no gravity, large enough that the walls play no part.
Scene openTank(const std::vector<std::string>& overrides) {
  const char* json = R"({"name": "open", "dimensions": 2, "domain": {"min": [0, 0], "max": [2, 2]},
    "particle_spacing": 0.02, "fluids": [{"box": {"min": [0.8, 0.8], "max": [1.2, 1.2]}}], "gravity": [0, 0]})";
  return parseScene(json, "test", overrides);
}

float minimumPairDistance(const ParticleFrame& frame) {
  float best = INFINITY;
  for (size_t i = 0; i < frame.size(); ++i)
    for (size_t j = i + 1; j < frame.size(); ++j) best = std::min(best, (frame.position[i] - frame.position[j]).norm());
  return best;
}

// Runs `steps` steps of 1/120 s; `closest`, if given, receives the smallest pair distance seen after any step.
ParticleFrame run(const Scene& scene, ParticleFrame frame, int steps, float* closest = nullptr) {
  PbfSolver<2> solver(scene);
  solver.setParticles(frame);
  if (closest) *closest = minimumPairDistance(frame);
  for (int s = 0; s < steps; ++s) {
    EXPECT_EQ(solver.step(1.0f / 120), -1);
    solver.getParticles(frame);
    if (closest) *closest = std::min(*closest, minimumPairDistance(frame));
  }
  solver.getParticles(frame);
  return frame;
}

TEST(PbfFeatures, ArtificialPressureStopsClustering) {
  // Two sparse rows of particles (two spacings apart), 20 each, fly into each other at 0.25 m/s each, offset
  // by a tenth of a spacing. Two sparse rows are far too thin to reach the rest density, so the one-sided
  // density constraint never acts and particles of the two rows pass through each other. s_corr repels pairs
  // closer than the rest spacing and keeps them apart.
  ParticleFrame frame;
  frame.dimensions = 2;
  for (int row = 0; row < 2; ++row)
    for (int i = 0; i < 20; ++i) {
      frame.position.emplace_back(0.6f + 0.04f * i + 0.002f * row, 0.95f + 0.1f * row, 0.0f);
      frame.velocity.emplace_back(0.0f, row == 0 ? 0.25f : -0.25f, 0.0f);
      frame.id.push_back(static_cast<uint32_t>(frame.id.size()));
    }
  const float spacing = 0.02f;
  float without = 0, with = 0;
  run(openTank({"solver.scorr_k=0", "solver.xsph_c=0"}), frame, 40, &without);
  run(openTank({"solver.xsph_c=0"}), frame, 40, &with);
  EXPECT_LT(without, 0.2f * spacing) << "the test no longer makes particles cluster without s_corr";
  EXPECT_GT(with, 0.4f * spacing);
}

// Total vorticity sum_i |omega_i| with omega_i of eq. 15 over all pairs closer than h (brute force).
double totalVorticity(const ParticleFrame& frame, float h) {
  Kernels<2> kernels(h);
  double total = 0;
  for (size_t i = 0; i < frame.size(); ++i) {
    float omega = 0;
    for (size_t j = 0; j < frame.size(); ++j) {
      const Vec<2> r = (frame.position[i] - frame.position[j]).head<2>();
      const Vec<2> gradient = -kernels.spikyGradient(r, r.norm());  // with respect to p_j
      const Vec<2> vij = (frame.velocity[j] - frame.velocity[i]).head<2>();
      omega += vij.x() * gradient.y() - vij.y() * gradient.x();
    }
    total += std::abs(omega);
  }
  return total;
}

TEST(PbfFeatures, VorticityConfinementKeepsTheSwirl) {
  // A square of fluid spinning with a vortex in it: velocity (-y, x) w(r) around the centre, w falling off
  // with the radius. The solver's projection and XSPH damp the swirl; confinement feeds it back.
  const Scene base = openTank({});
  ParticleFrame frame = initialParticles(base);
  const Eigen::Vector3f centre(1, 1, 0);
  for (size_t i = 0; i < frame.size(); ++i) {
    const Eigen::Vector3f d = frame.position[i] - centre;
    frame.velocity[i] = Eigen::Vector3f(-d.y(), d.x(), 0) * (5.0f * std::exp(-d.squaredNorm() / 0.01f));
  }
  const float h = static_cast<float>(base.solver.kernel_radius);
  const double without = totalVorticity(run(openTank({}), frame, 30), h);
  // Since omega is the curl in 1/s (eq. 15 with the particle volume), epsilon is in m/s and the confinement's
  // acceleration is epsilon |omega|: at 0.5 m/s about 5 m/s^2 at the swirl's 10 1/s, over the 0.25 s run as
  // much as the swirl's own speed. Without it the total vorticity left varies by about 10% with round-off
  // (at epsilon 0.05 this build read 1.18 times it and the sanitizer build 1.03), so 30% more is asked for.
  // Measured: 1.90 times.
  const double with = totalVorticity(run(openTank({"solver.vorticity_epsilon=0.5"}), frame, 30), h);
  EXPECT_GT(with, 1.3 * without) << "with " << with << " without " << without;
}

// The particle-scale velocity noise XSPH acts on: the mean squared difference between each velocity and the
// kernel-weighted mean velocity of its neighbours (brute force).
double localVelocityVariance(const ParticleFrame& frame, float h) {
  Kernels<2> kernels(h);
  double variance = 0;
  for (size_t i = 0; i < frame.size(); ++i) {
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    double weights = 0;
    for (size_t j = 0; j < frame.size(); ++j) {
      const double w = kernels.poly6((frame.position[i] - frame.position[j]).squaredNorm());
      weighted += w * frame.velocity[j].cast<double>();
      weights += w;
    }
    variance += (frame.velocity[i].cast<double>() - weighted / weights).squaredNorm();
  }
  return variance / double(frame.size());
}

TEST(PbfFeatures, XsphSmoothsVelocities) {
  // Random velocities of 0.1 m/s on a resting block: XSPH (eq. 17) pulls each velocity towards its neighbours'.
  // The projection alone already damps some of the noise; XSPH must lower it further.
  const Scene base = openTank({});
  ParticleFrame frame = initialParticles(base);
  std::mt19937 random(5);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  for (auto& v : frame.velocity) v = Eigen::Vector3f(noise(random), noise(random), 0);
  // The default c = 0.01 blends each velocity about 0.7% towards its neighbours' per step (the weights m W / rho_0
  // of the neighbours sum to about 0.7 in 2D at h = 2 spacings), so over 40 steps the particle-scale variance
  // falls by a factor of about (1 - 0.007)^80 = 0.57 more than without; we ask for 0.9.
  const float h = static_cast<float>(base.solver.kernel_radius);
  const double without = localVelocityVariance(run(openTank({"solver.xsph_c=0"}), frame, 40), h);
  const double with = localVelocityVariance(run(openTank({}), frame, 40), h);
  EXPECT_LT(with, 0.9 * without) << "with " << with << " without " << without;
}

}  // namespace
}  // namespace surge
