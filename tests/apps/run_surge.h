// Runs the `surge` program as a user would, for the end-to-end tests.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

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

// Writes a scene file into the test's temporary folder.
inline fs::path writeTestScene(const std::string& name, const std::string& text) {
  const fs::path path = fs::path(testing::TempDir()) / (std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path;
}

}  // namespace surge
