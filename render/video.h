// The video stage: assembles a run's frames/frame_NNNNN.png into <scene name>.mp4 with the ffmpeg program
// (H.264, yuv420p, scene.output.fps), so any player opens it.
#pragma once

#include "core/files.h"
#include "core/progress.h"
#include "core/scene.h"

namespace surge {

// Writes dir/<scene.name>.mp4 from dir/frames/frame_NNNNN.png, starting at the first frame present; the
// frames must be consecutive. The video is encoded under a temporary name in dir and renamed, so a
// half-written video never carries the final name. Throws InputError(dir, "frames", ...) when there are no
// frames or one is missing, RunError if ffmpeg is not installed or fails (with its messages), Interrupted on
// Ctrl-C.
void makeVideo(const fs::path& dir, const Scene& scene, Progress& progress);

// The number of video frames in a file, counted by ffprobe; -1 if ffprobe is not installed. Throws RunError
// if ffprobe cannot read the file.
int countVideoFrames(const fs::path& video);

}  // namespace surge
