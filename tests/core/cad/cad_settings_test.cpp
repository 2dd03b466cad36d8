#include "core/cad/cad_settings.h"

#include <gtest/gtest.h>

#include <cmath>

namespace surfinspect {
namespace {

TEST(CadSettings, DefaultsAreValid) { EXPECT_TRUE(ValidateCadSettings({}).ok()); }

TEST(CadSettings, EachFieldOutOfRangeIsNamed) {
  auto field_of = [](auto change) {
    CadSettings s;
    change(s);
    const absl::Status st = ValidateCadSettings(s);
    EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument);
    return std::string(st.message());
  };
  EXPECT_NE(field_of([](CadSettings& s) {
              s.tessellation.chord_tolerance_mm = 0;
            }).find("chord_tolerance_mm"),
            std::string::npos);
  EXPECT_NE(field_of([](CadSettings& s) {
              s.tessellation.chord_tolerance_mm = NAN;
            }).find("chord_tolerance_mm"),
            std::string::npos);
  EXPECT_NE(field_of([](CadSettings& s) {
              s.tessellation.angular_tolerance_deg = 90;
            }).find("angular_tolerance_deg"),
            std::string::npos);
  EXPECT_NE(field_of([](CadSettings& s) { s.limits.seconds = 0; }).find("limits.seconds"),
            std::string::npos);
  EXPECT_NE(field_of([](CadSettings& s) { s.limits.memory_mb = 1; }).find("memory_mb"),
            std::string::npos);
}

TEST(CadSettings, CadPathsByExtensionInAnyCase) {
  for (const char* p : {"a.step", "b.STP", "dir.x/c.Iges", "d.igs"}) EXPECT_TRUE(IsCadPath(p)) << p;
  for (const char* p : {"a.stl", "b.obj", "step", "c.step.bak", "dir.step/x.ply"})
    EXPECT_FALSE(IsCadPath(p)) << p;
}

}  // namespace
}  // namespace surfinspect
