// The study's figures: each run's stats.csv read by column name, the accuracy against the reference run,
// study.csv, and the plots through gnuplot.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "apps/study.h"

#include <nlohmann/json.hpp>
#include "core/errors.h"
#include "core/ply.h"
#include "sim/simulation.h"

extern char** environ;

namespace surge {
namespace {


double number(const std::vector<std::string>& fields, int column) {
  if (column < 0 || column >= int(fields.size()) || fields[column].empty()) return NAN;
  return std::atof(fields[column].c_str());
}

// Linear interpolation of (times, values) at t; NaN outside the times.
double interpolate(const std::vector<double>& times, const std::vector<double>& values, double t) {
  if (times.empty() || t < times.front() - 1e-9 || t > times.back() + 1e-9) return NAN;
  const size_t upper = std::lower_bound(times.begin(), times.end(), t - 1e-9) - times.begin();
  if (upper == 0) return values.front();
  if (upper >= times.size()) return values.back();
  const double t0 = times[upper - 1], t1 = times[upper];
  const double w = t1 > t0 ? (t - t0) / (t1 - t0) : 1.0;
  return values[upper - 1] + w * (values[upper] - values[upper - 1]);
}

// The fraction of the particles in each cell of a coarse grid over the domain: 32 cells along its longest
// axis, square cells, so a run at another particle spacing lands on the same grid. 32 cells over a 3.2 m tank
// are 10 cm, ten particles of the default dam break: coarse enough that one particle's jitter moves little mass,
// fine enough to see where the wave is.
std::vector<double> densityField(const ParticleFrame& frame, const Box& domain, int dimensions) {
  const Eigen::Vector3d extent = domain.max - domain.min;
  const double longest = dimensions == 2 ? std::max(extent.x(), extent.y()) : extent.maxCoeff();
  const double cell = longest / 32;
  int n[3] = {1, 1, 1};
  for (int k = 0; k < dimensions; ++k) n[k] = std::max(1, int(std::ceil(extent[k] / cell - 1e-9)));
  std::vector<double> field(size_t(n[0]) * size_t(n[1]) * size_t(n[2]), 0.0);
  for (const Eigen::Vector3f& p : frame.position) {
    int c[3] = {0, 0, 0};
    for (int k = 0; k < dimensions; ++k) c[k] = std::clamp(int((p[k] - domain.min[k]) / cell), 0, n[k] - 1);
    field[size_t((c[2] * n[1] + c[1]) * n[0] + c[0])] += 1.0 / double(frame.size());
  }
  return field;
}

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// True if an executable `name` is on PATH.
bool onPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream in(path ? path : "");
  std::string folder;
  while (std::getline(in, folder, ':'))
    if (!folder.empty() && access((fs::path(folder) / name).c_str(), X_OK) == 0) return true;
  return false;
}

// The 1-based column of stats.csv named `name`.
int statsColumn(const std::string& name) {
  const std::vector<std::string> header = splitCsvLine(statsCsvHeader());
  return int(std::find(header.begin(), header.end(), name) - header.begin()) + 1;
}

std::string label(const StudyRun& run) {
  std::string text;
  for (const std::string& value : run.values) text += (text.empty() ? "" : "/") + value;
  return text;
}

}  // namespace

std::string format(double value, const char* spec) {
  if (std::isnan(value)) return "";
  char text[64];
  std::snprintf(text, sizeof text, spec, value);
  return text;
}

void writeRunRecord(const StudyRun& run) {
  const nlohmann::json record = {{"status", run.status},           {"message", run.message},
                                 {"cpu_seconds", run.cpuSeconds},   {"wall_seconds", run.wallSeconds},
                                 {"peak_megabytes", run.peakMegabytes}};
  writeFileAtomically(run.folder / "run.json", [&](std::ostream& out) { out << record.dump(2) << "\n"; });
}

