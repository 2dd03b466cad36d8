// ReadCellConfig (client/cell/cell_config.cpp): the settings blocks of
// cell.json, and numbers that must not wrap or overflow on their way into
// fixed-width fields.
#include "client/cell/cell_config.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {

const char* kIdentity = R"({"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]})";

std::string Cell(const std::string& extra) {
  return std::string(R"({"part": {"mesh": "part.stl", "world_from_part": )") + kIdentity +
         R"(}, "viewpoints": [{"name": "v1"}])" + extra + "}";
}

absl::StatusOr<CellConfig> Read(const std::string& text) {
  static testing::TempDir dir;
  const std::string path = dir.File("cell.json");
  testing::WriteBytes(path, text);
  return ReadCellConfig(path);
}

TEST(CellConfig, ReadsTheSettingsBlocks) {
  auto c = Read(Cell(R"(, "tolerance_mm": 0.2,
      "error_map": {"max_distance_mm": 4, "allowed_fraction_outside": 0.01, "histogram_bins": 31},
      "filter": {"enabled": false, "link_distance_mm": 0.7, "min_cluster_points": 20,
                 "connectivity": 4})"));
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_DOUBLE_EQ(c->error_map.tolerance_mm, 0.2);
  EXPECT_DOUBLE_EQ(c->error_map.max_distance_mm, 4);
  EXPECT_DOUBLE_EQ(c->error_map.allowed_fraction_outside, 0.01);
  EXPECT_EQ(c->error_map.histogram_bins, 31);
  EXPECT_FALSE(c->filter);
  EXPECT_FLOAT_EQ(c->filter_settings.link_distance_mm, 0.7f);
  EXPECT_EQ(c->filter_settings.min_cluster_points, 20u);
  EXPECT_EQ(c->filter_settings.connectivity, 4);
}

// "units" for the scans and the part, sensor.units and part.units for each;
// absent = millimetres assumed (and doubted where implausible); a STEP part
// declares its own; a bad unit is named with its field.
TEST(CellConfig, UnitsAreStatedForBothOrEachAndAssumedOtherwise) {
  auto none = Read(Cell(""));
  ASSERT_TRUE(none.ok()) << none.status();
  EXPECT_FALSE(none->sensor_units.stated);
  EXPECT_FALSE(none->part_units.stated);
  auto both = Read(Cell(R"(, "units": "in")"));
  ASSERT_TRUE(both.ok()) << both.status();
  EXPECT_EQ(both->sensor_units.unit, LengthUnit::kInch);
  EXPECT_EQ(both->part_units.unit, LengthUnit::kInch);
  EXPECT_TRUE(both->part_units.stated);
  auto each = Read(Cell(R"(, "units": "mm", "sensor": {"units": "m"})"));
  ASSERT_TRUE(each.ok()) << each.status();
  EXPECT_EQ(each->sensor_units.unit, LengthUnit::kMetre);
  EXPECT_EQ(each->part_units.unit, LengthUnit::kMillimetre);
  EXPECT_TRUE(each->part_units.stated);
  const auto bad = Read(Cell(R"(, "sensor": {"units": "metres"})"));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("sensor.units: unknown length unit \"metres\""),
            std::string::npos)
      << bad.status();
  const auto number = Read(Cell(R"(, "units": 1000)"));
  EXPECT_NE(number.status().message().find("units: must be a string"), std::string::npos)
      << number.status();
}

TEST(CellConfig, AStepPartDeclaresItsOwnUnit) {
  const std::string step = std::string(R"({"part": {"mesh": "p.stp", "world_from_part": )") +
                           kIdentity + R"(}, "viewpoints": [{"name": "v1"}], "units": "m")";
  auto c = Read(step + "}");
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->sensor_units.unit, LengthUnit::kMetre);
  EXPECT_EQ(c->part_units.unit, LengthUnit::kMillimetre);  // OpenCASCADE converts
  EXPECT_TRUE(c->part_units.stated);
  std::string with_units = step;
  with_units.replace(with_units.find("\"p.stp\""), 7, R"("p.stp", "units": "in")");
  const auto refused = Read(with_units + "}");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("part.units: a STEP/IGES part declares its own unit"),
            std::string::npos)
      << refused.status();
}

