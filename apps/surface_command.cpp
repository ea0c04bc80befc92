// surge surface DIR: particle frames to OpenVDB level sets and meshes.
#include <chrono>
#include <cstdio>
#include <thread>

#include "apps/commands.h"
#include "core/errors.h"
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

namespace {

// --wait: surfaces the range's frames as the simulation writes them (a Slurm task started with the simulation),
// until every frame of the range up to the scene's last is done. Gives up, naming the first frame missing, when
// dir/sim_status.txt says the simulation failed or finished without it; keeps waiting while it is running or
// stopped (a requeued simulation goes on). The scene is read again each round: a resumed simulation may have
// changed output.frames.
void surfaceAsFramesArrive(const fs::path& dir, const FrameRange& range, const CommonOptions& options) {
  for (;;) {
    Progress::checkInterrupt();
    const fs::path scenePath = dir / "scene.json";
    std::error_code error;
    // Read before the frames are listed: a simulation that has finished wrote all its frames before saying so.
    const std::string status = readSimStatus(dir);
    if (fs::exists(scenePath, error)) {
      const Scene scene = sceneOfFolder(dir, options);
      const int last = std::min(range.last, scene.output.frames);
      if (range.first > last) return;
      const std::vector<int> all = listFrames(dir, "particles", "ply");
      int present = 0, lastPresent = -1;
      for (int f : all)
        if (f >= range.first && f <= last) ++present, lastPresent = f;
      const bool complete = present == last - range.first + 1;
      // The frames present are surfaced as they are: a frame is written whole or not at all.
      if (present > 0) runSurfaceStage(scene, dir, FrameRange{range.first, lastPresent}, options, true);
      if (complete) return;
      if (status.rfind("failed", 0) == 0 || status == "finished")
        throw RunError("surface --wait: frame " + std::to_string(lastPresent < 0 ? range.first : lastPresent + 1) +
                       " will not come: the simulation in " + dir.string() + " " +
                       (status == "finished" ? "finished without it" : "stopped: " + status));
    }
    for (int tenth = 0; tenth < 20; ++tenth) {  // two seconds, cancellable
      Progress::checkInterrupt();
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
}

}  // namespace

void addSurfaceCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string dir, frames;
    bool resume = false, wait = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("surface", "particle frames to level sets (VDB) and meshes (PLY)");
  command->add_option("dir", options->dir, "output folder of surge sim")->required();
  command->add_option("--frames", options->frames, "frames A:B (inclusive; either end may be left open)");
  command->add_flag("--resume", options->resume,
                    "leave the frames already up to date (newer than their particles and the surface settings)");
  command->add_flag("--wait", options->wait,
                    "surface the frames as a running simulation writes them, until the range is done (implies "
                    "--resume; for tasks started beside the simulation, surge run --slurm --stream)");
  addCommonOptions(*command, options->common, false);
  command->callback([options] {
    const FrameRange range = options->frames.empty() ? FrameRange{} : FrameRange::parse(options->frames);
    ThreadLimit threads(options->common.threads);
    if (options->wait) return surfaceAsFramesArrive(options->dir, range, options->common);
    const Scene scene = sceneOfFolder(options->dir, options->common);
    runSurfaceStage(scene, options->dir, range, options->common, options->resume);
  });
}

}  // namespace surge
