// surge render DIR: surface meshes to PNG frames.
#include <chrono>
#include <cstdio>

#include "apps/commands.h"
#include "core/parallel.h"
#include "render/renderer.h"

namespace surge {

namespace {

void renderStage(const Scene& scene, const fs::path& dir, const FrameRange& range,
                 const CommonOptions& options, const RenderOptions& renderOptions) {
  const auto start = std::chrono::steady_clock::now();
  checkOutputFolder(dir);
  TerminalProgress progress(!options.quiet);
  renderFrames(dir, scene, range, progress, renderOptions);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  char line[256];
  std::snprintf(line, sizeof line, "render: %.1f s -> %s/frames", seconds, dir.string().c_str());
  say(options, line);
}

}  // namespace

void runRenderStage(const Scene& scene, const fs::path& dir, const FrameRange& range,
                    const CommonOptions& options, const std::string& renderer, bool resume) {
  RenderOptions renderOptions;
  renderOptions.renderer = renderer;
  renderOptions.resume = resume;
  renderStage(scene, dir, range, options, renderOptions);
}

void addRenderCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string dir, frames, quality;
    RenderOptions render;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "render", "surface meshes to PNG frames (Embree path tracer, or OSMesa for a quick look)");
  command->add_option("dir", options->dir, "output folder of surge surface")->required();
  command->add_option("--frames", options->frames, "frames A:B (inclusive; either end may be left open)");
  command
      ->add_option("--renderer", options->render.renderer,
                   "embree (path tracer; the default in 3D) or gl (OSMesa; the default in 2D)")
      ->check(CLI::IsMember({"embree", "gl"}));
  command->add_option("--quality", options->quality, "preview, standard or final (sets render.quality)")
      ->check(CLI::IsMember({"preview", "standard", "final"}));
  command->add_flag("--particles", options->render.particles,
                    "gl: draw the particles as spheres (the default when there are no surface frames)");
  command->add_flag("--resume", options->render.resume,
                    "leave the frames already up to date (newer than their surfaces and the render settings)");
  addCommonOptions(*command, options->common, false);
  command->callback([options] {
    Scene scene = sceneOfFolder(options->dir, options->common);
    if (!options->quality.empty()) scene.render.quality = options->quality;
    const FrameRange range = options->frames.empty() ? FrameRange{} : FrameRange::parse(options->frames);
    ThreadLimit threads(options->common.threads);
    renderStage(scene, options->dir, range, options->common, options->render);
  });
}

}  // namespace surge
