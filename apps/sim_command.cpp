// surge sim SCENE: simulate a scene into particle frames and stats.csv.
#include <chrono>
#include <cmath>
#include <cstdio>

#include "apps/commands.h"
#include "core/errors.h"
#include "core/parallel.h"
#include "sim/rigid_bodies.h"
#include "sim/fluid_solver.h"
#include "sim/simulation.h"
#include "sim/solver_defaults.h"

namespace surge {

void writeSimStatus(const fs::path& dir, const std::string& status) {
  writeFileAtomically(dir / "sim_status.txt", [&](std::ostream& out) { out << status << "\n"; });
}

// On the way out of a failed run: the status is told if the disk allows, and the run's own error is the one
// reported (a full disk fails this write too).
void writeSimStatusIfPossible(const fs::path& dir, const std::string& status) {
  try {
    writeSimStatus(dir, status);
  } catch (const std::exception&) {
  }
}

std::string readSimStatus(const fs::path& dir) {
  std::error_code error;
  if (!fs::exists(dir / "sim_status.txt", error)) return "";
  std::string text = readTextFile(dir / "sim_status.txt");
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

void runSimStage(const Scene& scene, const fs::path& dir, bool resume, const CommonOptions& options) {
  checkSimulationMemory(scene);
  // The colliders' and bodies' files are read (and refused if bad), and bodies overlapping at the start are
  // refused, before anything is written.
  const std::shared_ptr<const ColliderShapes> shapes = buildColliderShapes(scene);
  for (const ColliderShape& shape : *shapes)
    if (!shape.note.empty()) say(options, "sim: " + shape.note);
  checkSimulationStart(scene, shapes);
  if (!scene.bodies.empty()) {
    const RigidBodies check(scene, shapes);
    // The coupling is explicit (docs/bodies.md): one particle's push in one step can throw a body lighter than it.
    const double particleMass = scene.solver.rest_density * std::pow(scene.particle_spacing, scene.dimensions);
    for (size_t b = 0; b < check.size(); ++b) {
      const double mass = check.massProperties(b).mass;
      if (!(mass < particleMass)) continue;
      const char* unit = scene.dimensions == 2 ? " kg/m" : " kg";
      char line[320];
      std::snprintf(line, sizeof line,
                    "sim: note: body %s (%.3g%s) is lighter than one fluid particle (%.3g%s): the water may throw "
                    "it; a finer particle_spacing or a heavier body holds it (docs/bodies.md)",
                    scene.bodies[b].solid.name.c_str(), mass, unit, particleMass, unit);
      say(options, line);
    }
  }
  for (const std::string& note : solverNotes(scene)) say(options, "sim: note: " + note);
  std::error_code error;
  // The particle frames still to write (28 bytes a particle and a header) must fit the disk: a run that would
  // fill it is refused now, not hours later. A resumed run writes the frames after its last one.
  const std::vector<int> written = resume ? listFrames(dir, "particles", "ply") : std::vector<int>{};
  const int framesLeft =
      written.empty() ? scene.output.frames + 1 : std::max(0, scene.output.frames - written.back());
  double freed = 0;  // a new run first removes an earlier run's frames from the folder
  for (const char* sub : {"particles", "surface", "frames"}) {
    if (resume) break;
    for (const auto& entry : fs::recursive_directory_iterator(dir / sub, error))
      if (entry.is_regular_file(error)) freed += double(entry.file_size(error));
  }
  checkFreeSpace(dir, "--out", double(framesLeft) * (28.0 * double(mostParticles(scene)) + 512.0) - freed,
                 std::to_string(framesLeft) + " particle frames");
  prepareSimulationFolder(scene, dir, resume);
  TerminalProgress progress(!options.quiet);
  writeSimStatus(dir, "running");
  SimulationSummary summary;
  try {
    summary = simulate(scene, shapes, dir, resume, progress);
  } catch (const Interrupted&) {
    writeSimStatusIfPossible(dir, "stopped");
    throw;
  } catch (const std::exception& e) {
    writeSimStatusIfPossible(dir, std::string("failed: ") + e.what());
    throw;
  }
  writeSimStatus(dir, "finished");
  if (summary.removedParticles > 0)
    say(options, "sim: removed " + std::to_string(summary.removedParticles) +
                     " fluid particles placed inside " + (scene.bodies.empty() ? "colliders" : "colliders and bodies"));
  // A density solver that stopped at its cap left the density error above solver.max_density_error there.
  const char* capKey = fluidMethod(scene.solver.method, scene.source).iterationCapKey;
  if (summary.cappedSteps > 0 && capKey)
    say(options, "sim: the density solver " + densityCapReport(summary) +
                     ", short of solver.max_density_error there (stats.csv's density_error_avg); more solver.substeps "
                     "or " + capKey + " let it converge");
  char line[256];
  std::snprintf(line, sizeof line, "sim: %zu particles, frames %d-%d in %.1f s -> %s/particles",
                summary.particles, summary.firstFrame, summary.lastFrame, summary.wallSeconds,
                dir.string().c_str());
  say(options, line);
}

void addSimCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string scene;
    bool resume = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command =
      app.add_subcommand("sim", "simulate a scene into particles/frame_NNNNN.ply and stats.csv");
  command->add_option("scene", options->scene, "scene file (JSON)")->required();
  command->add_flag("--resume", options->resume,
                    "continue from the last complete frame in the output folder");
  addCommonOptions(*command, options->common, true);
  command->callback([options] {
    const Scene scene = loadScene(options->scene, options->common.overrides);
    ThreadLimit threads(options->common.threads);
    runSimStage(scene, outputFolder(options->common, scene), options->resume, options->common);
  });
}

}  // namespace surge
