// The `surge` subcommands, one file each. Each registers its CLI11 options and the function that runs it.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "core/files.h"
#include "core/progress.h"
#include "core/scene.h"

namespace surge {

// Options every subcommand shares (DESIGN.md: --out, --set, --threads, --quiet).
struct CommonOptions {
  std::string out;
  std::vector<std::string> overrides;
  int threads = 0;
  bool quiet = false;
};

void addCommonOptions(CLI::App& command, CommonOptions& options, bool withOut);

// The output folder: --out, or out/<scene name>.
fs::path outputFolder(const CommonOptions& options, const Scene& scene);
// The scene of an output folder (its scene.json) with --set applied.
Scene sceneOfFolder(const fs::path& dir, const CommonOptions& options);
// Prints a line to stdout unless --quiet.
void say(const CommonOptions& options, const std::string& line);

// Each adds a subcommand to `app` and returns nothing; the command's callback does the work.
void addRunCommand(CLI::App& app);
void addSimCommand(CLI::App& app);
void addWhitewaterCommand(CLI::App& app);
void addSurfaceCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addVideoCommand(CLI::App& app);
void addKeysCommand(CLI::App& app);
void addStudyCommand(CLI::App& app);
void addExportCommand(CLI::App& app);
void addReportCommand(CLI::App& app);

// The stages, shared by their own subcommands and by `surge run`.
// With `resume` (surge sim --resume, surge run --resume) each stage picks up where a stopped run left off: the
// simulation from its last complete frame, the surface and render stages skipping the frames already up to date.
void runSimStage(const Scene& scene, const fs::path& dir, bool resume, const CommonOptions& options);
// The whitewater stage does nothing for a scene whose whitewater.enabled is 0.
void runWhitewaterStage(const Scene& scene, const fs::path& dir, const FrameRange& range, const CommonOptions& options,
                        bool resume = false);
void runSurfaceStage(const Scene& scene, const fs::path& dir, const FrameRange& range, const CommonOptions& options,
                     bool resume = false);
// renderer: "embree", "gl", or empty for the default of the scene's dimension.
void runRenderStage(const Scene& scene, const fs::path& dir, const FrameRange& range, const CommonOptions& options,
                    const std::string& renderer = "", bool resume = false);
void runVideoStage(const Scene& scene, const fs::path& dir, const CommonOptions& options);

// dir/sim_status.txt, one line the simulation keeps: "running", "finished", "stopped" (Ctrl-C, SIGTERM: a
// requeue or --resume goes on) or "failed: " and the error. `surge surface --wait` reads it to know when to
// give up. readSimStatus gives "" when there is none.
void writeSimStatus(const fs::path& dir, const std::string& status);
std::string readSimStatus(const fs::path& dir);

}  // namespace surge
