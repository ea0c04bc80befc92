// The fluid's energy account in stats.csv (issue 32), against what it must be: a pool's potential energy at
// rest, a free fall's exact account of the frame loop's steps, the work of each kind of source (source_work), and
// the stop of a fluid that gains energy from nowhere.
#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "core/files.h"
#include "core/progress.h"
#include "sim/pbf_solver.h"
#include "sim/simulation.h"
#include "tests/sim/stats_columns.h"

namespace surge {
namespace {

std::map<std::string, std::vector<double>> run(const Scene& scene, const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::remove_all(dir);
  Progress quiet;
  simulate(scene, dir, false, quiet);
  return readStats(dir);
}

// A 2D pool W wide and H deep at rest holds m g W H^2 / (2 s^2) against the floor: its particles sit at
// (j + 1/2) s, whose heights sum to exactly n^2 s / 2 over a column of n, m the method's particle mass (PBF's
// is rho s^2 less 1.4%, its rest lattice's share of the walls). Gravity along -x measures against the -x wall.
TEST(Energy, APoolHoldsItsWeightTimesHalfItsDepth) {
  for (const char* gravity : {"[0, -9.81]", "[-9.81, 0]"}) {
    const Scene scene = parseScene(std::string(R"({"name": "pool", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.5, 0.5]},
        "particle_spacing": 0.01, "gravity": )") + gravity + R"(,
        "fluids": [{"box": {"min": [0, 0], "max": [0.2, 0.2]}}], "output": {"fps": 30, "frames": 1}})",
                                   "pool.json");
    const auto stats = run(scene, "energy_pool");
    const double mass = PbfSolver<2>(scene).particleMass(), columns = 20, n = 20;
    const double expected = mass * 9.81 * columns * n * n * 0.01 / 2;
    std::printf("pool (gravity %s): potential energy %.4f J/m against m g W H^2 / (2 s^2) = %.4f (rho g W H^2 / 2 "
                "= %.4f)\n", gravity, stats.at("potential_energy")[0], expected, 1000 * 9.81 * 0.2 * 0.2 * 0.2 / 2);
    EXPECT_NEAR(stats.at("potential_energy")[0], expected, 1e-5 * expected) << gravity;
  }
}

// A block in free fall: the frame loop's step (v += g dt, then x += v dt) after n equal steps has given the block
// n g dt of speed and dropped it g dt^2 n (n + 1) / 2, so the potential energy it lost exceeds the kinetic it
// gained by exactly KE / n: the account must read that, to float rounding (1e-4 of the energies). 12 steps a
// frame meet the CFL step of its fastest (2.6 m/s) and the depth step of its 0.2 m column, so none is shortened.
TEST(Energy, AFreeFallAccountsForEveryStep) {
  const Scene scene = parseScene(
      R"({"name": "fall", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1]}, "particle_spacing": 0.01,
          "fluids": [{"box": {"min": [0.4, 0.5], "max": [0.6, 0.7]}}], "solver": {"substeps": 12},
          "output": {"fps": 30, "frames": 8}})",
      "fall.json");
  const auto stats = run(scene, "energy_fall");
  const std::vector<double>&pe = stats.at("potential_energy"), &ke = stats.at("kinetic_energy");
  double steps = 0;
  for (size_t f = 1; f < pe.size(); ++f) {
    EXPECT_EQ(stats.at("substeps")[f], 12) << "frame " << f;
    steps += stats.at("substeps")[f];
  }
  const double lost = pe.front() - pe.back(), gained = ke.back();
  std::printf("free fall over %.0f steps: potential energy lost %.4f J/m, kinetic gained %.4f, their difference "
              "%.5f against KE / n = %.5f\n", steps, lost, gained, lost - gained, gained / steps);
  ASSERT_GT(gained, 1.0);
  EXPECT_NEAR(lost - gained, gained / steps, 1e-4 * lost);
}

