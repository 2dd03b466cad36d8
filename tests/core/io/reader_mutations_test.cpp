// Random truncations and byte flips of valid files, seeded, through every
// byte-buffer parser (pcd_format, ply_cloud, ply_mesh, off_format,
// mesh_precheck). None may crash, hang or throw: each gives a value or an
// error with a message.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>

#include "core/io/mesh_precheck.h"
#include "core/io/off_format.h"
#include "core/io/pcd_format.h"
#include "core/io/ply_cloud.h"
#include "core/io/ply_mesh.h"

namespace surfinspect {
namespace {

namespace fs = std::filesystem;

using Parser = std::function<absl::Status(std::string_view)>;

std::vector<std::string> Seeds(const char* target) {
  std::vector<std::string> out;
  const fs::path dir = fs::path(SURFINSPECT_SOURCE_DIR) / "fuzz" / "corpus" / target;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().filename().string().rfind("seed-", 0) != 0) continue;
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    out.push_back(ss.str());
  }
  return out;
}

// Returns how many mutants parsed.
int Mutate(const char* target, const Parser& parse, int rounds) {
  const std::vector<std::string> seeds = Seeds(target);
  EXPECT_FALSE(seeds.empty()) << target;
  for (const std::string& s : seeds) EXPECT_TRUE(parse(s).ok()) << target << ": " << parse(s);
  std::mt19937 rng(20);
  int ok = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < rounds; ++i) {
    std::string m = seeds[rng() % seeds.size()];
    if (i % 3 == 0) {
      m.resize(rng() % m.size());
    } else {
      const int flips = 1 + rng() % 4;
      for (int k = 0; k < flips; ++k) {
        const char pool[] = " 0123456789.-+e\n\r\tnaxf#/\xff\x00";
        m[rng() % m.size()] = (i % 2) ? static_cast<char>(rng()) : pool[rng() % (sizeof(pool) - 1)];
      }
    }
    const absl::Status st = parse(m);
    if (st.ok()) {
      ++ok;
    } else {
      EXPECT_FALSE(st.message().empty()) << target << " mutant " << i;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 20.0) << target;
  return ok;
}

constexpr int kRounds = 3000;

TEST(ReaderMutations, Pcd) {
  Mutate(
      "pcd", [](std::string_view b) { return ParsePcd(b).status(); }, kRounds);
}

TEST(ReaderMutations, PlyCloud) {
  Mutate(
      "ply_cloud", [](std::string_view b) { return ParsePlyCloud(b).status(); }, kRounds);
}

TEST(ReaderMutations, PlyMesh) {
  Mutate(
      "ply_mesh", [](std::string_view b) { return ParsePlyMesh(b).status(); }, kRounds);
}

TEST(ReaderMutations, Off) {
  Mutate(
      "off", [](std::string_view b) { return ParseOff(b).status(); }, kRounds);
}

TEST(ReaderMutations, StlCheck) {
  Mutate(
      "stl", [](std::string_view b) { return CheckStl(b); }, kRounds);
}

TEST(ReaderMutations, ObjCheck) {
  Mutate(
      "obj", [](std::string_view b) { return CheckObj(b); }, kRounds);
}

}  // namespace
}  // namespace surfinspect
