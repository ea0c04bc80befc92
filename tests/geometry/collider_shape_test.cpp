#include "geometry/collider_shape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "core/errors.h"
#include "geometry/pose.h"
#include "geometry/shape_files.h"

namespace surge {
namespace {

using Vec3 = Eigen::Vector3f;

// A scene with one collider given as JSON; its files are found relative to TEST_TMPDIR.
Scene sceneWith(const std::string& collider, int dimensions = 3) {
  const std::string vector = dimensions == 3 ? "[1, 1, 1]" : "[1, 1]";
  const std::string zero = dimensions == 3 ? "[0, 0, 0]" : "[0, 0]";
  Scene scene = parseScene(R"({"name": "t", "dimensions": )" + std::to_string(dimensions) +
                               R"(, "domain": {"min": )" + zero + R"(, "max": )" + vector +
                               R"(}, "particle_spacing": 0.02, "fluids": [{"box": {"min": )" + zero +
                               R"(, "max": )" + (dimensions == 3 ? "[0.2, 0.2, 0.2]" : "[0.2, 0.2]") +
                               R"(}}], "colliders": [)" + collider + "]}",
                           "test.json");
  scene.source = "test.json";
  return scene;
}

std::string tempPath(const std::string& name) { return (fs::path(testing::TempDir()) / name).string(); }

// Random points in the box [-half, half]^3 (a fixed seed: the test is the same every run).
std::vector<Vec3> samplePoints(int n, float half = 1) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> u(-half, half);
  std::vector<Vec3> points(n);
  for (Vec3& p : points) p = Vec3(u(random), u(random), u(random));
  return points;
}

// Every analytic shape against its closed form, at random points inside and outside, and its normal against
// the gradient of the closed form by central differences. The analytic distances are exact, so the tolerance
// is float rounding of quantities of order 1 (1e-5); the normals, compared with differences of step 1e-3,
// agree to the difference's error, O(step * curvature) ~ 1e-2 in the worst corner.
TEST(ColliderShape, AnalyticDistancesMatchClosedForms) {
  struct Case {
    std::string json;
    std::function<float(const Vec3&)> exact;
  };
  const float r = 0.3f, hh = 0.25f;
  const std::vector<Case> cases = {
      {R"({"shape": "sphere", "position": [0.5, 0.5, 0.5], "radius": 0.3})",
       [&](const Vec3& q) { return q.norm() - r; }},
      {R"({"shape": "box", "position": [0.5, 0.5, 0.5], "size": [0.4, 0.6, 0.8]})",
       [](const Vec3& q) {
         const Vec3 d = q.cwiseAbs() - Vec3(0.2f, 0.3f, 0.4f);
         return d.cwiseMax(0.0f).norm() + std::min(d.maxCoeff(), 0.0f);
       }},
      {R"({"shape": "capsule", "position": [0.5, 0.5, 0.5], "radius": 0.3, "height": 0.5})",
       [&](const Vec3& q) { return (q - Vec3(0, std::clamp(q.y(), -hh, hh), 0)).norm() - r; }},
      {R"({"shape": "cylinder", "position": [0.5, 0.5, 0.5], "radius": 0.3, "height": 0.5})",
       [&](const Vec3& q) {
         const float dr = std::hypot(q.x(), q.z()) - r, dy = std::abs(q.y()) - hh;
         return std::hypot(std::max(dr, 0.0f), std::max(dy, 0.0f)) + std::min(std::max(dr, dy), 0.0f);
       }},
      {R"({"shape": "plane", "position": [0.5, 0.5, 0.5], "normal": [1, 2, 2]})",
       [](const Vec3& q) { return q.dot(Vec3(1, 2, 2) / 3.0f); }},
  };
  for (const Case& c : cases) {
    const ColliderShape shape = buildColliderShape(sceneWith(c.json), 0);
    int inside = 0;
    for (const Vec3& q : samplePoints(2000, 0.6f)) {
      Vec3 normal;
      const float d = shape.distance(q, normal);
      EXPECT_NEAR(d, c.exact(q), 1e-5f) << c.json << " at " << q.transpose();
      inside += d < 0;
      const float h = 1e-3f;
      Vec3 gradient;
      for (int a = 0; a < 3; ++a) gradient[a] = (c.exact(q + h * Vec3::Unit(a)) - c.exact(q - h * Vec3::Unit(a))) / (2 * h);
      if (gradient.norm() > 0.99f) {  // away from the medial axis, where the gradient is defined
        EXPECT_GT(normal.dot(gradient.normalized()), 0.99f) << c.json << " at " << q.transpose();
      }
    }
    EXPECT_GT(inside, 50) << c.json << ": the test points must probe the inside too";
  }
}

TEST(ColliderShape, ContainerIsTheOutside) {
  const ColliderShape shape =
      buildColliderShape(sceneWith(R"({"shape": "sphere", "position": [0.5, 0.5, 0.5], "radius": 0.3, "container": 1})"), 0);
  Vec3 normal;
  EXPECT_NEAR(shape.distance(Vec3(0.1f, 0, 0), normal), 0.2f, 1e-6f);  // inside the ball: fluid side
  EXPECT_NEAR(normal.x(), -1.0f, 1e-6f);                               // towards the centre, away from the wall
  EXPECT_NEAR(shape.distance(Vec3(0.5f, 0, 0)), -0.2f, 1e-6f);
}

TEST(ColliderShape, PoseInterpolatesKeyframes) {
  const Scene scene = sceneWith(R"({"shape": "box", "size": [0.1, 0.1, 0.1], "motion": [
      {"time": 0, "position": [0.2, 0.5, 0.5]},
      {"time": 1, "position": [0.8, 0.5, 0.5], "rotation": {"axis": [0, 1, 0], "degrees": 90}}]})");
  const Pose half = colliderPose(scene.colliders[0], 0.5);
  EXPECT_NEAR(half.translation.x(), 0.5, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(half.rotation).angle(), M_PI / 4, 1e-9);  // slerp: half the angle
  EXPECT_NEAR(colliderPose(scene.colliders[0], 5.0).translation.x(), 0.8, 1e-12);  // held after the last
  EXPECT_NEAR(colliderPose(scene.colliders[0], -1.0).translation.x(), 0.2, 1e-12);
}

