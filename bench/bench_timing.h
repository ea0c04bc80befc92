// Wall-clock timing shared by the plain benchmark programs (those that print a markdown table).
#pragma once

#include <algorithm>
#include <chrono>
#include <vector>

namespace surge {

using BenchClock = std::chrono::steady_clock;

inline double secondsSince(BenchClock::time_point start) {
  return std::chrono::duration<double>(BenchClock::now() - start).count();
}

// The share of a step that some work adds, from rounds timed in turn without it and with it (seconds a step):
// the median over the rounds of 1 - t_without / t_with, with its quartiles, and the median times. A round
// that the shared machine slowed counts once, where a best-of-rounds on each side paired two different
// rounds.
struct StepShare {
  double with = 0, without = 0;  // median seconds a step
  double share = 0, lowQuartile = 0, highQuartile = 0;
};

inline StepShare stepShare(const std::vector<double>& with, const std::vector<double>& without) {
  auto sorted = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  auto median = [](const std::vector<double>& s) { return 0.5 * (s[(s.size() - 1) / 2] + s[s.size() / 2]); };
  std::vector<double> shares;
  for (size_t r = 0; r < with.size() && r < without.size(); ++r) shares.push_back(1 - without[r] / with[r]);
  const std::vector<double> s = sorted(shares);
  StepShare result;
  result.with = median(sorted(with));
  result.without = median(sorted(without));
  result.share = median(s);
  result.lowQuartile = s[s.size() / 4];
  result.highQuartile = s[s.size() - 1 - s.size() / 4];
  return result;
}

}  // namespace surge
