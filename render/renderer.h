// The render stage: path-traces a water mesh and the colliders in their tank (Embree 3, render/shading.h)
// into an sRGB image, or rasterises them (or the particles) with OSMesa for a quick look
// (render/rasterizer.h), and turns a run's surface/frame_NNNNN.ply meshes into frames/frame_NNNNN.png. Embree
// and GL stay behind these headers.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/files.h"
#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"
#include "render/colliders.h"
#include "render/image.h"  // Image, writePng, readPng
#include "render/whitewater_spheres.h"

namespace surge {

struct Shading;

// The settings a `quality` preset stands for: "standard" keeps width, height, samples and max_depth;
// "preview" halves the resolution (at least 16 pixels) and uses 4 samples and depth 4; "final" scales the
// resolution up to at least 720 pixels high (1280x720 for the default 16:9) with at least 64 samples and
// depth 12. The camera is the settings' either way.
RenderSettings resolvedRenderSettings(const RenderSettings& settings);
// The scene's render settings so resolved, with the camera that frames the domain where the scene sets none
// (framedCamera, render/camera.h: its framing depends only on the aspect ratio, which the presets keep).
RenderSettings resolvedRenderSettings(const Scene& scene);

// What a render cost, for the benchmark.
struct RenderStats {
  uint64_t rays = 0;        // path segments and shadow rays cast
  uint64_t edgePixels = 0;  // pixels that took edge_samples
};

// Path-traces frame after frame with one Embree device, keeping its buffers from frame to frame (renderFrames
// uses one for a stage; renderMesh below makes one for a single image).
class PathTracer {
 public:
  PathTracer();
  ~PathTracer();
  PathTracer(const PathTracer&) = delete;
  PathTracer& operator=(const PathTracer&) = delete;

  // As renderMesh with the colliders, below.
  // `whitewater`: the frame's spray, foam and bubbles, if any (whitewater_spheres.h).
  Image render(const TriangleMesh& water, const std::vector<ColliderMesh>& colliders, const Scene& scene, int frame,
               RenderStats* stats = nullptr, const WhitewaterSpheres* whitewater = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Path-traces the water mesh with the scene's tank, ground, sky and camera at the resolved resolution and
// samples (resolvedRenderSettings). `frame` seeds the per-pixel random numbers, which depend only on (frame,
// pixel, sample): the image is the same bytes whatever the thread count. An empty mesh renders the empty
// tank. Stops early with surge::Interrupted if the user asks to stop; InputError for a bad mesh or settings.
Image renderMesh(const TriangleMesh& water, const Scene& scene, int frame, RenderStats* stats = nullptr);
// The same with the colliders (render/colliders.h) in the picture.
Image renderMesh(const TriangleMesh& water, const std::vector<ColliderMesh>& colliders, const Scene& scene,
                 int frame, RenderStats* stats = nullptr);
// The same with the look given explicitly instead of Shading::fromScene(scene) (tests use a white furnace).
Image renderMeshWith(const TriangleMesh& water, const Scene& scene, int frame, const Shading& shading,
                     RenderStats* stats = nullptr);

struct RenderOptions {
  std::string renderer;  // "embree" (path tracer), "gl" (OSMesa rasteriser), or empty: embree in 3D, gl in 2D
  bool particles = false;           // gl: draw particles/frame_NNNNN.ply as spheres instead of the surface
  // Leave a frame whose PNG is up to date: isUpToDate against its source, its moving colliders' frame files and
  // the render settings dir/render_settings.json (writeStageSettings), which the renderer's name is part of.
  bool resume = false;
};

// For every frame in `range` writes dir/frames/frame_NNNNN.png: from dir/surface/frame_NNNNN.ply, or with the
// gl renderer from dir/particles/frame_NNNNN.ply when options.particles is set or there are no surface frames
// at all, with the scene's visible colliders from dir/colliders/ (ColliderMeshes). Progress: start("render",
// frames), advance() per frame. Throws InputError(dir, ...) if there is nothing to render (or nothing in
// range) or the renderer is unknown, InputError naming the file if a collider's mesh is missing or bad,
// Interrupted when asked to stop.
void renderFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress,
                  const RenderOptions& options = {});

}  // namespace surge
