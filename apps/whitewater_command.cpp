// surge whitewater DIR: spray, foam and bubbles from the particle frames (whitewater/whitewater_stage.h).
#include <chrono>
#include <cstdio>

#include "apps/commands.h"
#include "core/errors.h"
#include "core/parallel.h"
#include "whitewater/whitewater_stage.h"

namespace surge {

void runWhitewaterStage(const Scene& scene, const fs::path& dir, const FrameRange& range,
                        const CommonOptions& options, bool resume) {
  if (!scene.whitewater.enabled) return;
  const auto start = std::chrono::steady_clock::now();
  checkOutputFolder(dir);
  TerminalProgress progress(!options.quiet);
  whitewaterFrames(dir, scene, range, progress, resume);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  char line[256];
  std::snprintf(line, sizeof line, "whitewater: %.1f s -> %s/whitewater", seconds, dir.string().c_str());
  say(options, line);
}

void addWhitewaterCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string dir, frames;
    bool resume = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "whitewater", "spray, foam and bubbles from the particle frames (whitewater/frame_NNNNN.ply)");
  command->add_option("dir", options->dir, "output folder of surge sim")->required();
  command->add_option("--frames", options->frames,
                      "frames A:B (inclusive; either end may be left open); frame A - 1 must be made already");
  command->add_flag("--resume", options->resume, "go on after the last frame that is up to date");
  addCommonOptions(*command, options->common, false);
  command->callback([options] {
    const FrameRange range = options->frames.empty() ? FrameRange{} : FrameRange::parse(options->frames);
    ThreadLimit threads(options->common.threads);
    Scene scene = sceneOfFolder(options->dir, options->common);
    // Run by hand, the stage makes whitewater whatever the scene says (with its keys' defaults if it has none).
    if (!scene.whitewater.enabled) {
      std::vector<std::string> overrides = options->common.overrides;
      overrides.push_back("whitewater.enabled=1");
      CommonOptions withWhitewater = options->common;
      withWhitewater.overrides = overrides;
      scene = sceneOfFolder(options->dir, withWhitewater);
    }
    runWhitewaterStage(scene, options->dir, range, options->common, options->resume);
  });
}

}  // namespace surge
