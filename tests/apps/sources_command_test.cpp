// A tank before the tap opens holds no particle: every stage (sim, surface, render, video, study) takes frames of
// any count, zero included. And a source the run would refuse is one line, exit 2, nothing written.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "core/files.h"
#include "core/ply.h"
#include "tests/apps/run_surge.h"

namespace surge {
namespace {

// The tap opens at 0.1 s (frame 3 at 30 fps) and closes at 0.2 s; the drain takes what reaches the floor.
const char* kTap = R"({
  "name": "tap",
  "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [0.3, 0.3, 0.3]},
  "particle_spacing": 0.02,
  "emitters": [{"position": [0.15, 0.25, 0.15], "direction": [0, -1, 0], "radius": 0.04, "speed": 1,
                "start": 0.1, "stop": 0.2}],
  "output": {"fps": 30, "frames": 6},
  "render": {"width": 96, "height": 64, "samples": 1}
})";

TEST(SourcesCommand, FramesWithoutParticlesGoThroughEveryStage) {
  const fs::path scene = writeTestScene("tap.json", kTap);
  const fs::path out = freshFolder("surge_tap");
  const SurgeResult r = runSurge("run '" + scene.string() + "' --out '" + out.string() + "' --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  for (int f = 0; f <= 6; ++f) {
    const size_t count = readParticlePly(framePath(out, "particles", f, "ply")).size();
    if (f <= 2) EXPECT_EQ(count, 0u) << f;
    if (f >= 4) EXPECT_GT(count, 0u) << f;  // frame 3 ends as the tap opens, at 0.1 s
    EXPECT_TRUE(fs::exists(framePath(out, "surface", f, "vdb"))) << f;
    EXPECT_TRUE(fs::exists(framePath(out, "frames", f, "png"))) << f;
  }
  EXPECT_EQ(countVideoFrames(out / "tap.mp4"), 7);
  const std::vector<std::string> stats = lines(readTextFile(out / "stats.csv"));
  ASSERT_EQ(stats.size(), 8u);
  EXPECT_NE(stats[0].find(",emitted,removed"), std::string::npos) << stats[0];

  // A study of the tap's speed: each run starts from an empty tank.
  const fs::path study = freshFolder("surge_tap_study");
  const SurgeResult s = runSurge("study '" + scene.string() + "' --quiet --sweep emitters[0].speed=0.5,1 --frames 5 --out " +
                                 study.string());
  ASSERT_EQ(s.status, 0) << s.err;
  const std::vector<std::string> rows = lines(readTextFile(study / "study.csv"));
  ASSERT_EQ(rows.size(), 3u);
  for (size_t i = 1; i < rows.size(); ++i) EXPECT_NE(rows[i].find(",ok"), std::string::npos) << rows[i];
}

TEST(SourcesCommand, ARefusedSourceIsOneLineAndWritesNothing) {
  std::string text = kTap;
  text.replace(text.find("\"output\""), 0,
               R"("colliders": [{"name": "cup", "shape": "sphere", "position": [0.15, 0.24, 0.15], "radius": 0.05}], )");
  const fs::path scene = writeTestScene("tap_in_cup.json", text);
  const fs::path out = freshFolder("surge_tap_in_cup");
  fs::remove_all(out);
  for (const char* command : {"run", "sim"}) {
    const SurgeResult r = runSurge(std::string(command) + " '" + scene.string() + "' --out '" + out.string() + "'");
    EXPECT_EQ(r.status, 2) << command;
    EXPECT_NE(r.err.find("tap_in_cup.json: emitters[0].position: lies inside collider cup"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(out)) << command;
  }
}

}  // namespace
}  // namespace surge
