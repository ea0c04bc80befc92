// The render stage: ray-traces a water mesh in its tank (Embree 3) into an sRGB image, and turns a run's
// surface/frame_NNNNN.ply meshes into frames/frame_NNNNN.png. Embree stays behind this header.
#pragma once

#include "core/files.h"
#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"
#include "render/image.h"  // Image, writePng, readPng

namespace surge {

// Renders the water mesh with the scene's tank, ground, sky and camera at scene.render.width x height and
// scene.render.samples jittered samples a pixel. `frame` seeds the per-pixel random numbers, which depend
// only on (frame, pixel, sample): the image is the same bytes whatever the thread count. An empty mesh
// renders the empty tank. Stops early with surge::Interrupted if the user asks to stop.
Image renderMesh(const TriangleMesh& water, const Scene& scene, int frame);

// For every dir/surface/frame_NNNNN.ply whose frame is in `range`, writes dir/frames/frame_NNNNN.png.
// Progress: start("render", frames), advance() per frame. Throws InputError(dir, ...) if there are no surface
// frames (or none in range), Interrupted between frames and tiles when asked to stop.
void renderFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress);

}  // namespace surge
