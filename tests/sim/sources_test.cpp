// Emitters, sinks, open faces and shaped fluids (sim/sources.h), measured against what they must do: the flux an
// emitter promises, a jet's ballistic range, Torricelli's drain, a river's steady state, a sink that touches
// nothing, the same bytes at any thread count and after a resume, and the scenes a run must refuse.
#include "sim/sources.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>
#include <tuple>

#include "core/errors.h"
#include "core/files.h"
#include "core/parallel.h"
#include "core/ply.h"
#include "core/progress.h"
#include "sim/simulation.h"
#include "sim/solver_defaults.h"
#include "tests/sim/run_scene.h"
#include "tests/sim/stats_columns.h"

namespace surge {
namespace {

double sum(const std::vector<double>& v, size_t from, size_t to) {
  return std::accumulate(v.begin() + std::ptrdiff_t(from), v.begin() + std::ptrdiff_t(to), 0.0);
}

// Particles emitted per second are area x speed / spacing^d: exactly per whole layer, so over any second within
// one layer's sites (79 of 11,781 for the 3D disc, 0.7%; 10 of 1,500 for the 2D segment), inside the 1% the
// issue asks. Both discs are 10 spacings across; the jet falls out through the open floor, so nothing blocks it.
TEST(Sources, AnEmitterDeliversAreaTimesSpeed) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    const std::string text =
        d == 2 ? R"({"name": "flux", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.4, 0.4], "open": ["-y"]},
                     "particle_spacing": 0.01, "emitters": [{"position": [0.2, 0.35], "direction": [0, -1],
                     "radius": 0.05, "speed": 1.5}], "output": {"fps": 30, "frames": 45}})"
               : R"({"name": "flux", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [0.4, 0.4, 0.4],
                     "open": ["-y"]}, "particle_spacing": 0.01, "emitters": [{"position": [0.2, 0.35, 0.2],
                     "direction": [0, -3, 0], "radius": 0.05, "speed": 1.5}], "output": {"fps": 30, "frames": 45}})";
    const Scene scene = parseScene(text, "flux.json");
    const auto stats = readStats(runScene(scene, "flux" + std::to_string(d)));
    const double area = d == 2 ? 0.1 : M_PI * 0.05 * 0.05;
    const double perSecond = area * 1.5 / std::pow(0.01, d);
    for (size_t first : {1, 16}) {  // frames 1-30 and 16-45: [0, 1] s and [0.5, 1.5] s
      const double emitted = sum(stats.at("emitted"), first, first + 30);
      EXPECT_NEAR(emitted / perSecond, 1.0, 0.01) << "from frame " << first;
    }
    // Everything emitted is either in the tank or has left through the floor.
    const double removed = sum(stats.at("removed"), 0, 46), emitted = sum(stats.at("emitted"), 0, 46);
    EXPECT_GT(removed, 0);
    EXPECT_DOUBLE_EQ(stats.at("particles").back(), emitted - removed);
  }
}

