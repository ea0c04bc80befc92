// A scene file must never choose where Surge writes (issue: hardening): its name is a plain file name, and a
// run writes inside the output folder it was given (or out/<name>) and nowhere else, whatever is planted there;
// an output folder that cannot be made or written is bad input (exit 2, one line naming it), not a crash.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>

#include "tests/apps/run_surge.h"

namespace surge {
namespace {

const char* kTiny = R"({
  "name": "NAME", "dimensions": 2,
  "domain": {"min": [0, 0], "max": [0.4, 0.4]},
  "particle_spacing": 0.02,
  "fluids": [{"box": {"min": [0, 0], "max": [0.1, 0.1]}}],
  "output": {"fps": 30, "frames": 2}
})";

std::string withName(const std::string& name) {
  std::string text = kTiny;
  text.replace(text.find("NAME"), 4, name);
  return text;
}

// Escapes through the name: absolute, .. and a path. Run from a fresh working folder, so that out/ is its own;
// nothing may appear anywhere under the test's temporary folder but the scene file.
TEST(OutputFolder, SceneNamesCannotEscape) {
  const fs::path base = freshFolder("escape_base");
  const fs::path work = base / "work" / "deeper";
  fs::create_directories(work);
  for (const std::string& name : {std::string("/tmp/surge_escape_abs") + std::to_string(::getpid()),
                                  std::string("../../escaped"), std::string("a/b"), std::string(".hidden"),
                                  std::string("..")}) {
    const fs::path scene = writeTestScene("escape.json", withName(name));
    const std::string command = "cd '" + work.string() + "' && " + std::string(SURGE_BINARY) + " sim '" +
                                scene.string() + "' --quiet > /dev/null 2> err.txt";
    const int raw = std::system(command.c_str());
    const int status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    const std::string err = readTextFile(work / "err.txt");
    fs::remove(work / "err.txt");
    EXPECT_EQ(status, 2) << name << ": " << err;
    EXPECT_EQ(err.rfind("surge: " + scene.string() + ": name: ", 0), 0u) << name << ": " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(fs::exists(work / "out")) << name;
    EXPECT_FALSE(fs::exists(base / "escaped")) << name;
    EXPECT_FALSE(fs::exists(base / "work" / "escaped")) << name;
    EXPECT_FALSE(fs::exists(std::string("/tmp/surge_escape_abs") + std::to_string(::getpid()))) << name;
  }
}

// A symbolic link planted inside the output folder (particles/ pointing elsewhere) is refused before anything
// is written through it.
TEST(OutputFolder, SymlinkPlantedInTheOutputFolderIsRefused) {
  const fs::path out = freshFolder("planted_out"), elsewhere = freshFolder("planted_elsewhere");
  fs::create_directories(out);
  fs::create_directories(elsewhere);
  fs::create_directory_symlink(elsewhere, out / "particles");
  const fs::path scene = writeTestScene("planted.json", withName("planted"));
  const SurgeResult r = runSurge("sim '" + scene.string() + "' --quiet --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("surge: " + (out / "particles").string() + ": ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(fs::is_empty(elsewhere));
  EXPECT_FALSE(fs::exists(out / "scene.json"));
}

// --out where no folder can be: under a file, or on a path that cannot be made. Exit 2, one line naming it.
TEST(OutputFolder, UnwritableOutIsBadInput) {
  const fs::path file = fs::path(testing::TempDir()) / "out_is_a_file";
  std::ofstream(file) << "x";
  const fs::path scene = writeTestScene("unwritable.json", withName("unwritable"));
  for (const fs::path& out : {file, file / "below", fs::path("/proc/surge_cannot_be_here")}) {
    const SurgeResult r = runSurge("sim '" + scene.string() + "' --quiet --out " + out.string());
    EXPECT_EQ(r.status, 2) << out << ": " << r.err;
    EXPECT_EQ(r.err.rfind("surge: " + out.string() + ": ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

}  // namespace
}  // namespace surge
