#include "render/renderer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/parallel.h"
#include "render/camera.h"
#include "render/random.h"
#include "render/rasterizer.h"
#include "render/shading.h"
#include "render/tracer.h"

namespace surge {

namespace {

constexpr int kTileSize = 32;

Image traceImage(const RayDevice& device, const TriangleMesh& water,
                 const std::vector<ColliderMesh>& colliders, const Scene& scene, int frame,
                 const Shading& shading, RenderStats* stats) {
  const RenderSettings settings = resolvedRenderSettings(scene.render);
  if (settings.width <= 0 || settings.height <= 0)
    throw InputError(scene.name, "render.width", "the image must be at least 1x1 pixels");
  const int width = settings.width, height = settings.height;
  const int samples = std::max(settings.samples, 1);
  Shading look = shading;
  look.maxDepth = settings.max_depth;

  const RayScene world(device, water, scene, colliders);
  const PinholeCamera camera(settings.camera, width, height);

  Image image;
  image.width = width;
  image.height = height;
  image.rgb.assign(size_t(width) * size_t(height) * 3, 0);

  // Tiles of 32x32 pixels, one task each; a pixel is written only by its tile, so the bytes do not depend on
  // which thread rendered which tile.
  std::atomic<uint64_t> rays{0};
  const int tilesX = (width + kTileSize - 1) / kTileSize, tilesY = (height + kTileSize - 1) / kTileSize;
  const auto renderTile = [&](int tile) {
    const int x0 = (tile % tilesX) * kTileSize, y0 = (tile / tilesX) * kTileSize;
    const int x1 = std::min(x0 + kTileSize, width), y1 = std::min(y0 + kTileSize, height);
    PathStats tileStats;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const auto pixel = static_cast<uint32_t>(y * width + x);
        Eigen::Vector3f sum = Eigen::Vector3f::Zero();
        for (int s = 0; s < samples; ++s) {
          SampleRandom random(static_cast<uint32_t>(frame), pixel, static_cast<uint32_t>(s),
                              static_cast<uint32_t>(samples));
          float jitterX = 0, jitterY = 0;
          random.next2(jitterX, jitterY);
          sum += traceRadiance(world, look, camera.rayThrough(x + jitterX, y + jitterY), random, &tileStats);
        }
        const Eigen::Vector3f colour = sum / float(samples);
        for (int k = 0; k < 3; ++k)
          image.rgb[3 * size_t(pixel) + k] = encodeSrgb(toneMap(colour[k], look.exposure));
      }
    rays.fetch_add(tileStats.rays, std::memory_order_relaxed);
  };
  parallelFor(
      0, size_t(tilesX) * size_t(tilesY),
      [&](size_t begin, size_t end) {
        for (size_t tile = begin; tile < end; ++tile) {
          if (Progress::wasInterrupted()) return;  // leave the remaining tiles; checked below
          renderTile(static_cast<int>(tile));
        }
      },
      1);
  Progress::checkInterrupt();
  if (stats) stats->rays += rays.load();
  return image;
}

}  // namespace

RenderSettings resolvedRenderSettings(const RenderSettings& settings) {
  RenderSettings r = settings;
  if (settings.quality == "preview") {
    r.width = std::max(16, settings.width / 2);
    r.height = std::max(16, settings.height / 2);
    r.samples = std::min(settings.samples, 4);
    r.max_depth = std::min(settings.max_depth, 4);
  } else if (settings.quality == "final") {
    const double scale = std::max(1.0, 720.0 / settings.height);
    r.width = int(std::lround(settings.width * scale));
    r.height = int(std::lround(settings.height * scale));
    r.samples = std::max(settings.samples, 64);
    r.max_depth = std::max(settings.max_depth, 12);
  } else if (settings.quality != "standard") {
    throw InputError("render.quality",
                     "unknown preset '" + settings.quality + "' (standard, preview, final)");
  }
  return r;
}

Image renderMesh(const TriangleMesh& water, const Scene& scene, int frame, RenderStats* stats) {
  return renderMeshWith(water, scene, frame, Shading::fromScene(scene), stats);
}

