#include "render/renderer.h"

#include <algorithm>
#include <string>

#include "core/errors.h"
#include "core/parallel.h"
#include "render/camera.h"
#include "render/random.h"
#include "render/shading.h"
#include "render/tracer.h"

namespace surge {

namespace {

constexpr int kTileSize = 32;

Image renderWith(const RayDevice& device, const TriangleMesh& water, const Scene& scene, int frame) {
  const RenderSettings& settings = scene.render;
  if (settings.width <= 0 || settings.height <= 0)
    throw InputError(scene.name, "render.width", "the image must be at least 1x1 pixels");
  const int width = settings.width, height = settings.height;
  const int samples = std::max(settings.samples, 1);

  const RayScene world(device, water, scene);
  const PinholeCamera camera(settings.camera, width, height);
  const Shading shading = Shading::fromScene(scene);

  Image image;
  image.width = width;
  image.height = height;
  image.rgb.assign(size_t(width) * size_t(height) * 3, 0);

  // Tiles of 32x32 pixels, one task each; a pixel is written only by its tile, so the bytes do not depend on
  // which thread rendered which tile.
  const int tilesX = (width + kTileSize - 1) / kTileSize, tilesY = (height + kTileSize - 1) / kTileSize;
  const auto renderTile = [&](int tile) {
    const int x0 = (tile % tilesX) * kTileSize, y0 = (tile / tilesX) * kTileSize;
    const int x1 = std::min(x0 + kTileSize, width), y1 = std::min(y0 + kTileSize, height);
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const auto pixel = static_cast<uint32_t>(y * width + x);
        Eigen::Vector3f sum = Eigen::Vector3f::Zero();
        for (int s = 0; s < samples; ++s) {
          SampleRandom random(static_cast<uint32_t>(frame), pixel, static_cast<uint32_t>(s));
          const float jitterX = random.next(), jitterY = random.next();
          sum += traceRadiance(world, shading, camera.rayThrough(x + jitterX, y + jitterY), random);
        }
        const Eigen::Vector3f colour = sum / float(samples);
        for (int k = 0; k < 3; ++k) image.rgb[3 * size_t(pixel) + k] = encodeSrgb(colour[k]);
      }
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
  return image;
}

}  // namespace

Image renderMesh(const TriangleMesh& water, const Scene& scene, int frame) {
  const RayDevice device;
  return renderWith(device, water, scene, frame);
}

void renderFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress) {
  const std::vector<int> all = listFrames(dir, "surface", "ply");
  if (all.empty())
    throw InputError(dir.string(), "no surface/frame_NNNNN.ply meshes to render; run surge surface first");
  std::vector<int> frames;
  std::copy_if(all.begin(), all.end(), std::back_inserter(frames), [&](int f) { return range.contains(f); });
  if (frames.empty())
    throw InputError(dir.string(), "--frames",
                     "no surface frame in the range (there are frames " + std::to_string(all.front()) +
                         " to " + std::to_string(all.back()) + ")");

  const RayDevice device;
  progress.start("render", frames.size());
  for (int frame : frames) {
    Progress::checkInterrupt();
    const TriangleMesh water = readMeshPly(framePath(dir, "surface", frame, "ply"));
    const Image image = renderWith(device, water, scene, frame);
    writePng(framePath(dir, "frames", frame, "png"), image);
    progress.advance();
  }
  progress.finish();
}

}  // namespace surge
