// surge run SCENE: all four stages, sim -> surface -> render -> video, into one output folder.
#include "apps/commands.h"
#include "apps/slurm.h"
#include "core/errors.h"
#include "core/parallel.h"
#include "sim/colliders.h"
#include "sim/rigid_bodies.h"
#include "sim/simulation.h"

namespace surge {

namespace {

struct RunOptions {
  CommonOptions common;
  std::string scene, renderer;
  bool resume = false;
  SlurmOptions slurm;
};

// surge run --slurm: the same checks of the scene's files as `surge sim` makes before it writes anything, the
// folder made ready (a new run's earlier frames removed, scene.json written, so that tasks started beside the
// simulation read this run's scene), then the jobs. The memory check is left to the simulation job: it knows
// its node's and its job's limit.
void submitRun(const Scene& scene, const fs::path& folder, const RunOptions& options) {
  const fs::path dir = fs::absolute(folder);
  const std::shared_ptr<const ColliderShapes> shapes = buildColliderShapes(scene);
  if (!scene.bodies.empty()) RigidBodies check(scene, shapes);
  const std::vector<SlurmJob> jobs = runJobs(scene, options.scene, dir, options.common.overrides, options.renderer,
                                             "", options.slurm);
  if (!options.slurm.dryRun) {
    sbatchProgram();
    checkOutputFolder(dir);
    if (!options.resume) {
      removeLaterStagesFrames(dir);
      removeFrames(dir, "particles", {"ply"});
      std::error_code error;
      fs::remove(dir / "sim_status.txt", error);
      // A resumed run leaves it to the simulation job, which first checks that the physics is the same.
      writeFileAtomically(dir / "scene.json", [&](std::ostream& out) { out << sceneToJson(scene); });
    }
  }
  submitJobs(jobs, dir, options.slurm, options.common);
}

}  // namespace

void addRunCommand(CLI::App& app) {
  using Options = RunOptions;
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("run", "simulate, surface, render and make the video of a scene");
  command->add_option("scene", options->scene, "scene file (JSON)")->required();
  command
      ->add_option("--renderer", options->renderer,
                   "embree (path tracer; the default in 3D) or gl (OSMesa; the default in 2D)")
      ->check(CLI::IsMember({"embree", "gl"}));
  command->add_flag("--resume", options->resume,
                    "pick up a stopped run: simulate on from the last complete frame, and surface and render "
                    "only the frames not yet up to date");
  addCommonOptions(*command, options->common, true);
  addSlurmOptions(*command, options->slurm, true);
  command->callback([options] {
    const Scene scene = loadScene(options->scene, options->common.overrides);
    ThreadLimit threads(options->common.threads);
    const fs::path dir = outputFolder(options->common, scene);
    if (options->slurm.enabled) return submitRun(scene, dir, *options);
    try {
      runSimStage(scene, dir, options->resume, options->common);
      runWhitewaterStage(scene, dir, FrameRange{}, options->common, options->resume);
      runSurfaceStage(scene, dir, FrameRange{}, options->common, options->resume);
      runRenderStage(scene, dir, FrameRange{}, options->common, options->renderer, options->resume);
    } catch (const Interrupted&) {
      throw Interrupted("the same command with --resume picks up from here");
    }
    runVideoStage(scene, dir, options->common);
  });
}

void addKeysCommand(CLI::App& app) {
  CLI::App* command = app.add_subcommand("keys", "print every scene key as a markdown table (docs/scene-format.md)");
  command->callback([] { std::fputs(sceneKeysMarkdown().c_str(), stdout); });
}

}  // namespace surge
