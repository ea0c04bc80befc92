// `surge run --slurm` and `surge study --slurm`: the stages as Slurm jobs, written as scripts into the output
// folder (DIR/slurm/) and submitted with sbatch. Surge schedules nothing itself: Slurm runs the jobs, their
// dependencies order them, and its requeue restarts a killed task, which then redoes only what is missing
// (every stage runs with --resume). docs/cluster.md has the commands and what happens when a task fails.
//
//   surge run:   sim (one job) -> whitewater (one job, afterok:sim, when the scene has it) -> surface (array over chunks of --chunk frames, afterok:sim, or with --stream
//                after:sim, each task surfacing its frames as the simulation writes them) -> render (array,
//                aftercorr:surface: a chunk renders once its own surfaces are done) -> video (afterok:render)
//   surge study: one array task a sweep point -> report (afterany: a run that diverged is a result too)
#pragma once

#include <string>
#include <vector>

#include "apps/commands.h"

namespace surge {

struct SlurmOptions {
  bool enabled = false;  // --slurm
  bool dryRun = false;   // print the scripts and the sbatch commands; write and submit nothing
  bool stream = false;   // surface tasks start with the simulation and wait for their frames
  int chunk = 10;        // frames a surface or render task
  // Passed to every job as #SBATCH lines when set.
  std::string partition, account, time, memory;
  int cpusPerTask = 0;
  std::vector<std::string> sbatchFlags;  // anything else, as written (--sbatch=--qos=high)
};

// Adds --slurm and its options to a command; `pipeline` adds --chunk and --stream (surge run).
void addSlurmOptions(CLI::App& command, SlurmOptions& options, bool pipeline);

// A job to submit: its script's name and text, and how it depends on the jobs submitted before it.
struct SlurmJob {
  std::string name;        // sim, surface, render, video; study_runs, study_report
  std::string script;      // the whole script
  std::string dependency;  // e.g. "afterok:" and the index of an earlier job in the list, as "afterok:%0"
};

// The jobs of `surge run --slurm` for a scene whose output folder is dir (absolute paths throughout).
// `scenePath` is the scene file as given (the simulation reads it again, with `overrides`, so that its
// collider files are found beside it); `renderer` and `quality` are passed to the render tasks when not empty.
std::vector<SlurmJob> runJobs(const Scene& scene, const fs::path& scenePath, const fs::path& dir,
                              const std::vector<std::string>& overrides, const std::string& renderer,
                              const std::string& quality, const SlurmOptions& options);

// The jobs of `surge study --slurm`: an array of `runs` tasks, each `surge study ... --run-index I`, and a
// report, `surge study ... --report`; `studyArguments` are the study command's own arguments after "study".
std::vector<SlurmJob> studyJobs(const std::string& name, const fs::path& dir, int runs,
                                const std::vector<std::string>& studyArguments, const SlurmOptions& options);

// Writes the scripts into dir/slurm/ and submits them in order with `sbatch --parsable`, replacing each %i in a
// dependency with the i-th job's id; writes dir/slurm/jobs.txt and prints the ids and how to follow them. With
// options.dryRun, prints the scripts and the commands instead and touches nothing. Throws RunError when sbatch
// is missing or refuses a job (the jobs already submitted are cancelled).
void submitJobs(const std::vector<SlurmJob>& jobs, const fs::path& dir, const SlurmOptions& options,
                const CommonOptions& common);

// sbatch's path; throws RunError when it is not on PATH. Asked before anything is written.
fs::path sbatchProgram();

// A word quoted for bash: 'text', with ' written as '\''.
std::string shellQuote(const std::string& text);

}  // namespace surge
