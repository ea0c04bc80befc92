#include "apps/slurm.h"

#include <cstdio>
#include <sstream>

#include "core/errors.h"
#include "core/process.h"

namespace surge {

namespace {

// This program's own path: the jobs run the same build (it must be on the filesystem the nodes share).
std::string surgeProgram() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  return error ? std::string("surge") : self.string();
}

// The #SBATCH lines every job shares, then the job's own.
std::string header(const std::string& jobName, const fs::path& dir, const std::string& logName, const SlurmOptions& o,
                   const std::string& array) {
  std::ostringstream s;
  s << "#!/bin/bash\n";
  s << "#SBATCH --job-name=" << jobName << "\n";
  s << "#SBATCH --output=" << (dir / "slurm" / "logs" / logName).string() << "\n";
  if (!array.empty()) s << "#SBATCH --array=" << array << "\n";
  // A task the scheduler kills (preemption, a node failure) goes back in the queue; it resumes, so it redoes
  // only the frames that are missing. Its log goes on in the same file.
  s << "#SBATCH --requeue\n#SBATCH --open-mode=append\n";
  if (!o.partition.empty()) s << "#SBATCH --partition=" << o.partition << "\n";
  if (!o.account.empty()) s << "#SBATCH --account=" << o.account << "\n";
  if (!o.time.empty()) s << "#SBATCH --time=" << o.time << "\n";
  if (!o.memory.empty()) s << "#SBATCH --mem=" << o.memory << "\n";
  if (o.cpusPerTask > 0) s << "#SBATCH --cpus-per-task=" << o.cpusPerTask << "\n";
  for (const std::string& flag : o.sbatchFlags) s << "#SBATCH " << flag << "\n";
  s << "# Written by surge; docs/cluster.md says what each job does.\n";
  s << "set -u\n";
  return s.str();
}

std::string words(const std::vector<std::string>& list) {
  std::string text;
  for (const std::string& word : list) text += " " + shellQuote(word);
  return text;
}

// The frames of chunk SLURM_ARRAY_TASK_ID, as "first:last".
std::string chunkLines(int chunk) {
  return "first=$(( SLURM_ARRAY_TASK_ID * " + std::to_string(chunk) + " ))\nlast=$(( first + " +
         std::to_string(chunk - 1) + " ))\n";
}

const char* kThreads = " --threads \"${SLURM_CPUS_PER_TASK:-0}\"";

}  // namespace

fs::path sbatchProgram() {
  const fs::path sbatch = findProgram("sbatch");
  if (sbatch.empty())
    throw RunError("sbatch not found: --slurm needs Slurm's client commands (apt-get install slurm-client) on PATH");
  return sbatch;
}

std::string shellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

void addSlurmOptions(CLI::App& command, SlurmOptions& o, bool pipeline) {
  CLI::Option* slurm = command.add_flag("--slurm", o.enabled,
                                        "submit the stages as Slurm jobs (sbatch) instead of running them here; "
                                        "the scripts go to DIR/slurm/");
  auto needs = [&](CLI::Option* option) { option->needs(slurm)->group("Slurm"); };
  needs(command.add_flag("--dry-run", o.dryRun, "print the job scripts and the sbatch commands; submit nothing"));
  needs(command.add_option("--partition", o.partition, "sbatch --partition"));
  needs(command.add_option("--account", o.account, "sbatch --account"));
  needs(command.add_option("--time", o.time, "sbatch --time, a limit for each job (e.g. 2:00:00)"));
  needs(command.add_option("--mem", o.memory, "sbatch --mem, memory for each job (e.g. 8G)"));
  needs(command.add_option("--cpus-per-task", o.cpusPerTask, "sbatch --cpus-per-task; surge uses that many threads")
            ->check(CLI::PositiveNumber));
  needs(command.add_option("--sbatch", o.sbatchFlags, "any other sbatch flag, as written (repeatable): --sbatch=--qos=high")
            ->type_name("FLAG"));
  if (pipeline) {
    slurm->group("Slurm");
    needs(command.add_option("--chunk", o.chunk, "frames a surface or render task (default 10)")
              ->check(CLI::PositiveNumber));
    needs(command.add_flag("--stream", o.stream,
                           "start the surface tasks with the simulation: each surfaces its frames as they are "
                           "written, instead of waiting for the whole simulation"));
  }
}