// An emitter's schedule is a function of time: keyframed speed, closed and opened again (SPlisHSPlasH #369: an
// emitter whose speed went to zero never restarted), moved and turned by keyframes (#79).
TEST(Sources, AnEmitterClosedByItsKeyframesOpensAgainAndMovesWithThem) {
  EmitterSettings e;
  e.position = Eigen::Vector3d(0.5, 0.5, 0);
  e.direction = Eigen::Vector3d(0, -1, 0);
  e.radius = 0.05;
  e.speed = 2;
  // 2 m/s, closing linearly to 0 at 1 s, shut until 2 s, then 1 m/s from 3 s on.
  e.motion = {{0, Eigen::Vector3d(0.5, 0.5, 0), Eigen::Vector3d::Zero(), -1},
              {1, Eigen::Vector3d(0.5, 0.5, 0), Eigen::Vector3d::Zero(), 0},
              {2, Eigen::Vector3d(0.5, 0.5, 0), Eigen::Vector3d::Zero(), 0},
              {3, Eigen::Vector3d(0.2, 0.5, 0), Eigen::Vector3d(1, 0, 0), 1}};
  const EmitterSchedule emitter(e, 0.01, 2);
  EXPECT_EQ(emitter.sitesPerLayer(), 10u);
  EXPECT_DOUBLE_EQ(emitter.pitch(), 0.01);
  EXPECT_NEAR(emitter.pushed(1.0), 1.0, 1e-12);   // the triangle under 2 m/s falling to 0
  EXPECT_NEAR(emitter.pushed(2.0), 1.0, 1e-12);   // shut
  EXPECT_EQ(emitter.speed(1.5), 0);
  EXPECT_NEAR(emitter.pushed(3.0), 1.5, 1e-12);   // opening from 0 to 1 m/s over the third second
  EXPECT_NEAR(emitter.pushed(5.0), 3.5, 1e-12);   // then 1 m/s
  EXPECT_EQ(emitter.layersBy(1.5), emitter.layersBy(2.0));
  EXPECT_GT(emitter.layersBy(2.5), emitter.layersBy(2.0));  // open again
  EXPECT_NEAR(emitter.position(2.5).x(), 0.35, 1e-12);      // halfway from 0.5 to 0.2
  EXPECT_NEAR(emitter.direction(3.5).x(), 1, 1e-12);        // turned to +x
  EXPECT_NEAR(emitter.direction(2.5).norm(), 1, 1e-12);     // unit between the keyframes
  // start and stop bound it: nothing before start, nothing more after stop.
  e.motion.clear();
  e.start = 0.5;
  e.stop = 1.5;
  const EmitterSchedule timed(e, 0.01, 2);
  EXPECT_EQ(timed.layersBy(0.5), 0u);
  EXPECT_EQ(timed.layersBy(1.5), timed.layersBy(9.0));
  EXPECT_EQ(timed.layersBy(9.0), 200u);  // 2 m over a 0.01 pitch
}

// A free horizontal jet from height H lands where a projectile would: x = v sqrt(2 (H - y) / g) from the face
// at every height y. The jet's internal forces cancel in its mean, so the particles in a band near the floor,
// each against the projectile's x at its own height, agree on average; 5% of the range is the issue's bound.
TEST(Sources, AHorizontalJetLandsWhereAProjectileWould) {
  const Scene scene = parseScene(
      R"({"name": "jet", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 0.6], "open": ["-y", "+x"]},
          "particle_spacing": 0.005, "emitters": [{"position": [0.01, 0.5], "direction": [1, 0], "radius": 0.01,
          "speed": 1}], "output": {"fps": 30, "frames": 40}})",
      "jet.json");
  const fs::path dir = runScene(scene, "jet");
  const double g = 9.81, H = 0.5, v = 1, range = v * std::sqrt(2 * H / g);
  double offset = 0;
  int counted = 0;
  for (int f = 30; f <= 40; ++f) {  // the steady jet's last third of a second
    const ParticleFrame frame = readParticlePly(framePath(dir, "particles", f, "ply"));
    for (size_t i = 0; i < frame.size(); ++i) {
      const double y = frame.position[i].y();
      if (y > 0.05) continue;
      offset += frame.position[i].x() - (0.01 + v * std::sqrt(2 * (H - y) / g));
      ++counted;
    }
  }
  std::printf("horizontal jet: %d particles near the floor land %.4f m from the projectile's x (range %.3f m)\n",
              counted, offset / counted, range);
  ASSERT_GT(counted, 100);
  EXPECT_LT(std::abs(offset / counted), 0.05 * range) << "mean landing offset " << offset / counted << " m";
}

