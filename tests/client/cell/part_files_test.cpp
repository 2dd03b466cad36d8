// client/cell/part_files.cpp: the catalogue of a part's files, its sets, and
// its writer: the files of a set and no others, report.json last.
#include "client/cell/part_files.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "core/io/disk_space.h"
#include "tests/support/small_file_system.h"
#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {

namespace fs = std::filesystem;

TEST(PartFiles, TheCatalogueNamesEachFileOnceWithTheReportFirst) {
  std::set<std::string> names, files;
  for (const PartFileEntry& e : PartFileCatalogue()) {
    EXPECT_TRUE(names.insert(e.name).second) << e.name;
    EXPECT_TRUE(files.insert(e.file_name).second) << e.file_name;
    EXPECT_EQ(&EntryOf(e.file), &e);
  }
  EXPECT_EQ(PartFileCatalogue().front().file, PartFile::kReport);
  EXPECT_EQ(PartFileNames(), "ply, csv, png, pdf, html, qif");
  for (const PartFileEntry& e : PartFileCatalogue())
    EXPECT_NE(PartFilesHelp().find(e.file_name), std::string::npos) << e.file_name;
}

TEST(PartFiles, DefaultsLeaveOutTheCsvAndTheReportIsAlwaysIn) {
  const PartFileSet d = PartFileSet::Defaults();
  EXPECT_FALSE(d.Has(PartFile::kCsv));
  for (PartFile f : {PartFile::kReport, PartFile::kPly, PartFile::kPng, PartFile::kPdf,
                     PartFile::kHtml, PartFile::kQif})
    EXPECT_TRUE(d.Has(f));
  PartFileSet none;
  none.Set(PartFile::kReport, false);
  EXPECT_TRUE(none.Has(PartFile::kReport));
  EXPECT_EQ(PartFileSet::All().Names(), "report, ply, csv, png, pdf, html, qif");
}

TEST(PartFiles, ASetIsParsedFromNamesAndAnUnknownNameIsRefusedByName) {
  auto set = ParsePartFileSet({"csv", "png"}, "cell.json: outputs");
  ASSERT_TRUE(set.ok()) << set.status();
  EXPECT_EQ(set->Names(), "report, csv, png");
  auto bad = ParsePartFileSet({"ply", "xlsx"}, "cell.json: outputs");
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("cell.json: outputs: unknown output \"xlsx\""),
            std::string::npos)
      << bad.status();
  EXPECT_NE(bad.status().message().find("ply, csv"), std::string::npos);
}

PartFileInputs SomeInputs(const PointCloud& points, const ErrorMapResult& map) {
  PartFileInputs in;
  in.part_id = "p";
  in.points = &points;
  in.error_map = &map;
  in.report_text = "{}\n";
  in.png = "png bytes";
  return in;
}

// The deviations of two points, with a band and a colour range.
ErrorMapResult TwoPointMap() {
  ErrorMapResult map;
  map.deviation_mm = {0.01f, -0.02f};
  map.tolerance_mm = 0.1;
  map.color_range_mm = 0.2;
  return map;
}

TEST(PartFiles, WritesTheSetAndNothingElseWithTheReportLast) {
  testing::TempDir dir;
  const PointCloud points = PointCloud::Unorganized({{0, 0, 0}, {1, 0, 0}});
  const ErrorMapResult map = TwoPointMap();
  PartFileSet set;
  set.Set(PartFile::kCsv, true);
  set.Set(PartFile::kPng, true);
  ASSERT_TRUE(WritePartFiles(dir.File("part"), set, SomeInputs(points, map)).ok());
  std::set<std::string> written;
  for (const auto& e : fs::directory_iterator(dir.File("part")))
    written.insert(e.path().filename().string());
  EXPECT_EQ(written, (std::set<std::string>{"deviations.csv", "errormap.png", "report.json"}));
  EXPECT_EQ(testing::ReadBytes(dir.File("part/errormap.png")), "png bytes");
}

TEST(PartFiles, AFailedWriterLeavesNoFileOfTheSet) {
  testing::TempDir dir;
  const PointCloud points = PointCloud::Unorganized({{0, 0, 0}, {1, 0, 0}});
  const ErrorMapResult map = TwoPointMap();
  PartFileSet set;
  set.Set(PartFile::kCsv, true);
  set.Set(PartFile::kPng, true);
  set.Set(PartFile::kPdf, true);  // written after the CSV and the PNG; fails without a report
  uint64_t bytes = 0;
  const absl::Status st = WritePartFiles(dir.File("part"), set, SomeInputs(points, map), &bytes);
  EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(st.message().find("report.pdf"), std::string::npos) << st;
  EXPECT_FALSE(fs::exists(dir.File("part"))) << "neither the CSV nor the PNG written before it";
  EXPECT_TRUE(fs::is_empty(dir.path())) << "nor a staging folder";
  EXPECT_GT(bytes, 9u) << "what was written before the failure";
}

TEST(PartFiles, AFullDiskIsToldAndLeavesNoFile) {
  std::string why;
  const auto small = testing::SmallFileSystem::Mount(256 << 10, &why);
  if (!small) GTEST_SKIP() << why;
  std::vector<Eigen::Vector3f> xyz(50000, Eigen::Vector3f(1, 2, 3));
  const PointCloud points = PointCloud::Unorganized(xyz);
  ErrorMapResult map;
  map.deviation_mm.assign(xyz.size(), 0.01f);
  map.tolerance_mm = 0.1;
  map.color_range_mm = 0.2;
  PartFileSet set;
  set.Set(PartFile::kPly, true);  // ~1 MB: more than the file system holds
  const absl::Status st = WritePartFiles(small->File("results/part"), set, SomeInputs(points, map));
  EXPECT_TRUE(IsDiskFull(st)) << st;
  EXPECT_FALSE(fs::exists(small->File("results/part")));
  EXPECT_TRUE(fs::is_empty(small->File("results"))) << "nor a staging folder";
  EXPECT_GT(DiskSpaceOf(small->path())->free_bytes, uint64_t{200} << 10) << "space given back";
}

TEST(PartFiles, HeavyFilesAreThoseThatGrowWithThePoints) {
  std::set<std::string> heavy;
  for (const PartFileEntry& e : PartFileCatalogue())
    if (e.heavy) heavy.insert(e.name);
  EXPECT_EQ(heavy, (std::set<std::string>{"ply", "csv", "html"}));
}

}  // namespace
}  // namespace surfinspect::client
