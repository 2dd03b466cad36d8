// The shape of core/, checked by reading the files: the stage folders include
// only from themselves and earlier stages, and every source file has a test.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

// The stages, lowest first; core/CMakeLists.txt lists the same order.
const std::vector<std::string> kStages = {"types",        "io",       "filter",     "distance",   "cad",
                                          "registration", "errormap", "plan",       "pipeline",
                                          "report",       "history",  "acceptance", "simulation"};

const fs::path kCore = fs::path(SURFINSPECT_SOURCE_DIR) / "core";
const fs::path kTests = fs::path(SURFINSPECT_SOURCE_DIR) / "tests" / "core";

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The folder names X of every `#include "core/X/..."` in the file.
std::vector<std::string> IncludedFolders(const fs::path& path) {
  static const std::regex include(R"(#include\s+"core/([a-z_]+)/)");
  const std::string text = ReadAll(path);
  std::vector<std::string> folders;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), include);
       it != std::sregex_iterator(); ++it)
    folders.push_back((*it)[1]);
  return folders;
}

int StageRank(const std::string& folder) {
  auto it = std::find(kStages.begin(), kStages.end(), folder);
  return it == kStages.end() ? -1 : static_cast<int>(it - kStages.begin());
}

std::vector<fs::path> SourcesIn(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const auto ext = entry.path().extension();
    if (ext == ".h" || ext == ".cpp") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(CoreLayering, TopLevelHoldsOnlyTheStageFoldersAndProcess) {
  for (const auto& entry : fs::directory_iterator(kCore)) {
    const std::string name = entry.path().filename().string();
    if (name == "CMakeLists.txt") continue;
    EXPECT_TRUE(entry.is_directory()) << "a file at the top of core/: " << name;
    EXPECT_TRUE(StageRank(name) >= 0 || name == "process") << "unknown folder core/" << name;
  }
}

TEST(CoreLayering, NoStageIncludesALaterStage) {
  int files = 0;
  for (std::size_t rank = 0; rank < kStages.size(); ++rank) {
    for (const auto& file : SourcesIn(kCore / kStages[rank])) {
      ++files;
      for (const auto& folder : IncludedFolders(file)) {
        const int included = StageRank(folder);
        EXPECT_GE(included, 0) << file << " includes core/" << folder << "/ (not a stage)";
        EXPECT_LE(included, static_cast<int>(rank))
            << file << " includes the later stage core/" << folder << "/";
      }
    }
  }
  EXPECT_GT(files, 40);  // the walk found the sources
}

TEST(CoreLayering, ProcessSettingsIncludeNoGeometry) {
  for (const auto& file : SourcesIn(kCore / "process"))
    for (const auto& folder : IncludedFolders(file))
      EXPECT_EQ(folder, "process") << file << " includes core/" << folder << "/";
}

TEST(CoreLayering, EveryCoreSourceHasATest) {
  // A source is covered by tests/core/STAGE/NAME_test.cpp, or by a test file
  // in the same stage folder that names "core/STAGE/NAME.cpp".
  std::vector<std::string> stages = kStages;
  stages.push_back("process");
  for (const auto& stage : stages) {
    std::string stage_tests;
    if (fs::exists(kTests / stage))
      for (const auto& test : SourcesIn(kTests / stage)) stage_tests += ReadAll(test);
    for (const auto& file : SourcesIn(kCore / stage)) {
      if (file.extension() != ".cpp") continue;
      const std::string name = file.stem().string();
      const std::string quoted = "core/" + stage + "/" + name + ".cpp";
      EXPECT_TRUE(fs::exists(kTests / stage / (name + "_test.cpp")) ||
                  stage_tests.find(quoted) != std::string::npos)
          << quoted << " has no test file and no test names it";
    }
  }
}

}  // namespace
