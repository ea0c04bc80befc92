// The frame loop on a scene into a folder of the test's temporary directory, for the tests that read its files.
#pragma once

#include <gtest/gtest.h>

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

}  // namespace surge
