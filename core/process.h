// The process and its surroundings: running other programs (ffmpeg, ffprobe, sbatch) without a shell, arguments
// passed as they are; and the memory this process may use.
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

// The memory this process may use: the least of the machine's physical memory, its cgroup's limit (v2
// memory.max, v1 memory.limit_in_bytes) and a Slurm job's (SLURM_MEM_PER_NODE, or SLURM_MEM_PER_CPU times
// SLURM_CPUS_ON_NODE), and which of them it is ("this machine's", "this cgroup's", "this Slurm job's").
struct MemoryLimit {
  double bytes = 0;
  std::string source;
};
MemoryLimit memoryLimit();

}  // namespace surge
