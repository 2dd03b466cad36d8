// Replays every file under fuzz/corpus/<target>/ through the reader of its
// target (pcd, ply_cloud: ReadPointCloud; stl, obj, ply_mesh, off:
// ReadMesh). A seed-* file must read; a regress-* file (a malformed input
// that once crashed, hung or exhausted a reader) must give an error with a
// message naming the file. Each read must end within a second.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"

namespace surfinspect {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(SURFINSPECT_SOURCE_DIR) / "fuzz" / "corpus";

struct Target {
  const char* name;
  bool cloud;
};
constexpr Target kTargets[] = {{"pcd", true},  {"ply_cloud", true}, {"stl", false},
                               {"obj", false}, {"ply_mesh", false}, {"off", false}};

absl::Status ReadThrough(const Target& t, const std::string& path) {
  if (t.cloud) return ReadPointCloud(path).status();
  return ReadMesh(path).status();
}

TEST(ReaderRegressions, EveryCorpusFileGivesItsExpectedStatusWithinASecond) {
  std::size_t seeds = 0, regressions = 0;
  for (const Target& t : kTargets) {
    const fs::path dir = kCorpus / t.name;
    ASSERT_TRUE(fs::is_directory(dir)) << dir;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) files.push_back(e.path());
    ASSERT_FALSE(files.empty()) << dir;
    for (const fs::path& f : files) {
      const std::string file = f.filename().string();
      const auto start = std::chrono::steady_clock::now();
      const absl::Status st = ReadThrough(t, f.string());
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      EXPECT_LT(seconds, 1.0) << t.name << "/" << file;
      if (file.rfind("seed-", 0) == 0) {
        ++seeds;
        EXPECT_TRUE(st.ok()) << t.name << "/" << file << ": " << st;
      } else {
        ASSERT_EQ(file.rfind("regress-", 0), 0u)
            << "corpus files are seed-* or regress-*: " << file;
        ++regressions;
        EXPECT_FALSE(st.ok()) << t.name << "/" << file;
        EXPECT_FALSE(st.message().empty()) << t.name << "/" << file;
        EXPECT_NE(st.message().find(f.string()), std::string::npos) << st;
      }
    }
  }
  EXPECT_GE(seeds, 12u);
  EXPECT_GE(regressions, 10u);
}

}  // namespace
}  // namespace surfinspect
