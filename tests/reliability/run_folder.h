// Helpers of the reliability tests: `surge run` in the background, and a run folder's files with their bytes.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/files.h"
#include "tests/apps/run_surge.h"

namespace surge {

// About 1.5 s end to end on this machine: 5200 particles, 13 frames; each stage lasts a few hundred ms, so
// a kill drawn inside a stage's window lands in it.
inline const char* kScene = R"({
  "name": "killed",
  "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [0.6, 0.4, 0.3]},
  "particle_spacing": 0.015,
  "fluids": [{"box": {"min": [0, 0, 0], "max": [0.2, 0.3, 0.3]}}],
  "output": {"fps": 30, "frames": 12},
  "render": {"width": 160, "height": 96, "samples": 4}
})";
inline const int kLastFrame = 12;

// The stages of `surge run`, each between two markers: the files that appear when it starts and when the next
// one starts (the surface and render settings files are written before a stage's first frame). The video is
// two windows, ffmpeg starting and ffmpeg writing (its temporary, .killed.mp4.partialPID, exists).
inline const char* kStages[] = {"simulation", "surfacing", "rendering", "ffmpeg start", "encoding"};
inline const int kStageCount = 5;
inline bool markerExists(const fs::path& dir, int marker) {
  const fs::path paths[] = {dir / "particles" / "frame_00000.ply", dir / "surface_settings.json",
                            dir / "render_settings.json", framePath(dir, "frames", kLastFrame, "png"), fs::path(),
                            dir / "killed.mp4"};
  if (marker != 4) return fs::exists(paths[marker]);
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dir, error))
    if (entry.path().filename().string().rfind(".killed.mp4.partial", 0) == 0) return true;
  return false;
}

// `surge run SCENE --out DIR --quiet --threads T [--resume]` started in the background.
// Its stderr goes to `errors` when one is given.
inline pid_t startRun(const fs::path& scene, const fs::path& dir, bool resume, int threads = 2,
                      const fs::path& errors = {}) {
  std::fflush(nullptr);  // the child must not write this process's buffered output again
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);  // its own process group: the test can end an ffmpeg a kill orphaned (killGroup)
    const std::string sceneArg = scene.string(), dirArg = dir.string(), threadsArg = std::to_string(threads);
    std::vector<const char*> argv = {SURGE_BINARY, "run",      sceneArg.c_str(),   "--out",
                                     dirArg.c_str(), "--quiet", "--threads", threadsArg.c_str()};
    if (resume) argv.push_back("--resume");
    argv.push_back(nullptr);
    ::freopen("/dev/null", "w", stdout);
    if (!errors.empty()) ::freopen(errors.c_str(), "w", stderr);
    ::execv(SURGE_BINARY, const_cast<char* const*>(argv.data()));
    ::_exit(127);
  }
  return pid;
}

// Ends what is left of a run started by startRun (an ffmpeg orphaned by killing surge alone), then removes its
// folder, again while a dying process may still add a file.
inline void killGroupAndRemove(pid_t pid, const fs::path& dir) {
  ::kill(-pid, SIGKILL);
  std::error_code error;
  for (int attempt = 0; attempt < 100; ++attempt) {
    fs::remove_all(dir, error);
    if (!error) return;
    ::usleep(10000);
  }
  FAIL() << "cannot remove " << dir << ": " << error.message();
}

inline int waitExit(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Every regular file under `dir` with its bytes, by relative path. stats.csv is kept without its measured
// times (wall_seconds and the ms_ columns), and sim_status.txt is left out: neither is a frame.
inline std::map<std::string, std::string> folderContents(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = fs::relative(entry.path(), dir).string();
    if (name == "sim_status.txt") continue;
    std::string bytes = readTextFile(entry.path());
    if (name == "stats.csv") {
      std::string kept;
      for (const std::string& line : lines(bytes)) {
        std::vector<std::string> fields;
        std::stringstream row(line);
        for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
        for (size_t i = 0; i < fields.size(); ++i)
          if (i < 8 || i > 12) kept += fields[i] + ",";  // columns 8-12: wall_seconds, ms_neighbors .. ms_viscosity
        kept += "\n";
      }
      bytes = kept;
    }
    files[name] = bytes;
  }
  return files;
}

// The folder's files are the expected ones, each with the expected bytes; `when` says what happened to it.
inline void expectSameFiles(const std::map<std::string, std::string>& got,
                            const std::map<std::string, std::string>& expected, const std::string& when) {
  std::vector<std::string> names, expectedNames;
  for (const auto& entry : got) names.push_back(entry.first);
  for (const auto& entry : expected) expectedNames.push_back(entry.first);
  EXPECT_EQ(names, expectedNames) << when;
  for (const auto& [name, bytes] : expected)
    EXPECT_TRUE(got.count(name) && got.at(name) == bytes) << name << " differs " << when;
}

}  // namespace surge
