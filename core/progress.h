// One progress-and-cancel interface for every long operation (after OpenVDB's interrupter): a stage calls
// start(), advance() once per finished item (a frame, a tile row, never a particle), checkInterrupt() between
// items, and finish(). Ctrl-C sets a flag that checkInterrupt() turns into surge::Interrupted (exit 130).
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace surge {

class Progress {
 public:
  virtual ~Progress() = default;
  virtual void start(const std::string& label, size_t total) { (void)label, (void)total; }
  virtual void advance(size_t count = 1) { (void)count; }
  virtual void finish() {}

  // True once SIGINT or SIGTERM arrived (see installInterruptHandler).
  static bool wasInterrupted();
  // Throws surge::Interrupted if the user asked to stop.
  static void checkInterrupt();
  // For tests and embedding: raise or clear the flag by hand.
  static void setInterrupted(bool value);
};

// Installs handlers so that SIGINT and SIGTERM ask every running stage to stop at its next checkInterrupt().
void installInterruptHandler();

// A bar on stderr: label, done/total, percentage, elapsed time and ETA. Draws only when enabled (not --quiet)
// and stderr is a terminal; redraws at most ten times a second. Safe to advance from several threads.
class TerminalProgress : public Progress {
 public:
  explicit TerminalProgress(bool enabled);
  ~TerminalProgress() override;
  void start(const std::string& label, size_t total) override;
  void advance(size_t count = 1) override;
  void finish() override;

 private:
  void draw(bool final);

  bool enabled_;
  std::string label_;
  size_t total_ = 0;
  std::atomic<size_t> done_{0};
  std::chrono::steady_clock::time_point startTime_, lastDraw_;
  std::mutex drawMutex_;
  bool active_ = false;
};

}  // namespace surge
