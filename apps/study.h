// `surge study`: a sweep of scene settings, each combination simulated by its own `surge sim` child process,
// compared with the most expensive run. study_command.cpp runs the sweep; study_report.cpp reads the runs'
// stats.csv and frames, computes the accuracy figures, and writes study.csv and the gnuplot plots.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/files.h"
#include "core/progress.h"
#include "core/scene.h"

namespace surge {

// One --sweep key=v1,v2,...
struct Sweep {
  std::string key;
  std::vector<std::string> values;
};

// Parses "key=v1,v2,...", splitting at commas outside brackets and quotes (so `fluids[0].velocity=[1,0],[2,0]`
// gives two values). Throws InputError naming --sweep.
Sweep parseSweep(const std::string& text);

// What one run left behind, and what the study measured of it.
struct StudyRun {
  int index = 0;
  std::vector<std::string> values;  // one per sweep, in sweep order
  fs::path folder;
  std::string status = "ok";  // ok, diverged, failed
  std::string message;        // the child's last stderr line when not ok
  double cpuSeconds = 0, wallSeconds = 0, peakMegabytes = 0;

  // From stats.csv.
  size_t particles = 0;
  int framesDone = 0;
  long steps = 0;
  double work = 0;  // sum over frames of particles x substeps x (1 + iterations): the cost the reference maximises
  double densityErrorAvg = 0, densityErrorMax = 0, kineticEnergyEnd = 0;
  std::vector<int> frame;
  std::vector<double> time, frontX, backHeight;

  // Against the reference run (NaN when not comparable).
  bool reference = false;
  double window = 0;  // front and height compared over [0, window] s: until the reference's front hits the far wall
  double frontRms = 0, heightRms = 0, fieldError = 0, error = 0;
};

// Runs `args` (args[0] "surge", args[1] its command; `--threads` added when threads > 0) as a child surge
// process with stdout and stderr into run.folder/log.txt, and fills the run's status, message (its last line when it failed), CPU and wall seconds
// (wait4: all its threads) and peak memory. Throws Interrupted if the child was interrupted.
void runChild(StudyRun& run, std::vector<std::string> args, int threads);

// A study of render settings (every swept key render.*, apps/render_study.cpp): the scene simulated and
// surfaced once into dir/base (`baseOverrides` applied), then each run renders those surfaces with its own
// settings (`surge render`, a child process each, CPU seconds measured), and its error is the RMS difference of
// its frames' 8-bit sRGB values from those of the reference, the unfiltered run of most CPU seconds. Fills runs; returns
// the reference's position, or -1. Throws RunError if the base simulation or surfacing fails.
int runRenderStudy(const fs::path& scenePath, const fs::path& dir, const std::vector<std::string>& baseOverrides,
                   std::vector<StudyRun>& runs, const std::vector<std::vector<std::string>>& runOverrides,
                   int threads, Progress& progress);

// The run's measures (status, message, CPU and wall seconds, peak memory) as run.json in its folder, written by
// the task that ran it and read by the report (surge study --slurm runs them in different jobs). A run without
// one reads as failed, "did not run".
void writeRunRecord(const StudyRun& run);
void readRunRecord(StudyRun& run);

// Reads the run's stats.csv into it (the columns are found by name). A run that stopped early keeps its rows.
void readRunStats(StudyRun& run);

// Picks the reference (the ok run of most work, then most CPU seconds) and fills every run's accuracy figures.
// damBreak: error is the RMS of front_x and back_height against the reference over time; otherwise it is the
// particle-density field difference at the final frame (fieldError is computed for every scene). Returns the reference's position in runs, or -1.
int compareWithReference(std::vector<StudyRun>& runs, bool damBreak, const Box& domain, int dimensions);

// study.csv, written atomically: one row per run.
void writeStudyCsv(const fs::path& path, const std::vector<Sweep>& sweeps, const std::vector<StudyRun>& runs);

// error_vs_cpu.png (Pareto front marked) and front_vs_time.png in dir, through a gnuplot script (plots.gp).
// Returns an empty string, or a one-line warning when gnuplot is missing or failed (the study still succeeds).
// errorLabel names the error's axis; the dam-break plot is drawn only when some run has stats.
std::string writeStudyPlots(const fs::path& dir, const std::vector<Sweep>& sweeps, const std::vector<StudyRun>& runs,
                            int reference, const std::string& errorLabel);

// The runs on the Pareto front of (CPU seconds, error): none cheaper is at least as accurate. Sorted by CPU.
std::vector<int> paretoFront(const std::vector<StudyRun>& runs);

// printf of one number with `spec`; "" for NaN (an empty CSV field).
std::string format(double value, const char* spec = "%.6g");
// Writes `text` to `script` and runs gnuplot on it (its output into the script's name with .log). Returns "" or
// a one-line warning when gnuplot is missing or failed.
std::string runGnuplot(const fs::path& script, const std::string& text);

// --measure (apps/study_convergence.cpp): a quantity read from each run at one time. `COLUMN@T` is a stats.csv
// column, `bodies.NAME.COLUMN@T` a body's bodies.csv column, `colliders.NAME.COLUMN@T` a collider's
// colliders.csv column, at T seconds (linear in time between frames).
struct Measure {
  std::string text;    // as given
  std::string file;    // stats.csv, bodies.csv or colliders.csv
  std::string name;    // the body or collider ("" for stats.csv)
  std::string column;
  double time = 0;
};
// InputError naming --measure for a form it does not know, a column its file lacks, a body or collider the
// scene does not have, or a time outside the run.
Measure parseMeasure(const std::string& text, const Scene& scene);
// The measure in a run's folder; NaN when the run ended before its time.
double readMeasure(const Measure& measure, const fs::path& folder, double fps);

// Richardson extrapolation over a spacing sweep: f(h) = f0 + C h^p through the three finest runs, p the observed
// order; each run's error estimate is |f - f0| (against the finest run when no order is found, as verdict says).
struct Convergence {
  std::vector<double> spacing, value, error;  // coarsest first
  double order = NAN, extrapolated = NAN, coefficient = NAN;
  std::string verdict;
};
Convergence richardson(std::vector<double> spacing, std::vector<double> value);
// convergence.csv (one row a run) and convergence.png in dir; returns "" or gnuplot's warning.
std::string writeConvergence(const fs::path& dir, const Measure& measure, const Convergence& result);

}  // namespace surge
