// surge export DIR --format vtk|usd: a run folder's frames for the tools people already use. export_command.cpp
// surveys the folder (and refuses it before anything is written), export_vtk.cpp writes ParaView's VTK XML
// PolyData and .pvd time series, export_usd.cpp one USD stage; docs/exchange-formats.md describes both.
#pragma once

#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/progress.h"
#include "core/scene.h"

namespace surge {

// The frame files of one kind in a run folder: particles/ and whitewater/ (points), surface/ and, in a scene of
// several fluids, surface_<name>/ (meshes).
struct FrameSeries {
  std::string kind;  // its folder's name: "particles", "whitewater", "surface", "surface_oil"
  bool mesh = false;
  std::vector<int> frames;  // present and within the range
};

// What a run folder holds for an export, read and checked before anything is written.
struct ExportRun {
  fs::path dir;
  Scene scene;
  std::vector<int> frames;          // the particle frames in the range: the time steps of every kind
  std::vector<FrameSeries> series;  // particles first, then whitewater, surface, surface_<name>
  std::vector<SolidFiles> solids;   // the scene's colliders, then its bodies

  double time(int frame) const { return frame / scene.output.fps; }
  // A solid's world mesh at a frame: a moving one's frame file where present, else its <name>.ply (frame 0).
  fs::path solidMesh(const SolidFiles& solid, int frame) const;
};

// The survey. Throws InputError naming the folder and what is missing (no scene.json, no particle frames in
// the range, a solid's mesh, bodies.csv where the scene has bodies).
ExportRun surveyRun(const fs::path& dir, const FrameRange& range, const CommonOptions& options);

// Each writes under run.dir/export, every file to a temporary name and renamed, the series files last, and
// returns the paths it wrote.
std::vector<fs::path> exportVtk(const ExportRun& run, Progress& progress);
std::vector<fs::path> exportUsd(const ExportRun& run, Progress& progress);

}  // namespace surge
