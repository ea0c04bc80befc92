// `surge sim` with rigid bodies as a user runs it: the same bytes at any thread count and after a resume (the
// bodies' state is part of each frame on disk), the body outputs (bodies.csv, meshes), and every bad body input
// refused before anything is written.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/ply.h"
#include "tests/apps/run_surge.h"

namespace surge {
namespace {

// Three boxes of three densities and a ball dropped into a small pool, beside a collider.
const char* kBodies = R"({
  "name": "drop", "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [0.6, 0.5, 0.4]},
  "particle_spacing": 0.025,
  "fluids": [{"box": {"min": [0, 0, 0], "max": [0.6, 0.2, 0.4]}}],
  "colliders": [{"name": "post", "shape": "cylinder", "position": [0.5, 0.15, 0.2], "radius": 0.04, "height": 0.3}],
  "bodies": [
    {"name": "light", "shape": "box", "position": [0.12, 0.3, 0.12], "size": [0.08, 0.05, 0.08], "density": 300},
    {"name": "half", "shape": "box", "position": [0.3, 0.33, 0.2], "size": [0.08, 0.05, 0.08], "density": 500,
     "rotation": {"axis": [0, 1, 1], "degrees": 20}, "angular_velocity": [0, 2, 0]},
    {"name": "heavy", "shape": "sphere", "position": [0.15, 0.4, 0.3], "radius": 0.04, "density": 2000,
     "velocity": [0.5, 0, 0]}
  ],
  "output": {"fps": 30, "frames": 6}
})";

TEST(BodiesCommand, SameBytesAtOneAndTwoThreadsAndAfterResume) {
  const ThreeRuns runs = simulateThreeWays(writeTestScene("drop.json", kBodies), "bodies", 3);
  ASSERT_TRUE(runs.ok) << runs.first.err;
  const fs::path &one = runs.one, &two = runs.two, &resumed = runs.resumed;
  for (int f = 0; f <= 6; ++f) {
    const std::string frame = readTextFile(framePath(one, "particles", f, "ply"));
    EXPECT_EQ(frame, readTextFile(framePath(two, "particles", f, "ply"))) << "frame " << f;
    EXPECT_EQ(frame, readTextFile(framePath(resumed, "particles", f, "ply"))) << "frame " << f;
    const std::string state = readTextFile(framePath(one, "bodies", f, "txt"));
    EXPECT_EQ(state, readTextFile(framePath(resumed, "bodies", f, "txt"))) << "frame " << f;
  }
  const std::string table = readTextFile(one / "bodies.csv");
  EXPECT_EQ(table, readTextFile(two / "bodies.csv"));
  EXPECT_EQ(table, readTextFile(resumed / "bodies.csv"));
  // One row a body a frame, frames 0..6, in the issue's columns.
  const std::vector<std::string> rows = lines(table);
  ASSERT_EQ(rows.size(), 1u + 3 * 7);
  EXPECT_EQ(rows[0], "frame,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,fx,fy,fz,tx,ty,tz");
  EXPECT_EQ(rows[1].rfind("0,light,", 0), 0u);
  EXPECT_EQ(rows[21].rfind("6,heavy,", 0), 0u);
  // colliders.csv keeps only the colliders.
  EXPECT_EQ(lines(readTextFile(one / "colliders.csv")).size(), 1u + 6);
  // Meshes: each body's at frame 0 and per frame, moved with it.
  const TriangleMesh box = readMeshPly(one / "bodies" / "light.ply");
  EXPECT_EQ(box.triangles.size(), 12u);
  const TriangleMesh ball0 = readMeshPly(framePath(one / "bodies", "heavy", 0, "ply"));
  const TriangleMesh ball6 = readMeshPly(framePath(one / "bodies", "heavy", 6, "ply"));
  Eigen::Vector3f c0 = Eigen::Vector3f::Zero(), c6 = Eigen::Vector3f::Zero();
  for (const auto& p : ball0.positions) c0 += p / float(ball0.positions.size());
  for (const auto& p : ball6.positions) c6 += p / float(ball6.positions.size());
  EXPECT_NEAR(c0.y(), 0.4f, 1e-4f);
  EXPECT_LT(c6.y(), 0.4f - 0.5f * 9.81f * 0.03f);  // fell at least 4/5 of a free fall's 0.049 m in 0.2 s
  EXPECT_GT(c6.x(), 0.15f + 0.05f);                // and moved along x
}

