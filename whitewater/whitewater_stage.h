// The whitewater stage (surge whitewater DIR): whitewater/frame_NNNNN.ply from particles/frame_NNNNN.ply, each
// frame advanced from the one before, frame 0 empty; and whitewater/counts.csv, one row a frame.
#pragma once

#include "core/files.h"
#include "core/progress.h"
#include "core/scene.h"

namespace surge {

// Makes the whitewater frames of `range` (up to the last particle frame). A range from frame A > 0 starts from
// whitewater frame A - 1, which must be there. With `resume`, starts after the last frame that is up to date
// (newer than its particle frame and whitewater_settings.json). Throws InputError for a folder without particle
// frames or with a gap in them.
void whitewaterFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress,
                      bool resume);

}  // namespace surge
