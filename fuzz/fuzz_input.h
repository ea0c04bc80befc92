// What every fuzz target shares: the input written to a file of this process's own (the readers take paths, as
// Surge reads what users hand it from disk), and the rule that a reader of outside data may only refuse bad
// bytes with surge::Error (an InputError naming the file, exit 2). Any other exception, a crash, or what ASan
// and UBSan report is a finding.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>

#include "core/errors.h"

namespace surge::fuzz {

// A file named after the process (libFuzzer may run several jobs), with the given extension.
inline std::string writeInput(const uint8_t* data, size_t size, const std::string& extension) {
  const char* folder = std::getenv("TMPDIR");
  const std::string path = std::string(folder ? folder : "/tmp") + "/surge_fuzz_" + std::to_string(::getpid()) +
                           "." + extension;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), long(size));
  return path;
}

// Runs `read`; a surge::Error is the reader refusing bad bytes as it should.
template <typename Read>
void expectOnlySurgeErrors(Read&& read) {
  try {
    read();
  } catch (const Error&) {
  }
}

}  // namespace surge::fuzz