// A body lighter than one fluid particle is simulated, with one line saying the water may throw it (the explicit
// coupling's limit, docs/bodies.md); the scene's own bodies, 15 g of particle against 96 g and more, say nothing.
TEST(BodiesCommand, ABodyLighterThanAParticleIsNoted) {
  std::string text = kBodies;
  const size_t start = text.find("\"bodies\""), end = text.find("\"output\"");
  text.replace(start, end - start,
               R"("bodies": [{"name": "cork", "shape": "box", "size": [0.04, 0.04, 0.04], "position": [0.3, 0.3, 0.2],
                 "density": 20}],
  )");
  const size_t frames = text.find("\"frames\": 6");
  text.replace(frames, 11, "\"frames\": 1");
  const fs::path out = freshFolder("cork_out");
  const SurgeResult r = runSurge("sim '" + writeTestScene("cork.json", text).string() + "' --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("sim: note: body cork (0.00128 kg) is lighter than one fluid particle (0.0156 kg)"),
            std::string::npos)
      << r.out;
  const SurgeResult quiet = runSurge("sim '" + writeTestScene("drop.json", kBodies).string() + "' --out " +
                                     freshFolder("drop_note_out").string() + " --set output.frames=1");
  EXPECT_EQ(quiet.status, 0) << quiet.err;
  EXPECT_EQ(quiet.out.find("lighter than one fluid particle"), std::string::npos) << quiet.out;
}

// Each bad body input: one line naming the scene file and the key, exit 2, and no output folder.
TEST(BodiesCommand, BadInputIsOneLineAndWritesNothing) {
  const std::string dir = testing::TempDir();
  std::ofstream(dir + "/square.obj") << "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 3 2\nf 1 4 3\n";
  struct Case {
    std::string bodies, key;
  };
  const std::vector<Case> cases = {
      {R"({"shape": "box", "size": [0.1, 0.1, 0.1], "position": [0.3, 0.3, 0.2], "density": 0})", "bodies[0].density"},
      {R"({"shape": "box", "size": [0.1, 0.1, 0.1], "position": [0.3, 0.3, 0.2], "density": -5})", "bodies[0].density"},
      {R"({"shape": "box", "size": [0.1, 0.1, 0.1], "position": [0.3, 0.3, 0.2], "density": 5, "mass": 1})",
       "bodies[0].mass"},
      {R"({"shape": "plane", "position": [0.3, 0.3, 0.2], "density": 500})", "bodies[0].shape"},
      {R"({"shape": "mesh", "file": "square.obj", "position": [0.3, 0.3, 0.2], "scale": 0.05, "density": 500})",
       "bodies[0].file"},
      {R"({"shape": "sphere", "position": [0.3, 0.3, 0.2], "radius": 0.05, "density": 500},
          {"shape": "sphere", "position": [0.33, 0.3, 0.2], "radius": 0.05, "density": 500})", "bodies[1]"},
      {R"({"shape": "sphere", "position": [0.58, 0.3, 0.2], "radius": 0.05, "density": 500})", "bodies[0].position"},
      {R"({"name": "post", "shape": "sphere", "position": [0.3, 0.3, 0.2], "density": 500})", "bodies[0].name"},
  };
  for (const Case& c : cases) {
    std::string text = kBodies;
    const size_t start = text.find("\"bodies\""), end = text.find("\"output\"");
    text.replace(start, end - start, "\"bodies\": [" + c.bodies + "],\n  ");
    const fs::path scene = writeTestScene("bad_body.json", text);
    const fs::path out = freshFolder("bad_body_out");
    const SurgeResult r = runSurge("sim '" + scene.string() + "' --out " + out.string());
    EXPECT_EQ(r.status, 2) << c.bodies << ": " << r.err;
    EXPECT_EQ(r.err.rfind("surge: " + scene.string() + ": " + c.key + ":", 0), 0u) << c.bodies << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.bodies;
  }
}

}  // namespace
}  // namespace surge
