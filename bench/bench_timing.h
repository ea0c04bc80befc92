// Wall-clock timing shared by the plain benchmark programs (those that print a markdown table).
#pragma once

#include <chrono>

namespace surge {

using BenchClock = std::chrono::steady_clock;

inline double secondsSince(BenchClock::time_point start) {
  return std::chrono::duration<double>(BenchClock::now() - start).count();
}

}  // namespace surge