// A wall moving at V meets a particle at rest: whatever the method, the particle leaves at V, so the wall gave it
// the impulse m V, and did the work m V . V = m V^2 on it, of which the particle keeps m V^2 / 2 (a perfectly
// inelastic collision loses the other half). source_work must read m V^2, to float rounding in the wall's
// velocity (the pose's difference over a step, 1e-3 here), and the energy must stay under it.
TEST(Energy, AMovingWallDoesTheWorkOfItsImpulse) {
  for (const char* method : {"pbf", "wcsph", "dfsph"}) {
    Scene scene = parseScene(
        R"({"name": "push", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 0.5]}, "particle_spacing": 0.01,
            "gravity": [0, 0], "fluids": [{"box": {"min": [0.5, 0.2], "max": [0.51, 0.21]}}],
            "colliders": [{"name": "wall", "shape": "box", "size": [0.02, 0.3], "motion": [
              {"time": 0, "position": [0.3, 0.2]}, {"time": 1, "position": [0.8, 0.2]}]}],
            "output": {"fps": 30, "frames": 27}})",
        "push.json", {std::string("solver.method=") + method});
    const auto stats = run(scene, std::string("energy_push_") + method);
    const double V = 0.5;
    const double work = stats.at("source_work").back(), kinetic = stats.at("kinetic_energy").back();
    std::printf("%s: a wall at %.1f m/s pushed a particle to kinetic energy %.6g J/m with work %.6g (their ratio "
                "%.4f, 0.5 for a perfectly inelastic collision)\n", method, V, kinetic, work, kinetic / work);
    EXPECT_NEAR(kinetic / work, 0.5, 1e-3) << method;
    EXPECT_GT(work, 0) << method;
  }
}

// An emitter in zero gravity sends each particle off at its speed U: it brings in m U^2 / 2 with each, and the
// nozzle that holds the first layers at U adds nothing while they keep it. The jet flies free, so the fluid's
// kinetic energy is source_work less what its internal forces (XSPH, the density solve at the face) take: under
// it, and within 2% of it.
TEST(Energy, AnEmitterBringsInTheEnergyOfWhatItEmits) {
  const Scene scene = parseScene(
      R"({"name": "jet", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 0.4], "open": ["+x"]},
          "particle_spacing": 0.01, "gravity": [0, 0],
          "emitters": [{"position": [0.02, 0.2], "direction": [1, 0], "radius": 0.04, "speed": 1}],
          "output": {"fps": 30, "frames": 15}})",
      "jet.json");
  const auto stats = run(scene, "energy_jet");
  const std::vector<double>&work = stats.at("source_work"), &kinetic = stats.at("kinetic_energy");
  const double mass = PbfSolver<2>(scene).particleMass(), particles = stats.at("particles").back();
  std::printf("jet: %.0f particles, kinetic energy %.5g J/m, source_work %.5g, N m U^2 / 2 = %.5g\n", particles,
              kinetic.back(), work.back(), particles * mass * 0.5);
  EXPECT_NEAR(work.back(), particles * mass * 0.5, 0.02 * work.back());
  EXPECT_LE(kinetic.back(), work.back());
  EXPECT_GE(kinetic.back(), 0.98 * work.back());
}