// The discharge coefficient of a 2D tank 0.5 m wide holding 0.4 m of water (spacing 0.005) that drains through an
// 8 cm hole in its floor, and how far sqrt(h) strays from its least-squares line from 0.2 s to 1.2 s. The water
// level h counts the particles above `floor`.
void drainCoefficient(const Scene& scene, const std::string& name, double floor, double& cd, double& worst,
                      double& start) {
  const fs::path dir = runScene(scene, name);
  const double W = 0.5, w = 0.08, s = 0.005, g = 9.81;
  std::vector<double> t, root;
  for (int f = 6; f <= 36; f += 2) {  // from 0.2 s, past the start's transient
    const ParticleFrame frame = readParticlePly(framePath(dir, "particles", f, "ply"));
    size_t above = 0;
    for (size_t i = 0; i < frame.size(); ++i) above += frame.position[i].y() > floor;
    t.push_back(f / 30.0);
    root.push_back(std::sqrt(double(above) * s * s / W));
  }
  const double n = double(t.size()), mt = sum(t, 0, t.size()) / n, mr = sum(root, 0, root.size()) / n;
  double stt = 0, str = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    stt += (t[k] - mt) * (t[k] - mt);
    str += (t[k] - mt) * (root[k] - mr);
  }
  const double slope = str / stt;
  worst = 0;
  for (size_t k = 0; k < t.size(); ++k) worst = std::max(worst, std::abs(root[k] - (mr + slope * (t[k] - mt))));
  cd = -slope / ((w / W) * std::sqrt(g / 2));
  start = root.front();
}

// A tank draining through a hole in its floor: Torricelli's v = sqrt(2 g h) through the hole makes
// d sqrt(h) / dt = -Cd (w / W) sqrt(g / 2), so sqrt(h) falls on a straight line whose slope gives the
// discharge coefficient Cd, between 0.55 (a sharp orifice's vena contracta, 0.61 in the textbooks) and 1. Two
// holes: a slot in a 2 cm plate above an open floor, and a sink flush with the tank's floor.
TEST(Sources, ATankDrainsAsTorricelliSays) {
  const Scene slot = parseScene(
      R"({"name": "drain", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.5, 0.6], "open": ["-y"]},
          "particle_spacing": 0.005, "fluids": [{"box": {"min": [0, 0.1], "max": [0.5, 0.5]}}],
          "colliders": [{"shape": "box", "position": [0.105, 0.09], "size": [0.21, 0.02]},
                        {"shape": "box", "position": [0.395, 0.09], "size": [0.21, 0.02]}],
          "output": {"fps": 30, "frames": 36}})",
      "drain.json");
  const Scene sink = parseScene(
      R"({"name": "drain", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.5, 0.5]},
          "particle_spacing": 0.005, "fluids": [{"box": {"min": [0, 0], "max": [0.5, 0.4]}}],
          "sinks": [{"shape": "box", "position": [0.25, 0.0025], "size": [0.08, 0.005]}],
          "output": {"fps": 30, "frames": 36}})",
      "drain.json");
  for (const auto& [scene, name, floor] : {std::tuple(slot, "drain_slot", 0.1), std::tuple(sink, "drain_sink", 0.0)}) {
    double cd = 0, worst = 0, start = 0;
    drainCoefficient(scene, name, floor, cd, worst, start);
    std::printf("Torricelli drain (%s): discharge coefficient %.3f, largest departure from the line %.4f m^0.5\n",
                name, cd, worst);
    EXPECT_GE(cd, 0.55) << name;
    EXPECT_LE(cd, 1.0) << name;
    // Straight: no point further from the line than 2% of sqrt(h) at the start.
    EXPECT_LT(worst, 0.02 * start) << name;
  }
}

// A river: an inflow along the floor of a channel, out through the open far wall. Once the water has crossed
// it and its layer has settled (about 5 s), what comes in goes out: the count holds within 2% over the last
// second (a layer is 8 of about 940).
TEST(Sources, ARiverWithInflowAndOutflowReachesASteadyCount) {
  const Scene scene = parseScene(
      R"({"name": "river", "dimensions": 2, "domain": {"min": [0, 0], "max": [1.2, 0.4], "open": ["+x"]},
          "particle_spacing": 0.01, "emitters": [{"position": [0.01, 0.05], "direction": [1, 0], "radius": 0.04,
          "speed": 1}], "output": {"fps": 30, "frames": 210}})",
      "river.json");
  const auto stats = readStats(runScene(scene, "river"));
  const std::vector<double>& count = stats.at("particles");
  const auto last = std::minmax_element(count.end() - 31, count.end());
  const double mean = sum(count, count.size() - 31, count.size()) / 31;
  std::printf("steady river: %.0f to %.0f particles over its last second\n", *last.first, *last.second);
  EXPECT_GT(mean, 500);
  EXPECT_LT((*last.second - *last.first) / mean, 0.02) << *last.first << " to " << *last.second;
  EXPECT_GT(sum(stats.at("removed"), count.size() - 30, count.size()), 0.9 * 800);  // the outflow is the inflow
}

