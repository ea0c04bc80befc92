#include "render/video.h"

#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"

extern char** environ;

namespace surge {

namespace {

// The full path of a program found on PATH, or empty.
fs::path findProgram(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream folders(path ? path : "");
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    if (folder.empty()) continue;
    const fs::path candidate = fs::path(folder) / name;
    if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate)) return candidate;
  }
  return {};
}

struct ProgramResult {
  int exitCode = -1;  // -1 if it did not exit normally (a signal)
  std::string output, errors;
};

// Runs a program without a shell (arguments are passed as they are) and collects what it prints.
ProgramResult runProgram(const fs::path& program, const std::vector<std::string>& arguments) {
  int outPipe[2], errPipe[2];
  if (::pipe(outPipe) != 0) throw RunError("cannot create a pipe: " + std::string(std::strerror(errno)));
  if (::pipe(errPipe) != 0) {
    ::close(outPipe[0]), ::close(outPipe[1]);
    throw RunError("cannot create a pipe: " + std::string(std::strerror(errno)));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, outPipe[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, errPipe[1], STDERR_FILENO);
  for (int fd : {outPipe[0], outPipe[1], errPipe[0], errPipe[1]})
    posix_spawn_file_actions_addclose(&actions, fd);

  std::vector<std::string> words{program.string()};
  words.insert(words.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);

  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(outPipe[1]);
  ::close(errPipe[1]);
  if (spawned != 0) {
    ::close(outPipe[0]), ::close(errPipe[0]);
    throw RunError("cannot run " + program.string() + ": " + std::strerror(spawned));
  }

  // Read both pipes until the program closes them, so neither can fill up and stall it.
  ProgramResult result;
  pollfd fds[2] = {{outPipe[0], POLLIN, 0}, {errPipe[0], POLLIN, 0}};
  std::string* sinks[2] = {&result.output, &result.errors};
  int open = 2;
  while (open > 0) {
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      char buffer[4096];
      const ssize_t n = ::read(fds[i].fd, buffer, sizeof buffer);
      if (n > 0) {
        sinks[i]->append(buffer, size_t(n));
      } else if (n == 0 || errno != EINTR) {
        ::close(fds[i].fd);
        fds[i].fd = -1;
        --open;
      }
    }
  }
  for (const pollfd& p : fds)
    if (p.fd >= 0) ::close(p.fd);

  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status)) result.exitCode = WEXITSTATUS(status);
  return result;
}

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
  const fs::path temporary = dir / ("." + scene.name + ".mp4.partial");
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
    if (result.exitCode == 0) fs::rename(temporary, video);
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
  if (result.exitCode != 0) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    Progress::checkInterrupt();  // Ctrl-C reaches ffmpeg too: report the interruption, not ffmpeg's exit
    throw RunError(
        "ffmpeg failed to make " + video.string() + ": " +
        (result.errors.empty() ? "exit status " + std::to_string(result.exitCode) : trimmed(result.errors)));
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