// Two emitters side by side, water and oil (800 kg/m^3, emitters[1].fluid): the same sites, so as many particles
// each, and each brings its own mass's m U^2 / 2: source_work is N m (1 + 0.8) / 2 x U^2 / 2, within the 2% above.
// Counted at water's mass, it would read 1.11 times that.
TEST(Energy, AnEmitterOfAnotherFluidBringsInItsOwnMass) {
  const Scene scene = parseScene(
      R"({"name": "jets", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 0.4], "open": ["+x"]},
          "particle_spacing": 0.01, "gravity": [0, 0],
          "fluids": [{"name": "water"}, {"name": "oil", "rest_density": 800}],
          "emitters": [{"position": [0.02, 0.1], "direction": [1, 0], "radius": 0.04, "speed": 1},
                       {"position": [0.02, 0.3], "direction": [1, 0], "radius": 0.04, "speed": 1, "fluid": "oil"}],
          "output": {"fps": 30, "frames": 15}})",
      "jets.json");
  const auto stats = run(scene, "energy_jets");
  const std::vector<double>&work = stats.at("source_work"), &kinetic = stats.at("kinetic_energy");
  const double mass = PbfSolver<2>(scene).particleMass(), particles = stats.at("particles").back();
  const double expected = particles * mass * (1 + 0.8) / 2 * 0.5;
  std::printf("two jets: %.0f particles, kinetic energy %.5g J/m, source_work %.5g, expected %.5g\n", particles,
              kinetic.back(), work.back(), expected);
  EXPECT_NEAR(work.back(), expected, 0.02 * expected);
  EXPECT_LE(kinetic.back(), work.back());
  EXPECT_GE(kinetic.back(), 0.98 * work.back());
}

// The attractor pushing (strength -20 m/s^2 at its centre, falling to 0 at 0.2 m) a lone particle out from 5 cm
// off its centre does m s [d - d^2 / (2 r)] from 0.05 to 0.2 m on it, 1.125 m J/m, all of which the particle keeps:
// source_work, the kick's own energy step by step, and the kinetic energy agree to float rounding (1e-4, over 130
// steps), and both with the integral to the integrator's error (3%).
TEST(Energy, TheAttractorsWorkIsTheEnergyItGives) {
  const Scene scene = parseScene(
      R"({"name": "push", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1]}, "particle_spacing": 0.01,
          "gravity": [0, 0], "fluids": [{"box": {"min": [0.55, 0.5], "max": [0.56, 0.51]}}],
          "attractor": {"radius": 0.2, "strength": -20, "keyframes": [{"time": 0, "position": [0.505, 0.505]}]},
          "solver": {"substeps": 16}, "output": {"fps": 30, "frames": 8}})",
      "attract.json");
  const auto stats = run(scene, "energy_attractor");
  const double mass = PbfSolver<2>(scene).particleMass(), expected = 1.125 * mass;
  const double work = stats.at("source_work").back(), kinetic = stats.at("kinetic_energy").back();
  std::printf("attractor: kinetic energy %.6g J/m, source_work %.6g, the integral %.6g\n", kinetic, work, expected);
  EXPECT_NEAR(work, kinetic, 1e-4 * kinetic);
  EXPECT_NEAR(kinetic, expected, 0.03 * expected);
}

// A jittered start (fluids[i].jitter) compresses WCSPH's fluid, which gives that energy back as motion: the account
// credits the compression, sum_i m_i e(rho_i) of the equation of state, as frame 1's source work (frame 0's is 0),
// so the run goes on. Without the credit this pool (0.4 x 0.2 m, jitter 0.4) turns 117 of its 208 J/m of
// compression into motion and height in its first frame, and the energy stop ends it there. The same pool on the
// lattice is credited nothing.
TEST(Energy, AJitteredWcsphStartIsCreditedItsCompression) {
  const std::string json = R"({"name": "jittered", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.4, 0.4]},
      "particle_spacing": 0.01, "fluids": [{"box": {"min": [0, 0], "max": [0.4, 0.2]}}],
      "solver": {"method": "wcsph"}, "output": {"fps": 30, "frames": 6}})";
  const auto jittered = run(parseScene(json, "jittered.json", {"fluids[0].jitter=0.4"}), "energy_jittered");
  ASSERT_EQ(jittered.at("frame").size(), 7u);
  EXPECT_EQ(jittered.at("source_work")[0], 0.0);
  const double credit = jittered.at("source_work")[1];
  std::printf("a jittered WCSPH pool: %.2f J/m of compression credited, kinetic energy %.2f J/m at frame 1\n", credit,
              jittered.at("kinetic_energy")[1]);
  EXPECT_GT(credit, jittered.at("kinetic_energy")[1]);
  EXPECT_EQ(jittered.at("source_work").back(), credit);
  const auto lattice = run(parseScene(json, "lattice.json"), "energy_lattice");
  EXPECT_EQ(lattice.at("source_work").back(), 0.0);
}