void readRunRecord(StudyRun& run) {
  std::error_code error;
  if (!fs::exists(run.folder / "run.json", error)) {
    run.status = "failed";
    run.message = "did not run (no " + (run.folder / "run.json").string() + ")";
    return;
  }
  const nlohmann::json record = nlohmann::json::parse(readTextFile(run.folder / "run.json"), nullptr, false);
  if (record.is_discarded() || !record.is_object())
    throw InputError((run.folder / "run.json").string(), "is not the JSON surge study writes");
  run.status = record.value("status", "failed");
  run.message = record.value("message", "");
  run.cpuSeconds = record.value("cpu_seconds", 0.0);
  run.wallSeconds = record.value("wall_seconds", 0.0);
  run.peakMegabytes = record.value("peak_megabytes", 0.0);
}

void readRunStats(StudyRun& run) {
  std::ifstream in(run.folder / "stats.csv");
  std::string line;
  if (!std::getline(in, line)) return;
  std::map<std::string, int> column;
  const std::vector<std::string> header = splitCsvLine(line);
  for (size_t c = 0; c < header.size(); ++c) column[header[c]] = int(c);
  auto at = [&](const char* name) { return column.count(name) ? column[name] : -1; };
  double errorSum = 0;
  int errorRows = 0;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = splitCsvLine(line);
    const int frame = int(number(f, at("frame")));
    const double particles = number(f, at("particles")), substeps = number(f, at("substeps"));
    run.particles = size_t(particles);
    run.framesDone = frame;
    run.steps += long(substeps);
    run.work += particles * substeps * (1 + number(f, at("iterations")));
    if (frame > 0) {  // frame 0 is the rest lattice: no error to speak of
      errorSum += number(f, at("density_error_avg"));
      ++errorRows;
      run.densityErrorMax = std::max(run.densityErrorMax, number(f, at("density_error_max")));
    }
    run.kineticEnergyEnd = number(f, at("kinetic_energy"));
    run.frame.push_back(frame);
    run.time.push_back(number(f, at("time")));
    run.frontX.push_back(number(f, at("front_x")));
    run.backHeight.push_back(number(f, at("back_height")));
  }
  run.densityErrorAvg = errorRows ? errorSum / errorRows : 0;
}

int compareWithReference(std::vector<StudyRun>& runs, bool damBreak, const Box& domain, int dimensions) {
  // The reference is the run that did the most work, counted from stats.csv (particles x steps x (1 +
  // iterations): a PBF step is a neighbour search and `iterations` constraint passes of about the same cost, a
  // WCSPH step one pass), so the choice does not depend on the machine's timing noise; CPU seconds break ties.
  int reference = -1;
  for (size_t i = 0; i < runs.size(); ++i) {
    if (runs[i].status != "ok") continue;
    if (reference < 0 || runs[i].work > runs[reference].work ||
        (runs[i].work == runs[reference].work && runs[i].cpuSeconds > runs[reference].cpuSeconds))
      reference = int(i);
  }
  for (StudyRun& run : runs) run.frontRms = run.heightRms = run.fieldError = run.error = NAN;
  if (reference < 0) return -1;
  StudyRun& ref = runs[reference];
  ref.reference = true;
  const ParticleFrame refFinal = readParticlePly(framePath(ref.folder, "particles", ref.framesDone, "ply"));
  // The dam break proper ends when the reference's front reaches the far wall: after the impact the flow splashes
  // and sloshes chaotically, and two runs differing in the last bit drift apart there (see docs/speed-accuracy.md),
  // so differences after it measure chaos more than accuracy. Measured up to that time (the whole run if the
  // front never arrives).
  const double length = domain.max.x() - domain.min.x();
  double window = INFINITY;
  for (size_t k = 0; k < ref.time.size() && std::isinf(window); ++k)
    if (ref.frontX[k] >= length * (1 - 1e-3)) window = ref.time[k];
  for (StudyRun& run : runs) run.window = window;
  for (StudyRun& run : runs) {
    if (run.status != "ok") continue;
    // Frames matched by time: the reference interpolated at the run's frame times (they coincide unless
    // output.fps is swept), over the times both cover, up to the window.
    double front = 0, height = 0;
    int count = 0;
    for (size_t k = 0; k < run.time.size() && run.time[k] <= window + 1e-9; ++k) {
      const double f = interpolate(ref.time, ref.frontX, run.time[k]);
      const double h = interpolate(ref.time, ref.backHeight, run.time[k]);
      if (std::isnan(f) || std::isnan(h)) continue;
      front += (run.frontX[k] - f) * (run.frontX[k] - f);
      height += (run.backHeight[k] - h) * (run.backHeight[k] - h);
      ++count;
    }
    if (count > 0) {
      run.frontRms = std::sqrt(front / count);
      run.heightRms = std::sqrt(height / count);
    }
    // The density field at the run's last frame against the reference's frame nearest that time: half the
    // summed absolute difference of the particle fractions, i.e. the fraction of the water in the wrong place.
    const double last = run.time.empty() ? NAN : run.time.back();
    size_t nearest = 0;
    for (size_t k = 0; k < ref.time.size(); ++k)
      if (std::abs(ref.time[k] - last) < std::abs(ref.time[nearest] - last)) nearest = k;
    if (!ref.time.empty() && std::abs(ref.time[nearest] - last) < 1e-6) {
      const ParticleFrame refFrame = ref.frame[nearest] == ref.framesDone
                                         ? refFinal
                                         : readParticlePly(framePath(ref.folder, "particles", ref.frame[nearest], "ply"));
      const ParticleFrame mine = readParticlePly(framePath(run.folder, "particles", run.framesDone, "ply"));
      const std::vector<double> a = densityField(mine, domain, dimensions), b = densityField(refFrame, domain, dimensions);
      double difference = 0;
      for (size_t c = 0; c < a.size(); ++c) difference += std::abs(a[c] - b[c]);
      run.fieldError = 0.5 * difference;
    }
    // Dam breaks: both lengths in metres, combined as their root mean square.
    run.error = damBreak ? std::sqrt(0.5 * (run.frontRms * run.frontRms + run.heightRms * run.heightRms))
                         : run.fieldError;
  }
  return reference;
}

