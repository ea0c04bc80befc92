// `surge sim` with colliders as a user runs it: the same bytes at any thread count and after a resume, the
// collider outputs (colliders.csv, meshes), and every bad collider input refused before anything is written.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/ply.h"
#include "tests/apps/run_surge.h"

namespace surge {
namespace {

// About 2,000 particles thrown at a rotated box, a sphere and a moving paddle, with friction on one.
const char* kObstacles = R"({
  "name": "obstacles", "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [0.8, 0.5, 0.3]},
  "particle_spacing": 0.025,
  "fluids": [{"box": {"min": [0, 0, 0], "max": [0.25, 0.3, 0.3]}, "velocity": [1, 0, 0]}],
  "colliders": [
    {"name": "block", "shape": "box", "position": [0.45, 0.05, 0.15], "size": [0.08, 0.1, 0.12],
     "rotation": {"axis": [0, 1, 0], "degrees": 30}, "friction": 0.5},
    {"name": "ball", "shape": "sphere", "position": [0.15, 0.1, 0.15], "radius": 0.06},
    {"name": "paddle", "shape": "box", "size": [0.02, 0.2, 0.2],
     "motion": [{"time": 0, "position": [0.7, 0.15, 0.15]}, {"time": 1, "position": [0.55, 0.15, 0.15],
                 "rotation": {"axis": [0, 0, 1], "degrees": 20}}]}
  ],
  "output": {"fps": 30, "frames": 6}
})";

TEST(CollidersCommand, SameBytesAtOneAndTwoThreadsAndAfterResume) {
  const ThreeRuns runs = simulateThreeWays(writeTestScene("obstacles.json", kObstacles), "colliders", 3);
  ASSERT_TRUE(runs.ok) << runs.first.err;
  const fs::path &one = runs.one, &two = runs.two, &resumed = runs.resumed;
  const SurgeResult& first = runs.first;
  for (int f = 0; f <= 6; ++f) {
    const std::string frame = readTextFile(framePath(one, "particles", f, "ply"));
    EXPECT_EQ(frame, readTextFile(framePath(two, "particles", f, "ply"))) << "frame " << f;
    EXPECT_EQ(frame, readTextFile(framePath(resumed, "particles", f, "ply"))) << "frame " << f;
  }
  const std::string table = readTextFile(one / "colliders.csv");
  EXPECT_EQ(table, readTextFile(two / "colliders.csv"));
  EXPECT_EQ(table, readTextFile(resumed / "colliders.csv"));
  // One row a collider a frame (frames 1..6: each row is the mean over the frame that ends there).
  const std::vector<std::string> rows = lines(table);
  ASSERT_EQ(rows.size(), 1u + 3 * 6);
  EXPECT_EQ(rows[0], "frame,collider,fx,fy,fz,tx,ty,tz");
  EXPECT_EQ(rows[1].rfind("1,block,", 0), 0u);
  EXPECT_EQ(rows[18].rfind("6,paddle,", 0), 0u);
  // The water thrown at the block pushes it along +x by frame 6.
  double fx = 0;
  for (const std::string& row : rows)
    if (row.rfind("6,block,", 0) == 0) fx = std::stod(row.substr(std::string("6,block,").size()));
  EXPECT_GT(fx, 0.0);
  // Meshes: one per collider, and the moving paddle's per frame, each a closed solid whose box matches.
  const TriangleMesh block = readMeshPly(one / "colliders" / "block.ply");
  EXPECT_EQ(block.triangles.size(), 12u);
  EXPECT_GT(readMeshPly(one / "colliders" / "ball.ply").triangles.size(), 100u);
  const TriangleMesh paddle0 = readMeshPly(framePath(one / "colliders", "paddle", 0, "ply"));
  const TriangleMesh paddle6 = readMeshPly(framePath(one / "colliders", "paddle", 6, "ply"));
  float x0 = 0, x6 = 0;
  for (const auto& p : paddle0.positions) x0 += p.x() / paddle0.positions.size();
  for (const auto& p : paddle6.positions) x6 += p.x() / paddle6.positions.size();
  EXPECT_NEAR(x0, 0.7f, 1e-5f);
  EXPECT_NEAR(x6, 0.7f - 0.15f * 0.2f, 1e-5f);  // 6 frames at 30 fps: a fifth of the way
  // Fluid placed inside the ball was removed, and said so.
  EXPECT_NE(first.out.find("sim: removed "), std::string::npos);
  EXPECT_LT(readParticlePly(framePath(one, "particles", 0, "ply")).size(), 10u * 12u * 12u);
}

