// surge sim SCENE: simulate a scene into particle frames and stats.csv.
#include <chrono>
#include <cstdio>

#include "apps/commands.h"
#include "core/parallel.h"
#include "sim/simulation.h"

namespace surge {

void runSimStage(const Scene& scene, const fs::path& dir, bool resume, const CommonOptions& options) {
  fs::create_directories(dir);
  // Rewritten only when it changes: its time tells the later stages' --resume whether their frames are stale.
  const std::string json = sceneToJson(scene);
  std::error_code error;
  if (!fs::exists(dir / "scene.json", error) || readTextFile(dir / "scene.json") != json)
    writeFileAtomically(dir / "scene.json", [&](std::ostream& out) { out << json; });
  TerminalProgress progress(!options.quiet);
  const SimulationSummary summary = simulate(scene, dir, resume, progress);
  char line[256];
  std::snprintf(line, sizeof line, "sim: %zu particles, frames %d-%d in %.1f s -> %s/particles", summary.particles,
                summary.firstFrame, summary.lastFrame, summary.wallSeconds, dir.string().c_str());
  say(options, line);
}

void addSimCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string scene;
    bool resume = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("sim", "simulate a scene into particles/frame_NNNNN.ply and stats.csv");
  command->add_option("scene", options->scene, "scene file (JSON)")->required();
  command->add_flag("--resume", options->resume, "continue from the last complete frame in the output folder");
  addCommonOptions(*command, options->common, true);
  command->callback([options] {
    const Scene scene = loadScene(options->scene, options->common.overrides);
    ThreadLimit threads(options->common.threads);
    runSimStage(scene, outputFolder(options->common, scene), options->resume, options->common);
  });
}

}  // namespace surge