std::vector<int> paretoFront(const std::vector<StudyRun>& runs) {
  std::vector<int> order;
  for (size_t i = 0; i < runs.size(); ++i)
    if (runs[i].status == "ok" && !std::isnan(runs[i].error)) order.push_back(int(i));
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return runs[a].cpuSeconds != runs[b].cpuSeconds ? runs[a].cpuSeconds < runs[b].cpuSeconds
                                                    : runs[a].error < runs[b].error;
  });
  std::vector<int> front;
  double best = INFINITY;
  for (int i : order)
    if (runs[i].error < best) {
      front.push_back(i);
      best = runs[i].error;
    }
  return front;
}

void writeStudyCsv(const fs::path& path, const std::vector<Sweep>& sweeps, const std::vector<StudyRun>& runs) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "run";
    for (const Sweep& sweep : sweeps) out << "," << csvField(sweep.key);
    out << ",particles,frames,steps,cpu_seconds,wall_seconds,peak_mb,density_error_avg,density_error_max,"
           "kinetic_energy_end,diverged,status,reference,compared_until,front_rms,height_rms,field_error,error,folder,"
           "message\n";
    for (const StudyRun& run : runs) {
      out << run.index;
      for (const std::string& value : run.values) out << "," << csvField(value);
      out << "," << run.particles << "," << run.framesDone << "," << run.steps << "," << format(run.cpuSeconds, "%.3f")
          << "," << format(run.wallSeconds, "%.3f") << "," << format(run.peakMegabytes, "%.1f") << ","
          << format(run.densityErrorAvg) << "," << format(run.densityErrorMax) << "," << format(run.kineticEnergyEnd)
          << "," << (run.status == "diverged") << "," << run.status << "," << run.reference << ","
          << format(run.window) << "," << format(run.frontRms) << "," << format(run.heightRms) << "," << format(run.fieldError) << ","
          << format(run.error) << "," << csvField(run.folder.filename().string()) << "," << csvField(run.message)
          << "\n";
    }
  });
}

