// surge study with render settings swept (every --sweep key render.*): the path tracer's cost against its image
// error. The scene is simulated and surfaced once, into DIR/base; each combination then renders those surfaces
// (DIR/runs/<index>_<key=value,...>/frames, its surface/ files hard links to the base's) in its own
// `surge render` child process, so that wait4 gives its CPU seconds. The reference is the unfiltered run of
// most CPU seconds (the most samples; the run of most CPU seconds if every run is filtered); each run's error
// is the RMS difference of its PNGs' 8-bit sRGB values from the reference's, over every pixel and channel of
// every frame, the measure of docs/performance.md.
#include <cmath>

#include "apps/study.h"
#include "core/errors.h"
#include "core/scene.h"
#include "render/image.h"

namespace surge {

namespace {

// The files of `from` hard-linked into `to` (copied where a link cannot be made): each run renders the base's
// surfaces without copying them, and without a symbolic link, which surge refuses in an output folder.
void linkFolder(const fs::path& from, const fs::path& to) {
  fs::remove_all(to);
  if (!fs::is_directory(from)) return;
  fs::create_directories(to);
  for (const fs::directory_entry& entry : fs::directory_iterator(from)) {
    if (!entry.is_regular_file()) continue;
    std::error_code error;
    fs::create_hard_link(entry.path(), to / entry.path().filename(), error);
    if (error) fs::copy_file(entry.path(), to / entry.path().filename());
  }
}

}  // namespace

int runRenderStudy(const fs::path& scenePath, const fs::path& dir, const std::vector<std::string>& baseOverrides,
                   std::vector<StudyRun>& runs, const std::vector<std::vector<std::string>>& runOverrides,
                   int threads, Progress& progress) {
  // The base: simulated and surfaced once.
  StudyRun base;
  base.folder = dir / "base";
  std::vector<std::string> simArgs = {"surge", "sim", scenePath.string(), "--quiet", "--out", base.folder.string()};
  for (const std::string& assignment : baseOverrides) simArgs.insert(simArgs.end(), {"--set", assignment});
  const std::vector<std::string> surfaceArgs = {"surge", "surface", base.folder.string(), "--quiet"};
  for (const auto& args : {simArgs, surfaceArgs}) {
    runChild(base, args, threads);
    if (base.status != "ok")
      throw RunError("study: the " + args[1] + " stage for the renders failed (" + base.message + "), see " +
                     (base.folder / "log.txt").string());
  }

  progress.start("study", runs.size());
  for (size_t i = 0; i < runs.size(); ++i) {
    Progress::checkInterrupt();
    StudyRun& run = runs[i];
    fs::create_directories(run.folder);
    fs::copy_file(base.folder / "scene.json", run.folder / "scene.json", fs::copy_options::overwrite_existing);
    for (const char* stage : {"surface", "colliders"}) linkFolder(base.folder / stage, run.folder / stage);
    std::vector<std::string> args = {"surge", "render", run.folder.string(), "--quiet"};
    for (const std::string& assignment : runOverrides[i]) args.insert(args.end(), {"--set", assignment});
    runChild(run, args, threads);
    run.framesDone = int(listFrames(run.folder, "frames", "png").size());
    writeRunRecord(run);
    progress.advance();
  }
  progress.finish();

  // The reference: an unfiltered run if there is one (a filtered image is not an unbiased estimate), the one of
  // most CPU seconds.
  std::vector<bool> filtered(runs.size(), false);
  for (size_t i = 0; i < runs.size(); ++i)
    filtered[i] = loadScene(runs[i].folder / "scene.json", runOverrides[i]).render.denoise != 0;
  int reference = -1;
  const auto better = [&](size_t i) {
    if (reference < 0) return true;
    if (filtered[i] != filtered[reference]) return !filtered[i];
    return runs[i].cpuSeconds > runs[reference].cpuSeconds;
  };
  for (size_t i = 0; i < runs.size(); ++i)
    if (runs[i].status == "ok" && better(i)) reference = int(i);
  // The reference's frames, decoded once.
  std::vector<int> frames;
  std::vector<Image> referenceFrames;
  if (reference >= 0) {
    frames = listFrames(runs[reference].folder, "frames", "png");
    for (int f : frames) referenceFrames.push_back(readPng(framePath(runs[reference].folder, "frames", f, "png")));
  }
  for (StudyRun& run : runs) {
    run.error = run.fieldError = run.frontRms = run.heightRms = run.window = NAN;
    run.reference = reference >= 0 && &run == &runs[reference];
    if (reference < 0 || run.status != "ok" || frames.empty() || listFrames(run.folder, "frames", "png") != frames)
      continue;
    // Every frame has the same size: the mean of the frames' mean squares is the mean square over them all.
    double sum = 0;
    for (size_t k = 0; k < frames.size(); ++k)
      sum += meanSquaredDifference(readPng(framePath(run.folder, "frames", frames[k], "png")), referenceFrames[k]);
    run.error = std::sqrt(sum / double(frames.size()));  // NaN if the sizes differ
  }
  return reference;
}

}  // namespace surge
