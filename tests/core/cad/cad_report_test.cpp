#include "core/cad/cad_report.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

TEST(CadReport, EncodeThenDecodeGivesTheSameReport) {
  CadReport r;
  r.source = "part.step";
  r.format = "STEP";
  r.declared_unit = "INCH";
  r.bodies = {"a", "b"};
  r.body = "b";
  r.faces = 3;
  r.triangles = 40;
  r.chord_tolerance_mm = 0.01;
  r.tessellation_error_mm = 0.0071;
  r.tolerance_held = true;
  r.passes = 2;
  r.face_error_mm = {0.001, 0.0071, 0.0};
  r.bounds_mm.Extend({1, 2, 3});
  r.bounds_mm.Extend({4, 5, 6});
  const auto back = DecodeCadReport(EncodeCadReport(r));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(EncodeCadReport(*back), EncodeCadReport(r));
  EXPECT_EQ(back->bodies, r.bodies);
  EXPECT_EQ(back->face_error_mm, r.face_error_mm);
  EXPECT_EQ(EncodeCadReport(r)["tessellation_error_mm"], 0.0071);
}

TEST(CadReport, AWrongTypeIsRefusedByName) {
  nlohmann::json j = EncodeCadReport({});
  j["face_error_mm"] = "many";
  const auto back = DecodeCadReport(j);
  EXPECT_EQ(back.status().code(), absl::StatusCode::kDataLoss);
  EXPECT_NE(back.status().message().find("cad.face_error_mm"), std::string::npos);
}

}  // namespace
}  // namespace surfinspect
