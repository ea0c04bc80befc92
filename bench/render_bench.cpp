// The renderer's benchmark: seconds per frame and rays per second at 1280x720 (the `final` preset of the
// default 16:9 scene) for a water mesh of about a million triangles, with the Embree path tracer and the
// OSMesa rasteriser. Prints a markdown table for docs/performance.md.
//
//   surge_render_bench [samples] [threads] [png prefix] [mesh.ply]
// Defaults: 64 samples, all threads, no PNGs, the generated wave mesh; a mesh given instead (for example a
// dam-break frame, surface/frame_00030.ply) is rendered in the same 1.6 x 0.9 x 0.6 m tank.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bench/bench_timing.h"
#include "core/parallel.h"
#include "render/rasterizer.h"
#include "render/renderer.h"

using surge::secondsSince;

namespace {

using surge::TriangleMesh;
using Vec3 = Eigen::Vector3f;

// The dam-break tank's water after the wave: a slab 0.25 m deep over the whole 1.6 x 0.6 m floor with a
// rolling surface, as a closed mesh. The top is a 1290 x 390 grid: 1,006,200 triangles, plus the walls.
TriangleMesh waveMesh() {
  const int nx = 1290, nz = 390;
  const float sizeX = 1.6f, sizeZ = 0.6f;
  const auto height = [](float x, float z) {
    return 0.25f + 0.03f * std::sin(9.0f * x + 2.0f * z) + 0.012f * std::sin(23.0f * z - 17.0f * x) +
           0.004f * std::sin(61.0f * x + 47.0f * z);
  };
  TriangleMesh mesh;
  for (int i = 0; i <= nx; ++i)
    for (int k = 0; k <= nz; ++k) {
      const float x = sizeX * i / nx, z = sizeZ * k / nz, e = 1e-3f;
      mesh.positions.emplace_back(x, height(x, z), z);
      const float dx = (height(x + e, z) - height(x - e, z)) / (2 * e),
                  dz = (height(x, z + e) - height(x, z - e)) / (2 * e);
      mesh.normals.push_back(Vec3(-dx, 1, -dz).normalized());
    }
  const auto top = [&](int i, int k) { return uint32_t(i * (nz + 1) + k); };
  for (int i = 0; i < nx; ++i)
    for (int k = 0; k < nz; ++k) {
      mesh.triangles.push_back({top(i, k), top(i, k + 1), top(i + 1, k)});
      mesh.triangles.push_back({top(i + 1, k), top(i, k + 1), top(i + 1, k + 1)});
    }
  // Walls: the top's rim joined to the same points on the floor, and the floor as a fan around its centre.
  std::vector<uint32_t> rim;
  for (int i = 0; i < nx; ++i) rim.push_back(top(i, 0));
  for (int k = 0; k < nz; ++k) rim.push_back(top(nx, k));
  for (int i = nx; i > 0; --i) rim.push_back(top(i, nz));
  for (int k = nz; k > 0; --k) rim.push_back(top(0, k));
  const auto base = uint32_t(mesh.positions.size());
  for (uint32_t v : rim) {
    mesh.positions.emplace_back(mesh.positions[v].x(), 0.0f, mesh.positions[v].z());
    mesh.normals.push_back(Vec3(0, -1, 0));
  }
  const auto centre = uint32_t(mesh.positions.size());
  mesh.positions.emplace_back(0.5f * sizeX, 0.0f, 0.5f * sizeZ);
  mesh.normals.push_back(Vec3(0, -1, 0));
  const auto n = uint32_t(rim.size());
  for (uint32_t j = 0; j < n; ++j) {
    const uint32_t a = rim[j], b = rim[(j + 1) % n], a0 = base + j, b0 = base + (j + 1) % n;
    mesh.triangles.push_back({a, b, a0});
    mesh.triangles.push_back({b, b0, a0});
    mesh.triangles.push_back({a0, b0, centre});
  }
  return mesh;
}

}  // namespace

int main(int argc, char** argv) {
  const int samples = argc > 1 ? std::atoi(argv[1]) : 64;
  const int threads = argc > 2 ? std::atoi(argv[2]) : 0;
  surge::ThreadLimit limit(threads);
  surge::Scene scene = surge::parseScene(R"({
    "name": "render_bench", "dimensions": 3,
    "domain": {"min": [0, 0, 0], "max": [1.6, 0.9, 0.6]},
    "particle_spacing": 0.02,
    "fluids": [{"box": {"min": [0, 0, 0], "max": [0.5, 0.6, 0.6]}}],
    "render": {"width": 1280, "height": 720}
  })",
                                         "bench");
  scene.render.samples = samples;
  scene.render.max_depth = 12;  // as the final preset
  const TriangleMesh mesh = argc > 4 ? surge::readMeshPly(argv[4]) : waveMesh();
  std::printf("| renderer | image | samples | triangles | threads | s / frame | Mrays / s |\n");
  std::printf("|---|---|---|---|---|---|---|\n");

  auto start = std::chrono::steady_clock::now();
  surge::Rasterizer rasterizer(scene);
  const surge::Image preview = rasterizer.drawMesh(mesh);
  const double glSeconds = secondsSince(start);
  std::printf("| gl (OSMesa) | %dx%d | - | %zu | %s | %.2f | - |\n", preview.width, preview.height,
              mesh.triangles.size(), threads ? std::to_string(threads).c_str() : "all", glSeconds);
  std::fflush(stdout);

  surge::RenderStats stats;
  start = std::chrono::steady_clock::now();
  const surge::Image traced = surge::renderMesh(mesh, scene, 0, &stats);
  const double seconds = secondsSince(start);
  std::printf("| embree path tracer | %dx%d | %d | %zu | %s | %.1f | %.2f |\n", traced.width, traced.height,
              samples, mesh.triangles.size(), threads ? std::to_string(threads).c_str() : "all", seconds,
              stats.rays / seconds * 1e-6);
  if (argc > 3) {
    surge::writePng(std::string(argv[3]) + "_gl.png", preview);
    surge::writePng(std::string(argv[3]) + "_embree.png", traced);
  }
  return 0;
}