// "outputs" names the files each part gets, by catalogue name; an unknown
// name is refused by name before any part is taken.
TEST(CellConfig, OutputsAreCatalogueNamesAndTheDefaultLeavesOutTheCsv) {
  auto plain = Read(Cell(""));
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_EQ(plain->outputs.Names(), PartFileSet::Defaults().Names());
  EXPECT_FALSE(plain->outputs.Has(PartFile::kCsv));
  auto some = Read(Cell(R"(, "outputs": ["csv", "pdf"])"));
  ASSERT_TRUE(some.ok()) << some.status();
  EXPECT_EQ(some->outputs.Names(), "report, csv, pdf");
  auto unknown = Read(Cell(R"(, "outputs": ["ply", "stl"])"));
  EXPECT_EQ(unknown.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(unknown.status().message().find("cell.json"), std::string::npos) << unknown.status();
  EXPECT_NE(unknown.status().message().find("unknown output \"stl\""), std::string::npos)
      << unknown.status();
  EXPECT_FALSE(Read(Cell(R"(, "outputs": "ply")")).ok());
  EXPECT_FALSE(Read(Cell(R"(, "outputs": [1])")).ok());
}

// The cell's name goes into results, topics and the store: it defaults to the
// folder's name and is refused, by name, when it could break a path or topic.
TEST(CellConfig, NameDefaultsToTheFolderAndIsCheckedForSafeCharacters) {
  auto c = Read(Cell(R"(, "name": "press-line_2.cell")"));
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->name, "press-line_2.cell");
  auto d = Read(Cell(""));
  ASSERT_TRUE(d.ok()) << d.status();
  EXPECT_EQ(d->name, std::filesystem::path(d->path).parent_path().filename().string());
  EXPECT_FALSE(d->name.empty());
  for (const char* bad : {R"("a/b")", R"("plant/#")", R"("")", R"(7)", R"("x y")"}) {
    auto e = Read(Cell(std::string(R"(, "name": )") + bad));
    ASSERT_FALSE(e.ok()) << bad;
    EXPECT_NE(std::string(e.status().message()).find("name"), std::string::npos) << e.status();
  }
}

TEST(CellConfig, RefusesNumbersThatWouldWrapOrOverflowByName) {
  const std::pair<std::string, std::string> cases[] = {
      {R"(, "filter": {"min_cluster_points": -5})", "filter.min_cluster_points"},
      {R"(, "filter": {"min_cluster_points": 1e300})", "filter.min_cluster_points"},
      {R"(, "filter": {"connectivity": 1e300})", "filter.connectivity"},
      {R"(, "filter": {"connectivity": 4.5})", "filter.connectivity"},
      {R"(, "filter": {"link_distance_mm": "x"})", "filter.link_distance_mm"},
      {R"(, "error_map": {"histogram_bins": 1e300})", "error_map.histogram_bins"},
      {R"(, "error_map": {"histogram_bins": 4294967337})", "error_map.histogram_bins"},
      {R"(, "error_map": {"max_distance_mm": null})", "error_map.max_distance_mm"},
      {R"(, "tolerance_mm": "0.1")", "cell.tolerance_mm"},
      {R"(, "error_map": [1, 2])", "error_map must be an object"},
  };
  for (const auto& [extra, field] : cases) {
    auto c = Read(Cell(extra));
    ASSERT_FALSE(c.ok()) << extra;
    EXPECT_EQ(c.status().code(), absl::StatusCode::kInvalidArgument) << extra;
    EXPECT_NE(c.status().message().find(field), std::string::npos) << extra << ": " << c.status();
  }
}

TEST(CellConfig, ValuesInRangeStillMeetTheOneValidator) {
  // A whole number in range reaches ValidateLinkClusteringSettings, which
  // knows connectivity is 4 or 8.
  auto c = Read(Cell(R"(, "filter": {"connectivity": 6})"));
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("connectivity"), std::string::npos) << c.status();
}

}  // namespace
}  // namespace surfinspect::client
