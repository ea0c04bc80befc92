#include "sim/colliders.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sim/particle_solver.h"
#include "sim/pbf_solver.h"
#include "sim/simulation.h"
#include "sim/fluid_solver.h"
#include "sim/wcsph_solver.h"

namespace surge {
namespace {

// A scene: the tank `domain`, fluid boxes and colliders as JSON, spacing h.
Scene makeScene(int dimensions, const std::string& domain, const std::string& fluids, const std::string& colliders,
                double spacing, const std::vector<std::string>& overrides = {}) {
  const std::string json = R"({"name": "c", "dimensions": )" + std::to_string(dimensions) + R"(, "domain": )" +
                           domain + R"(, "particle_spacing": )" + std::to_string(spacing) + R"(, "fluids": )" +
                           fluids + R"(, "colliders": )" + colliders + "}";
  Scene scene = parseScene(json, "test.json", overrides);
  return scene;
}

// The scene's initial particles less those inside its colliders, as `surge sim` starts them.
template <int Dim>
ParticleFrame withoutInside(const Scene& scene, const Colliders<Dim>& colliders, size_t* removed = nullptr) {
  ParticleFrame frame = initialParticles(scene);
  const size_t count = removeParticlesInside(colliders, frame);
  if (removed) *removed = count;
  return frame;
}

// Runs a solver for `seconds` as the frame loop does (PBF: the scene's substeps; WCSPH: its stable steps, ending
// on each frame); returns the last frame's mean wrenches.
template <typename Solver>
std::vector<Wrench> runFor(Solver& solver, const Scene& scene, double seconds, double& time) {
  const int frames = int(std::round(seconds * scene.output.fps));
  const double frame = 1.0 / scene.output.fps;
  std::vector<Wrench> wrenches;
  for (int f = 0; f < frames; ++f) {
    solver.beginFrame(time);
    double remaining = frame;
    while (remaining > 0) {
      const double count = solver.fixedSubsteps() > 0
                               ? double(solver.fixedSubsteps())
                               : std::max(1.0, std::ceil(remaining / solver.stableTimeStep() - 1e-9));
      const float dt = float(solver.fixedSubsteps() > 0 ? frame / count : remaining / count);
      EXPECT_EQ(solver.step(dt, time), -1) << "at t = " << time;
      time += dt;
      remaining = solver.fixedSubsteps() > 0 ? remaining - dt : (count == 1 ? 0 : remaining - dt);
      if (solver.fixedSubsteps() > 0 && remaining < 0.5 * dt) remaining = 0;
    }
    wrenches = solver.takeColliderWrenches(frame);
  }
  return wrenches;
}

// The smallest signed distance of any particle to any collider, in particle radii.
template <int Dim, typename Solver>
float closestApproach(const Solver& solver) {
  float closest = INFINITY;
  for (const Vec<Dim>& p : solver.positions())
    for (size_t c = 0; c < solver.colliders().size(); ++c) {
      Vec<Dim> n;
      closest = std::min(closest, solver.colliders().distance(c, p, n) / solver.colliders().particleRadius());
    }
  return closest;
}

// Fluid placed inside a collider is removed at set-up, exactly the lattice points closer to the solid than 0.99
// of a particle radius (a fluid box drawn against a wall keeps its layer): counted here independently from the
// lattice and the ball's closed form, |p - c| < r + 0.99 h / 2, and compared point for point with what is
// kept. A ball of radius 0.1 in a block of spacing 0.01 holds about 4/3 pi 0.1^3 / 0.01^3 = 4189 lattice points
// and a shell of 0.495 spacings more.
TEST(Colliders, FluidInsideIsRemoved) {
  const Scene scene = makeScene(3, R"({"min": [0, 0, 0], "max": [0.4, 0.4, 0.4]})",
                                R"([{"box": {"min": [0, 0, 0], "max": [0.4, 0.4, 0.4]}}])",
                                R"([{"shape": "sphere", "position": [0.2, 0.2, 0.2], "radius": 0.1}])", 0.01);
  PbfSolver<3> solver(scene);
  size_t removed = 0;
  const ParticleFrame kept = withoutInside<3>(scene, solver.colliders(), &removed);
  const ParticleFrame all = initialParticles(scene);
  const Eigen::Vector3d centre(0.2, 0.2, 0.2);
  std::vector<Eigen::Vector3f> expected;
  for (const Eigen::Vector3f& p : all.position)
    if ((p.cast<double>() - centre).norm() >= 0.1 + 0.99 * 0.005) expected.push_back(p);
  EXPECT_EQ(removed, all.size() - expected.size());
  ASSERT_EQ(kept.size(), expected.size());
  for (size_t i = 0; i < kept.size(); ++i) {
    ASSERT_EQ(kept.position[i], expected[i]) << "particle " << i;
    ASSERT_EQ(kept.id[i], uint32_t(i)) << "ids are renumbered";
  }
  const double ball = 4.0 / 3.0 * M_PI * std::pow(0.1, 3) / std::pow(0.01, 3);
  EXPECT_GT(double(removed), ball);
}

// A box counts the rest lattice continued into its solid exactly, beside a face, along an edge, at a corner and
// on both sides of a plate thinner than the support (Colliders::boxTerms): its share of the density sum, of the
// gradient sum and of WCSPH's hydrostatic wall pressure equals the sum over the lattice points inside it. The
// box is turned 30 degrees about (1, 2, 3); the particle and the lattice stand in its frame with every face
// half-way between two lattice planes, so the distances fall on nodes of the tank's tables and the two agree to
// float rounding (1e-4 of the interior sum). The flat wall the other shapes use counts a half-space beyond the
// nearest point instead: beside the edge it reads 0.26 of the interior sum where the box holds 0.070.
TEST(Colliders, BoxCountsTheLatticeInsideItExactly) {
  const float h = 0.05f;
  struct Case {
    const char* where;
    Eigen::Vector3f halfExtents, local;  // in spacings
    bool hydrostatic;                    // a corner's eighth has no moments in the tables
  };
  const Case cases[] = {
      {"beside a face", {2, 3, 4}, {2.5f, 0.5f, 0.5f}, true},
      {"beside a face near an edge", {2, 3, 4}, {2.5f, 2.5f, 0.5f}, true},
      {"beyond an edge", {2, 3, 4}, {2.5f, 3.5f, 0.5f}, true},
      {"beyond a corner", {2, 3, 4}, {2.5f, 3.5f, 4.5f}, false},
      {"beside a face near a corner", {2, 3, 4}, {2.5f, 2.5f, 3.5f}, false},
      {"above a plate one spacing thick", {6, 6, 0.5f}, {0.5f, 1.5f, 1}, true},
      {"beyond a plate's edge", {6, 6, 0.5f}, {6.5f, 0.5f, 1}, true},
  };
  const Eigen::Vector3f centre(0.5f, 0.5f, 0.5f), axis = Eigen::Vector3f(1, 2, 3).normalized();
  const Eigen::Matrix3f rotation = Eigen::AngleAxisf(float(30 * M_PI / 180), axis).toRotationMatrix();
  const Vec<3> gravity(0, -9.81f, 0);
  for (const Case& c : cases) {
    const Eigen::Vector3f size = 2 * h * c.halfExtents;
    const Scene scene = makeScene(
        3, R"({"min": [0, 0, 0], "max": [1, 1, 1]})", R"([{"box": {"min": [0, 0, 0], "max": [0.2, 0.2, 0.2]}}])",
        R"([{"shape": "box", "position": [0.5, 0.5, 0.5], "rotation": {"axis": [1, 2, 3], "degrees": 30}, "size": [)" +
            std::to_string(size.x()) + ", " + std::to_string(size.y()) + ", " + std::to_string(size.z()) + "]}]",
        h, {"solver.method=wcsph", "solver.kernel_radius=" + std::to_string(4 * h)});
    WcsphSolver<3> solver(scene);
    Colliders<3>& colliders = solver.colliders();
    colliders.beginStep(0, 0.001f);
    const CubicSplineKernel<3> kernel(float(scene.solver.kernel_radius));
    const Vec<3> p = centre + rotation * (h * c.local);
    float weight = 0, exactWeight = 0;
    Vec<3> gradient = Vec<3>::Zero(), exactGradient = Vec<3>::Zero(), exactHydrostatic = Vec<3>::Zero();
    for (int i = -4; i <= 4; ++i)
      for (int j = -4; j <= 4; ++j)
        for (int k = -4; k <= 4; ++k) {  // the support is 4 spacings
          const Eigen::Vector3f local = c.local + Eigen::Vector3f(float(i), float(j), float(k));
          if ((local.cwiseAbs().array() >= c.halfExtents.array()).any()) continue;  // not inside the box
          const Vec<3> b = centre + rotation * (h * local), r = p - b;
          exactWeight += kernel.value(r.norm());
          const Vec<3> g = kernel.gradientFactor(r.norm()) * r;
          exactGradient += g;
          exactHydrostatic += gravity.dot(b - p) * g;
        }
    Vec<3> n;
    const float d = colliders.distance(0, p, n);
    ASSERT_GT(d, 0) << c.where;
    colliders.wallTerms(0, p, d, n, weight, gradient);
    double interior = 0, unused = 0;
    latticeSums<3>(h, float(scene.solver.kernel_radius), [&](const Vec<3>& r) { return kernel.value(r.norm()); },
                   [&](const Vec<3>& r) -> Vec<3> { return kernel.gradientFactor(r.norm()) * r; }, &interior,
                   &unused);
    EXPECT_NEAR(weight, exactWeight, 1e-4 * interior) << c.where;
    EXPECT_NEAR((gradient - exactGradient).norm(), 0.0, 1e-4 * interior / h) << c.where;
    if (c.hydrostatic) {
      EXPECT_NEAR((colliders.hydrostaticSum(0, p, d, n, gravity) - exactHydrostatic).norm(), 0.0,
                  1e-4 * interior * 9.81) << c.where;
    }
    float flatWeight, flatGradient;
    sphRestLattice<3>(scene).walls.flatWall().lookup(d, flatWeight, flatGradient);
    std::printf("%-32s weight %.4f of the interior sum (exact %.4f, a flat wall at the nearest point %.4f)\n",
                c.where, weight / interior, exactWeight / interior, flatWeight / interior);
  }
}

// The thin plate: a box one spacing thick across the whole tank (through its walls) under a column of water
// thrown down at 10 m/s. Nothing may pass, through the plate or where it meets the walls: every particle stays
// above it, at least a radius minus a thousandth of a spacing (float rounding of the projection) from it.
// What a particle skips, it would have found nothing in (Colliders::farFrom, Found, nothingStops, carry): at
// points about every shape (a tilted box, a ball, a capsule, a cylinder, a box moving over the step), checked
// against the distances themselves, sampled along each move:
//  - a point its cell marks far lies two radii beyond the support, and a move that moveFarFrom passes stays
//    beyond the support;
//  - what add found bounds every collider's distance from below and counts those within the support;
//  - a move that nothingStops passes keeps a radius from every collider;
//  - a bound carried along moves leaves every collider beyond the support where clearOfSupport holds, and a
//    radius from every point of a move that nothingStops passes on it.
// Each was seen failing: with no margin for the far cells, with carry not taking the move off (of a bound clear
// of the support, and of one within it), and with nothingStops leaving out the radius.
TEST(Colliders, WhatAParticleSkipsItWouldFindNothingIn) {
  const Scene scene = makeScene(3, R"({"min": [0, 0, 0], "max": [1, 1, 1]})",
                                R"([{"box": {"min": [0, 0, 0], "max": [0.1, 0.1, 0.1]}}])", R"([
      {"shape": "box", "position": [0.3, 0.3, 0.3], "size": [0.2, 0.1, 0.15],
       "rotation": {"axis": [1, 1, 0], "degrees": 30}},
      {"shape": "sphere", "position": [0.7, 0.3, 0.3], "radius": 0.08},
      {"shape": "capsule", "position": [0.3, 0.7, 0.7], "radius": 0.05, "height": 0.2,
       "rotation": {"axis": [0, 0, 1], "degrees": 60}},
      {"shape": "cylinder", "position": [0.7, 0.7, 0.7], "radius": 0.06, "height": 0.15},
      {"shape": "box", "size": [0.05, 0.2, 0.2],
       "motion": [{"time": 0, "position": [0.5, 0.5, 0.2]}, {"time": 1, "position": [0.5, 0.5, 0.8]}]}])",
                                0.02);
  PbfSolver<3> solver(scene);
  Colliders<3>& colliders = solver.colliders();
  colliders.beginStep(0.5, 1.0f / 60);  // the moving box sweeps 1 cm over this step
  const float support = static_cast<float>(scene.solver.kernel_radius), radius = colliders.particleRadius();
  auto leastDistance = [&](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {  // over the move a -> b
    float least = INFINITY;
    for (int k = 0; k <= 16; ++k)
      for (size_t c = 0; c < colliders.size(); ++c) {
        Eigen::Vector3f n;
        least = std::min(least, colliders.distance(c, a + (k / 16.0f) * (b - a), n));
      }
    return least;
  };
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(-1, 1);
  auto offset = [&](float length) -> Eigen::Vector3f {
    const float x = unit(random), y = unit(random), z = unit(random);
    return length * Eigen::Vector3f(x, y, z);
  };
  const Eigen::Vector3f centres[] = {{0.3f, 0.3f, 0.3f}, {0.7f, 0.3f, 0.3f}, {0.3f, 0.7f, 0.7f}, {0.7f, 0.7f, 0.7f},
                                     {0.5f, 0.5f, 0.5f}};
  int farPoints = 0, far = 0, near = 0, unstopped = 0, carried = 0, carriedUnstopped = 0;
  for (int sample = 0; sample < 40000; ++sample) {
    const Eigen::Vector3f p = centres[sample % 5] + offset(0.25f);
    const Eigen::Vector3f q = p + offset(sample % 2 ? 3 * radius : 0.3f * radius);
    // A far point is far enough that any move to it that moveFarFrom passes (under two radii) stays beyond the
    // support.
    if (colliders.farFrom(p)) {
      ++farPoints;
      ASSERT_GE(leastDistance(p, p), support + 2 * radius) << "far point " << p.transpose();
    }
    if (colliders.moveFarFrom(p, q)) {
      ++far;
      ASSERT_GE(leastDistance(p, q), support) << "far move " << p.transpose() << " -> " << q.transpose();
    }
    float weight = 0;
    Eigen::Vector3f gradient = Eigen::Vector3f::Zero(), onlyGradient;
    Colliders<3>::Found found;
    colliders.add(p, weight, gradient, found, onlyGradient);
    int within = 0;
    for (size_t c = 0; c < colliders.size(); ++c) {
      Eigen::Vector3f n;
      const float d = colliders.distance(c, p, n);
      ASSERT_GE(d, found.clearance) << "collider " << c << " at " << p.transpose();
      within += d < support;
    }
    ASSERT_EQ(found.count, within) << p.transpose();
    near += within > 0;
    if (colliders.nothingStops(found, p, q)) {
      ++unstopped;
      ASSERT_GE(leastDistance(p, q), radius) << "unstopped move " << p.transpose() << " -> " << q.transpose();
    }
    // Carried along a walk of small moves: where it says the particle is clear of the support, it is, and a
    // move that it lets pass unswept keeps a radius from every collider.
    Eigen::Vector3f at = p;
    for (int step = 0; step < 8; ++step) {
      const Eigen::Vector3f next = at + offset(0.5f * radius);
      if (colliders.nothingStops(found, at, next)) {
        ++carriedUnstopped;
        ASSERT_GE(leastDistance(at, next), radius) << "carried, unstopped " << at.transpose();
      }
      colliders.carry(found, at, next);
      at = next;
      if (!colliders.clearOfSupport(found)) continue;
      ++carried;
      ASSERT_GE(leastDistance(at, at), support) << "carried to " << at.transpose();
    }
  }
  // Every kind of skip was exercised, and points near the colliders too.
  EXPECT_GT(farPoints, 1000);
  EXPECT_GT(far, 1000);
  EXPECT_GT(near, 1000);
  EXPECT_GT(unstopped, 1000);
  EXPECT_GT(carried, 1000);
  EXPECT_GT(carriedUnstopped, 1000);
  std::printf("far points %d, far moves %d, near points %d, unstopped moves %d, carried steps %d (clear) and %d "
              "(unstopped) of 40000 samples\n",
              farPoints, far, near, unstopped, carried, carriedUnstopped);
}

TEST(Colliders, ThinPlateHoldsAFastColumn) {
  const Scene scene = makeScene(3, R"({"min": [0, 0, 0], "max": [0.3, 0.8, 0.3]})",
                                R"([{"box": {"min": [0, 0.45, 0], "max": [0.3, 0.75, 0.3]}, "velocity": [0, -10, 0]}])",
                                R"([{"shape": "box", "position": [0.15, 0.3, 0.15], "size": [0.4, 0.02, 0.4]}])", 0.02);
  PbfSolver<3> solver(scene);
  solver.setParticles(withoutInside<3>(scene, solver.colliders()));
  double time = 0;
  float lowest = INFINITY, closest = INFINITY;
  for (int frame = 0; frame < 30; ++frame) {
    runFor(solver, scene, 1.0 / 30, time);
    for (const Eigen::Vector3f& p : solver.positions()) lowest = std::min(lowest, p.y());
    closest = std::min(closest, closestApproach<3>(solver));
  }
  EXPECT_GT(lowest, 0.31f + 0.01f - 0.001f * 0.02f) << "a particle got through the plate";
  EXPECT_GT(closest, 1.0f - 0.05f);
}

// Rest against a shape: a pool 20 spacings deep with the collider in it settles for 2 s; then, over 1 s:
//  - the motion and the average density error are no worse than the same pool's without the collider (PBF at
//    its default 4 substeps x 4 iterations leaves a 20-deep pool about 4% compressed and trembling at an RMS
//    speed of about 0.03 m/s; the collider must not add to that): the RMS speed within twice the pool's (a
//    pool's tremble differs from one shape of it to another by up to half: measured 0.87 to 1.48 times), the
//    error within 0.5% more. The fastest single particle, at the contact line where the free surface meets
//    the collider, within 3 times the pool's own fastest. The pool's fastest is the most of four runs whose
//    gravity differs in its fifth digit: one run's is a single particle's luck (0.14 to 0.69 m/s over 16 such
//    runs, in two builds), the most of four 0.33 to 0.69. A collider that pumps energy shows in
//    ImpactOnAPlaneIsAnImpactOnTheFloor below;
//  - no particle is inside the collider (closer than 0.95 radii);
//  - the fluid touching the collider has the interior's number density, neither a gap nor a pile: the particles
//    within 3 spacings of the surface against the count the lattice puts in that band (its area, measured on a
//    fine grid, over spacing^2), within 8%. A gap of half a spacing all along would be -17%, one layer piled
//    up +33%. (A band of one or two spacings aliases with the lattice's layers: +-30% on a plane.)
struct RestCase {
  std::string name, collider;
};

struct PoolMotion {
  float fastest = 0;
  double rmsSpeed = 0, densityError = 0;
};

template <typename Solver>
PoolMotion settleAndWatch(Solver& solver, const Scene& scene) {
  double time = 0;
  runFor(solver, scene, 2.0, time);
  PoolMotion m;
  constexpr int kFrames = 30;
  for (int frame = 0; frame < kFrames; ++frame) {
    runFor(solver, scene, 1.0 / 30, time);
    for (const auto& v : solver.velocities()) {
      m.fastest = std::max(m.fastest, v.norm());
      m.rmsSpeed += v.squaredNorm() / (double(kFrames) * solver.size());
    }
    m.densityError += solver.measure().densityErrorAvg / kFrames;
  }
  m.rmsSpeed = std::sqrt(m.rmsSpeed);
  return m;
}

const char* kPool2d = R"({"min": [0, 0], "max": [1, 0.6]})";
const char* kPoolWater2d = R"([{"box": {"min": [0, 0], "max": [1, 0.4]}}])";

// The pool without colliders over four runs: the most of their fastest, the RMS speed and error of them all.
const PoolMotion& poolWithoutColliders() {
  static const PoolMotion motion = [] {
    PoolMotion pooled;
    constexpr int kRuns = 4;
    for (int run = 0; run < kRuns; ++run) {
      const Scene scene =
          makeScene(2, kPool2d, kPoolWater2d, "[]", 0.02, {"gravity=[0,-9.81" + std::to_string(run) + "]"});
      PbfSolver<2> solver(scene);
      solver.setParticles(initialParticles(scene));
      const PoolMotion one = settleAndWatch(solver, scene);
      pooled.fastest = std::max(pooled.fastest, one.fastest);
      pooled.rmsSpeed += one.rmsSpeed * one.rmsSpeed / kRuns;
      pooled.densityError += one.densityError / kRuns;
    }
    pooled.rmsSpeed = std::sqrt(pooled.rmsSpeed);
    return pooled;
  }();
  return motion;
}

class RestAgainst : public ::testing::TestWithParam<RestCase> {};

TEST_P(RestAgainst, Shape) {
  const double h = 0.02;
  const Scene scene = makeScene(2, kPool2d, kPoolWater2d, "[" + GetParam().collider + "]", h);
  PbfSolver<2> solver(scene);
  solver.setParticles(withoutInside<2>(scene, solver.colliders()));
  const PoolMotion motion = settleAndWatch(solver, scene);
  const PoolMotion& reference = poolWithoutColliders();
  EXPECT_LT(motion.rmsSpeed, 2.0 * reference.rmsSpeed) << GetParam().name;
  EXPECT_LT(motion.fastest, 3.0f * reference.fastest) << GetParam().name;
  EXPECT_LT(motion.densityError, reference.densityError + 0.005) << GetParam().name;
  EXPECT_GT(closestApproach<2>(solver), 0.95f) << GetParam().name;
  // The band's area: points of the fluid region (away from the side walls and the floor, below the surface)
  // within 3 spacings of the collider, on a grid of a tenth of a spacing.
  const Colliders<2>& colliders = solver.colliders();
  auto inBand = [&](float x, float y, bool outsideOnly) {
    Eigen::Vector2f n;
    const float d = colliders.distance(0, Eigen::Vector2f(x, y), n);
    return (!outsideOnly || d > 0) && d < 3 * h && x > 1.5 * h && x < 1 - 1.5 * h && y > 1.5 * h && y < 0.36;
  };
  const double cell = h / 10;
  double bandArea = 0;
  for (double x = 0.5 * cell; x < 1; x += cell)
    for (double y = 0.5 * cell; y < 0.36; y += cell)
      if (inBand(float(x), float(y), true)) bandArea += cell * cell;
  size_t inside = 0;
  for (const Eigen::Vector2f& p : solver.positions()) inside += inBand(p.x(), p.y(), false);
  const double expected = bandArea / (h * h);
  ASSERT_GT(expected, 20) << GetParam().name;
  EXPECT_NEAR(inside / expected, 1.0, 0.08) << GetParam().name << ": " << inside << " particles, " << expected
                                            << " expected";
  std::printf("%s: rms %.4f (%.4f without) fastest %.3f (%.3f without), error %.4f (%.4f), band %.3f\n", GetParam().name.c_str(),
              motion.rmsSpeed, reference.rmsSpeed, motion.fastest, reference.fastest, motion.densityError, reference.densityError, inside / expected);
}

INSTANTIATE_TEST_SUITE_P(
    Colliders, RestAgainst,
    ::testing::Values(RestCase{"plane", R"({"shape": "plane", "position": [0.5, 0.1], "normal": [0, 1]})"},
                      RestCase{"tilted_plane", R"({"shape": "plane", "position": [0.5, 0.1], "normal": [-0.34, 0.94]})"},
                      RestCase{"sphere", R"({"shape": "sphere", "position": [0.5, 0.1], "radius": 0.15})"},
                      RestCase{"slope", R"({"shape": "box", "position": [0.3, 0.0], "size": [0.6, 0.2],
                                            "rotation": {"degrees": 20}})"},
                      RestCase{"capsule", R"({"shape": "capsule", "position": [0.6, 0.15], "radius": 0.06,
                                              "height": 0.2, "rotation": {"degrees": 60}})"},
                      // A cylinder along its y axis is a rectangle in the plane: here 0.12 x 0.2, tilted, its
                      // lowest corner 1.7 spacings above the floor. (Within a spacing of the floor, a particle
                      // caught under it ends 0.89 radii from it: docs/colliders.md, "Corners".)
                      RestCase{"cylinder", R"({"shape": "cylinder", "position": [0.45, 0.15], "radius": 0.06,
                                               "height": 0.2, "rotation": {"degrees": 30}})"},
                      // The shipped boulder (closed OBJ, baked by OpenVDB), 0.3 m across, its section at z = 0;
                      // its flat bottom 2.2 spacings above the floor (0.65 spacings: 0.87 radii, as above).
                      RestCase{"mesh", R"({"shape": "mesh", "file": ")" + std::string(SURGE_SOURCE_DIR) +
                                           R"(/scenes/assets/rock.obj", "position": [0.5, 0.13], "scale": 0.3})"},
                      // The shipped terrain (16-bit PNG) across the pool: its profile along the middle of z, a
                      // slope from 0.12 m down to a basin, crossing the winding channel's banks.
                      RestCase{"heightfield", R"({"shape": "heightfield", "file": ")" +
                                                  std::string(SURGE_SOURCE_DIR) +
                                                  R"(/scenes/assets/terrain.png", "position": [0.5, 0.0],
                                                  "size": [1.0, 0.5], "height": 0.15})"},
                      // A tilted box holding the water inside the tank: walls standing in the pool 10 cm in from
                      // the tank's, its floor 8 cm or more below the tank's. (0.9 m wide, its floor came within
                      // 1 cm of the tank's, and the band took a sliver of the floor's layers: 1.075.)
                      RestCase{"container", R"({"shape": "box", "container": 1, "position": [0.5, 0.35],
                                                "size": [0.8, 0.8], "rotation": {"degrees": 5}})"}),
    [](const ::testing::TestParamInfo<RestCase>& info) { return info.param.name; });

}  // namespace
}  // namespace surge

