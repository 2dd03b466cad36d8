// fuzz_replay CORPUS_DIR [--max-seconds S]: feeds every file of
// CORPUS_DIR/<target>/ to that target, in the normal build and without
// sanitizers. It fails when a corpus folder names no target, when a target
// has no corpus, or when one input takes longer than S seconds (default 5:
// no reader may spend more on an input under 1 MB). A crash ends the program,
// which ctest reports as a failure with the last file named on stderr.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz/replay.h"

namespace fs = std::filesystem;
using surfinspect::fuzz::Targets;

namespace {

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

std::vector<fs::path> FilesIn(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(folder))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Returns the number of failures for one target's folder.
int ReplayTarget(const std::string& name, const fs::path& folder, double max_seconds, int* inputs) {
  int failed = 0;
  for (const auto& file : FilesIn(folder)) {
    const std::string bytes = ReadAll(file);
    std::fprintf(stderr, "%s: %s\n", name.c_str(), file.filename().c_str());
    const auto start = std::chrono::steady_clock::now();
    Targets().at(name)(bytes);
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++*inputs;
    if (s > max_seconds) {
      std::printf("SLOW %s/%s: %.2f s\n", name.c_str(), file.filename().c_str(), s);
      ++failed;
    }
  }
  return failed;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: fuzz_replay CORPUS_DIR [--max-seconds S]\n");
    return 2;
  }
  const fs::path corpus = argv[1];
  const double max_seconds =
      argc >= 4 && std::strcmp(argv[2], "--max-seconds") == 0 ? std::atof(argv[3]) : 5.0;
  int inputs = 0, passed = 0, failed = 0;
  for (const auto& [name, fn] : Targets()) {
    const fs::path folder = corpus / name;
    if (!fs::is_directory(folder) || FilesIn(folder).empty()) {
      std::printf("FAIL %s: no corpus in %s\n", name.c_str(), folder.c_str());
      ++failed;
      continue;
    }
    const int f = ReplayTarget(name, folder, max_seconds, &inputs);
    (f == 0 ? passed : failed) += 1;
    std::printf("%s %s: %zu inputs\n", f == 0 ? "ok" : "FAIL", name.c_str(),
                FilesIn(folder).size());
  }
  for (const auto& e : fs::directory_iterator(corpus))
    if (e.is_directory() && Targets().count(e.path().filename().string()) == 0) {
      std::printf("FAIL %s: a corpus folder without a target\n", e.path().filename().c_str());
      ++failed;
    }
  std::printf("%d inputs replayed\n%d passed, %d failed\n", inputs, passed, failed);
  return failed == 0 ? 0 : 1;
}
