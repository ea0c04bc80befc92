// surge study --measure: one quantity read from every run of a particle_spacing sweep at one time, its observed
// order of convergence and its Richardson-extrapolated value from the three finest runs, and each run's error
// estimate against that value (Roache 1998's procedure, for spacings in any ratio); convergence.csv and
// convergence.png beside study.csv.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "apps/study.h"
#include "core/errors.h"
#include "core/files.h"
#include "sim/simulation.h"

namespace surge {
namespace {

int columnOf(const std::vector<std::string>& header, const std::string& name) {
  const auto at = std::find(header.begin(), header.end(), name);
  return at == header.end() ? -1 : int(at - header.begin());
}

// The columns a measure may name in each file: every column but those that say which row it is.
std::vector<std::string> measurableColumns(const char* header) {
  std::vector<std::string> columns;
  for (const std::string& name : splitCsvLine(header))
    if (name != "frame" && name != "time" && name != "body" && name != "collider") columns.push_back(name);
  return columns;
}

std::string listed(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

}  // namespace

Measure parseMeasure(const std::string& text, const Scene& scene) {
  const size_t at = text.rfind('@');
  if (at == std::string::npos || at == 0)
    throw InputError("--measure", text, "expected COLUMN@TIME, bodies.NAME.COLUMN@TIME or colliders.NAME.COLUMN@TIME");
  Measure measure;
  measure.text = text;
  const std::string what = text.substr(0, at), when = text.substr(at + 1);
  char* end = nullptr;
  measure.time = std::strtod(when.c_str(), &end);
  const double last = scene.output.frames / scene.output.fps;
  if (when.empty() || *end != '\0' || !(measure.time >= 0) || measure.time > last + 1e-9)
    throw InputError("--measure", text, "the time '" + when + "' is not a number of seconds within the run's " +
                                            format(last, "%.6g") + " s");
  std::vector<std::string> names;
  const bool body = what.rfind("bodies.", 0) == 0, collider = what.rfind("colliders.", 0) == 0;
  if (body || collider) {
    const std::string rest = what.substr(body ? 7 : 10);
    const size_t dot = rest.rfind('.');
    if (dot == std::string::npos || dot == 0)
      throw InputError("--measure", text, std::string("expected ") + (body ? "bodies" : "colliders") + ".NAME.COLUMN@TIME");
    measure.file = body ? "bodies.csv" : "colliders.csv";
    measure.name = rest.substr(0, dot);
    measure.column = rest.substr(dot + 1);
    if (body)
      for (const BodySettings& b : scene.bodies) names.push_back(b.solid.name);
    else
      for (const ColliderSettings& c : scene.colliders) names.push_back(c.name);
    if (std::find(names.begin(), names.end(), measure.name) == names.end())
      throw InputError("--measure", text, std::string("the scene has no ") + (body ? "body" : "collider") + " named '" +
                                              measure.name + "'" + (names.empty() ? "" : " (it has " + listed(names) + ")"));
  } else {
    measure.file = "stats.csv";
    measure.column = what;
  }
  const std::vector<std::string> columns = measurableColumns(
      measure.file == "stats.csv" ? statsCsvHeader() : measure.file == "bodies.csv" ? bodiesCsvHeader() : collidersCsvHeader());
  if (std::find(columns.begin(), columns.end(), measure.column) == columns.end())
    throw InputError("--measure", text, measure.file + " has no column '" + measure.column + "' (" + listed(columns) + ")");
  return measure;
}

double readMeasure(const Measure& measure, const fs::path& folder, double fps) {
  std::ifstream in(folder / measure.file);
  std::string line;
  if (!std::getline(in, line)) return NAN;
  const std::vector<std::string> header = splitCsvLine(line);
  const int value = columnOf(header, measure.column), frame = columnOf(header, "frame");
  const int name = columnOf(header, measure.file == "bodies.csv" ? "body" : "collider");
  double beforeTime = NAN, beforeValue = NAN;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = splitCsvLine(line);
    if (int(f.size()) <= std::max(value, frame)) continue;
    if (!measure.name.empty() && (name < 0 || int(f.size()) <= name || f[size_t(name)] != measure.name)) continue;
    const double t = std::atof(f[size_t(frame)].c_str()) / fps, v = std::atof(f[size_t(value)].c_str());
    if (std::abs(t - measure.time) < 1e-9) return v;
    if (t > measure.time)  // between two frames: linear in time
      return std::isnan(beforeTime) ? NAN : beforeValue + (v - beforeValue) * (measure.time - beforeTime) / (t - beforeTime);
    beforeTime = t;
    beforeValue = v;
  }
  return NAN;  // the run ended before the time
}

// f(h) = f0 + C h^p through the three finest runs: with differences d12 = f1 - f2 and d23 = f2 - f3 (h1 > h2 > h3),
// (h1^p - h2^p) / (h2^p - h3^p) = d12 / d23 gives p (bisection: the left side grows with p), then C and f0.
Convergence richardson(std::vector<double> spacing, std::vector<double> value) {
  Convergence result;
  std::vector<size_t> order(spacing.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return spacing[a] > spacing[b]; });
  for (size_t i : order) {
    result.spacing.push_back(spacing[i]);
    result.value.push_back(value[i]);
  }
  const size_t n = result.spacing.size();
  result.error.assign(n, NAN);
  for (double v : result.value)
    if (!std::isfinite(v)) {
      result.verdict = "a run did not reach the time: nothing to extrapolate";
      return result;
    }
  const double h1 = result.spacing[n - 3], h2 = result.spacing[n - 2], h3 = result.spacing[n - 1];
  const double d12 = result.value[n - 3] - result.value[n - 2], d23 = result.value[n - 2] - result.value[n - 1];
  const double ratio = d23 != 0 ? d12 / d23 : NAN;
  auto shape = [&](double p) { return (std::pow(h1, p) - std::pow(h2, p)) / (std::pow(h2, p) - std::pow(h3, p)); };
  const double lowest = 0.05, highest = 8;
  if (!(ratio > 0)) {
    result.verdict = d23 == 0 ? "the two finest runs agree exactly: converged, or insensitive to the spacing"
                              : "the differences change sign between the three finest runs: not yet in the "
                                "asymptotic range (the errors below are against the finest run)";
  } else if (ratio < shape(lowest) || ratio > shape(highest)) {
    result.verdict = "the observed order lies outside " + format(lowest, "%.2g") + " to " + format(highest, "%.2g") +
                     ": not yet in the asymptotic range (the errors below are against the finest run)";
  } else {
    double low = lowest, high = highest;
    for (int k = 0; k < 100; ++k) {
      const double mid = 0.5 * (low + high);
      (shape(mid) < ratio ? low : high) = mid;
    }
    result.order = 0.5 * (low + high);
    const double c = d23 / (std::pow(h2, result.order) - std::pow(h3, result.order));
    result.extrapolated = result.value[n - 1] - c * std::pow(h3, result.order);
    result.coefficient = c;
    result.verdict = "converging at order " + format(result.order, "%.2f");
  }
  const double target = std::isfinite(result.extrapolated) ? result.extrapolated : result.value[n - 1];
  for (size_t i = 0; i < n; ++i) result.error[i] = std::abs(result.value[i] - target);
  return result;
}

