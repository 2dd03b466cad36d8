// ValidateErrorMapSettings (core/errormap/error_map.cpp): each field's edges.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "core/errormap/error_map.h"

namespace surfinspect {
namespace {

void ExpectEdge(const std::string& field,
                const std::function<void(ErrorMapSettings&, double)>& edit, double ok, double bad) {
  ErrorMapSettings s;
  edit(s, ok);
  EXPECT_TRUE(ValidateErrorMapSettings(s).ok())
      << field << " = " << ok << ": " << ValidateErrorMapSettings(s);
  s = ErrorMapSettings{};
  edit(s, bad);
  const absl::Status st = ValidateErrorMapSettings(s);
  EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument) << field << " = " << bad;
  EXPECT_NE(st.message().find(field), absl::string_view::npos) << st;
}

TEST(ErrorMapSettings, DefaultsAreValid) { EXPECT_TRUE(ValidateErrorMapSettings({}).ok()); }

TEST(ErrorMapSettings, EachFieldAtItsEdges) {
  auto tol = [](ErrorMapSettings& s, double v) { s.tolerance_mm = v; };
  ExpectEdge("tolerance_mm", tol, 1e-9, 0);
  ExpectEdge("tolerance_mm", tol, 1e300, INFINITY);
  ExpectEdge("tolerance_mm", tol, 0.1, NAN);
  auto dist = [](ErrorMapSettings& s, double v) { s.max_distance_mm = v; };
  ExpectEdge("max_distance_mm", dist, INFINITY, 0);
  ExpectEdge("max_distance_mm", dist, 1e-9, NAN);
  auto frac = [](ErrorMapSettings& s, double v) { s.allowed_fraction_outside = v; };
  ExpectEdge("allowed_fraction_outside", frac, 0, -1e-12);
  ExpectEdge("allowed_fraction_outside", frac, 1, std::nextafter(1.0, 2.0));
  auto bins = [](ErrorMapSettings& s, double v) { s.histogram_bins = static_cast<int>(v); };
  ExpectEdge("histogram_bins", bins, 1, 0);
  ExpectEdge("histogram_bins", bins, kMaxHistogramBins, kMaxHistogramBins + 1);
  auto range = [](ErrorMapSettings& s, double v) { s.histogram_range_mm = v; };
  ExpectEdge("histogram_range_mm", range, 0, -1e-12);
  ExpectEdge("histogram_range_mm", range, 1e300, INFINITY);
  // Denormal lengths would overflow the bin width (bins / 2 range).
  ExpectEdge("histogram_range_mm", range, kMinLengthMm, 1e-310);
  ExpectEdge("tolerance_mm", tol, kMinLengthMm, 1e-310);
  auto threads = [](ErrorMapSettings& s, double v) { s.threads = static_cast<int>(v); };
  ExpectEdge("threads", threads, 0, -1);
  ExpectEdge("threads", threads, kMaxQueryThreads, kMaxQueryThreads + 1);
}

}  // namespace
}  // namespace surfinspect