std::vector<SlurmJob> runJobs(const Scene& scene, const fs::path& scenePath, const fs::path& dir,
                              const std::vector<std::string>& overrides, const std::string& renderer,
                              const std::string& quality, const SlurmOptions& o) {
  const std::string surge = shellQuote(surgeProgram()), folder = shellQuote(dir.string());
  const int frames = scene.output.frames + 1;  // 0..output.frames
  const int chunks = (frames + o.chunk - 1) / o.chunk;
  const std::string array = "0-" + std::to_string(chunks - 1);
  std::vector<SlurmJob> jobs;

  std::string sim = header("surge-sim-" + scene.name, dir, "sim_%j.out", o, "");
  sim += "# The simulation, one job; requeued, it goes on from its last complete frame.\n";
  sim += "exec " + surge + " sim " + shellQuote(fs::absolute(scenePath).string()) + " --out " + folder +
         " --resume" + kThreads;
  for (const std::string& assignment : overrides) sim += " --set " + shellQuote(assignment);
  jobs.push_back({"sim", sim + "\n", ""});

  // Whitewater (when the scene has it): one job after the simulation, each frame made from the one before; the
  // surfaces then wait for it (no streaming: a surface frame holds its frame's whitewater).
  const bool whitewater = scene.whitewater.enabled != 0;
  if (whitewater) {
    std::string white = header("surge-whitewater-" + scene.name, dir, "whitewater_%j.out", o, "");
    white += "# Spray, foam and bubbles, one job; requeued, it goes on from its last complete frame.\n";
    white += "exec " + surge + " whitewater " + folder + " --resume" + kThreads + "\n";
    jobs.push_back({"whitewater", white, "afterok:%0"});
  }
  const std::string before = whitewater ? "%1" : "%0", surfaces = whitewater ? "%2" : "%1",
                    renders = whitewater ? "%3" : "%2";

  std::string surface = header("surge-surface-" + scene.name, dir, "surface_%A_%a.out", o, array);
  surface += "# Frames first..last of chunk SLURM_ARRAY_TASK_ID; up-to-date frames are left as they are.\n";
  surface += chunkLines(o.chunk);
  surface += "exec " + surge + " surface " + folder + " --frames \"$first:$last\" --resume" + kThreads +
             (o.stream && !whitewater ? " --wait" : "") + "\n";
  jobs.push_back({"surface", surface, (o.stream && !whitewater ? "after:" : "afterok:") + before});

  std::string render = header("surge-render-" + scene.name, dir, "render_%A_%a.out", o, array);
  render += "# The same chunk's images, once its surfaces are done (aftercorr).\n";
  render += chunkLines(o.chunk);
  render += "exec " + surge + " render " + folder + " --frames \"$first:$last\" --resume" + kThreads;
  if (!renderer.empty()) render += " --renderer " + shellQuote(renderer);
  if (!quality.empty()) render += " --quality " + shellQuote(quality);
  jobs.push_back({"render", render + "\n", "aftercorr:" + surfaces});

  std::string video = header("surge-video-" + scene.name, dir, "video_%j.out", o, "");
  video += "exec " + surge + " video " + folder + kThreads + "\n";
  jobs.push_back({"video", video, "afterok:" + renders});
  return jobs;
}