// A pool 60 particles deep whose DFSPH density solve is cut off at 10 iterations a step springs up (204 J/m from
// nowhere by frame 3, 39% of its energy): the run stops with one line naming the frame, the figures and the
// remedy, and leaves the frames before it whole. (At one step a frame and the full 100 iterations it sprang up
// too, until DFSPH's step took the deepest column's limit, docs/speed-accuracy.md.)
TEST(Energy, AFluidThatGainsEnergyFromNowhereStops) {
  const Scene scene = parseScene(
      R"({"name": "pool", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.3, 1.0]}, "particle_spacing": 0.01,
          "fluids": [{"box": {"min": [0, 0], "max": [0.3, 0.6]}}],
          "solver": {"method": "dfsph", "substeps": 1, "max_iterations": 10}, "output": {"fps": 30, "frames": 30}})",
      "pool.json");
  const fs::path dir = fs::path(::testing::TempDir()) / "energy_stop";
  fs::remove_all(dir);
  Progress quiet;
  std::string message;
  try {
    simulate(scene, dir, false, quiet);
  } catch (const RunError& error) {
    message = error.what();
  }
  std::printf("%s\n", message.c_str());
  const std::string prefix = "the fluid gained energy from nowhere by frame ";
  ASSERT_EQ(message.rfind(prefix, 0), 0u) << message;
  EXPECT_NE(message.find("give it more solver.substeps or a smaller solver.max_density_error"), std::string::npos);
  EXPECT_EQ(message.find('\n'), std::string::npos);
  const int frame = std::atoi(message.c_str() + prefix.size());
  ASSERT_GE(frame, 1);
  std::vector<int> expected;
  for (int f = 0; f < frame; ++f) expected.push_back(f);
  EXPECT_EQ(listFrames(dir, "particles", "ply"), expected);
  EXPECT_EQ(readStats(dir).at("frame").size(), size_t(frame));
}

// A resumed run goes on from stats.csv's own figures: its source_work, frame by frame, is the uninterrupted run's,
// for a wall sweeping water across a 2D tank (work from frame 1 to the end).
TEST(Energy, AResumedRunKeepsTheSameAccount) {
  auto sweep = [](int frames) {
    return parseScene(
        R"({"name": "sweep", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 0.5]}, "particle_spacing": 0.02,
            "fluids": [{"box": {"min": [0.2, 0], "max": [0.6, 0.2]}}],
            "colliders": [{"name": "wall", "shape": "box", "size": [0.04, 0.3], "motion": [
              {"time": 0, "position": [0.1, 0.15]}, {"time": 1, "position": [0.7, 0.15]}]}],
            "output": {"fps": 30, "frames": )" + std::to_string(frames) + "}}",
        "sweep.json");
  };
  const auto whole = run(sweep(20), "energy_whole");
  const fs::path dir = fs::path(::testing::TempDir()) / "energy_resumed";
  fs::remove_all(dir);
  Progress quiet;
  simulate(sweep(9), dir, false, quiet);
  simulate(sweep(20), dir, true, quiet);
  const auto resumed = readStats(dir);
  ASSERT_EQ(resumed.at("source_work").size(), 21u);
  EXPECT_GT(whole.at("source_work").back(), 0.1);
  EXPECT_EQ(resumed.at("source_work"), whole.at("source_work"));
  EXPECT_EQ(resumed.at("kinetic_energy"), whole.at("kinetic_energy"));
}

}  // namespace
}  // namespace surge
