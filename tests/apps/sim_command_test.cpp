// `surge sim` as a user runs it: the same bytes at any thread count, divergence as an error, resume after kill.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "core/ply.h"
#include "tests/apps/run_surge.h"
#include "tests/sim/stats_columns.h"

extern char** environ;

namespace surge {
namespace {

// About 3,500 particles, 24 frames: a second or two of simulation.
const char* kSmallDamBreak = R"({
  "name": "small", "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [0.8, 0.5, 0.3]},
  "particle_spacing": 0.025,
  "fluids": [{"box": {"min": [0, 0, 0], "max": [0.25, 0.4, 0.3]}}],
  "solver": {"vorticity_epsilon": 0.01},
  "output": {"fps": 30, "frames": 24}
})";

TEST(SimCommand, SameBytesWithOneAndTwoThreads) {
  const fs::path scene = writeTestScene("small.json", kSmallDamBreak);
  const fs::path one = freshFolder("surge_threads_1"), two = freshFolder("surge_threads_2");
  ASSERT_EQ(runSurge("sim '" + scene.string() + "' --quiet --threads 1 --set output.frames=8 --out " + one.string()).status, 0);
  ASSERT_EQ(runSurge("sim '" + scene.string() + "' --quiet --threads 2 --set output.frames=8 --out " + two.string()).status, 0);
  for (int f = 0; f <= 8; ++f)
    EXPECT_EQ(readTextFile(framePath(one, "particles", f, "ply")), readTextFile(framePath(two, "particles", f, "ply")))
        << "frame " << f;
}

TEST(SimCommand, DivergenceStopsWithFrameSubstepAndParticle) {
  // Eight particles stacked on one point (eight one-particle fluid boxes) with no relaxation (epsilon = 0): they
  // are compressed (8 x W(0) exceeds the rest lattice's sum) while the gradients between them are next to
  // zero, so eq. 11 divides by (nearly) zero and the positions turn NaN within the first frame.
  std::string fluids;
  for (int k = 0; k < 8; ++k) fluids += std::string(k ? "," : "") + R"({"box": {"min": [0.3, 0.1, 0.1], "max": [0.325, 0.125, 0.125]}})";
  std::string text = kSmallDamBreak;
  const size_t start = text.find("\"fluids\""), end = text.find("\n", start);
  text.replace(start, end - start, "\"fluids\": [" + fluids + "],");
  const fs::path scene = writeTestScene("stacked.json", text);
  const fs::path out = freshFolder("surge_diverged");
  const SurgeResult r = runSurge("sim '" + scene.string() + "' --set solver.relaxation_epsilon=0 --out " + out.string());
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("simulation diverged at frame 1, substep "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(": particle "), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(listFrames(out, "particles", "ply"), std::vector<int>{0});  // earlier frames intact, no partial one
  EXPECT_EQ(readParticlePly(framePath(out, "particles", 0, "ply")).size(), 8u);
}

// A density solver that stops at its cap rather than at solver.max_density_error leaves the density error above
// it: surge sim says in how many of its steps, over which frames, and which key raises the cap. DFSPH held to 3
// iterations under a tolerance of 1e-5 stops at the cap in every step; at its defaults this dam break converges.
// PBF iterating to a tolerance names solver.iterations, its cap.
TEST(SimCommand, SaysWhereTheDensitySolverStoppedAtItsCap) {
  const fs::path scene = writeTestScene("capped.json", kSmallDamBreak);
  auto run = [&](const std::string& settings, const std::string& name) {
    const fs::path out = freshFolder(name);
    const SurgeResult r = runSurge("sim '" + scene.string() + "' --set output.frames=4 " + settings + " --out " +
                                   out.string());
    EXPECT_EQ(r.status, 0) << r.err;
    size_t steps = 0;
    const std::vector<double> substeps = readStats(out).at("substeps");
    for (size_t f = 1; f < substeps.size(); ++f) steps += size_t(substeps[f]);
    return std::make_pair(r.out, steps);
  };
  const auto [capped, steps] = run("--set solver.method=dfsph --set solver.max_iterations=3 "
                                   "--set solver.max_density_error=0.00001", "surge_capped");
  EXPECT_NE(capped.find("sim: the density solver stopped at its cap of 3 iterations in " + std::to_string(steps) +
                        " of " + std::to_string(steps) + " steps (frames 1-4)"),
            std::string::npos)
      << capped;
  EXPECT_NE(capped.find("solver.max_iterations let it converge"), std::string::npos) << capped;
  const auto [converged, unused] = run("--set solver.method=dfsph", "surge_converged");
  EXPECT_EQ(converged.find("stopped at its cap"), std::string::npos) << converged;
  const auto [pbf, pbfSteps] = run("--set solver.iterations=2 --set solver.max_density_error=0.00001", "surge_pbf_capped");
  EXPECT_NE(pbf.find("cap of 2 iterations"), std::string::npos) << pbf;
  EXPECT_NE(pbf.find("solver.iterations let it converge"), std::string::npos) << pbf;
  const auto [fixed, fixedSteps] = run("", "surge_pbf_fixed");
  EXPECT_EQ(fixed.find("stopped at its cap"), std::string::npos) << fixed;
  // A run the energy stop ends says so in its one line too: a column 1 m deep (10,000 particles at 1 cm) under
  // DFSPH held to 3 iterations gains energy by frame 4.
  const fs::path deep = writeTestScene("capped_column.json", R"({"name": "column", "dimensions": 2,
      "domain": {"min": [0, 0], "max": [3.2, 1.6]}, "particle_spacing": 0.01,
      "fluids": [{"box": {"min": [0, 0], "max": [1.0, 1.0]}}], "solver": {"method": "dfsph", "max_iterations": 3,
      "max_density_error": 0.00001}, "output": {"fps": 30, "frames": 4}})");
  const SurgeResult stopped = runSurge("sim '" + deep.string() + "' --out " + freshFolder("surge_capped_stop").string());
  EXPECT_EQ(stopped.status, 1) << stopped.err;
  EXPECT_NE(stopped.err.find("gained energy from nowhere"), std::string::npos) << stopped.err;
  EXPECT_NE(stopped.err.find("; its density solver stopped at its cap of 3 iterations in "), std::string::npos)
      << stopped.err;
  EXPECT_NE(stopped.err.find("a larger solver.max_iterations lets it converge"), std::string::npos) << stopped.err;
  EXPECT_EQ(std::count(stopped.err.begin(), stopped.err.end(), '\n'), 1) << stopped.err;
}

