// The frame loop on a scene into a folder of the test's temporary directory, for the tests that read its files.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/files.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "sim/simulation.h"
#include "tests/sim/stats_columns.h"

namespace surge {

// Runs `scene` into TempDir()/name at `threads` threads, into a fresh folder, or on from its frames with `resume`.
inline fs::path runScene(const Scene& scene, const std::string& name, int threads = 2, bool resume = false) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  if (!resume) fs::remove_all(dir);
  ThreadLimit limit(threads);
  Progress quiet;
  simulate(scene, dir, resume, quiet);
  return dir;
}

// The mean of colliders.csv's `column` over frames [first, last], of the rows of collider `name` (empty: every
// row, for a scene with one collider).
inline double meanColliderColumn(const fs::path& dir, const std::string& column, int first, int last,
                                 const std::string& name = "") {
  const auto rows = readCsvRows(dir / "colliders.csv");
  if (rows.empty()) {
    ADD_FAILURE() << "no colliders.csv in " << dir;
    return 0;
  }
  const auto found = std::find(rows[0].begin(), rows[0].end(), column);
  EXPECT_NE(found, rows[0].end()) << column;
  const size_t wanted = size_t(found - rows[0].begin());
  double sum = 0;
  int count = 0;
  for (size_t r = 1; r < rows.size(); ++r) {
    const auto& row = rows[r];
    if (row.size() <= wanted) continue;
    const int f = std::stoi(row[0]);
    if (f < first || f > last || (!name.empty() && row[1] != name)) continue;
    sum += std::stod(row[wanted]);
    ++count;
  }
  EXPECT_EQ(count, last - first + 1);
  return count ? sum / count : 0;
}
inline double meanColliderFy(const fs::path& dir, int first, int last) {
  return meanColliderColumn(dir, "fy", first, last);
}

}  // namespace surge
