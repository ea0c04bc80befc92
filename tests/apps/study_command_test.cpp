// `surge study` as a user runs it: a small sweep, its study.csv and plots; bad sweeps refused before anything is
// written; and the dam-break columns of stats.csv.
#include <gtest/gtest.h>

#include <cmath>
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
                                 "solver.substeps=20,30 --frames 8 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = readCsv(out / "study.csv");
  ASSERT_EQ(rows.size(), 5u);
  const auto& header = rows[0];
  const int iterations = column(header, "solver.iterations"), substeps = column(header, "solver.substeps");
  const int reference = column(header, "reference"), error = column(header, "error"), steps = column(header, "steps");
  const int cpu = column(header, "cpu_seconds"), peak = column(header, "peak_mb"), status = column(header, "status");
  ASSERT_GE(std::min({iterations, substeps, reference, error, steps, cpu, peak, status}), 0);
  // The first sweep varies slowest. (At 40 substeps PBF's s_corr, a push a step, gives this small dam break 2.6%
  // of its energy from nowhere, and the energy stop ends the run: docs/speed-accuracy.md.)
  EXPECT_EQ(rows[1][iterations] + rows[1][substeps] + rows[2][substeps] + rows[3][iterations], "120304");
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i][status], "ok");
    // Both counts are above what the flow needs (PBF's steps are never longer than its CFL and depth steps).
    EXPECT_EQ(std::stoi(rows[i][steps]), 8 * std::stoi(rows[i][substeps]));
    EXPECT_GT(std::stod(rows[i][cpu]), 0);
    EXPECT_GT(std::stod(rows[i][peak]), 1);
    // The reference (4 iterations, 30 substeps: the most work) compares as 0; the others differ from it.
    EXPECT_EQ(rows[i][reference], i == 4 ? "1" : "0");
    if (i == 4) EXPECT_LT(std::stod(rows[i][error]), 1e-9);
    else EXPECT_GT(std::stod(rows[i][error]), 1e-6);
  }
  EXPECT_TRUE(fs::exists(out / "runs" / "003_solver.iterations=4,solver.substeps=30" / "stats.csv"));
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
                                  "solver.iterations=1,-1", "surface.method=spheres,anisotropic"}) {
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

// The tiny dam break with a cork floating beyond the column, for a body's measure.
std::string tinyDamBreakWithCork() {
  std::string text = kTinyDamBreak;
  text.insert(text.find("\"output\""), R"("bodies": [{"name": "cork", "shape": "box", "size": [0.1, 0.06], "position": [0.8, 0.1],
    "density": 300}],
  )");
  return text;
}

// surge study --measure (issue 32): the observed order and the Richardson-extrapolated value of a quantity over a
// particle_spacing sweep, checked on runs whose answer is known exactly, on a real sweep, and on bad input.
// Runs already on disk whose front_x at 0.1 s is 2 + 3 h^2 exactly, at spacings in unequal ratios (0.04, 0.03,
// 0.02): `--report` reads them, and the observed order is 2 and the extrapolated value 2 to the printed digits,
// each run's error estimate 3 h^2. Half-way between two frames (0.05 s) the value is the frames' mean.
TEST(StudyConvergence, OrderAndExtrapolationOfAnExactlyKnownQuantity) {
  const fs::path scene = writeTestScene("tiny_convergence.json", tinyDamBreakWithCork());
  const fs::path out = fs::path(testing::TempDir()) / "surge_convergence_exact";
  fs::remove_all(out);
  const double spacings[] = {0.04, 0.03, 0.02};
  for (int k = 0; k < 3; ++k) {
    char name[64];
    std::snprintf(name, sizeof name, "%03d_particle_spacing=%g", k, spacings[k]);
    const fs::path run = out / "runs" / name;
    fs::create_directories(run);
    std::ofstream stats(run / "stats.csv");
    stats << "frame,time,particles,substeps,iterations,front_x,back_height\n";
    for (int frame = 0; frame <= 4; ++frame) {
      const double h = spacings[k], value = frame == 3 ? 2 + 3 * h * h : (frame == 1 ? 1.0 : 1.5);
      stats << frame << "," << frame / 30.0 << ",400,4,4," << value << ",0.3\n";
    }
    std::ofstream(run / "run.json") << R"({"status": "ok", "cpu_seconds": 1, "wall_seconds": 1})";
    // The last frame the report compares the runs' density fields at: one particle, the same in each.
    fs::create_directories(run / "particles");
    std::ofstream(run / "particles" / "frame_00004.ply")
        << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
        << "property float vx\nproperty float vy\nproperty float vz\nproperty uint id\nend_header\n"
        << "0.1 0.1 0 0 0 0 0\n";
  }
  const SurgeResult r = runSurge("study '" + scene.string() + "' --quiet --report --sweep particle_spacing=0.04,0.03,0.02" +
                                 " --measure front_x@0.1 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = readCsv(out / "convergence.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0][0] + rows[0][1] + rows[0][2] + rows[0][3] + rows[0][4],
            "particle_spacingmeasurederror_estimateobserved_orderextrapolated");
  for (size_t i = 1; i < rows.size(); ++i) {
    const double h = spacings[i - 1];
    EXPECT_DOUBLE_EQ(std::stod(rows[i][0]), h);
    EXPECT_NEAR(std::stod(rows[i][2]), 3 * h * h, 1e-8);
    EXPECT_NEAR(std::stod(rows[i][3]), 2.0, 1e-5);
    EXPECT_NEAR(std::stod(rows[i][4]), 2.0, 1e-8);
  }
  EXPECT_TRUE(fs::exists(out / "convergence.png"));
  // Between frames: the mean of frames 1 and 2, the same in every run, converged.
  const SurgeResult between = runSurge("study '" + scene.string() + "' --report --sweep particle_spacing=0.04,0.03,0.02" +
                                       " --measure front_x@0.05 --out " + out.string());
  ASSERT_EQ(between.status, 0) << between.err;
  EXPECT_NE(between.out.find("the two finest runs agree exactly"), std::string::npos) << between.out;
  EXPECT_DOUBLE_EQ(std::stod(readCsv(out / "convergence.csv")[1][1]), 1.25);
}