// fluids[i].velocity_field with a formula that parses but is not finite somewhere in its block (a square root of
// a negative x): one line naming the component, exit 2, no output folder (checked before the run starts).
TEST(SimCommand, AVelocityFieldNotFiniteInItsBlockIsOneLineAndWritesNothing) {
  std::string text = kSmallDamBreak;
  text.replace(text.find("}]"), 0, R"X(, "velocity_field": ["0", "sqrt(x - 0.1)", "0"])X");
  const fs::path scene = writeTestScene("field_not_finite.json", text);
  const fs::path out = freshFolder("surge_field_not_finite");
  fs::remove_all(out);
  for (const char* command : {"run", "sim"}) {
    const SurgeResult r = runSurge(std::string(command) + " '" + scene.string() + "' --out '" + out.string() + "'");
    EXPECT_EQ(r.status, 2) << command;
    EXPECT_NE(r.err.find("field_not_finite.json: fluids[0].velocity_field[1]: 'sqrt(x - 0.1)' is not finite at ("),
              std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(out)) << command;
  }
}

TEST(SimCommand, ResumeRefusesChangedPhysicsButTakesMoreFramesAndOtherRendering) {
  const fs::path scene = writeTestScene("small.json", kSmallDamBreak);
  const fs::path out = freshFolder("surge_resume_changed");
  const std::string base = "sim '" + scene.string() + "' --quiet --out " + out.string();
  ASSERT_EQ(runSurge(base + " --set output.frames=2").status, 0);
  const std::string frame2 = readTextFile(framePath(out, "particles", 2, "ply"));

  const SurgeResult changed = runSurge(base + " --resume --set output.frames=3 --set solver.iterations=7");
  EXPECT_EQ(changed.status, 2) << changed.err;
  EXPECT_NE(changed.err.find((out / "scene.json").string() + ": solver.iterations: differs"), std::string::npos)
      << changed.err;
  EXPECT_EQ(std::count(changed.err.begin(), changed.err.end(), '\n'), 1) << changed.err;
  EXPECT_EQ(listFrames(out, "particles", "ply"), (std::vector<int>{0, 1, 2}));  // nothing written
  EXPECT_EQ(readTextFile(framePath(out, "particles", 2, "ply")), frame2);

  const SurgeResult more = runSurge(base + " --resume --set output.frames=3 --set render.width=320");
  EXPECT_EQ(more.status, 0) << more.err;
  EXPECT_EQ(listFrames(out, "particles", "ply"), (std::vector<int>{0, 1, 2, 3}));
}