// A pool at rest with a sink above its surface: nothing is removed. The same sink lowered into the water
// removes what it holds, so the check is not one a broken sink would pass.
TEST(Sources, ASinkAboveAPoolAtRestRemovesNothing) {
  const char* text = R"({"name": "pool", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.5, 0.5]},
      "particle_spacing": 0.01, "fluids": [{"box": {"min": [0, 0], "max": [0.5, 0.2]}}],
      "sinks": [{"shape": "box", "position": [0.25, 0.3], "size": [0.3, 0.1]}], "output": {"fps": 30, "frames": 30}})";
  const auto above = readStats(runScene(parseScene(text, "pool.json"), "pool_sink_above"));
  EXPECT_EQ(sum(above.at("removed"), 0, 31), 0);
  EXPECT_EQ(above.at("particles").front(), 1000);
  EXPECT_EQ(above.at("particles").back(), 1000);
  const auto inside = readStats(runScene(parseScene(text, "pool.json", {"sinks[0].position=[0.25,0.15]"}), "pool_sink_in"));
  EXPECT_GT(sum(inside.at("removed"), 0, 31), 100);
}

// A sink moved by keyframes removes along its path: above the pool until 0.5 s it takes nothing, lowered into the
// water it takes what it meets.
TEST(Sources, AMovingSinkRemovesWhereItGoes) {
  const Scene scene = parseScene(
      R"({"name": "pool", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.5, 0.5]}, "particle_spacing": 0.01,
          "fluids": [{"box": {"min": [0, 0], "max": [0.5, 0.2]}}],
          "sinks": [{"shape": "box", "size": [0.1, 0.05], "motion": [{"time": 0.5, "position": [0.25, 0.35]},
                                                                      {"time": 0.8, "position": [0.25, 0.1]}]}],
          "output": {"fps": 30, "frames": 30}})",
      "pool.json");
  const auto stats = readStats(runScene(scene, "moving_sink"));
  EXPECT_EQ(sum(stats.at("removed"), 0, 16), 0);     // until 0.5 s
  EXPECT_GT(sum(stats.at("removed"), 16, 31), 200);  // lowered through the water
}

// A submerged emitter keeps emitting its whole flux (FLIP Fluids #322: a submerged inflow stopped): 10 cm under a
// closed pool, pushing sideways at 0.5 m/s through a segment of 8 sites, every method delivers its 400 particles
// in each whole second within one layer (8: a second holds 50 layers, whole or not at either end), its nozzle
// pushing the standing water in front as a piston would (docs/sources.md). Nothing leaves a closed pool.
TEST(Sources, ASubmergedEmitterDeliversItsFlux) {
  for (const char* method : {"pbf", "wcsph", "dfsph"}) {
    const Scene scene = parseScene(
        R"({"name": "submerged", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 0.6]}, "particle_spacing": 0.01,
            "fluids": [{"box": {"min": [0, 0], "max": [1, 0.3]}}],
            "emitters": [{"position": [0.2, 0.1], "direction": [1, 0], "radius": 0.04, "speed": 0.5}],
            "output": {"fps": 30, "frames": 60}})",
        "submerged.json", {std::string("solver.method=") + method});
    const auto stats = readStats(runScene(scene, std::string("submerged_") + method));
    const double perSecond = 0.08 * 0.5 / 1e-4, layer = 8;
    const double first = sum(stats.at("emitted"), 1, 31), second = sum(stats.at("emitted"), 31, 61);
    std::printf("submerged emitter (%s): %.0f and %.0f particles in its two seconds, of %.0f\n", method, first,
                second, perSecond);
    EXPECT_NEAR(first, perSecond, layer) << method;
    EXPECT_NEAR(second, perSecond, layer) << method;
    EXPECT_EQ(sum(stats.at("removed"), 0, 61), 0) << method;
    EXPECT_EQ(stats.at("particles").back(), 3000 + first + second) << method;
  }
}

