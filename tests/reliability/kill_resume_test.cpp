// `surge run` killed with SIGKILL at random points in every stage, then `surge run --resume`: every frame of
// every stage and the video end as the same bytes as an uninterrupted run's (issue 14). ctest -L reliability.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <random>
#include <thread>

#include "core/files.h"
#include "tests/reliability/run_folder.h"

namespace surge {
namespace {

using Clock = std::chrono::steady_clock;

TEST(KillAndResume, EveryStageKilledAtRandomPointsResumesToTheSameBytes) {
  const fs::path scene = writeTestScene("killed.json", kScene);

  // The uninterrupted run, timing when each marker appears.
  const fs::path reference = freshFolder("kill_reference");
  std::vector<double> seen(kStageCount + 1, -1);
  const Clock::time_point start = Clock::now();
  const pid_t pid = startRun(scene, reference, false);
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    const double now = std::chrono::duration<double>(Clock::now() - start).count();
    for (int m = 0; m < kStageCount; ++m)
      if (seen[m] < 0 && markerExists(reference, m)) seen[m] = now;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the uninterrupted run failed";
  seen.back() = std::chrono::duration<double>(Clock::now() - start).count();
  for (int m = 0; m < kStageCount; ++m) ASSERT_GE(seen[m], 0) << kStages[m] << " was not seen to start";
  // The bytes every run must end with: one uninterrupted run on one thread (the kills run on two, so the
  // comparison holds the thread count too).
  const fs::path oneThread = freshFolder("kill_reference_1");
  ASSERT_EQ(waitExit(startRun(scene, oneThread, false, 1)), 0);
  const std::map<std::string, std::string> expected = folderContents(oneThread);
  ASSERT_TRUE(folderContents(reference) == expected) << "two threads did not write the bytes one thread did";

  // Three kills in each stage, each at a time drawn uniformly from the stage's window in the run above, counted
  // from when that stage started. A kill that lands after the stage ended (the machine ran faster than in the
  // run above, which other tests may have slowed) is drawn again from half the window, up to six times: it is
  // the stage that must be hit, not a wall-clock instant.
  std::mt19937 random(20261129);
  int kills = 0;
  for (int stage = 0; stage < kStageCount; ++stage) {
    const double window = seen[stage + 1] - seen[stage];
    for (int point = 0; point < 3; ++point) {
      const fs::path dir = freshFolder("kill_" + std::to_string(stage) + "_" + std::to_string(point));
      bool landed = false;
      double delay = 0, drawn = window;
      pid_t run = 0;
      for (int attempt = 0; attempt < 7 && !landed; ++attempt, drawn *= 0.5) {
        if (run > 0) killGroupAndRemove(run, dir);  // a kill that missed may have orphaned ffmpeg
        fs::remove_all(dir);
        delay = std::uniform_real_distribution<double>(0, 0.9 * drawn)(random);
        run = startRun(scene, dir, false);
        // Wait for the stage to start (or the run to end), then for the drawn delay.
        bool ended = false;
        while (!markerExists(dir, stage) && !(ended = ::waitpid(run, &status, WNOHANG) == run))
          std::this_thread::sleep_for(std::chrono::microseconds(200));
        ASSERT_FALSE(ended) << kStages[stage] << " never started";
        std::this_thread::sleep_for(std::chrono::duration<double>(delay));
        ::kill(run, SIGKILL);
        ::waitpid(run, &status, 0);
        landed = WIFSIGNALED(status) && !markerExists(dir, stage + 1);
      }
      ASSERT_TRUE(landed) << "no kill landed in " << kStages[stage];
      ++kills;
      int temporaries = 0;
      for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        temporaries += name.find(".tmp") != std::string::npos || name.find(".partial") != std::string::npos;
      }
      std::printf("kill %2d in %-12s at %6.1f ms of its %6.1f ms: %2zu particle frames, %2zu surfaces, %2zu images, "
                  "%d temporaries left\n",
                  kills, kStages[stage], 1e3 * delay, 1e3 * window, listFrames(dir, "particles", "ply").size(),
                  listFrames(dir, "surface", "vdb").size(), listFrames(dir, "frames", "png").size(), temporaries);

      // What the killed run left: any frame under its own name is whole (the same bytes as the reference's).
      for (const auto& [name, bytes] : folderContents(dir)) {
        const bool frame = name.find("frame_") != std::string::npos && name.find(".tmp") == std::string::npos;
        if (frame && expected.count(name)) {
          EXPECT_TRUE(bytes == expected.at(name)) << name << " is not whole after a kill in " << kStages[stage];
        }
      }

      const pid_t resumed = startRun(scene, dir, true);
      ASSERT_EQ(waitExit(resumed), 0) << "--resume after a kill in " << kStages[stage] << " at " << delay << " s";
      // An ffmpeg orphaned by a kill during encoding may still be writing its temporary: the resumed run
      // removed its name first, so nothing of it is left to see.
      expectSameFiles(folderContents(dir), expected,
                      std::string("after a kill in ") + kStages[stage] + " at " + std::to_string(delay) +
                          " s and --resume");
      killGroupAndRemove(run, dir);
    }
  }
  EXPECT_EQ(kills, 3 * kStageCount);
  fs::remove_all(reference);
  fs::remove_all(oneThread);
}

}  // namespace
}  // namespace surge
