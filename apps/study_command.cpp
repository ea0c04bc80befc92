// surge study SCENE --sweep key=v1,v2,... [--sweep ...]: every combination of the sweeps simulated as its own
// `surge sim` child process (DIR/runs/<index>_<key=value,...>/), so that a run that diverges or runs out of
// memory cannot stop the study, and so that wait4 gives each run's own CPU seconds (all its TBB threads, user and
// system) and peak resident memory (ru_maxrss), which an in-process run could not separate from the study's.
// The runs go one after another: running two at once on a shared machine would make their CPU and wall times
// disturb each other.
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "apps/commands.h"
#include "apps/slurm.h"
#include "apps/study.h"
#include "core/errors.h"
#include "sim/simulation.h"
#include "sim/solver_defaults.h"

extern char** environ;

namespace surge {
namespace {

// Values of one sweep, split at commas outside [], {} and "".
std::vector<std::string> splitValues(const std::string& text) {
  std::vector<std::string> values;
  std::string current;
  int depth = 0;
  bool quoted = false;
  for (char c : text) {
    if (c == '"') quoted = !quoted;
    if (!quoted && (c == '[' || c == '{')) ++depth;
    if (!quoted && (c == ']' || c == '}')) --depth;
    if (c == ',' && depth == 0 && !quoted) {
      values.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  values.push_back(current);
  return values;
}

// A folder name for a run: its index and settings, with anything but [A-Za-z0-9._=,+-] replaced by '_'.
std::string runFolderName(int index, const std::vector<Sweep>& sweeps, const std::vector<std::string>& values) {
  char prefix[16];
  std::snprintf(prefix, sizeof prefix, "%03d_", index);
  std::string name = prefix;
  for (size_t s = 0; s < sweeps.size(); ++s) name += (s ? "," : "") + sweeps[s].key + "=" + values[s];
  for (size_t i = 4; i < name.size(); ++i) {
    const char c = name[i];
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '=' || c == ',' ||
                      c == '+' || c == '-';
    if (!keep) name[i] = '_';
  }
  return name;
}

// The combinations, the first sweep varying slowest.
std::vector<std::vector<std::string>> combinations(const std::vector<Sweep>& sweeps) {
  std::vector<std::vector<std::string>> all{{}};
  for (const Sweep& sweep : sweeps) {
    std::vector<std::vector<std::string>> next;
    for (const auto& prefix : all)
      for (const std::string& value : sweep.values) {
        next.push_back(prefix);
        next.back().push_back(value);
      }
    all = std::move(next);
  }
  return all;
}

// The last non-empty line of a text file (the child's error message).
std::string lastLine(const fs::path& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line)) {
    const size_t start = line.find_first_not_of(" \r\n");
    if (start != std::string::npos) last = line.substr(start);
  }
  return last;
}

}  // namespace

void runChild(StudyRun& run, std::vector<std::string> args, int threads) {
  if (threads > 0) args.insert(args.end(), {"--threads", std::to_string(threads)});
  fs::create_directories(run.folder);
  const std::string log = (run.folder / "log.txt").string();
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, STDOUT_FILENO, STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, "/proc/self/exe", &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  if (spawned != 0) throw RunError("study: cannot start surge " + args[1] + ": " + std::string(std::strerror(spawned)));

  int status = 0;
  rusage usage{};
  while (wait4(pid, &status, 0, &usage) < 0)
    if (errno != EINTR) throw RunError("study: lost the run in " + run.folder.string() + ": " + std::strerror(errno));
  run.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.cpuSeconds = usage.ru_utime.tv_sec + 1e-6 * usage.ru_utime.tv_usec + usage.ru_stime.tv_sec +
                   1e-6 * usage.ru_stime.tv_usec;
  run.peakMegabytes = usage.ru_maxrss / 1024.0;  // kilobytes on Linux

  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == kExitInterrupted || Progress::wasInterrupted()) throw Interrupted();
  if (code != 0) {
    run.message = lastLine(log);
    run.status = run.message.find("diverged") != std::string::npos ? "diverged" : "failed";
    if (run.message.empty())
      run.message = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                        : "exit status " + std::to_string(code);
  }
}

namespace {

// Runs `surge sim` for one combination with stdout and stderr into the run folder's log.txt, and measures it.
void runOne(StudyRun& run, const std::string& scenePath, const std::vector<std::string>& overrides, int threads) {
  std::vector<std::string> args = {"surge", "sim", scenePath, "--quiet", "--out", run.folder.string()};
  for (const std::string& assignment : overrides) args.insert(args.end(), {"--set", assignment});
  runChild(run, args, threads);
  readRunStats(run);
}

}  // namespace

