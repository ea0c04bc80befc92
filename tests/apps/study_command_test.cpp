// `surge study` as a user runs it: a small sweep, its study.csv and plots; bad sweeps refused before anything is
// written; and the dam-break columns of stats.csv.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "tests/apps/run_surge.h"

namespace surge {
namespace {

// 2D, 20 x 20 = 400 particles against the left wall, 10 frames: a fraction of a second per run.
const char* kTinyDamBreak = R"({
  "name": "tiny", "dimensions": 2,
  "domain": {"min": [0, 0], "max": [1.2, 0.6]},
  "particle_spacing": 0.02,
  "fluids": [{"box": {"min": [0, 0], "max": [0.4, 0.4]}}],
  "output": {"fps": 30, "frames": 10}
})";

std::vector<std::vector<std::string>> readCsv(const fs::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> row;
    std::string field;
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) row.push_back(field), field.clear();
      else field += c;
    }
    row.push_back(field);
    rows.push_back(row);
  }
  return rows;
}

int column(const std::vector<std::string>& header, const std::string& name) {
  const auto at = std::find(header.begin(), header.end(), name);
  return at == header.end() ? -1 : int(at - header.begin());
}

TEST(StudyCommand, SweepWritesOneRowPerRunAndPicksTheCostliestAsReference) {
  const fs::path scene = writeTestScene("tiny.json", kTinyDamBreak);
  const fs::path out = fs::path(testing::TempDir()) / "surge_study";
  fs::remove_all(out);
  const SurgeResult r = runSurge("study '" + scene.string() + "' --quiet --sweep solver.iterations=1,4 --sweep " +
                                 "solver.substeps=20,40 --frames 8 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = readCsv(out / "study.csv");
  ASSERT_EQ(rows.size(), 5u);
  const auto& header = rows[0];
  const int iterations = column(header, "solver.iterations"), substeps = column(header, "solver.substeps");
  const int reference = column(header, "reference"), error = column(header, "error"), steps = column(header, "steps");
  const int cpu = column(header, "cpu_seconds"), peak = column(header, "peak_mb"), status = column(header, "status");
  ASSERT_GE(std::min({iterations, substeps, reference, error, steps, cpu, peak, status}), 0);
  // The first sweep varies slowest.
  EXPECT_EQ(rows[1][iterations] + rows[1][substeps] + rows[2][substeps] + rows[3][iterations], "120404");
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i][status], "ok");
    // Both counts are above what the flow needs (PBF's steps are never longer than its CFL and depth steps).
    EXPECT_EQ(std::stoi(rows[i][steps]), 8 * std::stoi(rows[i][substeps]));
    EXPECT_GT(std::stod(rows[i][cpu]), 0);
    EXPECT_GT(std::stod(rows[i][peak]), 1);
    // The reference (4 iterations, 40 substeps: the most work) compares as 0; the others differ from it.
    EXPECT_EQ(rows[i][reference], i == 4 ? "1" : "0");
    if (i == 4) EXPECT_LT(std::stod(rows[i][error]), 1e-9);
    else EXPECT_GT(std::stod(rows[i][error]), 1e-6);
  }
  EXPECT_TRUE(fs::exists(out / "runs" / "003_solver.iterations=4,solver.substeps=40" / "stats.csv"));
}

