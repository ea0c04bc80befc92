// A full disk (issue 14): a run that cannot fit is refused up front; a disk that fills while frames are being
// written (another program takes the space) ends the run with exit 1 and one line, leaves no partial frame under
// a frame's name, and `--resume` finishes on the same bytes once there is room again. The runs write on a small
// tmpfs, which needs root (CI runs as root); elsewhere the tests are skipped, saying why.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>

#include "core/files.h"
#include "tests/reliability/run_folder.h"

namespace surge {
namespace {

// A tmpfs of `megabytes` at a fresh folder, unmounted when the test ends.
class SmallDisk {
 public:
  explicit SmallDisk(const std::string& name, int megabytes) : path_(freshFolder(name)) {
    fs::create_directories(path_);
    const std::string options = "size=" + std::to_string(megabytes) + "m";
    mounted_ = ::mount("tmpfs", path_.c_str(), "tmpfs", 0, options.c_str()) == 0;
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(path_.c_str(), MNT_DETACH);
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  bool mounted() const { return mounted_; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  bool mounted_ = false;
};

#define SKIP_UNLESS_MOUNTED(disk)                                                                        \
  if (!(disk).mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (needs root and CAP_SYS_ADMIN), so " \
                                         "there is no small disk to fill"

// Writes a file at `path` until the disk is full, as another program would take the space; its size.
size_t fillDisk(const fs::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return 0;
  std::setvbuf(file, nullptr, _IONBF, 0);
  const std::vector<char> block(64 * 1024, 'x');
  size_t written = 0;
  for (size_t n; (n = std::fwrite(block.data(), 1, block.size(), file)) > 0;) {
    written += n;
    if (n < block.size()) break;
  }
  std::fclose(file);
  return written;
}

TEST(DiskFull, RunThatCannotFitIsRefusedBeforeWritingAnything) {
  SmallDisk disk("disk_full_small", 1);  // 13 frames of 5200 particles are 1.9 MB
  SKIP_UNLESS_MOUNTED(disk);
  const fs::path scene = writeTestScene("killed.json", kScene);
  const fs::path errors = fs::path(testing::TempDir()) / "disk_full_refused.err";
  const fs::path out = disk.path() / "run";
  EXPECT_EQ(waitExit(startRun(scene, out, false, 2, errors)), 2);
  const std::vector<std::string> message = lines(readTextFile(errors));
  ASSERT_EQ(message.size(), 1u) << readTextFile(errors);
  EXPECT_NE(message[0].find(out.string()), std::string::npos) << message[0];
  EXPECT_NE(message[0].find("--out"), std::string::npos) << message[0];
  EXPECT_NE(message[0].find("1.9 MB"), std::string::npos) << message[0];
  EXPECT_TRUE(fs::is_empty(disk.path())) << "something was written";
}

TEST(DiskFull, DiskFillingInEveryStageIsOneLineNoPartialFrameAndResumeEndsOnTheSameBytes) {
  const fs::path scene = writeTestScene("killed.json", kScene);
  const fs::path reference = freshFolder("disk_full_reference");
  ASSERT_EQ(waitExit(startRun(scene, reference, false)), 0);
  const std::map<std::string, std::string> expected = folderContents(reference);
  const fs::path errors = fs::path(testing::TempDir()) / "disk_full.err";

  // The disk fills once the stage has started: simulation, surfacing, rendering, and the video as ffmpeg starts
  // (its whole output is 30 kB, which it can write in the time the filler takes once it has begun).
  for (const int stage : {0, 1, 2, 3}) {
    SmallDisk disk("disk_full_" + std::to_string(stage), 32);  // the whole run takes 13 MB
    SKIP_UNLESS_MOUNTED(disk);
    const fs::path out = disk.path() / "run", filler = disk.path() / "another_programs_file";
    const pid_t run = startRun(scene, out, false, 2, errors);
    int status = 0;
    bool ended = false;
    // Polled at 0.2 ms: stage 0 waits for frame 2, two frames into the simulation.
    while (!(stage == 0 ? fs::exists(framePath(out, "particles", 2, "ply")) : markerExists(out, stage)) &&
           !(ended = ::waitpid(run, &status, WNOHANG) == run))
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    ASSERT_FALSE(ended) << kStages[stage] << " never started";
    EXPECT_GT(fillDisk(filler), 0u);
    ::waitpid(run, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1) << "the disk filled in " << kStages[stage];
    const std::vector<std::string> message = lines(readTextFile(errors));
    ASSERT_EQ(message.size(), 1u) << kStages[stage] << ": " << readTextFile(errors);
    EXPECT_NE(message[0].find("disk is full"), std::string::npos) << kStages[stage] << ": " << message[0];
    std::printf("disk full in %-12s: %s\n", kStages[stage], message[0].c_str());

    // Nothing partial under a frame's name; the temporaries of the failed writes are gone.
    for (const auto& [name, bytes] : folderContents(out)) {
      EXPECT_EQ(name.find(".tmp"), std::string::npos) << name << " left after the disk filled in " << kStages[stage];
      if (name.rfind("solver/", 0) == 0 && !expected.count(name)) {
        // The solver's state is kept for the last two frames only, so an interrupted run holds earlier frames'
        // than the whole one: each must still be whole, the same size as the whole run's.
        const std::string last = framePath(fs::path(), "solver", kLastFrame, "bin").string();
        ASSERT_TRUE(expected.count(last)) << last << " missing from the whole run";
        EXPECT_EQ(bytes.size(), expected.at(last).size())
            << name << " is not whole after the disk filled in " << kStages[stage];
      } else if (name.find("frame_") != std::string::npos || name == "killed.mp4") {
        EXPECT_TRUE(expected.count(name) && bytes == expected.at(name))
            << name << " is not whole after the disk filled in " << kStages[stage];
      }
    }

    // Room again: the resumed run ends where an uninterrupted one does.
    fs::remove(filler);
    ASSERT_EQ(waitExit(startRun(scene, out, true, 2, errors)), 0) << readTextFile(errors);
    expectSameFiles(folderContents(out), expected,
                    std::string("after the disk filled in ") + kStages[stage] + " and --resume");
  }
  fs::remove_all(reference);
}

}  // namespace
}  // namespace surge