// A real sweep: three spacings of the tiny dam break, the cork's height from bodies.csv at 0.3 s. Every run
// reaches it, and the table has one row a spacing, coarsest first, with the measured values.
TEST(StudyConvergence, ASpacingSweepMeasuresABodyColumn) {
  const fs::path scene = writeTestScene("tiny_convergence.json", tinyDamBreakWithCork());
  const fs::path out = fs::path(testing::TempDir()) / "surge_convergence_sweep";
  fs::remove_all(out);
  const SurgeResult r = runSurge("study '" + scene.string() + "' --sweep particle_spacing=0.02,0.04,0.03" +
                                 " --measure bodies.cork.y@0.3 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("bodies.cork.y@0.3"), std::string::npos) << r.out;
  const auto rows = readCsv(out / "convergence.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[1][0] + "/" + rows[2][0] + "/" + rows[3][0], "0.04/0.03/0.02");
  for (size_t i = 1; i < rows.size(); ++i) {
    const double y = std::stod(rows[i][1]);
    EXPECT_GT(y, 0.0);  // the cork is in the tank, floating or carried
    EXPECT_LT(y, 0.6);
    EXPECT_GE(std::stod(rows[i][2]), 0.0);
  }
}

// One line naming the key, exit 2, nothing written: a column no file has, a body the scene lacks, a time past the
// run, two spacings, another key swept.
TEST(StudyConvergence, BadMeasuresAreRefusedBeforeAnythingIsWritten) {
  const fs::path scene = writeTestScene("tiny_convergence.json", tinyDamBreakWithCork());
  const fs::path out = fs::path(testing::TempDir()) / "surge_convergence_bad";
  fs::remove_all(out);
  const std::string spacings = " --sweep particle_spacing=0.04,0.03,0.02";
  const std::pair<std::string, std::string> cases[] = {
      {spacings + " --measure no_such_column@0.1", "--measure"},
      {spacings + " --measure bodies.ghost.y@0.1", "--measure"},
      {spacings + " --measure colliders.cork.fx@0.1", "--measure"},
      {spacings + " --measure bodies.cork.no_such@0.1", "--measure"},
      {spacings + " --measure front_x@5", "--measure"},
      {spacings + " --measure front_x", "--measure"},
      {" --sweep particle_spacing=0.04,0.02 --measure front_x@0.1", "--sweep"},
      {" --sweep solver.iterations=1,2,4 --measure front_x@0.1", "--measure"},
  };
  for (const auto& [arguments, key] : cases) {
    const SurgeResult r = runSurge("study '" + scene.string() + "' --quiet" + arguments + " --out " + out.string());
    EXPECT_EQ(r.status, 2) << arguments << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(key), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << arguments;
  }
}

}  // namespace
}  // namespace surge
