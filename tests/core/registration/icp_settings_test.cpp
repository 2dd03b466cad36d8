// ValidateIcpSettings (core/registration/icp.cpp): each field's edges.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "core/registration/icp.h"

namespace surfinspect {
namespace {

// OK with `edit` applied at `ok`, refused (naming `field`) at `bad`.
void ExpectEdge(const std::string& field, const std::function<void(IcpSettings&, double)>& edit,
                double ok, double bad) {
  IcpSettings s;
  edit(s, ok);
  EXPECT_TRUE(ValidateIcpSettings(s).ok())
      << field << " = " << ok << ": " << ValidateIcpSettings(s);
  s = IcpSettings{};
  edit(s, bad);
  const absl::Status st = ValidateIcpSettings(s);
  EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument) << field << " = " << bad;
  EXPECT_NE(st.message().find(field), absl::string_view::npos) << st;
}

TEST(IcpSettings, DefaultsAreValid) { EXPECT_TRUE(ValidateIcpSettings({}).ok()); }

TEST(IcpSettings, EachFieldAtItsEdges) {
  auto iterations = [](IcpSettings& s, double v) { s.max_iterations = static_cast<int>(v); };
  ExpectEdge("max_iterations", iterations, kMaxIcpIterations, kMaxIcpIterations + 1);
  ExpectEdge("max_iterations", iterations, 0, -1);
  ExpectEdge(
      "max_correspondence_mm", [](IcpSettings& s, double v) { s.max_correspondence_mm = v; }, 1e9,
      INFINITY);
  ExpectEdge(
      "max_correspondence_mm", [](IcpSettings& s, double v) { s.max_correspondence_mm = v; },
      IcpSettings{}.min_correspondence_mm, 0);
  auto min_corr = [](IcpSettings& s, double v) { s.min_correspondence_mm = v; };
  ExpectEdge("min_correspondence_mm", min_corr, IcpSettings{}.max_correspondence_mm,
             std::nextafter(IcpSettings{}.max_correspondence_mm, INFINITY));
  ExpectEdge("min_correspondence_mm", min_corr, 1e-9, 0);
  auto trim = [](IcpSettings& s, double v) { s.trim_fraction = v; };
  ExpectEdge("trim_fraction", trim, 0, -1e-9);
  ExpectEdge("trim_fraction", trim, std::nextafter(0.9, 0.0), 0.9);
  ExpectEdge(
      "kernel_scale_mm", [](IcpSettings& s, double v) { s.kernel_scale_mm = v; }, 1e-9, 0);
  auto rel = [](IcpSettings& s, double v) { s.relative_cost_tolerance = v; };
  ExpectEdge("relative_cost_tolerance", rel, 0, -1e-12);
  ExpectEdge("relative_cost_tolerance", rel, 1e300, INFINITY);
  ExpectEdge(
      "absolute_cost_mm2", [](IcpSettings& s, double v) { s.absolute_cost_mm2 = v; }, 0, -1e-12);
  ExpectEdge(
      "absolute_cost_mm2", [](IcpSettings& s, double v) { s.absolute_cost_mm2 = v; }, 0, NAN);
}

}  // namespace
}  // namespace surfinspect
