// What frames on many machines need (issue 13): every stage sees frames above 99,999, and only the simulation
// refuses a folder by the memory its particles need, against the job's limit rather than the machine's.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>

#include "core/files.h"
#include "core/ply.h"
#include "tests/apps/run_surge.h"

namespace surge {
namespace {

const char* kSmallScene = R"({
  "name": "small",
  "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [0.6, 0.4, 0.3]},
  "particle_spacing": 0.03,
  "fluids": [{"box": {"min": [0, 0, 0], "max": [0.18, 0.24, 0.15]}}],
  "output": {"fps": 30, "frames": 2},
  "render": {"width": 96, "height": 64, "samples": 1}
})";

// Frame 100,000 is written with six digits; the simulation resumes from it, and surface, render and video
// find it and the frames after it.
TEST(Cluster, EveryStageSeesFramesAboveNinetyNineThousand) {
  const fs::path scene = writeTestScene("small.json", kSmallScene);
  const fs::path out = freshFolder("surge_cluster_frames");
  const std::string folder = " --quiet --out '" + out.string() + "'";
  ASSERT_EQ(runSurge("sim '" + scene.string() + "'" + folder).status, 0);
  // As if the run had reached frame 100,000: its last frame renamed, its rows kept.
  fs::rename(framePath(out, "particles", 2, "ply"), framePath(out, "particles", 100000, "ply"));
  ASSERT_TRUE(fs::exists(out / "particles" / "frame_100000.ply"));
  // And as if a kill had cut the next row short: the resumed run drops it.
  std::ofstream(out / "stats.csv", std::ios::app) << "999";
  const SurgeResult resumed = runSurge("sim '" + scene.string() + "' --resume --set output.frames=100002" + folder);
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_EQ(listFrames(out, "particles", "ply"), (std::vector<int>{0, 1, 100000, 100001, 100002}));
  const std::vector<std::string> rows = lines(readTextFile(out / "stats.csv"));
  ASSERT_EQ(rows.size(), 6u);  // the header, frames 0-2 as first simulated, and 100001, 100002
  EXPECT_EQ(rows[4].rfind("100001,", 0), 0u) << rows[4];
  EXPECT_EQ(rows[5].rfind("100002,", 0), 0u) << rows[5];

  const std::string range = " --frames 100000: --quiet";
  const SurgeResult surfaced = runSurge("surface '" + out.string() + "'" + range);
  ASSERT_EQ(surfaced.status, 0) << surfaced.err;
  EXPECT_EQ(listFrames(out, "surface", "ply"), (std::vector<int>{100000, 100001, 100002}));
  const SurgeResult rendered = runSurge("render '" + out.string() + "' --renderer gl" + range);
  ASSERT_EQ(rendered.status, 0) << rendered.err;
  EXPECT_EQ(listFrames(out, "frames", "png"), (std::vector<int>{100000, 100001, 100002}));
  const SurgeResult video = runSurge("video '" + out.string() + "' --quiet");
  ASSERT_EQ(video.status, 0) << video.err;
  EXPECT_EQ(countVideoFrames(out / "small.mp4"), 3);
  fs::remove_all(out);
}

// A Slurm job that asked for 1 MB (SLURM_MEM_PER_NODE): the simulation of 6,480 particles (about 2.6 MB) is
// refused naming the job's limit, exit 2, nothing written; surfacing and rendering a folder of that size go on.
TEST(Cluster, OnlyTheSimulationChecksMemoryAndAgainstTheJobsLimit) {
  const fs::path scene = writeTestScene("small.json", kSmallScene);
  const fs::path out = freshFolder("surge_cluster_memory");
  const std::string args = "'" + scene.string() + "' --set particle_spacing=0.01 --quiet --out '" + out.string() + "'";
  ASSERT_EQ(runSurge("sim " + args).status, 0);
  ::setenv("SLURM_MEM_PER_NODE", "1", 1);
  const SurgeResult refused = runSurge("sim " + args + " --set output.frames=1");
  const SurgeResult surfaced = runSurge("surface '" + out.string() + "' --quiet");
  const SurgeResult rendered = runSurge("render '" + out.string() + "' --renderer gl --quiet");
  ::unsetenv("SLURM_MEM_PER_NODE");
  EXPECT_EQ(refused.status, 2);
  EXPECT_EQ(lines(refused.err).size(), 1u) << refused.err;
  EXPECT_NE(refused.err.find("particle_spacing: 6480 particles need about 2.6 MB to simulate, more than this Slurm "
                             "job's 1.0 MB allow"),
            std::string::npos)
      << refused.err;
  EXPECT_EQ(listFrames(out, "particles", "ply").size(), 3u) << "the refused run must leave the folder as it was";
  ASSERT_EQ(surfaced.status, 0) << surfaced.err;
  ASSERT_EQ(rendered.status, 0) << rendered.err;
  EXPECT_EQ(listFrames(out, "frames", "png"), (std::vector<int>{0, 1, 2}));
  fs::remove_all(out);
}