std::string writeConvergence(const fs::path& dir, const Measure& measure, const Convergence& result) {
  writeFileAtomically(dir / "convergence.csv", [&](std::ostream& out) {
    out << "particle_spacing,measured,error_estimate,observed_order,extrapolated\n";
    for (size_t i = 0; i < result.spacing.size(); ++i)
      out << format(result.spacing[i], "%.6g") << "," << format(result.value[i], "%.9g") << ","
          << format(result.error[i], "%.6g") << "," << format(result.order, "%.6g") << ","
          << format(result.extrapolated, "%.9g") << "\n";
  });
  // The measured values against the spacing, and the fitted f0 + C h^p down to h = 0.
  std::string script = "set terminal pngcairo size 900,600\nset output '" + (dir / "convergence.png").string() +
                       "'\nset datafile separator ','\nset xlabel 'particle spacing (m)'\n"
                       "set ylabel '" + measure.text + "' noenhanced\nset xrange [0:*]\nset title '" + result.verdict +
                       "' noenhanced\nset key bottom right noenhanced\n";
  std::string plot = "plot '" + (dir / "convergence.csv").string() +
                     "' every ::1 using 1:2 with linespoints pointtype 7 title 'runs'";
  if (std::isfinite(result.order)) {
    script += "f(x) = " + format(result.extrapolated, "%.9g") + " + " + format(result.coefficient, "%.9g") +
              " * x**" + format(result.order, "%.6g") + "\n";
    plot += ", f(x) title 'Richardson: " + format(result.extrapolated, "%.6g") + " + C h^" +
            format(result.order, "%.2f") + "' dashtype 2, " + format(result.extrapolated, "%.9g") +
            " title 'extrapolated' dashtype 3";
  }
  return runGnuplot(dir / "convergence.gp", script + plot + "\n");
}

}  // namespace surge
