// Scenes and meshes shared by the render tests.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"
#include "render/image.h"
#include "render/shading.h"

namespace surge::testing {

// A unit tank with a small image; `renderExtra` is spliced into the "render" object.
// The red, green and blue bytes of pixel (x, y).
inline const uint8_t* pixelAt(const Image& image, int x, int y) {
  return &image.rgb[3 * (size_t(y) * image.width + x)];
}

inline Scene unitTankScene(const std::string& renderExtra = "") {
  const std::string json = R"({
    "name": "render_test", "dimensions": 3,
    "domain": {"min": [0, 0, 0], "max": [1, 1, 1]},
    "particle_spacing": 0.05,
    "fluids": [{"box": {"min": [0, 0, 0], "max": [0.5, 0.5, 0.5]}}],
    "render": {"width": 64, "height": 48)" +
                           (renderExtra.empty() ? "" : ", " + renderExtra) + R"(}
  })";
  return parseScene(json, "test");
}

// An axis-aligned box of 12 triangles, without vertex normals (flat shading).
inline TriangleMesh boxMesh(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  TriangleMesh mesh;
  for (int c = 0; c < 8; ++c)
    mesh.positions.emplace_back(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z());
  const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& f : faces) {
    mesh.triangles.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
    mesh.triangles.push_back({uint32_t(f[0]), uint32_t(f[2]), uint32_t(f[3])});
  }
  return mesh;
}

// An axis-aligned box whose faces have their own vertices, with the face normals as vertex normals: smooth
// shading must render it exactly like the flat box.
inline TriangleMesh boxMeshWithFaceNormals(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  const TriangleMesh shared = boxMesh(lo, hi);
  TriangleMesh mesh;
  for (const auto& t : shared.triangles) {
    const Eigen::Vector3f& a = shared.positions[t[0]];
    const Eigen::Vector3f n = (shared.positions[t[1]] - a).cross(shared.positions[t[2]] - a).normalized();
    for (uint32_t v : t) {
      mesh.positions.push_back(shared.positions[v]);
      mesh.normals.push_back(n);
    }
    const auto base = uint32_t(mesh.positions.size() - 3);
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  return mesh;
}

// A UV sphere with outward vertex normals: `rings` bands of latitude, 2 x rings of longitude.
inline TriangleMesh sphereMesh(const Eigen::Vector3f& centre, float radius, int rings) {
  TriangleMesh mesh;
  const int segments = 2 * rings;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const float theta = float(M_PI) * i / rings, phi = 2.0f * float(M_PI) * j / segments;
      const Eigen::Vector3f n(std::sin(theta) * std::cos(phi), std::cos(theta),
                              std::sin(theta) * std::sin(phi));
      mesh.positions.push_back(centre + radius * n);
      mesh.normals.push_back(n);
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const auto a = uint32_t(i * (segments + 1) + j), b = a + uint32_t(segments + 1);
      mesh.triangles.push_back({a, b, a + 1});
      mesh.triangles.push_back({a + 1, b, b + 1});
    }
  return mesh;
}

// A fresh empty folder under the system's temporary folder, removed when the test ends.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("surge_render_" + std::string(test->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Records what a stage reports.
class CountingProgress : public Progress {
 public:
  void start(const std::string& label, size_t total) override {
    this->label = label;
    this->total = total;
  }
  void advance(size_t count) override { done += count; }
  void finish() override { finished = true; }

  std::string label;
  size_t total = 0, done = 0;
  bool finished = false;
};

// A white furnace's light: the sky is 1 in every direction, there is no sun, and every diffuse surface has albedo
// 1, so that whatever a path meets, the light it brings back is 1 in expectation less what the liquids absorb
// (the scene's; waterAbsorption and fluidAbsorption, which a test may zero).
inline Shading furnaceLight(const Scene& scene) {
  Shading s = Shading::fromScene(scene);
  s.skyZenith = s.skyHorizon = s.belowHorizon = Eigen::Vector3f::Ones();
  s.sunColor = Eigen::Vector3f::Zero();
  s.sunGlow = 0;
  s.floorAlbedo = s.groundAlbedo = s.tankAlbedo = 1;
  s.checkerContrast = 0;
  s.hazeDistance = std::numeric_limits<float>::infinity();
  return s;
}

}  // namespace surge::testing