TEST(SimCommand, ResumeAfterKillEndsOnTheSameBytes) {
  const fs::path scene = writeTestScene("small.json", kSmallDamBreak);
  const fs::path whole = freshFolder("surge_whole"), resumed = freshFolder("surge_resumed");
  ASSERT_EQ(runSurge("sim '" + scene.string() + "' --quiet --out " + whole.string()).status, 0);

  // Start the same run, and SIGKILL it once it has written frame 3.
  const std::string binary = SURGE_BINARY, out = resumed.string(), scenePath = scene.string();
  std::vector<const char*> argv = {binary.c_str(), "sim", scenePath.c_str(), "--quiet", "--out", out.c_str(), nullptr};
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, binary.c_str(), nullptr, nullptr, const_cast<char**>(argv.data()), environ), 0);
  const fs::path frame3 = framePath(resumed, "particles", 3, "ply");
  for (int wait = 0; wait < 60000 && !fs::exists(frame3); ++wait) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run ended before it could be killed; make the scene longer";
  ASSERT_LT(listFrames(resumed, "particles", "ply").back(), 24);
  // As if the kill had struck while a frame was being written: a half-written temporary file.
  const fs::path next = framePath(resumed, "particles", listFrames(resumed, "particles", "ply").back() + 1, "ply");
  writeFileAtomically(next.string() + ".tmp4242", [](std::ostream& o) { o << "ply\nformat binary_little_endian 1.0\nelem"; });

  const SurgeResult r = runSurge("sim '" + scene.string() + "' --quiet --resume --out " + resumed.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(readTextFile(framePath(resumed, "particles", 24, "ply")), readTextFile(framePath(whole, "particles", 24, "ply")));
  EXPECT_FALSE(fs::exists(next.string() + ".tmp4242"));
  // stats.csv has every frame once.
  std::ifstream stats(resumed / "stats.csv");
  std::string line;
  int rows = -1;
  while (std::getline(stats, line)) ++rows;
  EXPECT_EQ(rows, 25);
}

}  // namespace
}  // namespace surge