namespace surge {
namespace {

// Time-averaged wrench over `seconds` (frames of the scene's rate).
template <typename Solver>
Wrench meanWrench(Solver& solver, const Scene& scene, double seconds, double& time, size_t collider = 0) {
  Wrench mean;
  const int frames = int(std::round(seconds * scene.output.fps));
  for (int f = 0; f < frames; ++f) {
    const Wrench w = runFor(solver, scene, 1.0 / scene.output.fps, time)[collider];
    mean.force += w.force / frames;
    mean.torque += w.torque / frames;
  }
  return mean;
}

// A box on the floor under a column of water carries the column's weight: the force on its top face is the
// weight of the particles above that face (their mass times g, which holds whatever the solver's compression),
// and its sides' pressures cancel. Over 1 s after 1.5 s of settling, within 6%: PBF loses 7-8 N per metre of the
// top face's rim to the floor beside it (-10.0% and -5.5% on boxes 0.1 and 0.2 m wide over frames 46-75,
// docs/colliders.md; this window reads -4.0%), WCSPH reads within 1.5%. Sideways forces within 2% of the
// weight; the torque about its centre vanishes by symmetry (within 2% of the weight times the half-width).
template <typename Solver>
void checkBoxOnTheFloor(const std::string& method) {
  const Scene scene = makeScene(3, R"({"min": [0, 0, 0], "max": [0.4, 0.6, 0.4]})",
                                R"([{"box": {"min": [0, 0, 0], "max": [0.4, 0.4, 0.4]}}])",
                                R"([{"shape": "box", "position": [0.2, 0.05, 0.2], "size": [0.2, 0.1, 0.2]}])", 0.02,
                                {"solver.method=" + method});
  Solver solver(scene);
  solver.setParticles(withoutInside<3>(scene, solver.colliders()));
  double time = 0;
  runFor(solver, scene, 1.5, time);
  const Wrench w = meanWrench(solver, scene, 1.0, time);
  size_t above = 0;
  for (const Eigen::Vector3f& p : solver.positions())
    above += p.y() > 0.1f && std::abs(p.x() - 0.2f) < 0.1f && std::abs(p.z() - 0.2f) < 0.1f;
  const double weight = above * solver.particleMass() * 9.81;
  EXPECT_NEAR(-w.force.y(), weight, 0.06 * weight) << method;
  EXPECT_NEAR(w.force.x(), 0.0, 0.02 * weight) << method;
  EXPECT_NEAR(w.force.z(), 0.0, 0.02 * weight) << method;
  EXPECT_LT(w.torque.norm(), 0.02 * weight * 0.05) << method;
  std::printf("box, %s: F = (%.3f, %.3f, %.3f) N, column weight %.3f N\n", method.c_str(), w.force.x(),
              w.force.y(), w.force.z(), weight);
}

TEST(Colliders, BoxOnTheFloorCarriesTheWaterAbovePbf) { checkBoxOnTheFloor<PbfSolver<3>>("pbf"); }
TEST(Colliders, BoxOnTheFloorCarriesTheWaterAboveWcsph) { checkBoxOnTheFloor<WcsphSolver<3>>("wcsph"); }

// A fixed sphere under water feels Archimedes' rho g V upward. PBF keeps the pool within about 4% of rho_0
// (its compression under 4 x 4 iterations, measured on this pool), so rho is taken as the mean density of the
// water, the particles' mass over the volume they fill (up to the mean surface height), and the force must
// match rho g V within 5%, the sideways force within 1% of it.
// Sideways, the force should vanish, but it need not: the sphere's removed particles and round-off break the
// pool's symmetry (how, depends on the build's floating point). PBF's pool never stops sloshing, and its sideways
// force swings by 5-10% of rho g V from frame to frame; WCSPH's comes to rest, in an arrangement that is not
// mirror-symmetric at the grain of one particle and holds a steady sideways force (measured: 2.3 N/m in 2D, 1.1%
// of rho g V and 0.6 of one particle's weight; 0.1 N in 3D, 0.5%). So the sideways check is that the mean lies
// under 2% of rho g V, and the window must have the power to see that (three standard errors of the mean under
// it, the errors from the means of half-second blocks, longer than the swings), else it is too short. This sees
// the pool's symmetry more than the wall's: at rest the water stands off a wall that pushes too hard, so a ball
// whose wall term was made 10% stronger on one side still read -2.3 N/m in 2D (tried); 50% stronger, it read
// -15.3 N/m (7.7%) and the 2D WCSPH test failed, while PBF's 3D ball still read -0.03 N.
template <int Dim, typename Solver>
void checkBuoyancy(const Scene& scene, double sphereVolume, double settle, double watch, double tolerance = 0.05) {
  Solver solver(scene);
  solver.setParticles(withoutInside<Dim>(scene, solver.colliders()));
  double time = 0;
  runFor(solver, scene, settle, time);
  const int blockFrames = int(std::round(0.5 * scene.output.fps)), blocks = int(std::round(watch / 0.5));
  Wrench w;
  std::vector<double> blockMeans;
  for (int b = 0; b < blocks; ++b) {
    const Wrench block = meanWrench(solver, scene, double(blockFrames) / scene.output.fps, time);
    w.force += block.force / blocks;
    blockMeans.push_back(block.force.x());
  }
  double spread = 0;
  for (double m : blockMeans) spread += (m - w.force.x()) * (m - w.force.x());
  const double standardError = std::sqrt(spread / (blocks - 1) / blocks);
  // The mean density: total mass over the volume below the surface (the mean height of the top layer plus half a
  // spacing) less the sphere's.
  std::vector<float> heights;
  for (const auto& p : solver.positions()) heights.push_back(p.y());
  std::sort(heights.begin(), heights.end());
  const float spacing = float(scene.particle_spacing);
  double topSum = 0;
  size_t topCount = 0;
  for (float y : heights)
    if (y > heights.back() - spacing) topSum += y, ++topCount;
  const double surface = topSum / topCount + 0.5 * spacing;
  double footprint = 1;
  for (int k = 0; k < Dim; ++k)
    if (k != 1) footprint *= scene.domain.max[k] - scene.domain.min[k];
  const double rho = solver.size() * solver.particleMass() / (surface * footprint - sphereVolume);
  const double archimedes = rho * 9.81 * sphereVolume;
  EXPECT_NEAR(w.force.y(), archimedes, tolerance * archimedes) << "rho = " << rho;
  EXPECT_LT(std::abs(w.force.x()), 0.02 * archimedes) << "a sideways bias";
  EXPECT_LT(3 * standardError, 0.02 * archimedes) << "the window is too short to see a 2% sideways bias";
  std::printf("buoyancy %dD: F = (%.4f, %.4f) N over %.1f s, standard error of F_x %.3f N, rho g V = %.4f N "
              "(rho %.1f)\n", Dim, w.force.x(), w.force.y(), watch, standardError, archimedes, rho);
}

// Watched for 10 s: this pool also swings slowly from side to side, measured with the warm start (0.5) at a
// period of about 8 s and an amplitude of 0.25 N (1.2% of rho g V) in the half-second means, so a 4 s window saw
// half a swing (+0.16 N, four of its standard errors, which assume blocks independent of one another); over 10 s
// the mean read +0.02 N.
TEST(Colliders, SubmergedSphereFeelsArchimedesPbf) {
  const Scene scene = makeScene(3, R"({"min": [0, 0, 0], "max": [0.3, 0.6, 0.3]})",
                                R"([{"box": {"min": [0, 0, 0], "max": [0.3, 0.4, 0.3]}}])",
                                R"([{"shape": "sphere", "position": [0.15, 0.2, 0.15], "radius": 0.08}])", 0.02);
  checkBuoyancy<3, PbfSolver<3>>(scene, 4.0 / 3.0 * M_PI * std::pow(0.08, 3), 1.5, 10.0);
}

TEST(Colliders, SubmergedSphereFeelsArchimedesWcsph) {
  // In 2D a ball is a disc: V is its area, the force per unit depth. With the wall's pressure continued
  // hydrostatically (Colliders::hydrostaticSum) WCSPH reads within 1% of rho g V here; mirroring the particle's
  // pressure alone read 7.7% over (docs/colliders.md). Held to the 5% PBF is held to, after 2.5 s of settling:
  // WCSPH's pool sloshes longer than PBF's, and after 1.5 s its sideways force still swung by 2-3% of rho g V.
  const Scene scene = makeScene(2, R"({"min": [0, 0], "max": [0.6, 0.6]})", R"([{"box": {"min": [0, 0], "max": [0.6, 0.4]}}])",
                                R"([{"shape": "sphere", "position": [0.3, 0.2], "radius": 0.08}])", 0.02,
                                {"solver.method=wcsph"});
  checkBuoyancy<2, WcsphSolver<2>>(scene, M_PI * 0.08 * 0.08, 2.5, 8.0);
}

// The same ball as PBF's, in 3D. WCSPH reads it -0.1% from rho g V (rho the water's mean) since its tank walls
// mirror the fluid (session 66); +4.0% while they continued the particle's pressure into the lattice beyond them,
// +15.5% while they mirrored the particle's pressure alone: the water beside the walls missed the walls' share of
// its support and the pressure below the ball rose 13% over hydrostatic (docs/colliders.md).
TEST(Colliders, SubmergedSphereFeelsArchimedesWcsph3d) {
  const Scene scene = makeScene(3, R"({"min": [0, 0, 0], "max": [0.3, 0.6, 0.3]})",
                                R"([{"box": {"min": [0, 0, 0], "max": [0.3, 0.4, 0.3]}}])",
                                R"([{"shape": "sphere", "position": [0.15, 0.2, 0.15], "radius": 0.08}])", 0.02,
                                {"solver.method=wcsph"});
  checkBuoyancy<3, WcsphSolver<3>>(scene, 4.0 / 3.0 * M_PI * std::pow(0.08, 3), 2.5, 4.0);
}

// The force bookkeeping is exact where the model is: a plane laid as the tank's floor carries all the water's
// weight once it is at rest (the side walls are vertical and frictionless), for every solver, within 2% (the
// residual sloshing's mean over a second, and the corners the side walls share).
TEST(Colliders, FloorPlaneCarriesAllTheWeight) {
  for (const std::string& method : fluidSolverMethods()) {
    const Scene scene = makeScene(2, R"({"min": [0, 0], "max": [0.6, 0.6]})", R"([{"box": {"min": [0, 0.1], "max": [0.6, 0.4]}}])",
                                  R"([{"shape": "plane", "position": [0.3, 0.1], "normal": [0, 1]}])", 0.02,
                                  {"solver.method=" + method});
    double time = 0;
    const std::unique_ptr<FluidSolver<2>> solver = makeFluidSolver<2>(scene);
    solver->setParticles(withoutInside<2>(scene, solver->colliders()));
    runFor(*solver, scene, 1.0, time);
    const Wrench w = meanWrench(*solver, scene, 1.0, time);
    const double weight = 1000 * 9.81 * 0.6 * 0.3;
    EXPECT_NEAR(-w.force.y(), weight, 0.02 * weight) << method;
    EXPECT_NEAR(w.force.x(), 0.0, 0.01 * weight) << method;
  }
}

// A keyframed paddle moving through a pool moves the water its way, and the water pushes back on it.
TEST(Colliders, MovingPaddleMovesWater) {
  const Scene scene = makeScene(2, R"({"min": [0, 0], "max": [1, 0.5]})", R"([{"box": {"min": [0, 0], "max": [1, 0.3]}}])",
                                R"([{"shape": "box", "size": [0.04, 0.3], "motion": [
                                     {"time": 0, "position": [0.2, 0.2]}, {"time": 1, "position": [0.7, 0.2]}]}])",
                                0.02);
  PbfSolver<2> solver(scene);
  solver.setParticles(withoutInside<2>(scene, solver.colliders()));
  double time = 0;
  const Wrench w = meanWrench(solver, scene, 0.5, time);
  double momentum = 0;
  for (const Eigen::Vector2f& v : solver.velocities()) momentum += solver.particleMass() * v.x();
  // The paddle sweeps 0.5 m/s through water 0.3 deep; after 0.5 s the water ahead of it moves. Its momentum,
  // at least a tenth of the swept water's (0.3 x 0.25 m^2 x 1000 kg/m^3 x 0.5 m/s = 37.5 kg m/s per metre).
  EXPECT_GT(momentum, 0.1 * 37.5);
  EXPECT_LT(w.force.x(), 0.0) << "the water must push back on the paddle";
  for (const Eigen::Vector2f& p : solver.positions()) {
    Eigen::Vector2f n;
    EXPECT_GT(solver.colliders().distance(0, p, n), 0.95f * solver.colliders().particleRadius());
  }
}

}  // namespace
}  // namespace surge

