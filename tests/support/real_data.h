// The real public files of ../shared/realdata beside the checkout (PCL's
// clouds in metres, STEP parts; their licences are there). Tests that need
// one skip loudly without them, as the QIF schema test does.
#pragma once

#include <filesystem>
#include <string>

namespace surfinspect::testing {

// `relative` under realdata/, e.g. "clouds/table_scene_mug_stereo_textured.pcd".
inline std::string RealData(const std::string& relative) {
  return (std::filesystem::path(SURFINSPECT_SOURCE_DIR) / ".." / "shared" / "realdata" / relative)
      .lexically_normal()
      .string();
}

inline bool HaveRealData(const std::string& relative) {
  return std::filesystem::exists(RealData(relative));
}

#define SKIP_WITHOUT_REAL_DATA(relative)               \
  if (!::surfinspect::testing::HaveRealData(relative)) \
  GTEST_SKIP() << "../shared/realdata/" << (relative)  \
               << " not found beside the checkout: REAL FILES NOT CHECKED"

}  // namespace surfinspect::testing
