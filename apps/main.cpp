// surge: scene in, video out. See `surge --help` and docs/ARCHITECTURE.md.
#include <unistd.h>

#include <cstdio>
#include <exception>

#include "apps/commands.h"
#include "core/errors.h"
#include "core/parallel.h"

namespace surge {

void addCommonOptions(CLI::App& command, CommonOptions& options, bool withOut) {
  if (withOut) command.add_option("--out", options.out, "output folder (default: out/<scene name>)");
  command.add_option("--set", options.overrides, "override a scene value: key.path=value (repeatable)")
      ->type_name("KEY=VALUE");
  command.add_option("--threads", options.threads, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  command.add_flag("--quiet", options.quiet, "no progress bars or summaries");
}

fs::path outputFolder(const CommonOptions& options, const Scene& scene) {
  return options.out.empty() ? fs::path("out") / scene.name : fs::path(options.out);
}

Scene sceneOfFolder(const fs::path& dir, const CommonOptions& options) {
  const fs::path path = dir / "scene.json";
  if (!fs::exists(path)) throw InputError(dir.string(), "scene.json", "missing: not an output folder of surge sim");
  return loadScene(path, options.overrides);
}

void say(const CommonOptions& options, const std::string& line) {
  if (!options.quiet) std::printf("%s\n", line.c_str());
}

}  // namespace surge

int main(int argc, char** argv) {
  using namespace surge;
  CLI::App app{"surge: particle fluids from a scene file to a video (PBF simulation, OpenVDB surfaces, Embree "
               "rendering, ffmpeg video)"};
  app.require_subcommand(1);
  addRunCommand(app);
  addSimCommand(app);
  addWhitewaterCommand(app);
  addSurfaceCommand(app);
  addRenderCommand(app);
  addVideoCommand(app);
  addKeysCommand(app);
  addStudyCommand(app);
  addExportCommand(app);
  addReportCommand(app);
  installInterruptHandler();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "surge: %s (see surge --help)\n", e.what());
    return kExitBadInput;
  } catch (const Error& e) {
    // On a terminal a progress bar may hold the line: start a new one.
    std::fprintf(stderr, "%ssurge: %s\n", isatty(STDERR_FILENO) ? "\n" : "", e.what());
    return e.exitStatus();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%ssurge: %s\n", isatty(STDERR_FILENO) ? "\n" : "", e.what());
    return kExitFailure;
  }
  return kExitOk;
}
