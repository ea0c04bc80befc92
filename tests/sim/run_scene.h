// The frame loop on a scene into a folder of the test's temporary directory, for the tests that read its files.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/files.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "sim/simulation.h"

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
  std::ifstream in(dir / "colliders.csv");
  std::string line, cell;
  std::getline(in, line);
  std::stringstream header(line);
  int wanted = -1;
  for (int c = 0; std::getline(header, cell, ','); ++c)
    if (cell == column) wanted = c;
  EXPECT_GE(wanted, 2) << column;
  double sum = 0;
  int rows = 0;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::vector<std::string> row;
    while (std::getline(cells, cell, ',')) row.push_back(cell);
    if (wanted < 0 || row.size() <= size_t(wanted)) continue;
    const int f = std::stoi(row[0]);
    if (f < first || f > last || (!name.empty() && row[1] != name)) continue;
    sum += std::stod(row[wanted]);
    ++rows;
  }
  EXPECT_EQ(rows, last - first + 1);
  return rows ? sum / rows : 0;
}
inline double meanColliderFy(const fs::path& dir, int first, int last) {
  return meanColliderColumn(dir, "fy", first, last);
}

}  // namespace surge