// An icosphere of radius 1, subdivided `levels` times (closed, outward winding).
TriangleMesh icosphere(int levels) {
  const float t = (1 + std::sqrt(5.0f)) / 2;
  TriangleMesh mesh;
  mesh.positions = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                    {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (Vec3& p : mesh.positions) p.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> middle;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      mesh.positions.push_back((mesh.positions[a] + mesh.positions[b]).normalized());
      return middle[key] = uint32_t(mesh.positions.size() - 1);
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (const auto& f : mesh.triangles) {
      const uint32_t ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    mesh.triangles = next;
  }
  return mesh;
}

// A distance grid (geometry/distance_grid.h) interpolates the samples it was given: at random points across a
// grid of unequal counts, at its samples and at its far faces, the sample and its gradient match trilinear
// interpolation of those values in double precision, to float rounding of values about 1 (1e-5). Outside, the
// distance grows by the distance to the box. A read one sample off along any axis misses by the values' spread
// (they are random in [-1, 1]); seen failing that way (0.45 off).
TEST(ColliderShape, DistanceGridInterpolatesItsSamples) {
  const Eigen::Array3i counts(8, 5, 11);
  const Vec3 origin(-0.3f, 0.1f, 0.2f);
  const float voxel = 0.05f;
  std::mt19937 random(3);
  std::uniform_real_distribution<float> unit(-1, 1);
  std::vector<float> values(size_t(counts.prod()));
  for (float& v : values) v = unit(random);
  const DistanceGrid grid(origin, voxel, counts, values);
  auto at = [&](int i, int j, int k) { return double(values[(size_t(k) * counts[1] + j) * counts[0] + i]); };
  auto reference = [&](const Vec3& p, Eigen::Vector3d& gradient) {
    // The point in voxels as the grid finds it (in float, kept a ten-thousandth of a voxel inside the far faces);
    // the interpolation from there in double.
    const Vec3 u = (p - origin) / voxel;
    int cell[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
      const float inside = std::min(std::max(u[a], 0.0f), float(counts[a] - 1) - 1e-4f);
      cell[a] = int(inside);
      f[a] = double(inside) - cell[a];
    }
    double value = 0;
    gradient.setZero();
    for (int corner = 0; corner < 8; ++corner) {
      const int o[3] = {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
      double w[3], dw[3];
      for (int a = 0; a < 3; ++a) {
        w[a] = o[a] ? f[a] : 1 - f[a];
        dw[a] = o[a] ? 1 : -1;
      }
      const double c = at(cell[0] + o[0], cell[1] + o[1], cell[2] + o[2]);
      value += w[0] * w[1] * w[2] * c;
      gradient += Eigen::Vector3d(dw[0] * w[1] * w[2], w[0] * dw[1] * w[2], w[0] * w[1] * dw[2]) * c / voxel;
    }
    return value;
  };
  std::vector<Vec3> points;
  for (int n = 0; n < 4000; ++n) {
    const Vec3 u(0.5f * (unit(random) + 1) * (counts[0] - 1), 0.5f * (unit(random) + 1) * (counts[1] - 1),
                 0.5f * (unit(random) + 1) * (counts[2] - 1));
    points.push_back(origin + voxel * u);
  }
  for (int k = 0; k < counts[2]; ++k)
    for (int j = 0; j < counts[1]; ++j)
      for (int i = 0; i < counts[0]; ++i) points.push_back(origin + voxel * Vec3(float(i), float(j), float(k)));
  for (const Vec3& p : points) {
    Vec3 gradient;
    Eigen::Vector3d expectedGradient;
    const float value = grid.sample(p, gradient);
    ASSERT_NEAR(value, reference(p, expectedGradient), 1e-5) << p.transpose();
    // At a sample on a cell's face the gradient is one-sided; the row-major grid took the same side.
    const Vec3 u = (p - origin) / voxel;
    if ((u.array() - u.array().round()).abs().minCoeff() < 1e-3f) continue;
    ASSERT_LT((gradient.cast<double>() - expectedGradient).norm(), 1e-5 / voxel) << p.transpose();
  }
  // Outside the box: the value at the nearest point of the box, plus the distance to it.
  const Vec3 corner = origin + voxel * Vec3(float(counts[0] - 1), float(counts[1] - 1), float(counts[2] - 1));
  Vec3 gradient;
  Eigen::Vector3d unused;
  const Vec3 beyond = corner + Vec3(0.03f, 0.04f, 0.0f);
  EXPECT_NEAR(grid.sample(beyond, gradient), reference(corner, unused) + 0.05, 1e-5);
  EXPECT_NEAR(gradient.dot(Vec3(0.6f, 0.8f, 0.0f)), 1.0f, 1e-5f);
}

// The mesh's baked distance against the sphere it approximates. An icosphere of 4 levels (5120 triangles) lies
// within 1 - cos(pi / 5 / 16)^-ish ~ 0.1% of the radius of the true sphere; trilinear interpolation of a distance
// on a grid of voxel v errs by at most ~ v^2 / (8 R) for a sphere (its curvature), far below the voxel. So the
// distance must match |q| - R within a tenth of a voxel plus the facets' 0.2% of R.
TEST(ColliderShape, MeshDistanceMatchesTheSphereItApproximates) {
  const TriangleMesh sphere = icosphere(4);
  EXPECT_TRUE(isClosedManifold(sphere));
  const float voxel = 0.02f, band = 0.1f;
  const DistanceGrid grid = bakeMeshDistance(sphere, voxel, band, 0.0f);
  float worst = 0;
  int checked = 0;
  for (const Vec3& p : samplePoints(3000)) {
    const Vec3 q = 1.1f * p;
    const float exact = q.norm() - 1.0f;
    if (std::abs(exact) > band) continue;  // the band is all the simulator reads
    Vec3 gradient;
    worst = std::max(worst, std::abs(grid.sample(q, gradient) - exact));
    ++checked;
    if (std::abs(exact) < 0.5f * band) {
      EXPECT_GT(gradient.normalized().dot(q.normalized()), 0.98f);
    }
  }
  EXPECT_GT(checked, 200);
  EXPECT_LT(worst, 0.1f * voxel + 0.002f);
}

TEST(ColliderShape, OpenMeshBecomesAShell) {
  // One square (two triangles) in the plane y = 0: open. A shell of thickness 0.1 about it.
  TriangleMesh square;
  square.positions = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  square.triangles = {{0, 2, 1}, {0, 3, 2}};
  EXPECT_FALSE(isClosedManifold(square));
  const DistanceGrid grid = bakeMeshDistance(square, 0.02f, 0.1f, 0.1f);
  Vec3 gradient;
  EXPECT_NEAR(grid.sample(Vec3(0, 0.2f, 0), gradient), 0.15f, 0.01f);
  EXPECT_NEAR(grid.sample(Vec3(0, -0.2f, 0), gradient), 0.15f, 0.01f);  // both sides are outside
  EXPECT_LT(grid.sample(Vec3(0.3f, 0.0f, 0.2f), gradient), -0.04f);     // inside the shell
}

TEST(ColliderShape, HeightfieldFromA16BitPng) {
  // A ramp: grey rising linearly along x from 0 to 65535, written as a 16-bit PNG by the renderer's own
  // library would need render/; write it with stb here instead.
  const std::string path = tempPath("ramp16.png");
  {
    // A minimal 16-bit grey PNG: 3 x 2 pixels, values 0, 32768, 65535 on each row (big-endian samples).
    // Built by hand with zlib's stored blocks so the test needs no writer.
    std::vector<uint8_t> raw;
    for (int row = 0; row < 2; ++row) {
      raw.push_back(0);  // filter: none
      for (uint16_t v : {uint16_t(0), uint16_t(32768), uint16_t(65535)}) {
        raw.push_back(uint8_t(v >> 8));
        raw.push_back(uint8_t(v & 255));
      }
    }
    auto crc = [](const std::vector<uint8_t>& data) {
      uint32_t c = 0xFFFFFFFFu;
      for (uint8_t b : data) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
      }
      return c ^ 0xFFFFFFFFu;
    };
    auto adler = [](const std::vector<uint8_t>& data) {
      uint32_t a = 1, b = 0;
      for (uint8_t x : data) a = (a + x) % 65521, b = (b + a) % 65521;
      return (b << 16) | a;
    };
    auto be32 = [](std::vector<uint8_t>& out, uint32_t v) {
      for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(v >> s));
    };
    std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
    auto chunk = [&](const char* type, const std::vector<uint8_t>& body) {
      be32(png, uint32_t(body.size()));
      std::vector<uint8_t> typed(type, type + 4);
      typed.insert(typed.end(), body.begin(), body.end());
      png.insert(png.end(), typed.begin(), typed.end());
      be32(png, crc(typed));
    };
    std::vector<uint8_t> header;
    be32(header, 3);
    be32(header, 2);
    header.insert(header.end(), {16, 0, 0, 0, 0});  // 16-bit grey
    chunk("IHDR", header);
    std::vector<uint8_t> z = {0x78, 0x01, 0x01, uint8_t(raw.size()), uint8_t(raw.size() >> 8),
                              uint8_t(~raw.size()), uint8_t(~raw.size() >> 8)};
    z.insert(z.end(), raw.begin(), raw.end());
    be32(z, adler(raw));
    chunk("IDAT", z);
    chunk("IEND", {});
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(png.data()), png.size());
  }
  const Heightfield h = readHeightfieldPng(path, 2.0f, 1.0f, 0.5f, "test.json", "colliders[0].file");
  ASSERT_EQ(h.width, 3);
  ASSERT_EQ(h.depth, 2);
  float sx, sz;
  EXPECT_NEAR(h.heightAt(-1.0f, 0, sx, sz), 0.0f, 1e-6f);
  EXPECT_NEAR(h.heightAt(1.0f, 0, sx, sz), 0.5f, 1e-6f);
  EXPECT_NEAR(h.heightAt(0.5f, 0.2f, sx, sz), 0.375f, 1e-4f);  // 16 bits: 32768 is not 32767.5, 1e-5 of white
  EXPECT_NEAR(sx, 0.25f, 1e-4f);
  EXPECT_NEAR(sz, 0.0f, 1e-6f);
  // The distance of the slope y = 0.25 (x + 1): (y - h) cos(atan 0.25), exact on a plane.
  ColliderShape shape;
  shape.kind = ShapeKind::Heightfield;
  shape.heightfield = h;
  const Vec3 q(0.2f, 0.6f, 0.1f);
  EXPECT_NEAR(shape.distance(q), (0.6f - 0.3f) / std::sqrt(1 + 0.0625f), 1e-4f);
}

