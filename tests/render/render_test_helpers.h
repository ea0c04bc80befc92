// Scenes and meshes shared by the render tests.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"

namespace surge::testing {

// A unit tank with a small image; `renderExtra` is spliced into the "render" object.
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

}  // namespace surge::testing