// A moving emitter gives its particles its own velocity beside the jet's: without gravity, nothing else changes
// the mean horizontal velocity of what it emits (the solver's forces between particles cancel in the mean).
TEST(Sources, AMovingEmitterGivesItsParticlesItsVelocity) {
  const Scene scene = parseScene(
      R"({"name": "hose", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1]}, "particle_spacing": 0.01,
          "gravity": [0, 0], "emitters": [{"position": [0.2, 0.9], "direction": [0, -1], "radius": 0.03, "speed": 1,
          "motion": [{"time": 0, "position": [0.2, 0.9]}, {"time": 1, "position": [0.7, 0.9]}]}],
          "output": {"fps": 30, "frames": 15}})",
      "hose.json");
  const ParticleFrame frame = readParticlePly(framePath(runScene(scene, "hose"), "particles", 15, "ply"));
  ASSERT_GT(frame.size(), 100u);
  double vx = 0;
  for (size_t i = 0; i < frame.size(); ++i) vx += frame.velocity[i].x();
  EXPECT_NEAR(vx / double(frame.size()), 0.5, 0.01);
}

// Every method in 2D and 3D, pouring past a collider into a sink and out of an open face: the same bytes at one
// and two threads, and a run resumed mid-pour ends on the bytes of the uninterrupted one.
TEST(Sources, APourIsTheSameBytesAtAnyThreadCountAndAfterAResume) {
  for (const char* method : {"pbf", "wcsph", "dfsph"})
    for (int d : {2, 3}) {
      SCOPED_TRACE(std::string(method) + " " + std::to_string(d) + "D");
      const std::string text =
          d == 2 ? R"({"name": "pour", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.4, 0.4], "open": ["+x"]},
                       "particle_spacing": 0.01, "fluids": [{"box": {"min": [0, 0], "max": [0.4, 0.06]}}],
                       "emitters": [{"position": [0.1, 0.3], "direction": [1, -1], "radius": 0.03, "speed": 1}],
                       "sinks": [{"shape": "sphere", "position": [0.05, 0.02], "radius": 0.04}],
                       "colliders": [{"shape": "sphere", "position": [0.25, 0.12], "radius": 0.04}],
                       "output": {"fps": 30, "frames": 8}})"
                 : R"({"name": "pour", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [0.3, 0.3, 0.2],
                       "open": ["+x"]}, "particle_spacing": 0.015, "fluids": [{"box": {"min": [0, 0, 0],
                       "max": [0.3, 0.045, 0.2]}}], "emitters": [{"position": [0.08, 0.22, 0.1],
                       "direction": [1, -1, 0], "radius": 0.03, "speed": 1}], "sinks": [{"shape": "sphere",
                       "position": [0.04, 0.02, 0.1], "radius": 0.04}], "colliders": [{"shape": "sphere",
                       "position": [0.18, 0.1, 0.1], "radius": 0.03}], "output": {"fps": 30, "frames": 8}})";
      const Scene scene = parseScene(text, "pour.json", {std::string("solver.method=") + method});
      const std::string tag = std::string("pour_") + method + std::to_string(d);
      const fs::path two = runScene(scene, tag + "_2", 2), one = runScene(scene, tag + "_1", 1);
      const std::string last = readTextFile(framePath(two, "particles", 8, "ply"));
      EXPECT_EQ(readTextFile(framePath(one, "particles", 8, "ply")), last);
      const auto stats = readStats(two);
      EXPECT_GT(sum(stats.at("emitted"), 0, 9), 0);
      EXPECT_GT(sum(stats.at("removed"), 0, 9), 0);
      // Stopped after frame 4 (mid-pour), then resumed to frame 8.
      Scene shorter = scene;
      shorter.output.frames = 4;
      const fs::path resumed = runScene(shorter, tag + "_r", 1);
      runScene(scene, tag + "_r", 2, true);
      EXPECT_EQ(readTextFile(framePath(resumed, "particles", 8, "ply")), last);
      EXPECT_EQ(readStats(resumed).at("emitted"), stats.at("emitted"));
    }
}

