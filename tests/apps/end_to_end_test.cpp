// Runs the `surge` program as a user would and reads back every stage's files.
#include <gtest/gtest.h>

#include <set>
#include <tuple>
#include <stb/stb_image.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "core/files.h"
#include "core/ply.h"
#include "tests/apps/run_surge.h"

namespace surge {
namespace {

const char* kTinyScene = R"({
  "name": "tiny",
  "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [0.6, 0.4, 0.3]},
  "particle_spacing": 0.03,
  "fluids": [{"box": {"min": [0, 0, 0], "max": [0.18, 0.24, 0.15]}}],
  "output": {"fps": 30, "frames": 3},
  "render": {"width": 160, "height": 96, "samples": 1}
})";

TEST(EndToEnd, RunMakesEveryStagesFiles) {
  const fs::path scene = writeTestScene("tiny.json", kTinyScene);
  const fs::path out = fs::path(testing::TempDir()) / "surge_e2e_tiny";
  fs::remove_all(out);
  const SurgeResult r = runSurge("run '" + scene.string() + "' --out '" + out.string() + "' --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << "--quiet prints nothing: " << r.out;

  // 6 x 8 x 5 lattice cells of 0.03 in the fluid box.
  const size_t particles = 240;
  EXPECT_EQ(listFrames(out, "particles", "ply"), (std::vector<int>{0, 1, 2, 3}));
  for (int f = 0; f <= 3; ++f) EXPECT_EQ(readParticlePly(framePath(out, "particles", f, "ply")).size(), particles);
  // Frame 0 is the lattice at rest; the water has moved by frame 3 (it falls and spreads under gravity).
  const ParticleFrame first = readParticlePly(framePath(out, "particles", 0, "ply"));
  const ParticleFrame last = readParticlePly(framePath(out, "particles", 3, "ply"));
  // The lattice at rest: every particle at a cell centre (i + 1/2) 0.03 of the box, not moving.
  std::set<std::tuple<int, int, int>> cells;
  for (size_t i = 0; i < first.size(); ++i) {
    const Eigen::Vector3f cell = first.position[i] / 0.03f - Eigen::Vector3f::Constant(0.5f);
    const Eigen::Vector3f nearest = cell.array().round();
    EXPECT_LT((cell - nearest).norm(), 1e-4f) << "particle " << i;
    EXPECT_EQ(first.velocity[i], Eigen::Vector3f::Zero()) << "particle " << i;
    cells.insert({int(nearest.x()), int(nearest.y()), int(nearest.z())});
  }
  EXPECT_EQ(cells.size(), particles);  // each cell once
  for (const auto& [i, j, k] : cells) EXPECT_TRUE(i >= 0 && i < 6 && j >= 0 && j < 8 && k >= 0 && k < 5);
  float speed = 0;
  for (const auto& v : last.velocity) speed = std::max(speed, v.norm());
  EXPECT_GT(speed, 0.05f);

  // stats.csv: a header and one row per frame.
  std::ifstream stats(out / "stats.csv");
  std::string header, line;
  std::getline(stats, header);
  EXPECT_EQ(header.rfind("frame,time,particles,substeps,iterations,density_error_avg,density_error_max,"
                         "kinetic_energy,wall_seconds", 0), 0u);
  int rows = 0;
  while (std::getline(stats, line)) ++rows;
  EXPECT_EQ(rows, 4);
  EXPECT_TRUE(fs::exists(out / "scene.json"));

  openvdb::initialize();
  for (int f = 0; f <= 3; ++f) {
    openvdb::io::File file(framePath(out, "surface", f, "vdb").string());
    file.open();
    openvdb::GridBase::Ptr grid = file.readGrid("surface");
    ASSERT_TRUE(grid);
    EXPECT_EQ(grid->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_GT(grid->activeVoxelCount(), 0u);
    file.close();
    const TriangleMesh mesh = readMeshPly(framePath(out, "surface", f, "ply"));
    EXPECT_GT(mesh.triangles.size(), 100u);

    int width = 0, height = 0, channels = 0;
    unsigned char* pixels = stbi_load(framePath(out, "frames", f, "png").c_str(), &width, &height, &channels, 3);
    ASSERT_NE(pixels, nullptr);
    EXPECT_EQ(width, 160);
    EXPECT_EQ(height, 96);
    stbi_image_free(pixels);
  }
  EXPECT_EQ(countVideoFrames(out / "tiny.mp4"), 4);

  // A shorter run into the same folder: no stage keeps the earlier run's later frames, nor the video them.
  const SurgeResult shorter =
      runSurge("run '" + scene.string() + "' --set output.frames=1 --out '" + out.string() + "' --quiet");
  ASSERT_EQ(shorter.status, 0) << shorter.err;
  const std::vector<int> two = {0, 1};
  EXPECT_EQ(listFrames(out, "particles", "ply"), two);
  EXPECT_EQ(listFrames(out, "surface", "ply"), two);
  EXPECT_EQ(listFrames(out, "surface", "vdb"), two);
  EXPECT_EQ(listFrames(out, "frames", "png"), two);
  EXPECT_EQ(countVideoFrames(out / "tiny.mp4"), 2);
}

TEST(EndToEnd, ResumedRunRedoesOnlyWhatIsMissingAndEndsOnTheSameBytes) {
  const fs::path scene = writeTestScene("tiny.json", kTinyScene);
  const fs::path out = fs::path(testing::TempDir()) / ("surge_e2e_resume_" + std::to_string(::getpid()));
  fs::remove_all(out);
  ASSERT_EQ(runSurge("run '" + scene.string() + "' --out '" + out.string() + "' --quiet").status, 0);
  const fs::path mesh1 = framePath(out, "surface", 1, "ply"), vdb1 = framePath(out, "surface", 1, "vdb");
  const fs::path png2 = framePath(out, "frames", 2, "png"), png0 = framePath(out, "frames", 0, "png");
  const std::string meshBytes = readTextFile(mesh1), pngBytes = readTextFile(png2);
  const auto png0Time = fs::last_write_time(png0);

  // As if the run had been stopped before surfacing frame 1 and rendering frame 2 (and so frame 1).
  fs::remove(mesh1);
  fs::remove(vdb1);
  fs::remove(png2);
  fs::remove(framePath(out, "frames", 1, "png"));
  const SurgeResult r = runSurge("run '" + scene.string() + "' --resume --out '" + out.string() + "' --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(readTextFile(mesh1), meshBytes);
  EXPECT_EQ(readTextFile(png2), pngBytes);
  EXPECT_EQ(fs::last_write_time(png0), png0Time) << "frame 0 was up to date and should have been left";
  EXPECT_EQ(countVideoFrames(out / "tiny.mp4"), 4);

  // A changed render setting makes every image stale, and nothing before it: the render's size changes on
  // every frame, the surfaces and particles are left as they were.
  auto times = [&](const std::string& sub, const std::string& ext) {
    std::vector<fs::file_time_type> t;
    for (int f = 0; f <= 3; ++f) t.push_back(fs::last_write_time(framePath(out, sub, f, ext)));
    return t;
  };
  const auto surfaceTimes = times("surface", "ply"), particleTimes = times("particles", "ply");
  const SurgeResult wider = runSurge("run '" + scene.string() + "' --resume --set render.width=128 --out '" +
                                     out.string() + "' --quiet");
  ASSERT_EQ(wider.status, 0) << wider.err;
  for (int f = 0; f <= 3; ++f) {
    int width = 0, height = 0, channels = 0;
    unsigned char* pixels = stbi_load(framePath(out, "frames", f, "png").c_str(), &width, &height, &channels, 3);
    ASSERT_NE(pixels, nullptr);
    EXPECT_EQ(width, 128) << "frame " << f;
    stbi_image_free(pixels);
  }
  EXPECT_EQ(times("surface", "ply"), surfaceTimes) << "a render setting made the surfaces stale";
  EXPECT_EQ(times("particles", "ply"), particleTimes);
  // A changed surface setting makes the surfaces stale, and so the images made from them, not the particles.
  const auto pngTimes = times("frames", "png");
  const SurgeResult finer = runSurge("run '" + scene.string() +
                                     "' --resume --set render.width=128 --set surface.voxel_size=0.012 --out '" +
                                     out.string() + "' --quiet");
  ASSERT_EQ(finer.status, 0) << finer.err;
  const auto newSurfaceTimes = times("surface", "ply"), newPngTimes = times("frames", "png");
  for (int f = 0; f <= 3; ++f) {
    EXPECT_GT(newSurfaceTimes[f], surfaceTimes[f]) << "frame " << f;
    EXPECT_GT(newPngTimes[f], pngTimes[f]) << "frame " << f;
  }
  EXPECT_EQ(times("particles", "ply"), particleTimes);
  fs::remove_all(out);
}

// A fluid's colour and absorption distance are its look, not its physics: a run resumed with them changed renders
// its frames again and leaves its particles and surfaces, and a fluid that gives no colour follows the render's
// water_color when the run's folder is rendered again (the folder's scene.json leaves it unset).
TEST(EndToEnd, AFluidsColourIsALookToChangeOnARun) {
  const fs::path scene = writeTestScene("tiny.json", kTinyScene);
  const fs::path out = fs::path(testing::TempDir()) / ("surge_e2e_colour_" + std::to_string(::getpid()));
  fs::remove_all(out);
  ASSERT_EQ(runSurge("run '" + scene.string() + "' --out '" + out.string() + "' --quiet").status, 0);
  const fs::path particles = framePath(out, "particles", 2, "ply"), surface = framePath(out, "surface", 2, "ply");
  const fs::path png = framePath(out, "frames", 2, "png");
  const auto particleTime = fs::last_write_time(particles), surfaceTime = fs::last_write_time(surface);
  const std::string blue = readTextFile(png);

  const SurgeResult green =
      runSurge("render '" + out.string() + "' --set 'render.water_color=[0.2, 0.9, 0.2]' --quiet");
  ASSERT_EQ(green.status, 0) << green.err;
  EXPECT_TRUE(readTextFile(png) != blue) << "the render's water_color did not reach the run's fluid";

  const SurgeResult amber = runSurge("run '" + scene.string() +
                                     "' --resume --set 'fluids[0].color=[0.9, 0.5, 0.1]' --set "
                                     "fluids[0].absorption_distance=0.05 --out '" +
                                     out.string() + "' --quiet");
  ASSERT_EQ(amber.status, 0) << amber.err;
  const std::string amberFrame = readTextFile(png);
  EXPECT_TRUE(amberFrame != blue) << "the fluid's colour did not reach the render";
  EXPECT_EQ(fs::last_write_time(particles), particleTime) << "a colour made the simulation run again";
  EXPECT_EQ(fs::last_write_time(surface), surfaceTime) << "a colour made the surfaces stale";
  // Rendered again at the same colour, the frame is the same: the change above was the colour's.
  const SurgeResult again = runSurge("run '" + scene.string() +
                                     "' --set 'fluids[0].color=[0.9, 0.5, 0.1]' --set "
                                     "fluids[0].absorption_distance=0.05 --out '" +
                                     out.string() + "' --quiet");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_TRUE(readTextFile(png) == amberFrame) << "a resumed render differs from a new run's";
  fs::remove_all(out);
}

TEST(EndToEnd, BadSceneIsOneLineExitTwoAndWritesNothing) {
  std::string text = kTinyScene;
  text.replace(text.find("\"particle_spacing\": 0.03"), 24, "\"particle_spacing\": -1");
  const fs::path scene = writeTestScene("bad.json", text);
  const fs::path out = fs::path(testing::TempDir()) / "surge_e2e_bad";
  fs::remove_all(out);
  const SurgeResult r = runSurge("run '" + scene.string() + "' --out '" + out.string() + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.json: particle_spacing: -1 is out of range"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));

  const SurgeResult unknown = runSurge("sim '" + scene.string() + "' --bogus");
  EXPECT_EQ(unknown.status, 2);
  const SurgeResult badSet = runSurge("sim '" + writeTestScene("ok.json", kTinyScene).string() + "' --set solver.substeps=x");
  EXPECT_EQ(badSet.status, 2);
  EXPECT_NE(badSet.err.find("--set: solver.substeps: expected an integer"), std::string::npos) << badSet.err;
  const SurgeResult missing = runSurge("surface '" + out.string() + "'");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("scene.json"), std::string::npos) << missing.err;
}

TEST(EndToEnd, HelpForEveryCommand) {
  for (const char* command : {"", "run", "sim", "surface", "render", "video", "keys", "export", "report"}) {
    const SurgeResult r = runSurge(std::string(command) + " --help");
    EXPECT_EQ(r.status, 0) << command;
    EXPECT_NE(r.out.find("--help"), std::string::npos) << command;
  }
}

}  // namespace
}  // namespace surge
