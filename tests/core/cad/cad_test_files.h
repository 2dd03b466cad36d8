// The real STEP files of ../shared/realdata/cad beside the checkout, and the
// built worker. Tests that need a real file skip loudly without it.
#pragma once

#include <filesystem>
#include <string>

namespace surfinspect::testing {

inline std::string RealCad(const std::string& name) {
  return (std::filesystem::path(SURFINSPECT_SOURCE_DIR) / ".." / "shared" / "realdata" / "cad" /
          name)
      .lexically_normal()
      .string();
}

inline bool HaveRealCad() { return std::filesystem::exists(RealCad("cube-mm.step")); }

#define SKIP_WITHOUT_REAL_CAD()                                                            \
  if (!::surfinspect::testing::HaveRealCad())                                              \
  GTEST_SKIP() << "../shared/realdata/cad not found beside the checkout: REAL STEP FILES " \
                  "NOT CHECKED"

}  // namespace surfinspect::testing
