#include "render/video.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <fstream>
#include <string>

#include "core/errors.h"
#include "render/image.h"
#include "render_test_helpers.h"

namespace surge {
namespace {

using testing::CountingProgress;
using testing::TemporaryFolder;
using testing::unitTankScene;

bool ffmpegInstalled() {
  return std::system("ffmpeg -version > /dev/null 2>&1") == 0;
}

// Small frames of a flat colour that changes from frame to frame.
void writeFrames(const fs::path& dir, const std::vector<int>& frames, int width, int height) {
  for (int frame : frames) {
    Image image;
    image.width = width;
    image.height = height;
    image.rgb.resize(size_t(width) * height * 3);
    for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = uint8_t(40 * frame + 60 * (i % 3));
    writePng(framePath(dir, "frames", frame, "png"), image);
  }
}

TEST(VideoTest, ThreePngsMakeAThreeFrameMp4) {
  if (!ffmpegInstalled()) GTEST_SKIP() << "ffmpeg is not installed";
  TemporaryFolder folder;
  writeFrames(folder.path(), {4, 5, 6}, 64, 48);  // starting past 0: -start_number
  CountingProgress progress;
  makeVideo(folder.path(), unitTankScene(), progress);
  const fs::path video = folder.path() / "render_test.mp4";
  ASSERT_TRUE(fs::exists(video));
  EXPECT_EQ(countVideoFrames(video), 3);
  EXPECT_EQ(progress.label, "video");
  EXPECT_TRUE(progress.finished);
  // Only the frames folder and the video: the temporary file was renamed.
  EXPECT_EQ(std::distance(fs::directory_iterator(folder.path()), fs::directory_iterator()), 2);
}

TEST(VideoTest, OddImageSidesArePaddedForYuv420) {
  if (!ffmpegInstalled()) GTEST_SKIP() << "ffmpeg is not installed";
  TemporaryFolder folder;
  writeFrames(folder.path(), {0, 1}, 65, 49);
  CountingProgress progress;
  makeVideo(folder.path(), unitTankScene(), progress);
  EXPECT_EQ(countVideoFrames(folder.path() / "render_test.mp4"), 2);
}

TEST(VideoTest, NoFramesIsInputError) {
  TemporaryFolder folder;
  CountingProgress progress;
  try {
    makeVideo(folder.path(), unitTankScene(), progress);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.exitStatus(), kExitBadInput);
    EXPECT_NE(std::string(error.what()).find("run surge render first"), std::string::npos) << error.what();
  }
}

TEST(VideoTest, MissingFrameIsInputError) {
  TemporaryFolder folder;
  writeFrames(folder.path(), {0, 1, 3}, 16, 16);
  CountingProgress progress;
  try {
    makeVideo(folder.path(), unitTankScene(), progress);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("frame_00002.png"), std::string::npos) << error.what();
  }
}

TEST(VideoTest, MissingFfmpegIsAClearRunError) {
  TemporaryFolder folder;
  writeFrames(folder.path(), {0}, 16, 16);
  const std::string path = getenv("PATH") ? getenv("PATH") : "";
  setenv("PATH", folder.path().c_str(), 1);  // a folder without ffmpeg
  CountingProgress progress;
  std::string message;
  try {
    makeVideo(folder.path(), unitTankScene(), progress);
  } catch (const RunError& error) {
    message = error.what();
  }
  const int frames = countVideoFrames(folder.path() / "none.mp4");
  setenv("PATH", path.c_str(), 1);
  EXPECT_NE(message.find("ffmpeg not found"), std::string::npos) << message;
  EXPECT_EQ(frames, -1);  // no ffprobe either
}

TEST(VideoTest, FfmpegFailureCarriesItsMessage) {
  if (!ffmpegInstalled()) GTEST_SKIP() << "ffmpeg is not installed";
  TemporaryFolder folder;
  fs::create_directories(folder.path() / "frames");
  { std::ofstream(framePath(folder.path(), "frames", 0, "png")) << "not a png"; }
  CountingProgress progress;
  try {
    makeVideo(folder.path(), unitTankScene(), progress);
    FAIL() << "expected RunError";
  } catch (const RunError& error) {
    EXPECT_NE(std::string(error.what()).find("ffmpeg failed"), std::string::npos) << error.what();
    EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos) << "one line";
  }
  EXPECT_FALSE(fs::exists(folder.path() / "render_test.mp4"));
  EXPECT_EQ(std::distance(fs::directory_iterator(folder.path()), fs::directory_iterator()),
            1);  // no temp left
}

}  // namespace
}  // namespace surge
