// Running other programs (ffmpeg, ffprobe, sbatch) without a shell: arguments are passed as they are.
#pragma once

#include <string>
#include <vector>

#include "core/files.h"

namespace surge {

// The full path of a program found on PATH, or empty.
fs::path findProgram(const std::string& name);

struct ProgramResult {
  int exitCode = -1;  // -1 if it did not exit normally (a signal)
  std::string output, errors;
};

// Runs a program and collects what it prints on stdout and stderr. Throws RunError if it cannot be started.
ProgramResult runProgram(const fs::path& program, const std::vector<std::string>& arguments);

}  // namespace surge