// Render settings swept: the scene is simulated and surfaced once (base/), each run renders it, and its error
// is the image RMSE against the reference, the unfiltered run of most CPU seconds: here 16 samples unfiltered.
// One sample is far off it (the noise of a single sample, tens of levels), the filter brings one sample closer,
// and 16 filtered samples are closer still. Each run has its frames; the base's surfaces are not copied.
TEST(StudyCommand, RenderSweepComparesImagesWithTheMostCostlyUnfilteredRun) {
  const fs::path scene = writeTestScene("tiny3d.json", R"({
    "name": "tiny3d", "dimensions": 3,
    "domain": {"min": [0, 0, 0], "max": [0.8, 0.5, 0.4]},
    "particle_spacing": 0.04,
    "fluids": [{"box": {"min": [0, 0, 0], "max": [0.3, 0.3, 0.4]}}],
    "output": {"fps": 30, "frames": 2},
    "render": {"width": 96, "height": 54}
  })");
  const fs::path out = fs::path(testing::TempDir()) / "surge_render_study";
  fs::remove_all(out);
  const SurgeResult r = runSurge("study '" + scene.string() +
                                 "' --quiet --sweep render.samples=1,16 --sweep render.denoise=0,1 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = readCsv(out / "study.csv");
  ASSERT_EQ(rows.size(), 5u);
  const int reference = column(rows[0], "reference"), error = column(rows[0], "error"),
            status = column(rows[0], "status"), frames = column(rows[0], "frames");
  ASSERT_GE(std::min({reference, error, status, frames}), 0);
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i][status], "ok");
    EXPECT_EQ(rows[i][frames], "3");
    EXPECT_EQ(rows[i][reference], i == 3 ? "1" : "0");
  }
  // Rows: 1 sample unfiltered, 1 filtered, 16 unfiltered (the reference), 16 filtered.
  const double one = std::stod(rows[1][error]), oneFiltered = std::stod(rows[2][error]),
               sixteenFiltered = std::stod(rows[4][error]);
  std::printf("image RMSE: 1 sample %.2f, filtered %.2f; 16 filtered %.2f\n", one, oneFiltered, sixteenFiltered);
  EXPECT_EQ(std::stod(rows[3][error]), 0.0);
  EXPECT_GT(one, 5.0);
  EXPECT_LT(oneFiltered, one);
  EXPECT_LT(sixteenFiltered, oneFiltered);
  EXPECT_TRUE(fs::exists(out / "base" / "surface" / "frame_00002.ply"));
  EXPECT_TRUE(fs::exists(out / "runs" / "003_render.samples=16,render.denoise=1" / "frames" / "frame_00002.png"));
  EXPECT_TRUE(fs::exists(out / "error_vs_cpu.png"));
  // Mixed with a simulation setting, refused before anything is written.
  fs::remove_all(out);
  const SurgeResult mixed = runSurge("study '" + scene.string() +
                                     "' --quiet --sweep render.samples=1,2 --sweep solver.iterations=1,2 --out " +
                                     out.string());
  EXPECT_EQ(mixed.status, 2) << mixed.err;
  EXPECT_EQ(std::count(mixed.err.begin(), mixed.err.end(), '\n'), 1) << mixed.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(StudyCommand, BadSweepsAreRefusedBeforeAnythingIsWritten) {
  const fs::path scene = writeTestScene("tiny.json", kTinyDamBreak);
  const fs::path out = fs::path(testing::TempDir()) / "surge_study_bad";
  fs::remove_all(out);
  for (const std::string sweep : {"solver.iterations", "=1,2", "solver.iterations=1,,2", "solver.no_such_key=1,2",
                                  "solver.iterations=1,0", "surface.method=spheres,anisotropic"}) {
    const SurgeResult r = runSurge("study '" + scene.string() + "' --quiet --sweep '" + sweep + "' --out " + out.string());
    EXPECT_EQ(r.status, 2) << sweep << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(out)) << sweep;
  }
}

TEST(StudyCommand, StatsCarryFrontAndBackHeightOfTheDamBreak) {
  // At rest the measures read the box exactly (the edge particle's centre plus the particle radius); then the
  // front advances and the column drops. Against the right wall they read the same (distances from that wall).
  for (const std::string side : {"left", "right"}) {
    const fs::path scene = writeTestScene("tiny.json", kTinyDamBreak);
    const fs::path out = fs::path(testing::TempDir()) / ("surge_front_" + side);
    fs::remove_all(out);
    const std::string set = side == "right" ? " --set 'fluids[0].box.min=[0.8,0]' --set 'fluids[0].box.max=[1.2,0.4]'" : "";
    ASSERT_EQ(runSurge("sim '" + scene.string() + "' --quiet --out " + out.string() + set).status, 0);
    const auto rows = readCsv(out / "stats.csv");
    ASSERT_EQ(rows.size(), 12u);
    const int front = column(rows[0], "front_x"), height = column(rows[0], "back_height");
    // Appended after the columns before them (which keep their positions), and before later ones (emitted).
    ASSERT_EQ(front, column(rows[0], "divergence_iterations") + 1);
    ASSERT_EQ(height, front + 1);
    ASSERT_EQ(column(rows[0], "emitted"), height + 1);
    EXPECT_NEAR(std::stod(rows[1][front]), 0.4, 1e-6) << side;
    EXPECT_NEAR(std::stod(rows[1][height]), 0.4, 1e-6) << side;
    EXPECT_GT(std::stod(rows[11][front]), 0.6) << side;   // 1/3 s: the front has run about 2 column heights
    EXPECT_LT(std::stod(rows[11][height]), 0.35) << side;
  }
}

}  // namespace
}  // namespace surge
