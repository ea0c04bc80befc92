#include "whitewater/whitewater_stage.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "core/errors.h"
#include "core/ply.h"
#include "whitewater/whitewater.h"

namespace surge {
namespace {

const char* kCountsHeader = "frame,spray,foam,bubbles,born,died,substeps,seconds";

// counts.csv's rows by frame, as the file holds them (none when it is missing).
std::map<int, std::string> readCounts(const fs::path& path) {
  std::map<int, std::string> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    const std::vector<std::string> fields = splitCsvLine(line);
    if (fields.size() == 8 && !fields[0].empty()) rows[std::atoi(fields[0].c_str())] = line;
  }
  return rows;
}

void writeCounts(const fs::path& path, const std::map<int, std::string>& rows) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << kCountsHeader << "\n";
    for (const auto& [frame, row] : rows) out << row << "\n";
  });
}

}  // namespace

void whitewaterFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress,
                      bool resume) {
  const std::vector<int> all = listFrames(dir, "particles", "ply");
  if (all.empty()) throw InputError(dir.string(), "no particle frames (particles/frame_NNNNN.ply) to make whitewater from");
  for (size_t k = 0; k < all.size(); ++k)
    if (all[k] != int(k))
      throw InputError(framePath(dir, "particles", int(k), "ply").string(),
                       "missing: whitewater advances frame by frame from frame 0");
  const int last = std::min(range.last, all.back());
  if (range.first > last)
    throw InputError(dir.string(), "--frames",
                     "no particle frame in " + std::to_string(range.first) + ":" + std::to_string(range.last));
  removeTemporaries(dir, "whitewater", "ply", FrameRange{range.first, last});
  const fs::path settings = writeStageSettings(dir, "whitewater", scene);
  auto upToDate = [&](int f) {
    return isUpToDate({framePath(dir, "whitewater", f, "ply")}, {framePath(dir, "particles", f, "ply"), settings});
  };
  // The frame to start from: range.first's predecessor, or on resume the last of an up-to-date run of frames.
  int start = range.first;
  if (resume && (start == 0 || upToDate(start - 1)))
    while (start <= last && upToDate(start)) ++start;
  if (start > last) return;
  DiffuseFrame diffuse;
  diffuse.dimensions = scene.dimensions;
  const fs::path countsPath = dir / "whitewater" / "counts.csv";
  std::map<int, std::string> rows = readCounts(countsPath);
  for (auto it = rows.lower_bound(start); it != rows.end();) it = rows.erase(it);
  fs::create_directories(dir / "whitewater");
  if (start == 0) {
    writeDiffusePly(framePath(dir, "whitewater", 0, "ply"), diffuse);
    rows[0] = "0,0,0,0,0,0,0,0";
    ++start;
  } else {
    const fs::path before = framePath(dir, "whitewater", start - 1, "ply");
    std::error_code error;
    if (!fs::exists(before, error))
      throw InputError(before.string(), "missing: whitewater frame " + std::to_string(start) +
                                            " is made from it (run the stage from an earlier frame)");
    diffuse = readDiffusePly(before);
  }
  WhitewaterStepper stepper(scene);
  progress.start("whitewater", size_t(std::max(0, last - start + 1)));
  ParticleFrame next = start <= last ? readParticlePly(framePath(dir, "particles", start - 1, "ply")) : ParticleFrame{};
  for (int f = start; f <= last; ++f) {
    Progress::checkInterrupt();
    const auto began = std::chrono::steady_clock::now();
    const ParticleFrame a = std::move(next);
    next = readParticlePly(framePath(dir, "particles", f, "ply"));
    stepper.advance(a, next, f - 1, diffuse);
    writeDiffusePly(framePath(dir, "whitewater", f, "ply"), diffuse);
    const WhitewaterCounts& c = stepper.counts();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    char row[256];
    std::snprintf(row, sizeof row, "%d,%zu,%zu,%zu,%zu,%zu,%d,%.4f", f, c.spray, c.foam, c.bubbles, c.born, c.died,
                  c.substeps, seconds);
    rows[f] = row;
    writeCounts(countsPath, rows);
    progress.advance();
  }
  progress.finish();
}

}  // namespace surge
