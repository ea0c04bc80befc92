// surge video DIR: PNG frames to an H.264 MP4 with ffmpeg.
#include <chrono>
#include <cstdio>

#include "apps/commands.h"
#include "render/contact_sheet.h"
#include "render/video.h"

namespace surge {

void runVideoStage(const Scene& scene, const fs::path& dir, const CommonOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  checkOutputFolder(dir);
  TerminalProgress progress(!options.quiet);
  makeVideo(dir, scene, progress);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  char line[256];
  std::snprintf(line, sizeof line, "video: %.1f s -> %s", seconds,
                (dir / (scene.name + ".mp4")).string().c_str());
  say(options, line);
}

void addVideoCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string dir;
    bool contactSheet = false;
    int sheetFrames = 12;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("video", "assemble frames/frame_NNNNN.png into <name>.mp4 (ffmpeg)");
  command->add_option("dir", options->dir, "output folder of surge render")->required();
  command->add_flag("--contact-sheet", options->contactSheet,
                    "write <name>_contact_sheet.png, a grid of frames, instead of the video");
  command->add_option("--sheet-frames", options->sheetFrames, "frames on the contact sheet, evenly spaced")
      ->check(CLI::Range(1, 1000));
  addCommonOptions(*command, options->common, false);
  command->callback([options] {
    const Scene scene = sceneOfFolder(options->dir, options->common);
    if (options->contactSheet) {
      const fs::path sheet = makeContactSheet(options->dir, scene, options->sheetFrames);
      say(options->common, "contact sheet -> " + sheet.string());
      return;
    }
    runVideoStage(scene, options->dir, options->common);
  });
}

}  // namespace surge