// Every bad collider input is an InputError naming the scene file and the key.
TEST(ColliderShape, BadInputNamesTheFileAndKey) {
  auto message = [](const std::string& json) -> std::string {
    try {
      buildColliderShape(sceneWith(json), 0);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(message(R"({"shape": "mesh", "file": "/nonexistent/x.obj"})"),
            "test.json: colliders[0].file: '/nonexistent/x.obj' does not exist");
  const std::string notPng = tempPath("not_a.png");
  std::ofstream(notPng) << "hello";
  EXPECT_NE(message(R"({"shape": "heightfield", "file": ")" + notPng + R"(", "size": [1, 1]})")
                .find("test.json: colliders[0].file: "),
            std::string::npos);
  const std::string empty = tempPath("empty.obj");
  std::ofstream(empty) << "v 0 0 0\nv 1 0 0\n";
  EXPECT_EQ(message(R"({"shape": "mesh", "file": ")" + empty + R"("})"),
            "test.json: colliders[0].file: '" + empty + "' has no triangles");
  EXPECT_EQ(message(R"({"shape": "sphere", "position": [5, 5, 5], "radius": 0.1})"),
            "test.json: colliders[0]: lies entirely outside the domain");
}

TEST(ColliderShape, SceneChecksCollidersKeys) {
  auto message = [](const std::string& json) -> std::string {
    try {
      sceneWith(json);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(message(R"({"shape": "cone"})").rfind("test.json: colliders[0].shape: ", 0), 0u);
  EXPECT_EQ(message(R"({"shape": "box", "size": [1, 1]})"),
            "test.json: colliders[0].size: a box needs its full extents, 3 numbers");
  EXPECT_EQ(message(R"({"shape": "mesh"})"), "test.json: colliders[0].file: a mesh needs a file");
  EXPECT_EQ(message(R"({"shape": "sphere", "position": [0.5, 1e400, 0.5]})").rfind("test.json", 0), 0u);
  EXPECT_EQ(message(R"({"shape": "sphere", "rotation": {"axis": [0, 0, 0], "degrees": 10}})"),
            "test.json: colliders[0].rotation.axis: must not be the zero vector");
  EXPECT_EQ(message(R"({"shape": "sphere", "name": "../x"})").rfind("test.json: colliders[0].name: ", 0), 0u);
  EXPECT_EQ(message(R"({"shape": "sphere", "name": "a"}, {"shape": "sphere", "name": "a"})"),
            "test.json: colliders[1].name: 'a' is used twice");
}

}  // namespace
}  // namespace surge
