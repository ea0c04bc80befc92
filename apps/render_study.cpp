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

// Sum of squared differences of the 8-bit values of two frames, and how many values; false if the sizes differ.
bool squaredDifference(const fs::path& a, const fs::path& b, double& sum, double& count) {
  const Image x = readPng(a), y = readPng(b);
  if (x.width != y.width || x.height != y.height) return false;
  for (size_t i = 0; i < x.rgb.size(); ++i) {
    const double d = double(x.rgb[i]) - double(y.rgb[i]);
    sum += d * d;
  }
  count += double(x.rgb.size());
  return true;
}

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
  std::vector<std::string> threadArgs;
  if (threads > 0) threadArgs = {"--threads", std::to_string(threads)};
  const auto withThreads = [&](std::vector<std::string> args) {
    args.insert(args.end(), threadArgs.begin(), threadArgs.end());
    return args;
  };
  // The base: simulated and surfaced once.
  StudyRun base;
  base.folder = dir / "base";
  std::vector<std::string> simArgs = withThreads({"surge", "sim", scenePath.string(), "--quiet", "--out",
                                                  base.folder.string()});
  for (const std::string& assignment : baseOverrides) simArgs.insert(simArgs.end(), {"--set", assignment});
  for (const auto& args : {simArgs, withThreads({"surge", "surface", base.folder.string(), "--quiet"})}) {
    runChild(base, args);
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
    std::vector<std::string> args = withThreads({"surge", "render", run.folder.string(), "--quiet"});
    for (const std::string& assignment : runOverrides[i]) args.insert(args.end(), {"--set", assignment});
    runChild(run, args);
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
  for (StudyRun& run : runs) {
    run.error = run.fieldError = run.frontRms = run.heightRms = run.window = NAN;
    run.reference = reference >= 0 && &run == &runs[reference];
    if (reference < 0 || run.status != "ok") continue;
    double sum = 0, count = 0;
    bool comparable = run.framesDone == runs[reference].framesDone;
    for (int f : listFrames(run.folder, "frames", "png"))
      comparable = comparable && squaredDifference(framePath(run.folder, "frames", f, "png"),
                                                   framePath(runs[reference].folder, "frames", f, "png"), sum, count);
    if (comparable && count > 0) run.error = std::sqrt(sum / count);
  }
  return reference;
}

}  // namespace surge
