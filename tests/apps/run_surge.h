// Runs the `surge` program as a user would, for the end-to-end tests.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/files.h"

namespace surge {

struct SurgeResult {
  int status = -1;
  std::string out, err;
};

// Runs surge with `arguments` (a shell-quoted string), capturing stdout and stderr.
// The captured output goes to files of this process's own (ctest runs test programs in parallel).
inline SurgeResult runSurge(const std::string& arguments) {
  const fs::path dir = fs::path(testing::TempDir()) / ("surge_e2e_io_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string command = std::string(SURGE_BINARY) + " " + arguments + " >" + (dir / "out").string() +
                              " 2>" + (dir / "err").string();
  SurgeResult result;
  const int raw = std::system(command.c_str());
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = readTextFile(dir / "out");
  result.err = readTextFile(dir / "err");
  return result;
}

// The frames ffprobe counts in a video, or -1.
inline int countVideoFrames(const fs::path& mp4) {
  const std::string command = "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                              "stream=nb_read_frames -of csv=p=0 '" + mp4.string() + "'";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return -1;
  char buffer[64] = {0};
  const bool read = std::fgets(buffer, sizeof buffer, pipe) != nullptr;
  pclose(pipe);
  return read ? std::atoi(buffer) : -1;
}

// Writes a scene file into the test's temporary folder.
inline fs::path writeTestScene(const std::string& name, const std::string& text) {
  const fs::path path = fs::path(testing::TempDir()) / (std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path;
}

// An empty place for a run's output folder under the test's temporary folder.
inline fs::path freshFolder(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / name;
  fs::remove_all(dir);
  return dir;
}

// The lines of a text (a CSV file's rows).
inline std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// `surge sim` on one scene three ways: at 1 thread, at 2, and at 2 stopped after `stopAfter` frames and then
// resumed; the folders are `prefix`_1, _2 and _r. first is the 1-thread run's result.
struct ThreeRuns {
  fs::path one, two, resumed;
  SurgeResult first;
  bool ok = false;
};
inline ThreeRuns simulateThreeWays(const fs::path& scene, const std::string& prefix, int stopAfter) {
  ThreeRuns runs;
  runs.one = freshFolder(prefix + "_1");
  runs.two = freshFolder(prefix + "_2");
  runs.resumed = freshFolder(prefix + "_r");
  const std::string base = "sim '" + scene.string() + "' --quiet --threads 2";
  runs.first = runSurge("sim '" + scene.string() + "' --threads 1 --out " + runs.one.string());
  runs.ok = runs.first.status == 0 && runSurge(base + " --out " + runs.two.string()).status == 0 &&
            runSurge(base + " --set output.frames=" + std::to_string(stopAfter) + " --out " +
                     runs.resumed.string()).status == 0 &&
            runSurge(base + " --resume --out " + runs.resumed.string()).status == 0;
  return runs;
}

}  // namespace surge
