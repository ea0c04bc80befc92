#include "sim/energy_ledger.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "core/errors.h"

namespace surge {
namespace {

// A value as stats.csv prints it (%.6g for the energies, %.9g for source_work), read back.
double asPrinted(double value, const char* format = "%.9g") {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return std::strtod(text, nullptr);
}

}  // namespace

GravityPotential::GravityPotential(const Scene& scene) {
  const int d = scene.dimensions;
  gravity.head(d) = scene.gravity.head(d);
  for (int k = 0; k < d; ++k)
    if (scene.isPeriodic(k)) gravity[k] = 0;  // work instead (periodicGravityWork, sim/simulation.cpp)
  for (int k = 0; k < d; ++k) corner[k] = gravity[k] < 0 ? scene.domain.min[k] : scene.domain.max[k];
}

void EnergyLedger::start(double kinetic, double potential) {
  work_ = 0;
  start_ = most_ = asPrinted(kinetic, "%.6g") + asPrinted(potential, "%.6g");
}

void EnergyLedger::resume(const fs::path& stats, int frame) {
  std::error_code error;
  const std::string text = fs::exists(stats, error) ? readTextFile(stats) : std::string();
  std::stringstream in(text);
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = splitCsvLine(line);
  auto column = [&](const char* name) {
    for (size_t c = 0; c < header.size(); ++c)
      if (header[c] == name) return long(c);
    return -1L;
  };
  const long kinetic = column("kinetic_energy"), potential = column("potential_energy"), work = column("source_work");
  bool started = false;
  while (std::getline(in, line)) {
    const std::vector<std::string> row = splitCsvLine(line);
    if (row.empty() || std::atoi(row[0].c_str()) > frame) continue;
    auto value = [&](long c) { return c >= 0 && size_t(c) < row.size() ? std::strtod(row[c].c_str(), nullptr) : 0.0; };
    const double energy = value(kinetic) + value(potential);
    if (!started) start_ = most_ = energy;
    started = true;
    work_ = value(work);
    most_ = std::max(most_, energy);
  }
}

double EnergyLedger::sourceWork() {
  work_ = asPrinted(work_);
  return work_;
}

void EnergyLedger::check(int frame, double kinetic, double potential, double mass) {
  mass_ = mass;
  const double energy = asPrinted(kinetic, "%.6g") + asPrinted(potential, "%.6g");
  most_ = std::max(most_, energy);
  const double gain = energy - start_ - work_;
  if (!stops_ || !(gain > tolerance())) return;
  const char* unit = dimensions_ == 2 ? "J/m" : "J";
  char line[768];
  std::snprintf(line, sizeof line,
                "the fluid gained energy from nowhere by frame %d: its mechanical energy is %.4g %s, %.4g %s above "
                "frame 0's %.4g %s and what its sources did (%.4g %s), beyond the %.4g %s its method's error allows "
                "(%g%% of the most it held); give it %s",
                frame, energy, unit, gain, unit, start_, unit, work_, unit, tolerance(), unit, 100 * kTolerance,
                remedy_.c_str());
  throw RunError(line);
}

}  // namespace surge
