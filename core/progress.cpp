#include "core/progress.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>

#include "core/errors.h"

namespace surge {
namespace {

volatile std::sig_atomic_t gInterrupted = 0;

void onSignal(int) { gInterrupted = 1; }

std::string formatSeconds(double seconds) {
  if (seconds < 0 || seconds > 1e7) return "--:--";
  const long s = static_cast<long>(seconds + 0.5);
  char buffer[32];
  if (s >= 3600)
    std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(buffer, sizeof buffer, "%02ld:%02ld", s / 60, s % 60);
  return buffer;
}

}  // namespace

bool Progress::wasInterrupted() { return gInterrupted != 0; }

void Progress::checkInterrupt() {
  if (wasInterrupted()) throw Interrupted();
}

void Progress::setInterrupted(bool value) { gInterrupted = value ? 1 : 0; }

void installInterruptHandler() {
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
}

TerminalProgress::TerminalProgress(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}

TerminalProgress::~TerminalProgress() {
  if (active_) finish();
}

void TerminalProgress::start(const std::string& label, size_t total) {
  label_ = label;
  total_ = total;
  done_ = 0;
  startTime_ = lastDraw_ = std::chrono::steady_clock::now();
  active_ = true;
  draw(false);
}

void TerminalProgress::advance(size_t count) {
  done_ += count;
  if (!enabled_) return;
  std::unique_lock<std::mutex> lock(drawMutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - lastDraw_ < std::chrono::milliseconds(100) && done_ < total_) return;
  lastDraw_ = now;
  draw(false);
}

void TerminalProgress::finish() {
  if (!active_) return;
  active_ = false;
  draw(true);
}

void TerminalProgress::draw(bool final) {
  if (!enabled_) return;
  const size_t done = std::min<size_t>(done_, total_);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - startTime_).count();
  const double fraction = total_ ? double(done) / double(total_) : 1.0;
  const double eta = done ? elapsed * (double(total_) - double(done)) / double(done) : -1.0;
  constexpr int kWidth = 30;
  std::string bar(kWidth, ' ');
  for (int i = 0; i < static_cast<int>(fraction * kWidth); ++i) bar[i] = '#';
  std::fprintf(stderr, "\r%-8s [%s] %zu/%zu %3d%%  %s elapsed  ETA %s ", label_.c_str(), bar.c_str(), done,
               total_, static_cast<int>(fraction * 100), formatSeconds(elapsed).c_str(),
               final ? "00:00" : formatSeconds(eta).c_str());
  if (final) std::fputc('\n', stderr);
  std::fflush(stderr);
}

}  // namespace surge
