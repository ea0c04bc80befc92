// surge run SCENE: all four stages, sim -> surface -> render -> video, into one output folder.
#include "apps/commands.h"
#include "core/errors.h"
#include "core/parallel.h"

namespace surge {

void addRunCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string scene, renderer;
    bool resume = false;
  };
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
  command->callback([options] {
    const Scene scene = loadScene(options->scene, options->common.overrides);
    ThreadLimit threads(options->common.threads);
    const fs::path dir = outputFolder(options->common, scene);
    try {
      runSimStage(scene, dir, options->resume, options->common);
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
