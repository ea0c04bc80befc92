// File helpers shared by every stage: atomic writes, frame file names, frame listing and ranges.
#pragma once

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace surge {

namespace fs = std::filesystem;

// Writes through a temporary file beside `path` and renames it into place, so that a reader sees either the
// old file or the whole new one. On any exception the temporary file is removed and the exception rethrown.
void writeFileAtomically(const fs::path& path, const std::function<void(std::ostream&)>& write);

// Why a write failed, from its errno, for a one-line message: "the disk is full (...)" for ENOSPC and EDQUOT.
std::string writeFailure(int error);

// Throws InputError naming `dir` and `key` when the file system holding `dir` has fewer than `bytes` free:
// a run that would fill the disk is refused before it starts. `what` says what needs the space.
void checkFreeSpace(const fs::path& dir, const std::string& key, double bytes, const std::string& what);

// "12.3 MB" or "4.5 GB", for messages about memory and disk space.
std::string formatBytes(double bytes);

// dir/sub/frame_NNNNN.ext: five digits, more for frames above 99,999 (output.frames reaches 10^7).
fs::path framePath(const fs::path& dir, const std::string& sub, int frame, const std::string& ext);
// The mesh of fluid `name` beside a frame's first mesh in a scene of several fluids: dir/surface_<name>/frame_NNNNN.ply
// beside dir/surface/frame_NNNNN.ply.
fs::path fluidMeshPath(const fs::path& meshPath, const std::string& name);

// The frame numbers of the dir/sub/frame_NNNNN.ext files present (any number of digits framePath writes), sorted.
std::vector<int> listFrames(const fs::path& dir, const std::string& sub, const std::string& ext);

// Removes every dir/sub/frame_NNNNN.ext, for each of `exts`.
void removeFrames(const fs::path& dir, const std::string& sub, const std::vector<std::string>& exts);

struct FrameRange;
// Removes what a killed run left of the frames in `range`: dir/sub/frame_NNNNN.ext.tmpPID, the temporaries of
// writeFileAtomically. A stage calls it for its own frames only, so that a task writing other frames beside it
// (a Slurm array task) keeps its own.
void removeTemporaries(const fs::path& dir, const std::string& sub, const std::string& ext, const FrameRange& range);

// Whether every one of `outputs` exists and none is older than any of `inputs`: a frame made from these inputs
// by an earlier run that stopped later (`surge run --resume` skips it; the bytes would be the same).
bool isUpToDate(const std::vector<fs::path>& outputs, const std::vector<fs::path>& inputs);

// An inclusive range of frames, from a --frames "A:B" flag ("A:" and ":B" leave an end open).
struct FrameRange {
  int first = 0;
  int last = 1 << 30;
  bool contains(int frame) const { return frame >= first && frame <= last; }
  static FrameRange parse(const std::string& text);  // throws InputError naming --frames
};

// Makes `dir` ready to be written by a stage, or throws InputError naming it (one line, exit 2): it must be a
// folder (made if missing) that can be written, and hold no symbolic link to a folder anywhere inside it, so that
// a run writes inside the output folder it was given and nowhere else, whatever was planted there.
void checkOutputFolder(const fs::path& dir);

// Reads a whole text file; throws InputError naming the file if it cannot be read.
std::string readTextFile(const fs::path& path);
// The fields of one line of the CSV files surge writes (no quoting: only study.csv quotes, and is not read).
std::vector<std::string> splitCsvLine(const std::string& line);
// A CSV file surge writes (stats.csv, bodies.csv, colliders.csv) by column name: its header and each row's fields;
// a row of another field count (cut short by a killed run) is left out. Throws InputError naming the file when it
// cannot be read or is empty.
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  int column(const std::string& name) const;  // its index, or -1
};
CsvTable readCsvTable(const fs::path& path);

// `text` with & < > " escaped, to stand in XML or HTML text or an attribute (the exporters' and the report's).
std::string escapeXml(const std::string& text);

}  // namespace surge