Image renderMesh(const TriangleMesh& water, const std::vector<ColliderMesh>& colliders, const Scene& scene,
                 int frame, RenderStats* stats) {
  const RayDevice device;
  return traceImage(device, water, colliders, scene, frame, Shading::fromScene(scene), stats);
}

Image renderMeshWith(const TriangleMesh& water, const Scene& scene, int frame, const Shading& shading,
                     RenderStats* stats) {
  const RayDevice device;
  return traceImage(device, water, {}, scene, frame, shading, stats);
}

void renderFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress,
                  const RenderOptions& options) {
  // No renderer named: the path tracer for 3D scenes, the clean 2D view of the rasteriser for 2D ones.
  const std::string renderer = options.renderer.empty() ? (scene.dimensions == 2 ? "gl" : "embree") : options.renderer;
  if (renderer != "embree" && renderer != "gl")
    throw InputError(dir.string(), "--renderer", "unknown renderer '" + renderer + "' (embree, gl)");
  const bool gl = renderer == "gl";
  std::vector<int> all = listFrames(dir, "surface", "ply");
  const bool particles = gl && (options.particles || all.empty());
  if (particles) all = listFrames(dir, "particles", "ply");
  if (all.empty())
    throw InputError(dir.string(),
                     gl ? "no surface/ or particles/frame_NNNNN.ply to render; run surge sim first"
                        : "no surface/frame_NNNNN.ply meshes to render; run surge surface first");
  std::vector<int> frames;
  std::copy_if(all.begin(), all.end(), std::back_inserter(frames), [&](int f) { return range.contains(f); });
  if (frames.empty())
    throw InputError(dir.string(), "--frames",
                     "no " + std::string(particles ? "particle" : "surface") +
                         " frame in the range (there are frames " + std::to_string(all.front()) + " to " +
                         std::to_string(all.back()) + ")");
  // The standing colliders are read here once, a moving one's mesh with each frame.
  ColliderMeshes colliders(dir, scene);
  removeTemporaries(dir, "frames", "png", range);
  // Written before any frame, so that every frame made with these settings is newer than it.
  const fs::path settings = writeStageSettings(
      dir, "render", scene,
      std::string("{\"renderer\": \"") + renderer + "\", \"particles\": " + (particles ? "true" : "false") + "}");
  if (options.resume) {
    // A moving collider's frame file is an input of the image too; its <name>.ply is not, as the simulation
    // writes it again when it resumes.
    const auto done = [&](int f) {
      std::vector<fs::path> inputs = colliders.frameFiles(f);
      inputs.push_back(framePath(dir, particles ? "particles" : "surface", f, "ply"));
      inputs.push_back(settings);
      return isUpToDate({framePath(dir, "frames", f, "png")}, inputs);
    };
    frames.erase(std::remove_if(frames.begin(), frames.end(), done), frames.end());
  }

  progress.start("render", frames.size());
  if (gl) {
    Rasterizer rasterizer(scene);
    for (int frame : frames) {
      Progress::checkInterrupt();
      const std::vector<ColliderMesh>& solids = colliders.atFrame(frame);
      const Image image =
          particles
              ? rasterizer.drawParticles(readParticlePly(framePath(dir, "particles", frame, "ply")), solids)
              : rasterizer.drawMesh(readMeshPly(framePath(dir, "surface", frame, "ply")), solids);
      writePng(framePath(dir, "frames", frame, "png"), image);
      progress.advance();
    }
  } else {
    const RayDevice device;
    const Shading shading = Shading::fromScene(scene);
    for (int frame : frames) {
      Progress::checkInterrupt();
      const TriangleMesh water = readMeshPly(framePath(dir, "surface", frame, "ply"));
      const Image image = traceImage(device, water, colliders.atFrame(frame), scene, frame, shading, nullptr);
      writePng(framePath(dir, "frames", frame, "png"), image);
      progress.advance();
    }
  }
  progress.finish();
}

}  // namespace surge