namespace surge {
namespace {

// A block dropped 0.1 m onto a plane collider must land as it lands on the tank's floor at the same height (the
// same table, the same clamp to a radius): the kinetic energy frame by frame within 10% plus 1 J/m (after the
// impact the two runs part like any two chaotic splashes, so only the peak and the first frames after it are
// compared). A collision that held back particles moving off the wall (the density pushing them away) once
// made the plane's impact 7 times as energetic as the floor's, with 60-fold compression.
TEST(Colliders, ImpactOnAPlaneIsAnImpactOnTheFloor) {
  const std::string fluid = R"([{"box": {"min": [0.03, 0.6], "max": [0.45, 1.0]}}])";
  const Scene onPlane = makeScene(2, R"({"min": [0, 0], "max": [2, 1.5]})", fluid,
                                  R"([{"shape": "plane", "position": [0, 0.5], "normal": [0, 1]}])", 0.005);
  const Scene onFloor = makeScene(2, R"({"min": [0, 0.5], "max": [2, 1.5]})", fluid, "[]", 0.005);
  PbfSolver<2> plane(onPlane), floor(onFloor);
  plane.setParticles(initialParticles(onPlane));
  floor.setParticles(initialParticles(onFloor));
  double tp = 0, tf = 0, peakPlane = 0, peakFloor = 0;
  for (int frame = 1; frame <= 9; ++frame) {
    runFor(plane, onPlane, 1.0 / 30, tp);
    runFor(floor, onFloor, 1.0 / 30, tf);
    const double ep = plane.measure().kineticEnergy, ef = floor.measure().kineticEnergy;
    peakPlane = std::max(peakPlane, ep);
    peakFloor = std::max(peakFloor, ef);
    EXPECT_NEAR(ep, ef, 0.1 * ef + 1) << "frame " << frame;
  }
  EXPECT_NEAR(peakPlane, peakFloor, 0.1 * peakFloor);
}

}  // namespace
}  // namespace surge
