// surge export DIR --format vtk|usd: the survey of a run folder and the subcommand.
#include <algorithm>
#include <chrono>
#include <cstdio>

#include "apps/export.h"
#include "core/errors.h"
#include "core/parallel.h"

namespace surge {

fs::path ExportRun::solidMesh(const SolidFiles& solid, int frame) const {
  if (solid.moving) {
    const fs::path path = framePath(dir / solid.folder, solid.settings.name, frame, "ply");
    std::error_code error;
    if (fs::exists(path, error)) return path;
  }
  return dir / solid.folder / (solid.settings.name + ".ply");
}

namespace {

std::vector<int> framesInRange(const fs::path& dir, const std::string& sub, const FrameRange& range) {
  std::vector<int> frames;
  for (int f : listFrames(dir, sub, "ply"))
    if (range.contains(f)) frames.push_back(f);
  return frames;
}

}  // namespace

ExportRun surveyRun(const fs::path& dir, const FrameRange& range, const CommonOptions& options) {
  std::error_code error;
  if (!fs::is_directory(dir, error)) throw InputError(dir.string(), "not a folder");
  ExportRun run;
  run.dir = dir;
  run.scene = sceneOfFolder(dir, options);
  run.frames = framesInRange(dir, "particles", range);
  if (run.frames.empty())
    throw InputError((dir / "particles").string(), listFrames(dir, "particles", "ply").empty()
                                                       ? "no particle frames: run surge sim first"
                                                       : "no particle frames in --frames");
  run.series.push_back({"particles", false, run.frames});
  const std::vector<int> whitewater = framesInRange(dir, "whitewater", range);
  if (!whitewater.empty()) run.series.push_back({"whitewater", false, whitewater});
  // surface/, then each fluid's surface_<name>/ of a scene of several fluids, in name order.
  std::vector<std::string> meshFolders;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory(error) && name.rfind("surface_", 0) == 0) meshFolders.push_back(name);
  }
  std::sort(meshFolders.begin(), meshFolders.end());
  meshFolders.insert(meshFolders.begin(), "surface");
  for (const std::string& folder : meshFolders) {
    const std::vector<int> frames = framesInRange(dir, folder, range);
    if (!frames.empty()) run.series.push_back({folder, true, frames});
  }
  run.solids = solidFiles(run.scene);
  for (const SolidFiles& solid : run.solids) {
    const fs::path first = dir / solid.folder / (solid.settings.name + ".ply");
    if (!fs::exists(first, error))
      throw InputError(first.string(), "missing: the simulation writes colliders/ and bodies/; run surge sim again");
  }
  if (!run.scene.bodies.empty() && !fs::exists(dir / "bodies.csv", error))
    throw InputError((dir / "bodies.csv").string(), "missing: the scene has bodies; run surge sim again");
  return run;
}

void addExportCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string dir, format, frames;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "export", "a run's frames for other tools: vtk (ParaView .pvd series of .vtp) or usd (one .usda stage)");
  command->add_option("dir", options->dir, "output folder of surge sim (and surge surface)")->required();
  command->add_option("--format", options->format, "vtk or usd")->required();
  command->add_option("--frames", options->frames, "frames A:B (inclusive; either end may be left open)");
  addCommonOptions(*command, options->common, false);
  command->callback([options] {
    const auto start = std::chrono::steady_clock::now();
    if (options->format != "vtk" && options->format != "usd")
      throw InputError("--format", "'" + options->format + "' is not one of vtk, usd");
    const FrameRange range = options->frames.empty() ? FrameRange{} : FrameRange::parse(options->frames);
    ThreadLimit threads(options->common.threads);
    const ExportRun run = surveyRun(options->dir, range, options->common);
    checkOutputFolder(run.dir / "export");
    TerminalProgress progress(!options->common.quiet);
    const std::vector<fs::path> written =
        options->format == "vtk" ? exportVtk(run, progress) : exportUsd(run, progress);
    double bytes = 0;
    std::error_code error;
    for (const fs::path& path : written) bytes += double(fs::file_size(path, error));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    char line[512];
    std::snprintf(line, sizeof line, "export %s: %zu files, %s in %.1f s -> %s", options->format.c_str(),
                  written.size(), formatBytes(bytes).c_str(), seconds, (run.dir / "export").string().c_str());
    say(options->common, line);
  });
}

}  // namespace surge
