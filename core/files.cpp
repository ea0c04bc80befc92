#include "core/files.h"

#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/errors.h"

namespace surge {

std::string writeFailure(int error) {
  if (error == ENOSPC || error == EDQUOT) return "the disk is full (" + std::string(std::strerror(error)) + ")";
  return error != 0 ? std::string(std::strerror(error)) : "the write failed";
}

void writeFileAtomically(const fs::path& path, const std::function<void(std::ostream&)>& write) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  fs::path temporary = path;
  temporary += ".tmp" + std::to_string(::getpid());
  try {
    {
      errno = 0;
      std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
      if (!out) throw RunError("cannot write " + path.string() + ": " + writeFailure(errno));
      write(out);
      out.flush();
      if (out) out.close();
      // The stream keeps no error code of its own: errno still holds the failed write's (ENOSPC on a full disk).
      if (!out) throw RunError("cannot write " + path.string() + ": " + writeFailure(errno));
    }
    fs::rename(temporary, path);
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
}

fs::path fluidMeshPath(const fs::path& meshPath, const std::string& name) {
  return meshPath.parent_path().parent_path() / ("surface_" + name) / meshPath.filename();
}

fs::path framePath(const fs::path& dir, const std::string& sub, int frame, const std::string& ext) {
  char name[64];
  std::snprintf(name, sizeof name, "frame_%05d.%s", frame, ext.c_str());
  return dir / sub / name;
}

namespace {

// The frame number of a file name framePath writes (frame_ and five digits or more, then .ext), or -1: frames
// above 99,999 take six or seven digits; a name framePath would not write (frame_0123456.ply) is not a frame.
int frameNumber(const std::string& name, const std::string& ext) {
  const std::string suffix = "." + ext;
  if (name.size() <= 6 + suffix.size() || name.rfind("frame_", 0) != 0) return -1;
  if (name.compare(name.size() - suffix.size(), std::string::npos, suffix) != 0) return -1;
  const std::string digits = name.substr(6, name.size() - 6 - suffix.size());
  if (digits.size() < 5 || digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), ::isdigit)) return -1;
  const int frame = std::stoi(digits);
  return framePath("", "", frame, ext).filename() == name ? frame : -1;
}

}  // namespace

std::vector<int> listFrames(const fs::path& dir, const std::string& sub, const std::string& ext) {
  std::vector<int> frames;
  const fs::path folder = dir / sub;
  std::error_code error;
  if (!fs::is_directory(folder, error)) return frames;
  for (const auto& entry : fs::directory_iterator(folder))
    if (const int frame = frameNumber(entry.path().filename().string(), ext); frame >= 0) frames.push_back(frame);
  std::sort(frames.begin(), frames.end());
  return frames;
}

void removeTemporaries(const fs::path& dir, const std::string& sub, const std::string& ext, const FrameRange& range) {
  const fs::path folder = dir / sub;
  std::error_code error;
  if (!fs::is_directory(folder, error)) return;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    const size_t tmp = name.rfind(".tmp");
    if (tmp == std::string::npos) continue;
    const int frame = frameNumber(name.substr(0, tmp), ext);
    if (frame >= 0 && range.contains(frame)) fs::remove(entry.path(), error);
  }
}

void removeFrames(const fs::path& dir, const std::string& sub, const std::vector<std::string>& exts) {
  for (const std::string& ext : exts)
    for (int frame : listFrames(dir, sub, ext)) fs::remove(framePath(dir, sub, frame, ext));
}

bool isUpToDate(const std::vector<fs::path>& outputs, const std::vector<fs::path>& inputs) {
  std::error_code error;
  fs::file_time_type newestInput = fs::file_time_type::min();
  for (const fs::path& input : inputs) {
    const auto time = fs::last_write_time(input, error);
    if (error) return false;
    newestInput = std::max(newestInput, time);
  }
  for (const fs::path& output : outputs) {
    const auto time = fs::last_write_time(output, error);
    if (error || time < newestInput) return false;
  }
  return true;
}

FrameRange FrameRange::parse(const std::string& text) {
  FrameRange range;
  const auto colon = text.find(':');
  auto number = [&](const std::string& part, int fallback) {
    if (part.empty()) return fallback;
    if (!std::all_of(part.begin(), part.end(), ::isdigit) || part.size() > 9)
      throw InputError("--frames", "expected A:B with frame numbers, got '" + text + "'");
    return std::stoi(part);
  };
  if (colon == std::string::npos) {
    range.first = range.last = number(text, 0);
    if (text.empty()) throw InputError("--frames", "expected A:B, got an empty value");
  } else {
    range.first = number(text.substr(0, colon), 0);
    range.last = number(text.substr(colon + 1), range.last);
  }
  if (range.last < range.first) throw InputError("--frames", "the range '" + text + "' is empty");
  return range;
}

std::string readTextFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot be read");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

int CsvTable::column(const std::string& name) const {
  for (size_t c = 0; c < header.size(); ++c)
    if (header[c] == name) return int(c);
  return -1;
}

CsvTable readCsvTable(const fs::path& path) {
  std::istringstream lines(readTextFile(path));
  CsvTable table;
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    std::vector<std::string> fields = splitCsvLine(line);
    if (table.header.empty()) table.header = std::move(fields);
    else if (fields.size() == table.header.size()) table.rows.push_back(std::move(fields));
  }
  if (table.header.empty()) throw InputError(path.string(), "empty: no header line");
  return table;
}

std::string escapeXml(const std::string& text) {
  std::string escaped;
  for (char c : text) {
    if (c == '&') escaped += "&amp;";
    else if (c == '<') escaped += "&lt;";
    else if (c == '>') escaped += "&gt;";
    else if (c == '"') escaped += "&quot;";
    else escaped += c;
  }
  return escaped;
}

void checkOutputFolder(const fs::path& dir) {
  std::error_code error;
  if (fs::exists(dir, error) && !fs::is_directory(dir, error))
    throw InputError(dir.string(), "the output folder is a file, not a folder");
  fs::create_directories(dir, error);
  if (error) throw InputError(dir.string(), "the output folder cannot be made: " + error.message());
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(dir.string(), "the output folder cannot be written: " + std::string(std::strerror(errno)));
  for (auto entry = fs::recursive_directory_iterator(dir, error); !error && entry != fs::recursive_directory_iterator();
       entry.increment(error))
    if (entry->is_symlink(error) && fs::is_directory(entry->path(), error))
      throw InputError(entry->path().string(),
                       "is a symbolic link to a folder; Surge writes only inside its output folder");
}

void checkFreeSpace(const fs::path& dir, const std::string& key, double bytes, const std::string& what) {
  // The folder may not be made yet: its nearest existing parent is on the same file system.
  fs::path existing = fs::absolute(dir);
  std::error_code error;
  while (!fs::exists(existing, error) && existing.has_parent_path() && existing != existing.parent_path())
    existing = existing.parent_path();
  struct statvfs info {};
  if (::statvfs(existing.c_str(), &info) != 0) return;  // a file system that cannot say: left to the writes
  const double free = double(info.f_bavail) * double(info.f_frsize);
  if (bytes <= free) return;
  throw InputError(dir.string(), key,
                   what + " need about " + formatBytes(bytes) + " and its file system has " + formatBytes(free) +
                       " free");
}

std::string formatBytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, bytes >= 1e9 ? "%.1f GB" : "%.1f MB", bytes >= 1e9 ? bytes / 1e9 : bytes / 1e6);
  return text;
}

}  // namespace surge