std::vector<SlurmJob> studyJobs(const std::string& name, const fs::path& dir, int runs,
                                const std::vector<std::string>& studyArguments, const SlurmOptions& o) {
  const std::string surge = shellQuote(surgeProgram());
  std::string each = header("surge-study-" + name, dir, "run_%A_%a.out", o, "0-" + std::to_string(runs - 1));
  each += "# One sweep point a task: its own surge sim, measured (CPU seconds, peak memory) into its run.json.\n";
  each += "exec " + surge + " study" + words(studyArguments) + " --run-index \"$SLURM_ARRAY_TASK_ID\"" + kThreads +
          "\n";
  std::string report = header("surge-study-report-" + name, dir, "report_%j.out", o, "");
  report += "# study.csv and the plots, from every run's run.json and stats.csv.\n";
  report += "exec " + surge + " study" + words(studyArguments) + " --report\n";
  return {{"study_runs", each, ""}, {"study_report", report, "afterany:%0"}};
}

void submitJobs(const std::vector<SlurmJob>& jobs, const fs::path& dir, const SlurmOptions& options,
                const CommonOptions& common) {
  const fs::path folder = dir / "slurm";
  auto dependencyOf = [&](const SlurmJob& job, const std::vector<std::string>& ids) {
    std::string text = job.dependency;
    for (size_t i = 0; i < ids.size(); ++i) {
      const std::string mark = "%" + std::to_string(i);
      for (size_t at = text.find(mark); at != std::string::npos; at = text.find(mark))
        text.replace(at, mark.size(), ids[i]);
    }
    return text;
  };
  auto arguments = [&](const SlurmJob& job, const std::vector<std::string>& ids) {
    std::vector<std::string> args = {"--parsable"};
    if (!job.dependency.empty())
      args.insert(args.end(), {"--dependency=" + dependencyOf(job, ids), "--kill-on-invalid-dep=yes"});
    args.push_back((folder / (job.name + ".sh")).string());
    return args;
  };

  if (options.dryRun) {
    std::vector<std::string> ids;
    for (size_t i = 0; i < jobs.size(); ++i) ids.push_back("<" + jobs[i].name + " job id>");
    for (const SlurmJob& job : jobs) {
      std::printf("# %s\n%s\n", (folder / (job.name + ".sh")).string().c_str(), job.script.c_str());
    }
    for (const SlurmJob& job : jobs) std::printf("sbatch%s\n", words(arguments(job, ids)).c_str());
    return;
  }

  const fs::path sbatch = sbatchProgram();
  fs::create_directories(folder / "logs");
  for (const SlurmJob& job : jobs)
    writeFileAtomically(folder / (job.name + ".sh"), [&](std::ostream& out) { out << job.script; });

  std::vector<std::string> ids;
  for (const SlurmJob& job : jobs) {
    const ProgramResult result = runProgram(sbatch, arguments(job, ids));
    std::string id = result.output.substr(0, result.output.find_first_of(";\n"));
    if (result.exitCode != 0 || id.empty()) {
      // Leave nothing half-submitted: the jobs that would wait for this one forever go too.
      if (const fs::path scancel = findProgram("scancel"); !ids.empty() && !scancel.empty()) runProgram(scancel, ids);
      std::string why = result.errors;
      while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
      for (char& c : why)
        if (c == '\n') c = ' ';
      throw RunError("sbatch refused " + (folder / (job.name + ".sh")).string() + ": " + why);
    }
    ids.push_back(id);
  }
  writeFileAtomically(folder / "jobs.txt", [&](std::ostream& out) {
    for (size_t i = 0; i < jobs.size(); ++i) out << jobs[i].name << " " << ids[i] << "\n";
  });
  std::string list;
  for (const std::string& id : ids) list += (list.empty() ? "" : ",") + id;
  for (size_t i = 0; i < jobs.size(); ++i)
    say(common, "slurm: " + jobs[i].name + " job " + ids[i] + (jobs[i].dependency.empty() ? "" : " (" + dependencyOf(jobs[i], ids) + ")"));
  say(common, "slurm: follow with `squeue -j " + list + "` and `sacct -j " + list + "`; logs in " +
                  (folder / "logs").string());
}

}  // namespace surge
