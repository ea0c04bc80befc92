#include "core/process.h"

#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/errors.h"

extern char** environ;

namespace surge {

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

MemoryLimit memoryLimit() {
  MemoryLimit limit{double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE)), "this machine's"};
  auto lower = [&](double bytes, const char* source) {
    if (bytes > 0 && bytes < limit.bytes) limit = {bytes, source};
  };
  // A number of bytes in a file ("max" or a huge value means no limit).
  auto fileBytes = [](const char* path) {
    std::ifstream in(path);
    std::string text;
    if (!(in >> text) || text.empty() || !std::isdigit(static_cast<unsigned char>(text[0]))) return 0.0;
    return std::strtod(text.c_str(), nullptr);
  };
  lower(fileBytes("/sys/fs/cgroup/memory.max"), "this cgroup's");                        // cgroup v2
  lower(fileBytes("/sys/fs/cgroup/memory/memory.limit_in_bytes"), "this cgroup's");      // cgroup v1
  auto environment = [](const char* name) {
    const char* value = std::getenv(name);
    return value ? std::strtod(value, nullptr) : 0.0;
  };
  // Slurm's --mem and --mem-per-cpu, in MB, which hold even where Slurm does not enforce them with cgroups.
  lower(environment("SLURM_MEM_PER_NODE") * 1048576.0, "this Slurm job's");
  lower(environment("SLURM_MEM_PER_CPU") * 1048576.0 * std::max(1.0, environment("SLURM_CPUS_ON_NODE")),
        "this Slurm job's");
  return limit;
}

}  // namespace surge
