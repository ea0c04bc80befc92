// Errors that carry the process exit status of DESIGN.md: 2 for bad input, 1 for a failure while running,
// 130 when interrupted. Messages are one line and name the file and the key or line at fault.
#pragma once

#include <stdexcept>
#include <string>

namespace surge {

enum ExitStatus : int { kExitOk = 0, kExitFailure = 1, kExitBadInput = 2, kExitInterrupted = 130 };

class Error : public std::runtime_error {
 public:
  Error(int exitStatus, const std::string& message) : std::runtime_error(message), exitStatus_(exitStatus) {}
  int exitStatus() const { return exitStatus_; }

 private:
  int exitStatus_;
};

// Bad input: a scene, a particle file, a flag. `where` is the file (or flag), `key` the key or line.
class InputError : public Error {
 public:
  InputError(const std::string& where, const std::string& key, const std::string& message);
  InputError(const std::string& where, const std::string& message);
};

// A failure while running, for example a simulation that diverged.
class RunError : public Error {
 public:
  explicit RunError(const std::string& message) : Error(kExitFailure, message) {}
};

// The user pressed Ctrl-C (or the process got SIGTERM).
class Interrupted : public Error {
 public:
  Interrupted() : Error(kExitInterrupted, "interrupted") {}
  // The same, with what to do next ("interrupted; <hint>").
  explicit Interrupted(const std::string& hint) : Error(kExitInterrupted, "interrupted; " + hint) {}
};

}  // namespace surge
