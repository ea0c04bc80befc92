// The whitewater stage run as a user runs it (surge sim, then surge whitewater): none from a pool at rest, alike at
// 1x and 100x scale, the same bytes at any thread count and after a resume, one line for bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "core/ply.h"
#include "core/scene_fields.h"
#include "tests/apps/run_surge.h"

namespace surge {
namespace {

// A 2D dam break, `scale` times the size, with its time scaled by sqrt(scale) (Froude similarity: the same flow).
std::string damBreak(double scale) {
  const double fps = 30 / std::sqrt(scale);
  auto n = [&](double v) { return formatNumber(v * scale); };
  return R"({"name": "ww_dam", "dimensions": 2, "domain": {"min": [0, 0], "max": [)" + n(1.6) + ", " + n(0.8) +
         R"(]}, "particle_spacing": )" + n(0.01) + R"(, "fluids": [{"box": {"min": [0, 0], "max": [)" + n(0.4) +
         ", " + n(0.4) + R"(]}}], "solver": {"method": "pbf", "substeps": 8, "iterations": 4},
         "output": {"fps": )" + formatNumber(fps) + R"(, "frames": 45}, "whitewater": {"enabled": 1}})";
}

// Every whitewater frame's particles summed, and the largest frame.
struct Totals {
  double particleFrames = 0;
  size_t most = 0;
  int frames = 0;
};
Totals whitewaterTotals(const fs::path& dir) {
  Totals t;
  for (int f : listFrames(dir, "whitewater", "ply")) {
    const size_t n = readDiffusePly(framePath(dir, "whitewater", f, "ply")).size();
    t.particleFrames += double(n);
    t.most = std::max(t.most, n);
    ++t.frames;
  }
  return t;
}

fs::path simulateAndWhiten(const std::string& name, const std::string& scene, const std::string& flags = "") {
  const fs::path path = writeTestScene(name + ".json", scene);
  const fs::path dir = freshFolder(name);
  const SurgeResult sim = runSurge("sim " + path.string() + " --out " + dir.string() + " --quiet");
  EXPECT_EQ(sim.status, 0) << sim.err;
  const SurgeResult ww = runSurge("whitewater " + dir.string() + " --quiet " + flags);
  EXPECT_EQ(ww.status, 0) << ww.err;
  return dir;
}

TEST(WhitewaterStage, APoolAtRestMakesNone) {
  for (const char* dims : {"2", "3"}) {
    const bool three = dims[0] == '3';
    const std::string scene = std::string(R"({"name": "ww_pool", "dimensions": )") + dims +
                              R"(, "domain": {"min": )" + (three ? "[0, 0, 0]" : "[0, 0]") + R"(, "max": )" +
                              (three ? "[0.4, 0.4, 0.2]" : "[0.4, 0.4]") +
                              R"(}, "particle_spacing": 0.02, "fluids": [{"box": {"min": )" +
                              (three ? "[0, 0, 0]" : "[0, 0]") + R"(, "max": )" +
                              (three ? "[0.4, 0.2, 0.2]" : "[0.4, 0.2]") +
                              R"(}}], "output": {"frames": 30}, "whitewater": {"enabled": 1}})";
    const fs::path dir = simulateAndWhiten(std::string("ww_pool_") + dims, scene);
    const Totals totals = whitewaterTotals(dir);
    EXPECT_EQ(totals.frames, 31) << dims << "D";
    EXPECT_EQ(totals.most, 0u) << dims << "D: a pool at rest made whitewater";
  }
}

// Thresholds on (|v| / U)^2, v_diff / (U S) and curvature / S, rates per T = diagonal / U: all the same numbers
// at any scale of a Froude-similar flow. What may differ is the simulation itself (its float rounding at 100 m,
// the chaos of a splash), hence a factor of 2 as the issue asks.
TEST(WhitewaterStage, ADamBreakAtOneAndAHundredTimesItsSizeMakesAlike) {
  const fs::path small = simulateAndWhiten("ww_scale_1", damBreak(1));
  const fs::path large = simulateAndWhiten("ww_scale_100", damBreak(100));
  const Totals a = whitewaterTotals(small), b = whitewaterTotals(large);
  const double fluid = 40 * 40;  // particles of the 0.4 m block at 0.01
  ASSERT_GT(a.most, 100u) << "the dam break made almost no whitewater";
  const double ratio = (b.particleFrames / fluid) / (a.particleFrames / fluid);
  EXPECT_GT(ratio, 0.5) << a.particleFrames << " at 1x, " << b.particleFrames << " at 100x";
  EXPECT_LT(ratio, 2.0) << a.particleFrames << " at 1x, " << b.particleFrames << " at 100x";
}

TEST(WhitewaterStage, TheSameBytesAtAnyThreadCountAndAfterAResume) {
  const fs::path one = simulateAndWhiten("ww_threads_1", damBreak(1), "--threads 1");
  const fs::path two = freshFolder("ww_threads_2");
  fs::copy(one, two, fs::copy_options::recursive);
  fs::remove_all(two / "whitewater");
  ASSERT_EQ(runSurge("whitewater " + two.string() + " --quiet --threads 2").status, 0);
  const fs::path resumed = freshFolder("ww_threads_r");
  fs::copy(one, resumed, fs::copy_options::recursive);
  fs::remove_all(resumed / "whitewater");
  ASSERT_EQ(runSurge("whitewater " + resumed.string() + " --quiet --frames 0:20").status, 0);
  EXPECT_EQ(listFrames(resumed, "whitewater", "ply").size(), 21u);
  ASSERT_EQ(runSurge("whitewater " + resumed.string() + " --quiet --resume").status, 0);
  int compared = 0;
  for (int f : listFrames(one, "whitewater", "ply")) {
    const std::string reference = readTextFile(framePath(one, "whitewater", f, "ply"));
    EXPECT_EQ(readTextFile(framePath(two, "whitewater", f, "ply")), reference) << "frame " << f << " at 2 threads";
    EXPECT_EQ(readTextFile(framePath(resumed, "whitewater", f, "ply")), reference) << "frame " << f << " resumed";
    ++compared;
  }
  EXPECT_EQ(compared, 46);
  EXPECT_GT(whitewaterTotals(one).most, 0u);
}

TEST(WhitewaterStage, BadInputIsOneLineAndExitTwo) {
  const fs::path scene = writeTestScene("ww_bad.json", damBreak(1));
  const SurgeResult bad =
      runSurge("sim " + scene.string() + " --out " + freshFolder("ww_bad").string() +
               " --set whitewater.trapped_air_max=0.01");
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(lines(bad.err).size(), 1u) << bad.err;
  EXPECT_NE(bad.err.find("whitewater.trapped_air_max"), std::string::npos) << bad.err;
  const fs::path empty = freshFolder("ww_empty");
  fs::create_directories(empty);
  const SurgeResult none = runSurge("whitewater " + empty.string());
  EXPECT_EQ(none.status, 2);
  EXPECT_EQ(lines(none.err).size(), 1u) << none.err;
}

}  // namespace
}  // namespace surge
