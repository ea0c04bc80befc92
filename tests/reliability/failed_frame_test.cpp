// A frame that fails while others are being surfaced beside it (frames run in parallel): the run stops with that
// frame's error, and the frames that were in flight are written whole or not at all, never cut short by the
// failure's cancellation of the work inside them (issue 14). `surge surface --resume` would keep such a frame.
#include <gtest/gtest.h>

#include <fstream>

#include "core/files.h"
#include "tests/reliability/run_folder.h"

namespace surge {
namespace {

TEST(FailedFrame, FramesBesideAFailingOneAreWholeOrAbsent) {
  const fs::path scene = writeTestScene("killed.json", kScene);
  const fs::path reference = freshFolder("failed_frame_reference");
  ASSERT_EQ(waitExit(startRun(scene, reference, false)), 0);
  const std::map<std::string, std::string> expected = folderContents(reference);

  // The same particles, surfaced again with one frame's file cut short: frame 6 fails as soon as it is read,
  // while the frames beside it are in the middle of their level sets.
  const fs::path dir = freshFolder("failed_frame");
  fs::create_directories(dir / "particles");
  for (int f = 0; f <= kLastFrame; ++f)
    fs::copy_file(framePath(reference, "particles", f, "ply"), framePath(dir, "particles", f, "ply"));
  fs::copy_file(reference / "scene.json", dir / "scene.json");
  const std::string bytes = readTextFile(framePath(reference, "particles", 6, "ply"));
  std::ofstream(framePath(dir, "particles", 6, "ply"), std::ios::binary | std::ios::trunc)
      << bytes.substr(0, bytes.size() / 2);
  const SurgeResult r = runSurge("surface '" + dir.string() + "' --quiet");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("frame_00006.ply"), std::string::npos) << r.err;
  int written = 0;
  for (const auto& [name, got] : folderContents(dir)) {
    if (name.rfind("surface/", 0) != 0) continue;
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name << " left behind";
    EXPECT_TRUE(expected.count(name) && got == expected.at(name)) << name << " was written, but not whole";
    ++written;
  }
  std::printf("frame 6 failed; %d surface files of the other frames were written\n", written);
  fs::remove_all(reference);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace surge