// surge surface --wait (the surface tasks of surge run --slurm --stream) started beside a running simulation
// surfaces every frame as it arrives and ends when the last is done.
TEST(Cluster, SurfaceWaitFollowsARunningSimulation) {
  const fs::path scene = writeTestScene("small.json", kSmallScene);
  const fs::path out = freshFolder("surge_cluster_wait");
  const std::string log = (fs::path(testing::TempDir()) / "surge_cluster_wait.log").string();
  const std::string command = "(" + std::string(SURGE_BINARY) + " sim '" + scene.string() +
                              "' --set output.frames=20 --quiet --out '" + out.string() + "' & " + SURGE_BINARY +
                              " surface '" + out.string() + "' --wait --quiet; s=$?; wait; exit $s) >" + log + " 2>&1";
  const int raw = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << readTextFile(log);
  std::vector<int> all(21);
  for (int f = 0; f <= 20; ++f) all[f] = f;
  EXPECT_EQ(listFrames(out, "surface", "ply"), all);
  EXPECT_EQ(lines(readTextFile(out / "sim_status.txt")), std::vector<std::string>{"finished"});
  // The surfaces are the same as surfacing the finished simulation (a frame is read only once it is whole).
  const std::string frame20 = readTextFile(framePath(out, "surface", 20, "ply"));
  ASSERT_EQ(runSurge("surface '" + out.string() + "' --quiet").status, 0);
  EXPECT_EQ(readTextFile(framePath(out, "surface", 20, "ply")), frame20);

  // A simulation that has finished without the frames asked for: --wait gives up, naming the first missing.
  const SurgeResult gaveUp = runSurge("surface '" + out.string() + "' --wait --frames 18:25 --set output.frames=30");
  EXPECT_EQ(gaveUp.status, 1);
  EXPECT_NE(gaveUp.err.find("frame 21 will not come"), std::string::npos) << gaveUp.err;
  fs::remove_all(out);
}

// --slurm --dry-run prints every job's script with the options a cluster needs and the sbatch commands that
// chain them, and writes nothing; without sbatch on PATH, --slurm stops before writing anything.
TEST(Cluster, SlurmDryRunPrintsTheJobsAndWritesNothing) {
  const fs::path scene = writeTestScene("small.json", kSmallScene);
  const fs::path out = freshFolder("surge_cluster_dry");
  const SurgeResult dry = runSurge("run '" + scene.string() + "' --slurm --dry-run --chunk 2 --partition gpu " +
                                   "--account lab --time 1:00:00 --mem 4G --cpus-per-task 3 " +
                                   "--sbatch=--qos=low --set output.frames=4 --out '" + out.string() + "'");
  ASSERT_EQ(dry.status, 0) << dry.err;
  EXPECT_FALSE(fs::exists(out)) << "a dry run wrote " << out;
  for (const char* line : {"#SBATCH --partition=gpu", "#SBATCH --account=lab", "#SBATCH --time=1:00:00",
                           "#SBATCH --mem=4G", "#SBATCH --cpus-per-task=3", "#SBATCH --qos=low", "#SBATCH --requeue",
                           "#SBATCH --array=0-2", "--set 'output.frames=4'", "first=$(( SLURM_ARRAY_TASK_ID * 2 ))",
                           "--dependency=afterok:<sim job id>", "--dependency=aftercorr:<surface job id>",
                           "--dependency=afterok:<render job id>"})
    EXPECT_NE(dry.out.find(line), std::string::npos) << "missing: " << line << "\n" << dry.out;
  // Frames 0-4 in chunks of 2: three tasks, in each of the two arrays, and every script names the folder.
  size_t arrays = 0;
  for (size_t at = dry.out.find("#SBATCH --array=0-2"); at != std::string::npos;
       at = dry.out.find("#SBATCH --array=0-2", at + 1))
    ++arrays;
  EXPECT_EQ(arrays, 2u);
  EXPECT_EQ(dry.out.find("whitewater"), std::string::npos) << "a scene without whitewater got its job";

  // With whitewater, its one job comes between the simulation and the surfaces, which wait for it.
  const SurgeResult white = runSurge("run '" + scene.string() + "' --slurm --dry-run --chunk 2 --set output.frames=4 " +
                                     "--set whitewater.enabled=1 --out '" + out.string() + "'");
  ASSERT_EQ(white.status, 0) << white.err;
  for (const char* line : {" whitewater ", "--dependency=afterok:<sim job id>",
                           "--dependency=afterok:<whitewater job id>", "--dependency=aftercorr:<surface job id>"})
    EXPECT_NE(white.out.find(line), std::string::npos) << "missing: " << line << "\n" << white.out;
  EXPECT_FALSE(fs::exists(out));

  const char* path = std::getenv("PATH");
  const std::string saved = path ? path : "";
  ::setenv("PATH", "/nonexistent", 1);
  const SurgeResult missing = runSurge("run '" + scene.string() + "' --slurm --out '" + out.string() + "'");
  ::setenv("PATH", saved.c_str(), 1);
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("sbatch not found"), std::string::npos) << missing.err;
  EXPECT_FALSE(fs::exists(out));
  // Slurm's options need --slurm.
  EXPECT_EQ(runSurge("run '" + scene.string() + "' --chunk 3 --out '" + out.string() + "'").status, 2);
}

}  // namespace
}  // namespace surge
