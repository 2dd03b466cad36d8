// The wire (proto/convert) and the cell file (client/cell/cell_config) refuse
// exactly the error-map settings that ValidateErrorMapSettings refuses, and
// the wire refuses the ICP settings ValidateIcpSettings refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "client/cell/cell_config.h"
#include "core/io/atomic_file.h"
#include "core/io/io_transform.h"
#include "proto/convert.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

// A minimal cell file with one error-map field set to `value`.
absl::Status ReadCellWith(const std::string& dir, const std::string& field, double value) {
  nlohmann::json cell = {
      {"part",
       {{"mesh", "part.stl"},
        {"world_from_part", TransformToJsonValue(Eigen::Isometry3d::Identity())}}},
      {"viewpoints", {{{"name", "v1"}}}}};
  if (field == "tolerance_mm")
    cell["tolerance_mm"] = value;
  else if (field == "histogram_bins")
    cell["error_map"][field] = static_cast<int>(value);
  else
    cell["error_map"][field] = value;
  const std::string path = dir + "/cell.json";
  if (auto st = WriteStringAtomically(path, cell.dump()); !st.ok()) return st;
  return client::ReadCellConfig(path).status();
}

absl::Status WireWith(const std::string& field, double value) {
  v1::ErrorMapSettings msg;
  if (field == "tolerance_mm") msg.set_tolerance_mm(value);
  if (field == "max_distance_mm") msg.set_max_distance_mm(value);
  if (field == "allowed_fraction_outside") msg.set_allowed_fraction_outside(value);
  if (field == "histogram_bins") msg.set_histogram_bins(static_cast<uint32_t>(value));
  return wire::ErrorMapSettingsFromProto(msg, "settings").status();
}

TEST(SettingsLimits, WireAndCellFileRefuseTheSameErrorMapSettings) {
  testing::TempDir dir;
  struct Case {
    std::string field;
    double value;
  };
  const Case cases[] = {
      {"tolerance_mm", 0.3},
      {"tolerance_mm", 0},
      {"tolerance_mm", -0.1},
      {"tolerance_mm", 1e-9},
      {"max_distance_mm", 5},
      {"max_distance_mm", 0},
      {"max_distance_mm", -1},
      {"allowed_fraction_outside", 0.001},
      {"allowed_fraction_outside", 1},
      {"allowed_fraction_outside", 1.5},
      {"allowed_fraction_outside", -0.1},
      {"histogram_bins", 1},
      {"histogram_bins", 0},
      {"histogram_bins", kMaxHistogramBins},
      {"histogram_bins", kMaxHistogramBins + 1},
      {"histogram_bins", 10001},
  };
  for (const Case& c : cases) {
    ErrorMapSettings s;
    if (c.field == "tolerance_mm") s.tolerance_mm = c.value;
    if (c.field == "max_distance_mm") s.max_distance_mm = c.value;
    if (c.field == "allowed_fraction_outside") s.allowed_fraction_outside = c.value;
    if (c.field == "histogram_bins") s.histogram_bins = static_cast<int>(c.value);
    const bool core_ok = ValidateErrorMapSettings(s).ok();
    const absl::Status wire = WireWith(c.field, c.value);
    const absl::Status cell = ReadCellWith(dir.path(), c.field, c.value);
    EXPECT_EQ(wire.ok(), core_ok) << c.field << " = " << c.value << ": " << wire;
    EXPECT_EQ(cell.ok(), core_ok) << c.field << " = " << c.value << ": " << cell;
    if (!core_ok) {
      EXPECT_NE(wire.message().find(c.field), absl::string_view::npos) << wire;
      EXPECT_NE(cell.message().find(c.field), absl::string_view::npos) << cell;
    }
  }
}

TEST(SettingsLimits, WireRefusesWhatTheIcpValidatorRefuses) {
  for (uint32_t iterations :
       {0u, 1u, uint32_t(kMaxIcpIterations), uint32_t(kMaxIcpIterations) + 1, 4000000000u}) {
    v1::IcpSettings msg;
    msg.set_max_iterations(iterations);
    IcpSettings s;
    s.max_iterations = static_cast<int>(std::min<uint32_t>(iterations, INT32_MAX));
    const absl::Status wire = wire::IcpSettingsFromProto(msg, "icp").status();
    EXPECT_EQ(wire.ok(), ValidateIcpSettings(s).ok()) << iterations << ": " << wire;
    if (!wire.ok()) {
      EXPECT_NE(wire.message().find("max_iterations"), absl::string_view::npos) << wire;
    }
  }
  v1::IcpSettings msg;
  msg.set_trim_fraction(0.95);
  const absl::Status wire = wire::IcpSettingsFromProto(msg, "icp").status();
  EXPECT_FALSE(wire.ok());
  EXPECT_NE(wire.message().find("trim_fraction"), absl::string_view::npos) << wire;
}

}  // namespace
}  // namespace surfinspect