// Each bad collider input: one line naming the scene file and the key, exit 2, and no output folder.
TEST(CollidersCommand, BadInputIsOneLineAndWritesNothing) {
  const std::string dir = testing::TempDir();
  std::ofstream(dir + "/notapng.png") << "not a png";
  std::ofstream(dir + "/flat.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  struct Case {
    std::string collider, key;
  };
  const std::vector<Case> cases = {
      {R"({"shape": "cone"})", "colliders[0].shape"},
      {R"({"shape": "mesh", "file": "missing.obj"})", "colliders[0].file"},
      {R"({"shape": "heightfield", "file": "notapng.png", "size": [1, 1], "height": 0.1})", "colliders[0].file"},
      {R"({"shape": "mesh", "file": "flat.obj"})", "colliders[0].file"},
      {R"({"shape": "sphere", "position": [5, 5, 5]})", "colliders[0]"},
      {R"({"shape": "sphere", "rotation": {"axis": [0, 0, 0], "degrees": 5}})", "colliders[0].rotation.axis"},
      {R"({"shape": "box", "size": [0.1, 0.1]})", "colliders[0].size"},
      // NaN as Python's json module writes it (JSON itself has none).
      {R"({"shape": "sphere", "position": [0.3, NaN, 0.1], "radius": 0.05})", "colliders[0].position"},
      {R"({"shape": "sphere", "rotation": {"axis": [0, 1, 0], "degrees": NaN}})", "colliders[0].rotation.degrees"},
      {R"({"shape": "sphere", "scale": Infinity})", "colliders[0].scale"},
  };
  for (const Case& c : cases) {
    std::string text = kObstacles;
    const size_t start = text.find("\"colliders\""), end = text.find("\"output\"");
    text.replace(start, end - start, "\"colliders\": [" + c.collider + "],\n  ");
    const fs::path scene = writeTestScene("bad_collider.json", text);
    const fs::path out = freshFolder("bad_collider_out");
    const SurgeResult r = runSurge("sim '" + scene.string() + "' --out " + out.string());
    EXPECT_EQ(r.status, 2) << c.collider << ": " << r.err;
    EXPECT_EQ(r.err.rfind("surge: " + scene.string() + ": " + c.key + ":", 0), 0u) << c.collider << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.collider;
  }
  // A NaN cannot be written in JSON; a number too large for a double is the nearest thing.
  std::string text = kObstacles;
  text.replace(text.find("[0.45, 0.05, 0.15]"), 18, "[0.45, 1e400, 0.15]");
  const fs::path scene = writeTestScene("bad_collider.json", text);
  const SurgeResult r = runSurge("sim '" + scene.string() + "' --out " + freshFolder("bad_nan").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("surge: " + scene.string() + ": ", 0), 0u) << r.err;
}

}  // namespace
}  // namespace surge

namespace surge {
namespace {

// An open mesh (one square, as users bring them) is given the spacing as its thickness, says so in one line,
// and holds the water: nothing falls through it.
TEST(CollidersCommand, OpenMeshBecomesAShellAndSaysSo) {
  const std::string dir = testing::TempDir();
  std::ofstream(dir + "/square.obj") << "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 3 2\nf 1 4 3\n";
  std::string text = kObstacles;
  const size_t start = text.find("\"colliders\""), end = text.find("\"output\"");
  text.replace(start, end - start,
               R"("colliders": [{"name": "sheet", "shape": "mesh", "file": "square.obj", "position": [0.4, 0.15, 0.15]}],
  )");
  const fs::path scene = writeTestScene("open_mesh.json", text);
  const fs::path out = fs::path(testing::TempDir()) / "open_mesh_out";
  fs::remove_all(out);
  const SurgeResult r = runSurge("sim '" + scene.string() + "' --set 'fluids[0].box.min=[0,0.2,0]' "
                                 "--set 'fluids[0].box.max=[0.8,0.4,0.3]' --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("sim: colliders[0] (square.obj) is open or non-manifold: treated as a shell 0.025 m thick"),
            std::string::npos)
      << r.out;
  const ParticleFrame last = readParticlePly(framePath(out, "particles", 6, "ply"));
  for (const Eigen::Vector3f& p : last.position) EXPECT_GT(p.y(), 0.15f) << "a particle fell through the sheet";
}

}  // namespace
}  // namespace surge
