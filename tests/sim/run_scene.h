// The frame loop on a scene into a folder of the test's temporary directory, for the tests that read its files.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

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

// The mean fy of colliders.csv's rows (collider 0, the only one) over frames [first, last].
inline double meanColliderFy(const fs::path& dir, int first, int last) {
  std::ifstream in(dir / "colliders.csv");
  std::string line;
  std::getline(in, line);
  double sum = 0;
  int rows = 0;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::string frame, collider, fx, fy;
    std::getline(cells, frame, ',');
    std::getline(cells, collider, ',');
    std::getline(cells, fx, ',');
    std::getline(cells, fy, ',');
    const int f = std::stoi(frame);
    if (f < first || f > last) continue;
    sum += std::stod(fy);
    ++rows;
  }
  EXPECT_EQ(rows, last - first + 1);
  return rows ? sum / rows : 0;
}

}  // namespace surge