Sweep parseSweep(const std::string& text) {
  const size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0)
    throw InputError("--sweep", text, "expected key.path=value1,value2,...");
  Sweep sweep;
  sweep.key = text.substr(0, equals);
  sweep.values = splitValues(text.substr(equals + 1));
  for (const std::string& value : sweep.values)
    if (value.empty()) throw InputError("--sweep", sweep.key, "an empty value in '" + text + "'");
  // A surface setting would give every run the same simulation and nothing to compare.
  if (sweep.key.rfind("surface.", 0) == 0)
    throw InputError("--sweep", sweep.key, "the study compares simulations or renders, not surfaces");
  return sweep;
}

void addStudyCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string scene;
    std::vector<std::string> sweeps;
    int frames = 0;
    std::string measure;
    int runIndex = -1;
    bool report = false;
    SlurmOptions slurm;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "study", "simulate every combination of --sweep values and compare speed and accuracy (study.csv, plots)");
  command->add_option("scene", options->scene, "scene file (JSON)")->required();
  command->add_option("--sweep", options->sweeps, "a scene key and its values: key.path=v1,v2,... (repeatable)")
      ->type_name("KEY=V1,V2,...")
      ->required();
  command->add_option("--frames", options->frames, "output frames per run (default: the scene's output.frames)")
      ->check(CLI::PositiveNumber);
  command->add_option("--measure", options->measure,
                      "a convergence study over a particle_spacing sweep of three or more values: the observed order, "
                      "the Richardson-extrapolated value and each run's error estimate of COLUMN@T (stats.csv), "
                      "bodies.NAME.COLUMN@T or colliders.NAME.COLUMN@T (convergence.csv, convergence.png)")
      ->type_name("WHAT@SECONDS");
  command->add_option("--run-index", options->runIndex,
                      "run only the sweep point of this index (0-based) into its runs/ folder, no report (a Slurm "
                      "array task of surge study --slurm)")
      ->check(CLI::NonNegativeNumber);
  command->add_flag("--report", options->report,
                    "run nothing: write study.csv and the plots from the runs already in the folder (the last job "
                    "of surge study --slurm)");
  addCommonOptions(*command, options->common, true);
  addSlurmOptions(*command, options->slurm, false);
  command->callback([options] {
    const CommonOptions& common = options->common;
    std::vector<Sweep> sweeps;
    for (const std::string& text : options->sweeps) sweeps.push_back(parseSweep(text));
    for (size_t a = 0; a < sweeps.size(); ++a)
      for (size_t b = 0; b < a; ++b)
        if (sweeps[a].key == sweeps[b].key) throw InputError("--sweep", sweeps[a].key, "swept twice");
    // Render settings are swept alone: the scene is simulated once and each run renders it (render_study.cpp).
    size_t renderKeys = 0;
    for (const Sweep& sweep : sweeps) renderKeys += sweep.key.rfind("render.", 0) == 0;
    const bool renderStudy = renderKeys > 0;
    if (renderStudy && renderKeys < sweeps.size())
      throw InputError("--sweep", sweeps.front().key, "sweep render settings alone or simulation settings alone");
    if (renderStudy && (options->slurm.enabled || options->runIndex >= 0 || options->report))
      throw InputError("--sweep", sweeps.front().key,
                       "render settings are swept in one local study (no --slurm, --run-index or --report)");

    // Every combination's scene is loaded (and so checked) before anything is written or run.
    std::vector<std::string> base = common.overrides;
    if (options->frames > 0) base.push_back("output.frames=" + std::to_string(options->frames));
    const Scene scene = loadScene(options->scene, base);
    const fs::path dir = outputFolder(common, scene).string() + (common.out.empty() ? "_study" : "");
    Measure measure;
    if (!options->measure.empty()) {
      measure = parseMeasure(options->measure, scene);
      if (sweeps.size() != 1 || sweeps[0].key != "particle_spacing")
        throw InputError("--measure", options->measure, "measures convergence over one sweep, of particle_spacing");
      if (sweeps[0].values.size() < 3)
        throw InputError("--sweep", "particle_spacing", "a convergence study needs three spacings or more, not " +
                                                            std::to_string(sweeps[0].values.size()));
      std::vector<double> spacings;
      for (const std::string& value : sweeps[0].values) spacings.push_back(std::atof(value.c_str()));
      std::sort(spacings.begin(), spacings.end());
      if (std::adjacent_find(spacings.begin(), spacings.end()) != spacings.end())
        throw InputError("--sweep", "particle_spacing", "a convergence study needs distinct spacings");
    }
    std::vector<StudyRun> runs;
    std::vector<std::vector<std::string>> overrides;
    for (const std::vector<std::string>& values : combinations(sweeps)) {
      std::vector<std::string> assignments = base;
      for (size_t s = 0; s < sweeps.size(); ++s) assignments.push_back(sweeps[s].key + "=" + values[s]);
      checkSimulationMemory(loadScene(options->scene, assignments));
      StudyRun run;
      run.index = static_cast<int>(runs.size());
      run.values = values;
      run.folder = dir / "runs" / runFolderName(run.index, sweeps, values);
      runs.push_back(run);
      overrides.push_back(assignments);
    }

    if (options->runIndex >= int(runs.size()))
      throw InputError("--run-index", std::to_string(options->runIndex) + " is past the last of the " +
                                          std::to_string(runs.size()) + " sweep points");
    if (options->slurm.enabled) {
      // Each task runs this same command (absolute paths, the same sweeps and settings) with --run-index.
      const fs::path absolute = fs::absolute(dir);
      std::vector<std::string> arguments = {fs::absolute(options->scene).string(), "--out", absolute.string()};
      for (const std::string& sweep : options->sweeps) arguments.insert(arguments.end(), {"--sweep", sweep});
      if (options->frames > 0) arguments.insert(arguments.end(), {"--frames", std::to_string(options->frames)});
      if (!options->measure.empty()) arguments.insert(arguments.end(), {"--measure", options->measure});
      for (const std::string& assignment : common.overrides) arguments.insert(arguments.end(), {"--set", assignment});
      arguments.push_back("--quiet");
      if (!options->slurm.dryRun) {
        sbatchProgram();
        checkOutputFolder(absolute);
        writeFileAtomically(absolute / "scene.json", [&](std::ostream& out) { out << sceneToJson(scene); });
      }
      submitJobs(studyJobs(scene.name, absolute, int(runs.size()), arguments, options->slurm), absolute,
                 options->slurm, common);
      return;
    }
    checkOutputFolder(dir);
    if (options->runIndex >= 0) {
      StudyRun& run = runs[size_t(options->runIndex)];
      runOne(run, options->scene, overrides[size_t(options->runIndex)], common.threads);
      writeRunRecord(run);
      say(common, "study: run " + std::to_string(run.index) + " " + run.status + " in " +
                      std::to_string(run.cpuSeconds) + " CPU s -> " + run.folder.string());
      return;
    }
    if (!options->report)
      writeFileAtomically(dir / "scene.json", [&](std::ostream& out) { out << sceneToJson(scene); });
    const auto start = std::chrono::steady_clock::now();
    TerminalProgress progress(!common.quiet);
    int reference = -1;
    std::string errorLabel;
    if (renderStudy) {
      std::vector<std::vector<std::string>> renderOverrides;
      for (const std::vector<std::string>& assignments : overrides)
        renderOverrides.emplace_back(assignments.end() - sweeps.size(), assignments.end());
      reference = runRenderStudy(options->scene, dir, base, runs, renderOverrides, common.threads, progress);
      errorLabel = "image RMSE against the reference (8-bit sRGB values)";
    } else {
      progress.start("study", runs.size());
      for (size_t i = 0; i < runs.size(); ++i) {
        Progress::checkInterrupt();
        if (options->report) {
          readRunRecord(runs[i]);
          readRunStats(runs[i]);
        } else {
          runOne(runs[i], options->scene, overrides[i], common.threads);
          writeRunRecord(runs[i]);
        }
        progress.advance();
      }
      progress.finish();
      const bool damBreak = isDamBreak(scene);
      reference = compareWithReference(runs, damBreak, scene.domain, scene.dimensions);
      errorLabel = damBreak ? "RMS error of front and back height (m)" : "density field error (fraction)";
    }
    writeStudyCsv(dir / "study.csv", sweeps, runs);
    std::string warning = writeStudyPlots(dir, sweeps, runs, reference, errorLabel);
    if (!warning.empty()) std::fprintf(stderr, "surge: warning: %s\n", warning.c_str());
    if (!options->measure.empty()) {
      std::vector<double> spacings, values;
      for (const StudyRun& run : runs) {
        spacings.push_back(std::atof(run.values[0].c_str()));
        values.push_back(readMeasure(measure, run.folder, scene.output.fps));
      }
      const Convergence result = richardson(spacings, values);
      warning = writeConvergence(dir, measure, result);
      if (!warning.empty()) std::fprintf(stderr, "surge: warning: %s\n", warning.c_str());
      say(common, "study: " + measure.text + ": " + result.verdict +
                      (std::isfinite(result.extrapolated) ? ", extrapolated " + format(result.extrapolated) : "") +
                      " -> " + (dir / "convergence.csv").string());
    }

    int bad = 0;
    for (const StudyRun& run : runs) bad += run.status != "ok";
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    char line[512];
    std::snprintf(line, sizeof line, "study: %zu runs (%d diverged or failed) in %.1f s, reference run %d -> %s",
                  runs.size(), bad, seconds, reference, (dir / "study.csv").string().c_str());
    say(common, line);
  });
}

}  // namespace surge
