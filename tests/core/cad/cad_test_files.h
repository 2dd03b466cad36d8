// The real STEP files of ../shared/realdata/cad beside the checkout. Tests
// that need a real file skip loudly without it.
#pragma once

#include <string>

#include "tests/support/real_data.h"

namespace surfinspect::testing {

inline std::string RealCad(const std::string& name) { return RealData("cad/" + name); }

#define SKIP_WITHOUT_REAL_CAD() SKIP_WITHOUT_REAL_DATA("cad/cube-mm.step")

}  // namespace surfinspect::testing