std::string writeStudyPlots(const fs::path& dir, const std::vector<Sweep>& sweeps, const std::vector<StudyRun>& runs,
                            int reference, const std::string& errorLabel) {
  if (!onPath("gnuplot")) return "gnuplot is not installed: no plots (study.csv is complete)";
  std::string keys;
  for (const Sweep& sweep : sweeps) keys += (keys.empty() ? "" : "/") + sweep.key;

  // Data files: every comparable run (cpu, error, label), and the Pareto front in CPU order.
  writeFileAtomically(dir / "plot_runs.dat", [&](std::ostream& out) {
    for (const StudyRun& run : runs)
      if (run.status == "ok" && !std::isnan(run.error) && !run.reference)
        out << format(run.cpuSeconds) << " " << format(run.error) << " \"" << label(run) << "\"\n";
  });
  writeFileAtomically(dir / "plot_pareto.dat", [&](std::ostream& out) {
    for (int i : paretoFront(runs))
      if (!runs[i].reference) out << format(runs[i].cpuSeconds) << " " << format(runs[i].error) << "\n";
  });

  const std::string ref = reference >= 0 ? label(runs[reference]) : "none";
  std::ostringstream gp;
  gp << "set terminal pngcairo size 900,600 font 'sans,10'\n"
     << "set datafile separator whitespace\n"
     << "set output '" << (dir / "error_vs_cpu.png").string() << "'\n"
     << "set title \"Error against CPU time (" << keys << "); reference " << ref << "\" noenhanced\n"
     << "set xlabel 'CPU seconds (all threads)'\nset logscale x\nset logscale y\nset grid\n"
     << "set ylabel '" << errorLabel << "'\nset key top right\n"
     << "plot '" << (dir / "plot_runs.dat").string() << "' using 1:2 with points pt 7 ps 1.2 title 'runs', \\\n"
     << "  '' using 1:2:3 with labels offset 0,1 font ',8' noenhanced notitle, \\\n"
     << "  '" << (dir / "plot_pareto.dat").string() << "' using 1:2 with linespoints lw 2 pt 6 ps 2 title 'Pareto front'\n";
  bool anyStats = false;
  for (const StudyRun& run : runs) anyStats = anyStats || !run.time.empty();
  if (anyStats) {
    gp << "set output '" << (dir / "front_vs_time.png").string() << "'\n"
       << "set terminal pngcairo size 900,900 font 'sans,10'\n"
       << "unset logscale\nset datafile separator ','\nset key outside right noenhanced\n"
       << (reference >= 0 && std::isfinite(runs[reference].window)
               ? "set arrow from " + format(runs[reference].window) +
                     ", graph 0 to " + format(runs[reference].window) + ", graph 1 nohead dt 2\n" +
                     "set label 'compared until here' at " + format(runs[reference].window) + ", graph 0.95 offset 0.5,0\n"
               : std::string())
       << "set multiplot layout 2,1 title \"Dam break measures per run (" << keys << ")\" noenhanced\n";
    for (const char* measure : {"front_x", "back_height"}) {
      gp << "set title '" << measure << "' noenhanced\nset xlabel 'time (s)'\nset ylabel '" << measure << " (m)' noenhanced\n"
         << "plot ";
      bool first = true;
      for (const StudyRun& run : runs) {
        if (run.time.empty()) continue;
        gp << (first ? "" : ", \\\n  ") << "'" << (run.folder / "stats.csv").string() << "' every ::1 using "
           << statsColumn("time") << ":" << statsColumn(measure) << " with lines " << (run.reference ? "lw 3 " : "lw 1 ")
           << "title '" << label(run) << (run.reference ? " (ref)" : "") << (run.status != "ok" ? " (diverged)" : "")
           << "'";
        first = false;
      }
      gp << "\n";
    }
    gp << "unset multiplot\n";
  }
  return runGnuplot(dir / "plots.gp", gp.str());
}

std::string runGnuplot(const fs::path& script, const std::string& text) {
  if (!onPath("gnuplot")) return "gnuplot is not installed: no plots (the tables are complete)";
  writeFileAtomically(script, [&](std::ostream& out) { out << text; });
  const std::string scriptText = script.string(), log = fs::path(script).replace_extension(".log").string();
  std::vector<std::string> args = {"gnuplot", scriptText};
  std::vector<char*> argv = {args[0].data(), args[1].data(), nullptr};
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, "gnuplot", &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  if (spawned != 0) return "cannot start gnuplot: no plots";
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return "gnuplot failed (see " + log + "): plots may be missing";
  return "";
}

}  // namespace surge