namespace surge {
namespace {

// The value of column `name` in a stats.csv row, by the header's names.
double statsColumn(const std::string& header, const std::string& row, const std::string& name) {
  std::istringstream names(header), values(row);
  std::string key, value;
  while (std::getline(names, key, ',') && std::getline(values, value, ','))
    if (key == name) return std::stod(value);
  ADD_FAILURE() << "no column " << name << " in " << header;
  return 0.0;
}

// Runs the small dam break with `settings` to frame 6 at 1 and 2 threads, and to frame 3 then resumed to 6:
// the particle frames must be the same bytes, and for a method that `carriesState`, its state kept for the last
// two frames. Returns the folders of the 1-thread run and the resumed one.
std::pair<fs::path, fs::path> expectSameAtAnyThreadCountAndResumed(const std::string& settings, const std::string& tag,
                                                                  bool carriesState) {
  const fs::path scene = writeTestScene("small.json", kSmallDamBreak);
  const std::string run = " --quiet " + settings + " --out ";
  const fs::path one = freshFolder(tag + "_1"), two = freshFolder(tag + "_2"), resumed = freshFolder(tag + "_r");
  EXPECT_EQ(runSurge("sim '" + scene.string() + "' --threads 1 --set output.frames=6" + run + one.string()).status, 0);
  EXPECT_EQ(runSurge("sim '" + scene.string() + "' --threads 2 --set output.frames=6" + run + two.string()).status, 0);
  for (int f = 0; f <= 6; ++f)
    EXPECT_EQ(readTextFile(framePath(one, "particles", f, "ply")), readTextFile(framePath(two, "particles", f, "ply")))
        << tag << " frame " << f;
  if (carriesState) {
    EXPECT_TRUE(fs::exists(framePath(one, "solver", 6, "bin"))) << tag;
    EXPECT_TRUE(fs::exists(framePath(one, "solver", 5, "bin"))) << tag;
    EXPECT_FALSE(fs::exists(framePath(one, "solver", 4, "bin"))) << tag;
  }
  EXPECT_EQ(runSurge("sim '" + scene.string() + "' --set output.frames=3" + run + resumed.string()).status, 0);
  EXPECT_EQ(runSurge("sim '" + scene.string() + "' --resume --set output.frames=6" + run + resumed.string()).status, 0);
  EXPECT_EQ(readTextFile(framePath(resumed, "particles", 6, "ply")), readTextFile(framePath(one, "particles", 6, "ply")))
      << tag;
  return {one, resumed};
}

// The value of stats.csv's column `name` at frame 1 of the run in `folder`.
double frameOneStat(const fs::path& folder, const std::string& name) {
  std::ifstream stats(folder / "stats.csv");
  std::string header, row;
  std::getline(stats, header);
  std::getline(stats, row);  // frame 0
  std::getline(stats, row);  // frame 1
  return statsColumn(header, row, name);
}

// WCSPH through the same frame loop: its own step sizes, the same guarantees.
TEST(SimCommand, WcsphIsTheSameWithOneAndTwoThreadsAndResumesExactly) {
  // Three frames, then resume to six: the integrator restarts at frame 3 exactly as the whole run did.
  const fs::path one = expectSameAtAnyThreadCountAndResumed("--set solver.method=wcsph", "surge_wcsph", false).first;
  // stats.csv reports the step and the largest pressure of each frame.
  EXPECT_GT(frameOneStat(one, "time_step"), 0.0);
  EXPECT_LT(frameOneStat(one, "time_step"), 1.0 / 30 / 10);  // many steps a frame at this speed of sound
  EXPECT_GT(frameOneStat(one, "pressure_max"), 0.0);
}

// DFSPH through the same frame loop: its CFL steps, and its warm starts carried from frame to frame in
// solver/frame_NNNNN.bin (the last two kept), so that a resumed run ends on the same bytes.
TEST(SimCommand, DfsphIsTheSameWithOneAndTwoThreadsAndResumesExactly) {
  const fs::path scene = writeTestScene("small.json", kSmallDamBreak);
  const auto [one, resumed] = expectSameAtAnyThreadCountAndResumed("--set solver.method=dfsph", "surge_dfsph", true);
  // Without the carried state the resumed run cannot be exact: it is refused in one line.
  fs::remove(framePath(resumed, "solver", 6, "bin"));
  const auto again = runSurge("sim '" + scene.string() + "' --resume --quiet --set solver.method=dfsph "
                              "--set output.frames=8 --out " + resumed.string());
  EXPECT_EQ(again.status, 1) << again.err;
  EXPECT_NE(again.err.find("solver's state"), std::string::npos) << again.err;
  // stats.csv reports both solvers' iterations: the density solver's at least 2 a step (the paper's minimum),
  // the divergence solver's at least 1.
  EXPECT_GE(frameOneStat(one, "iterations"), 2.0);
  EXPECT_GE(frameOneStat(one, "divergence_iterations"), 1.0);
  EXPECT_GT(frameOneStat(one, "pressure_max"), 0.0);
}

// PBF with its warm start carries its lambda sums the same way: the same bytes at 1 and 2 threads and resumed.
TEST(SimCommand, PbfWarmStartIsTheSameWithOneAndTwoThreadsAndResumesExactly) {
  expectSameAtAnyThreadCountAndResumed("--set solver.warm_start=0.5", "surge_warm", true);
  // Off (the default), PBF carries nothing.
  const fs::path scene = writeTestScene("small.json", kSmallDamBreak);
  const fs::path cold = freshFolder("surge_warm_off");
  ASSERT_EQ(runSurge("sim '" + scene.string() + "' --quiet --set output.frames=2 --out " + cold.string()).status, 0);
  EXPECT_FALSE(fs::exists(framePath(cold, "solver", 2, "bin")));
}

}  // namespace
}  // namespace surge