// A fluid given as a shape fills the lattice sites inside it, less those inside a collider.
TEST(Sources, AFluidShapeFillsItsLatticeSites) {
  const Scene scene = parseScene(
      R"({"name": "ball", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [1, 1, 1]}, "particle_spacing": 0.02,
          "fluids": [{"shape": "sphere", "position": [0.5, 0.5, 0.5], "radius": 0.2}],
          "output": {"fps": 30, "frames": 1}})",
      "ball.json");
  const ParticleFrame ball = initialParticles(scene);
  // The sites within 0.2 of the centre: the sphere's volume over s^3 (4,189) within the lattice's rounding.
  EXPECT_NEAR(double(ball.size()) / (4.0 / 3.0 * M_PI * 0.008 / 8e-6), 1.0, 0.02);
  for (size_t i = 0; i < ball.size(); ++i) EXPECT_LT((ball.position[i] - Eigen::Vector3f(0.5f, 0.5f, 0.5f)).norm(), 0.2f);
  EXPECT_NEAR(double(mostParticles(scene)) / double(ball.size()), 1.0, 0.02);  // the memory check's estimate
}

// What a run refuses before it writes anything: one line naming the file and the key.
TEST(Sources, BadSourcesAreRefusedNamingTheKey) {
  const std::string base = R"({"name": "bad", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1]},
      "particle_spacing": 0.02, "fluids": [{"box": {"min": [0, 0], "max": [1, 0.2]}}],
      "colliders": [{"name": "rock", "shape": "sphere", "position": [0.5, 0.6], "radius": 0.1}],
      "output": {"fps": 30, "frames": 2}})";
  auto refusal = [&](const std::vector<std::string>& sets) {
    try {
      const Scene scene = parseScene(base, "bad.json", sets);
      checkSimulationStart(scene, buildColliderShapes(scene));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refusal({R"(emitters=[{"position": [0.5, 0.62], "direction": [0, -1]}])"}),
            "bad.json: emitters[0].position: lies inside collider rock");
  EXPECT_EQ(refusal({R"(emitters=[{"position": [0.5, 0.8], "direction": [0, -1]}])"}), "accepted");
  EXPECT_EQ(refusal({R"(sinks=[{"shape": "box", "position": [0.5, 0.1], "size": [1.2, 0.3]}])"}),
            "bad.json: sinks: hold the whole initial fluid: nothing would be left to simulate");
  EXPECT_EQ(refusal({R"(sinks=[{"shape": "box", "position": [0.5, 0.1], "size": [0.5, 0.3]}])"}), "accepted");
  EXPECT_EQ(refusal({R"(fluids=[{"shape": "sphere", "position": [0.5, 0.3], "radius": 0.001}])"}),
            "bad.json: fluids[0]: the shape holds no lattice site at particle_spacing 0.02");
  // An open mesh cannot hold water.
  const fs::path open = fs::path(::testing::TempDir()) / "open_sheet.obj";
  std::ofstream(open) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n";
  const std::string sheet = R"({"name": "sheet", "dimensions": 3, "domain": {"min": [-1, -1, -1], "max": [2, 2, 2]},
      "particle_spacing": 0.05, "fluids": [{"shape": "mesh", "file": ")" + open.string() + R"("}],
      "output": {"fps": 30, "frames": 2}})";
  try {
    const Scene scene = parseScene(sheet, "sheet.json");
    checkSimulationStart(scene, buildColliderShapes(scene));
    ADD_FAILURE() << "an open mesh was filled";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fluids[0]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("open_sheet.obj"), std::string::npos) << e.what();
  }
}

// The memory check counts what the emitters can make by the last frame: a tap that would pour 10^10 particles
// is refused before the run.
TEST(Sources, TheMemoryCheckCountsTheEmittersParticles) {
  const Scene scene = parseScene(
      R"({"name": "flood", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [10, 10, 10]}, "particle_spacing": 0.01,
          "emitters": [{"position": [5, 5, 5], "direction": [1, 0, 0], "radius": 1, "speed": 10}],
          "output": {"fps": 30, "frames": 3000}})",
      "flood.json");
  // 100 s of pi m^2 at 10 m/s, over 1e-6 m^3 a particle.
  EXPECT_NEAR(double(mostEmittedParticles(scene, 100.0)) / (M_PI * 10 * 100 / 1e-6), 1.0, 0.001);
  try {
    checkSimulationMemory(scene);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("flood.json: particle_spacing:"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace surge
