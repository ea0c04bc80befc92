// surge surface DIR: particle frames to OpenVDB level sets and meshes.
#include <chrono>
#include <cstdio>

#include "apps/commands.h"
#include "core/parallel.h"
#include "surface/surfacer.h"

namespace surge {

void runSurfaceStage(const Scene& scene, const fs::path& dir, const FrameRange& range, const CommonOptions& options,
                     bool resume) {
  const auto start = std::chrono::steady_clock::now();
  checkOutputFolder(dir);
  TerminalProgress progress(!options.quiet);
  surfaceFrames(dir, scene, range, progress, resume);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  char line[256];
  std::snprintf(line, sizeof line, "surface: %.1f s -> %s/surface", seconds, dir.string().c_str());
  say(options, line);
}

void addSurfaceCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string dir, frames;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("surface", "particle frames to level sets (VDB) and meshes (PLY)");
  command->add_option("dir", options->dir, "output folder of surge sim")->required();
  command->add_option("--frames", options->frames, "frames A:B (inclusive; either end may be left open)");
  addCommonOptions(*command, options->common, false);
  command->callback([options] {
    const Scene scene = sceneOfFolder(options->dir, options->common);
    const FrameRange range = options->frames.empty() ? FrameRange{} : FrameRange::parse(options->frames);
    ThreadLimit threads(options->common.threads);
    runSurfaceStage(scene, options->dir, range, options->common);
  });
}

}  // namespace surge
