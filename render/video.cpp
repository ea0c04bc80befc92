#include "render/video.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/process.h"

namespace surge {

namespace {

std::string trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.pop_back();
  for (char& c : text)
    if (c == '\n') c = ' ';  // errors are one line
  return text;
}

}  // namespace

void makeVideo(const fs::path& dir, const Scene& scene, Progress& progress) {
  const std::vector<int> frames = listFrames(dir, "frames", "png");
  if (frames.empty())
    throw InputError(dir.string(), "frames", "no frames/frame_NNNNN.png to assemble; run surge render first");
  for (size_t i = 1; i < frames.size(); ++i)
    if (frames[i] != frames[i - 1] + 1)
      throw InputError(
          framePath(dir, "frames", frames[i - 1] + 1, "png").string(),
          "is missing: the frames must be consecutive (render it, or remove the frames after it)");
  const fs::path ffmpeg = findProgram("ffmpeg");
  if (ffmpeg.empty()) throw RunError("ffmpeg not found: install it (apt-get install ffmpeg) to make videos");

  const fs::path video = dir / (scene.name + ".mp4");
  // The temporary carries the process id: an ffmpeg left running by a killed `surge` (SIGKILL reaches only surge)
  // may still be writing its own, which must neither mix with this one nor be left behind.
  const std::string partial = "." + scene.name + ".mp4.partial";
  auto removePartials = [&] {
    std::error_code listing;
    for (const auto& entry : fs::directory_iterator(dir, listing))
      if (entry.path().filename().string().rfind(partial, 0) == 0) fs::remove(entry.path(), listing);
  };
  removePartials();
  const fs::path temporary = dir / (partial + std::to_string(::getpid()));
  std::ostringstream fps;
  fps << scene.output.fps;
  const std::vector<std::string> arguments = {"-nostdin",
                                              "-hide_banner",
                                              "-loglevel",
                                              "error",
                                              "-y",
                                              "-framerate",
                                              fps.str(),
                                              "-start_number",
                                              std::to_string(frames.front()),
                                              "-i",
                                              (dir / "frames" / "frame_%05d.png").string(),
                                              "-frames:v",
                                              std::to_string(frames.size()),
                                              "-vf",
                                              "pad=ceil(iw/2)*2:ceil(ih/2)*2",  // yuv420p needs even sides
                                              "-c:v",
                                              "libx264",
                                              "-pix_fmt",
                                              "yuv420p",
                                              "-crf",
                                              "18",
                                              "-movflags",
                                              "+faststart",
                                              "-f",
                                              "mp4",
                                              temporary.string()};

  progress.start("video", 1);
  ProgramResult result;
  try {
    result = runProgram(ffmpeg, arguments);
    if (result.exitCode == 0) {
      fs::rename(temporary, video);
      // An orphan that was still starting when this run began has opened its temporary since: gone again (an
      // orphan still writing writes on into the unlinked file).
      removePartials();
    }
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
  if (result.exitCode != 0) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    Progress::checkInterrupt();  // Ctrl-C reaches ffmpeg too: report the interruption, not ffmpeg's exit
    // ffmpeg's own words for a full disk are several lines about headers and codec parameters.
    const bool full = result.errors.find(std::strerror(ENOSPC)) != std::string::npos;
    throw RunError("ffmpeg failed to make " + video.string() + ": " +
                   (full                   ? writeFailure(ENOSPC)
                    : result.errors.empty() ? "exit status " + std::to_string(result.exitCode)
                                            : trimmed(result.errors)));
  }
  progress.advance();
  progress.finish();
}

int countVideoFrames(const fs::path& video) {
  const fs::path ffprobe = findProgram("ffprobe");
  if (ffprobe.empty()) return -1;
  const ProgramResult result = runProgram(
      ffprobe, {"-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                "stream=nb_read_frames", "-of", "default=noprint_wrappers=1:nokey=1", video.string()});
  try {
    if (result.exitCode == 0) return std::stoi(result.output);
  } catch (const std::exception&) {
  }
  throw RunError("ffprobe cannot count the frames of " + video.string() + ": " +
                 (result.errors.empty() ? trimmed(result.output) : trimmed(result.errors)));
}

}  // namespace surge
