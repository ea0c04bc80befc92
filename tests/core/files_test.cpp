#include "core/files.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "core/errors.h"
#include "core/parallel.h"

namespace surge {
namespace {

TEST(Files, AtomicWriteLeavesOldFileWhenWriterFails) {
  const fs::path dir = fs::path(testing::TempDir()) / "surge_files_test";
  fs::remove_all(dir);
  const fs::path path = dir / "a.txt";
  writeFileAtomically(path, [](std::ostream& out) { out << "first"; });
  EXPECT_THROW(writeFileAtomically(path,
                                   [](std::ostream& out) {
                                     out << "half";
                                     throw std::runtime_error("disk full");
                                   }),
               std::runtime_error);
  EXPECT_EQ(readTextFile(path), "first");
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1u);  // no temporary left behind
}

TEST(Files, FrameNamesAndListing) {
  const fs::path dir = fs::path(testing::TempDir()) / "surge_frames_test";
  fs::remove_all(dir);
  EXPECT_EQ(framePath(dir, "particles", 7, "ply"), dir / "particles" / "frame_00007.ply");
  for (int f : {3, 0, 12}) writeFileAtomically(framePath(dir, "particles", f, "ply"), [](std::ostream&) {});
  writeFileAtomically(dir / "particles" / "frame_00004.ply.tmp123", [](std::ostream&) {});
  EXPECT_EQ(listFrames(dir, "particles", "ply"), (std::vector<int>{0, 3, 12}));
  // Frames above 99,999 take six and seven digits (output.frames reaches 10^7); every stage lists them.
  for (int f : {99999, 100000, 1234567}) writeFileAtomically(framePath(dir, "particles", f, "ply"), [](std::ostream&) {});
  EXPECT_EQ(framePath(dir, "particles", 1234567, "ply").filename(), "frame_1234567.ply");
  for (const char* odd : {"frame_0000012.ply", "frame_1234.ply", "frame_12345.plyx", "frame_1x345.ply"})
    writeFileAtomically(dir / "particles" / odd, [](std::ostream&) {});
  EXPECT_EQ(listFrames(dir, "particles", "ply"), (std::vector<int>{0, 3, 12, 99999, 100000, 1234567}));
  EXPECT_TRUE(listFrames(dir, "nothing", "ply").empty());
  // A killed run's temporaries go, for the frames in the range only (another task may be writing the others).
  writeFileAtomically(dir / "particles" / "frame_100000.ply.tmp77", [](std::ostream&) {});
  removeTemporaries(dir, "particles", "ply", FrameRange::parse("5:99999"));
  EXPECT_TRUE(fs::exists(dir / "particles" / "frame_00004.ply.tmp123"));
  removeTemporaries(dir, "particles", "ply", FrameRange::parse("4:100000"));
  EXPECT_FALSE(fs::exists(dir / "particles" / "frame_00004.ply.tmp123"));
  EXPECT_FALSE(fs::exists(dir / "particles" / "frame_100000.ply.tmp77"));
  EXPECT_TRUE(fs::exists(framePath(dir, "particles", 100000, "ply")));
}

TEST(Files, FrameRanges) {
  EXPECT_EQ(FrameRange::parse("2:5").first, 2);
  EXPECT_EQ(FrameRange::parse("2:5").last, 5);
  EXPECT_TRUE(FrameRange::parse("4:").contains(100000));
  EXPECT_FALSE(FrameRange::parse(":4").contains(5));
  EXPECT_EQ(FrameRange::parse("7").last, 7);
  EXPECT_THROW(FrameRange::parse("5:2"), InputError);
  EXPECT_THROW(FrameRange::parse("a:b"), InputError);
}

// The report and the USD export read stats.csv and bodies.csv by column name; a row a killed run cut short is left out.
TEST(Files, CsvTablesByColumnName) {
  const fs::path dir = fs::path(testing::TempDir()) / "surge_csv_test";
  fs::create_directories(dir);
  writeFileAtomically(dir / "bodies.csv",
                      [](std::ostream& out) { out << "frame,body,x\n0,crate,0.5\n1,crate,0.25\n2,cra"; });
  const CsvTable table = readCsvTable(dir / "bodies.csv");
  ASSERT_EQ(table.rows.size(), 2u);
  EXPECT_EQ(table.column("x"), 2);
  EXPECT_EQ(table.column("y"), -1);
  EXPECT_EQ(table.rows[1][2], "0.25");
  writeFileAtomically(dir / "empty.csv", [](std::ostream&) {});
  EXPECT_THROW(readCsvTable(dir / "empty.csv"), InputError);
  EXPECT_EQ(escapeXml("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
}

TEST(Parallel, SumIsTheSameWhateverTheThreadCount) {
  // Floating-point sums depend on their order; fixed chunks make the order independent of the threads.
  auto sum = [] {
    return parallelSum<double>(0, 1000003, [](size_t b, size_t e) {
      double s = 0;
      for (size_t i = b; i < e; ++i) s += 1.0 / double(i + 1);
      return s;
    });
  };
  double one, two;
  {
    ThreadLimit limit(1);
    one = sum();
  }
  {
    ThreadLimit limit(2);
    two = sum();
  }
  EXPECT_EQ(one, two);
  EXPECT_NEAR(one, std::log(1000003.0) + 0.5772156649, 1e-6);
}

}  // namespace
}  // namespace surge
