#include "render/renderer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <future>
#include <string>

#include "core/errors.h"
#include "core/parallel.h"
#include "render/camera.h"
#include "render/denoiser.h"
#include "render/random.h"
#include "render/rasterizer.h"
#include "render/shading.h"
#include "render/tracer.h"

namespace surge {

namespace {

constexpr int kTileSize = 32;

// A pixel's samples summed (and what its guide chains saw).
struct PixelSums {
  Eigen::Vector3f colour = Eigen::Vector3f::Zero(), kept = Eigen::Vector3f::Zero(),
                  albedo = Eigen::Vector3f::Zero(), normal = Eigen::Vector3f::Zero();
  float depth = 0, luminanceSquare = 0;
  int taken = 0;
  bool mixed = false;  // its samples met different surfaces
  SampleFeatures first;
};

}  // namespace

// What traceImage keeps from frame to frame: a 960x540 frame's buffers are about 100 MB, and on these machines
// fresh pages cost more in page faults than the denoiser's arithmetic.
struct RenderWorkspace {
  std::vector<PixelSums> sums;
  std::vector<uint8_t> edge;
  std::vector<PixelFeatures> features;
  Denoiser denoiser;
};

namespace {

// True if two samples met different surfaces: the sky and something, normals more than 18 degrees apart, a
// point off the other's tangent plane by more than 1% of its distance, or albedos more than 0.05 apart. (The
// distances alone would not do: on the ground far off, neighbouring pixels' distances differ by several %.)
bool differentSurfaces(const SampleFeatures& a, const SampleFeatures& b) {
  if ((a.depth == 0) != (b.depth == 0)) return true;
  if (a.depth == 0) return false;
  return a.normal.dot(b.normal) < 0.95f || std::abs(a.normal.dot(b.point - a.point)) > 0.01f * a.depth ||
         (a.albedo - b.albedo).cwiseAbs().maxCoeff() > 0.05f;
}

Image traceImage(RenderWorkspace& workspace, const RayDevice& device, const TriangleMesh& water,
                 const std::vector<ColliderMesh>& colliders, const Scene& scene, int frame,
                 const Shading& shading, RenderStats* stats, const WhitewaterSpheres* whitewater = nullptr) {
  const RenderSettings settings = resolvedRenderSettings(scene);
  if (settings.width <= 0 || settings.height <= 0)
    throw InputError(scene.name, "render.width", "the image must be at least 1x1 pixels");
  const int width = settings.width, height = settings.height;
  const int samples = std::max(settings.samples, 1);
  Shading look = shading;
  look.maxDepth = settings.max_depth;

  const RayScene world(device, water, scene, colliders, whitewater);
  const PinholeCamera camera(settings.camera, width, height);

  Image image;
  image.width = width;
  image.height = height;
  image.rgb.assign(size_t(width) * size_t(height) * 3, 0);

  // Tiles of 32x32 pixels, one task each; a pixel is written only by its tile, so the bytes do not depend on
  // which thread rendered which tile.
  // Guided (denoiser or edge samples on), each sample also brings what the tracer's guide chain saw
  // (SampleFeatures, drawing no random numbers), summed per pixel. With edge samples, a second round gives a
  // pixel edge_samples in all where it straddles surfaces (anti-aliasing the filter cannot do): where its own
  // samples met different surfaces, or its first sample met another surface than a neighbour's first did.
  // Every pixel's samples are then drawn as the first of edge_samples stratified ones. The second round reads
  // only the first round's results, so the bytes stay independent of the threads.
  const bool denoising = settings.denoise != 0;
  const int most = std::max(samples, settings.edge_samples);
  const bool guided = denoising || most > samples;
  std::vector<PixelSums>& sums = workspace.sums;
  sums.assign(size_t(width) * size_t(height), PixelSums{});
  std::atomic<uint64_t> rays{0};
  uint64_t edgePixels = 0;
  const int tilesX = (width + kTileSize - 1) / kTileSize, tilesY = (height + kTileSize - 1) / kTileSize;
  const auto sample = [&](int x, int y, int s, PixelSums& pixelSums, PathStats& tileStats) {
    const auto pixel = static_cast<uint32_t>(y * width + x);
    SampleRandom random(static_cast<uint32_t>(frame), pixel, static_cast<uint32_t>(s), static_cast<uint32_t>(most));
    float jitterX = 0, jitterY = 0;
    random.next2(jitterX, jitterY);
    SampleFeatures seen;
    const Eigen::Vector3f light = traceRadiance(world, look, camera.rayThrough(x + jitterX, y + jitterY), random,
                                                &tileStats, guided ? &seen : nullptr);
    pixelSums.colour += light;
    ++pixelSums.taken;
    if (!guided) return;
    if (s == 0) pixelSums.first = seen;
    pixelSums.mixed = pixelSums.mixed || differentSurfaces(pixelSums.first, seen);
    const float l = luminance(light - seen.reflection);
    pixelSums.luminanceSquare += l * l;
    pixelSums.kept += seen.reflection;
    pixelSums.albedo += seen.albedo;
    pixelSums.normal += seen.normal;
    pixelSums.depth += seen.depth;
  };
  const auto forTiles = [&](const auto& perPixel) {
    parallelFor(
        0, size_t(tilesX) * size_t(tilesY),
        [&](size_t begin, size_t end) {
          for (size_t tile = begin; tile < end; ++tile) {
            if (Progress::wasInterrupted()) return;  // leave the remaining tiles; checked below
            const int x0 = int(tile % tilesX) * kTileSize, y0 = int(tile / tilesX) * kTileSize;
            const int x1 = std::min(x0 + kTileSize, width), y1 = std::min(y0 + kTileSize, height);
            PathStats tileStats;
            for (int y = y0; y < y1; ++y)
              for (int x = x0; x < x1; ++x) perPixel(x, y, sums[size_t(y) * width + x], tileStats);
            rays.fetch_add(tileStats.rays, std::memory_order_relaxed);
          }
        },
        1);
    Progress::checkInterrupt();
  };
  forTiles([&](int x, int y, PixelSums& pixelSums, PathStats& stats) {
    for (int s = 0; s < samples; ++s) sample(x, y, s, pixelSums, stats);
  });
  if (most > samples) {
    std::vector<uint8_t>& edge = workspace.edge;
    edge.assign(sums.size(), 0);
    parallelFor(0, size_t(height), [&](size_t y0, size_t y1) {
      for (size_t y = y0; y < y1; ++y)
        for (int x = 0; x < width; ++x) {
          const PixelSums& p = sums[y * width + x];
          bool straddles = p.mixed;
          const int offsets[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
          for (const auto& o : offsets) {
            const int qx = x + o[0], qy = int(y) + o[1];
            if (qx >= 0 && qy >= 0 && qx < width && qy < height)
              straddles = straddles || differentSurfaces(p.first, sums[size_t(qy) * width + qx].first);
          }
          edge[y * width + x] = straddles;
        }
    });
    forTiles([&](int x, int y, PixelSums& pixelSums, PathStats& stats) {
      if (!edge[size_t(y) * width + x]) return;
      for (int s = samples; s < most; ++s) sample(x, y, s, pixelSums, stats);
    });
    edgePixels = uint64_t(std::count(edge.begin(), edge.end(), uint8_t(1)));
  }
  // Each pixel's mean, filtered when denoising, tone-mapped.
  const auto toImage = [&](const auto& colourOf) {
    for (size_t pixel = 0; pixel < sums.size(); ++pixel) {
      const Eigen::Vector3f colour = colourOf(pixel);
      for (int k = 0; k < 3; ++k) image.rgb[3 * pixel + k] = encodeSrgb(toneMap(colour[k], look.exposure));
    }
  };
  if (!denoising) {
    toImage([&](size_t pixel) { return Eigen::Vector3f(sums[pixel].colour / float(sums[pixel].taken)); });
  } else {
    std::vector<PixelFeatures>& features = workspace.features;
    features.resize(sums.size());
    for (size_t pixel = 0; pixel < sums.size(); ++pixel) {
      const PixelSums& p = sums[pixel];
      const float n = float(p.taken);
      PixelFeatures& mean = features[pixel];
      mean.kept = p.kept / n;
      mean.colour = p.colour / n - mean.kept;
      mean.albedo = p.albedo / n;
      mean.normal = p.normal / n;
      mean.depth = p.depth / n;
      mean.luminanceSquare = p.luminanceSquare / n;
      mean.samples = p.taken;
    }
    const std::vector<Eigen::Vector3f>& filtered = workspace.denoiser.filter(features, width, height);
    toImage([&](size_t pixel) { return filtered[pixel]; });
  }
  if (stats) {
    stats->rays += rays.load();
    stats->edgePixels += edgePixels;
  }
  return image;
}

// A scene of several fluids: the meshes of the fluids after the first (surface_<name>/), each with its colour's
// absorption; none in a scene of one.
std::vector<FluidMesh> otherFluidMeshes(const fs::path& dir, const Scene& scene, int frame) {
  std::vector<FluidMesh> others;
  for (size_t b : scene.laterFluids()) {
    FluidMesh other;
    other.mesh = readMeshPly(fluidMeshPath(framePath(dir, "surface", frame, "ply"), scene.fluids[b].name));
    other.absorption = Shading::absorptionOf(scene.fluidColor(b), scene.fluidAbsorptionDistance(b));
    others.push_back(std::move(other));
  }
  return others;
}

// The path tracer's liquids: the first fluid's mesh with the others' appended, each triangle marked with its
// fluid (TriangleMesh::fluid, the index into Shading::fluidAbsorption).
TriangleMesh allFluids(TriangleMesh water, const std::vector<FluidMesh>& others) {
  if (!others.empty()) water.fluid.assign(water.triangles.size(), 0);
  for (size_t k = 0; k < others.size(); ++k) {
    const FluidMesh& other = others[k];
    const uint32_t base = uint32_t(water.positions.size());
    const bool normals = water.normals.size() == base && other.mesh.normals.size() == other.mesh.positions.size();
    water.positions.insert(water.positions.end(), other.mesh.positions.begin(), other.mesh.positions.end());
    if (normals) water.normals.insert(water.normals.end(), other.mesh.normals.begin(), other.mesh.normals.end());
    else water.normals.clear();
    water.velocities.clear();
    for (const auto& t : other.mesh.triangles) water.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    water.fluid.resize(water.triangles.size(), uint8_t(std::min<size_t>(k + 1, 255)));
  }
  return water;
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

RenderSettings resolvedRenderSettings(const Scene& scene) {
  RenderSettings r = resolvedRenderSettings(scene.render);
  r.camera = framedCamera(scene);
  return r;
}

struct PathTracer::Impl {
  RayDevice device;
  RenderWorkspace workspace;
};

PathTracer::PathTracer() : impl_(std::make_unique<Impl>()) {}
PathTracer::~PathTracer() = default;

Image PathTracer::render(const TriangleMesh& water, const std::vector<ColliderMesh>& colliders, const Scene& scene,
                         int frame, RenderStats* stats, const WhitewaterSpheres* whitewater) {
  return traceImage(impl_->workspace, impl_->device, water, colliders, scene, frame, Shading::fromScene(scene),
                    stats, whitewater);
}

Image renderMesh(const TriangleMesh& water, const Scene& scene, int frame, RenderStats* stats) {
  return renderMeshWith(water, scene, frame, Shading::fromScene(scene), stats);
}

Image renderMesh(const TriangleMesh& water, const std::vector<ColliderMesh>& colliders, const Scene& scene,
                 int frame, RenderStats* stats) {
  return PathTracer().render(water, colliders, scene, frame, stats);
}

Image renderMeshWith(const TriangleMesh& water, const Scene& scene, int frame, const Shading& shading,
                     RenderStats* stats) {
  RenderWorkspace workspace;
  const RayDevice device;
  return traceImage(workspace, device, water, {}, scene, frame, shading, stats);
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
      for (size_t b : particles ? std::vector<size_t>() : scene.laterFluids())
        inputs.push_back(fluidMeshPath(framePath(dir, "surface", f, "ply"), scene.fluids[b].name));
      inputs.push_back(settings);
      if (std::error_code error; fs::exists(framePath(dir, "whitewater", f, "ply"), error))
        inputs.push_back(framePath(dir, "whitewater", f, "ply"));
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
              : rasterizer.drawMesh(readMeshPly(framePath(dir, "surface", frame, "ply")), solids,
                                    whitewaterSpheresAt(dir, frame, scene), otherFluidMeshes(dir, scene, frame));
      writePng(framePath(dir, "frames", frame, "png"), image);
      progress.advance();
    }
  } else {
    PathTracer tracer;
    // Each frame's PNG is encoded and written (stb's filters take about 0.07 s a 960x540 frame, on one core)
    // while the next frame renders. A write's error surfaces when it is waited for; on any error the write
    // under way is finished first (writes are atomic: a frame is whole or absent).
    std::future<void> writing;
    const auto finishWriting = [&] {
      if (!writing.valid()) return;
      writing.get();
      progress.advance();
    };
    try {
      for (int frame : frames) {
        Progress::checkInterrupt();
        const TriangleMesh water =
            allFluids(readMeshPly(framePath(dir, "surface", frame, "ply")), otherFluidMeshes(dir, scene, frame));
        const WhitewaterSpheres whitewater = whitewaterSpheresAt(dir, frame, scene);
        Image image = tracer.render(water, colliders.atFrame(frame), scene, frame, nullptr, &whitewater);
        finishWriting();
        writing = std::async(std::launch::async, [path = framePath(dir, "frames", frame, "png"),
                                                  image = std::move(image)] { writePng(path, image); });
      }
      finishWriting();
    } catch (...) {
      if (writing.valid()) writing.wait();
      throw;
    }
  }
  progress.finish();
}

}  // namespace surge
